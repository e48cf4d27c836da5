/* Material colours and the table's parameter (property x texture), normal map and tangent frame, then
 * shade_sh (sh_shading.glsl).  Writes Combined, Diffuse and Specular; the GBUFFER variant writes Diffuse,
 * Specular and the shading inputs for the numpy mirror, as the other techniques' surfaces do.
 * SH_PARAMETER: the MaterialData field of the table's parameter axis (techniques/spherical_harmonics.py). */
void main()
{
  bool front = gl_FrontFacing != (determinant(mat3(model_matrix)) < 0.0);
  vec3 normal = front ? world_normal : -world_normal;
#ifdef HAS_TRANSFER
  load_per_vertex_rows();                        /* transfer_rows: the vertex's [1, w_0, ...], interpolated */
#endif
  vec3 diffuse_color = material.diffuse_color.rgb;
  vec3 specular_color = material.specular_color.rgb;
#ifdef HAS_TEXTURE_DIFFUSE_COLOR
  diffuse_color *= texture(texture_diffuse_color, texcoord).rgb;
#endif
#ifdef HAS_TEXTURE_SPECULAR_COLOR
  specular_color *= texture(texture_specular_color, texcoord).rgb;
#endif
  float parameter = SH_PARAMETER;
#ifdef SH_PARAMETER_TEXTURE
  parameter *= texture(SH_PARAMETER_TEXTURE, texcoord).r;
#endif
  vec4 tangent = material.options.x > 0.5 ?
                     vec4(mat3(model_matrix) * material.tangent_axis_rotation.xyz, 1.0) : world_tangent;
  vec3 shading_normal = normal;
#ifdef HAS_NORMAL_MAP
  shading_normal = apply_normal_map(normal, tangent, texture(texture_normal_map, texcoord).rgb,
                                    material.parameters1.w);
#endif
  vec3 shading_tangent = rotate_tangent(shading_normal, tangent.xyz, material.tangent_axis_rotation.w);
  vec3 diffuse, specular;
  shade_sh(world_position, shading_normal, shading_tangent, diffuse_color, specular_color, parameter, diffuse,
           specular);
#ifndef GBUFFER
  out_combined = vec4(diffuse + specular, 1.0);
#endif
  out_diffuse = vec4(diffuse, 1.0);
  out_specular = vec4(specular, 1.0);
#ifdef GBUFFER
  out_position = vec4(world_position, float(gbuffer_triangle_offset + gl_PrimitiveID) + 1.0);
  out_normal = vec4(normal, float(gbuffer_object_index) + 1.0);
  out_tangent = tangent;
  out_uv = vec4(texcoord, material.options.y, 1.0);
#endif
}
