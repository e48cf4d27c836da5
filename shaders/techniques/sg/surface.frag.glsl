/* Material parameters (property x texture over the active UV map), normal map, tangent
 * frame, then shade_surface (sg_shading.glsl).  Writes Combined, Diffuse and
 * Specular; the GBUFFER variant writes Diffuse, Specular and the shading inputs for the
 * numpy mirror (framebuffers take 6 attachments: Combined is summed on the CPU). */
void main()
{
  /* a mirroring transform (negative determinant) reverses the triangles' winding: its front faces face away */
  bool front = gl_FrontFacing != (determinant(mat3(model_matrix)) < 0.0);
  vec3 normal = front ? world_normal : -world_normal;
#ifdef HAS_VISIBILITY
  set_visibility_frame(world_vertex_normal);     /* the bake's frame: not flipped for back faces */
  load_per_vertex_rows();     /* the SSDF coefficients and the diffuse lobes' fractions (sg_lobes.py) */
#endif
  vec3 diffuse_color = material.diffuse_color.rgb;
  vec3 specular_color = material.specular_color.rgb;
  vec4 p = material.parameters0;                  /* roughness, ior, exponent, alpha_x */
  vec4 q = vec4(material.parameters1.xyz, BRDF_AS_RF0);   /* alpha_y, nu, nv, rf0 */
#ifdef MODEL_FITTED
  /* the stored fit at the UV's nearest texel: kd and eta from the base layer, the colour in the lobes */
  fitted_select_texel(texcoord);
  vec4 fitted_base = fitted_layer(0);
  diffuse_color = fitted_base.rgb;
  specular_color = vec3(1.0);
  p.y = fitted_base.w;
#endif
#ifdef HAS_TEXTURE_DIFFUSE_COLOR
  diffuse_color *= texture(texture_diffuse_color, texcoord).rgb;
#endif
#ifdef HAS_TEXTURE_SPECULAR_COLOR
  specular_color *= texture(texture_specular_color, texcoord).rgb;
#endif
#ifdef HAS_TEXTURE_ROUGHNESS
  p.x *= texture(texture_roughness, texcoord).r;
#endif
#ifdef HAS_TEXTURE_IOR
  p.y *= texture(texture_ior, texcoord).r;
#endif
#ifdef HAS_TEXTURE_EXPONENT
  p.z *= texture(texture_exponent, texcoord).r;
#endif
#ifdef HAS_TEXTURE_ALPHA_X
  p.w *= texture(texture_alpha_x, texcoord).r;
#endif
#ifdef HAS_TEXTURE_ALPHA_Y
  q.x *= texture(texture_alpha_y, texcoord).r;
#endif
#ifdef HAS_TEXTURE_NU
  q.y *= texture(texture_nu, texcoord).r;
#endif
#ifdef HAS_TEXTURE_NV
  q.z *= texture(texture_nv, texcoord).r;
#endif

  /* tangent input: the UV map's, or the object axis in world space */
  vec4 tangent = material.options.x > 0.5 ?
                     vec4(mat3(model_matrix) * material.tangent_axis_rotation.xyz, 1.0) : world_tangent;
  vec3 shading_normal = normal;
#ifdef HAS_NORMAL_MAP
  shading_normal = apply_normal_map(normal, tangent, texture(texture_normal_map, texcoord).rgb,
                                    material.parameters1.w);
#endif
  vec3 shading_tangent = rotate_tangent(shading_normal, tangent.xyz, material.tangent_axis_rotation.w);

  vec3 diffuse, specular;
  shade_surface(world_position, shading_normal, shading_tangent, p, q, diffuse_color, specular_color,
                diffuse, specular);
#ifndef GBUFFER
  out_combined = vec4(diffuse + specular, 1.0);
#endif
  out_diffuse = vec4(diffuse, 1.0);
  out_specular = vec4(specular, 1.0);
#ifdef GBUFFER
  /* w: the triangle (index into the mesh's triangle list) and object (draw order) + 1 */
  out_position = vec4(world_position, float(gbuffer_triangle_offset + gl_PrimitiveID) + 1.0);
  out_normal = vec4(normal, float(gbuffer_object_index) + 1.0);
  out_tangent = tangent;
  out_uv = vec4(texcoord, material.options.y, 1.0);
#endif
}
