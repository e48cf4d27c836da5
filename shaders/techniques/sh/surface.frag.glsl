/* Material colours and the table's parameter (property x texture), normal map and tangent frame
 * (common/surface_io.glsl), then shade_sh (sh_shading.glsl).  Writes the passes as the other techniques'
 * surfaces do.  SH_PARAMETER: the MaterialData field of the table's parameter axis
 * (techniques/sh/spherical_harmonics.py).  SH_FITTED: kd from the lobe fit's texel, the colours in its lobes. */
void main()
{
  surface_coverage();
  vec3 normal = surface_facing_normal();
#ifdef HAS_TRANSFER
  load_per_vertex_rows();                        /* transfer_rows: the vertex's [1, w_0, ...], interpolated */
#endif
  vec3 diffuse_color = material.diffuse_color.rgb;
  vec3 specular_color = material.specular_color.rgb;
#ifdef SH_FITTED
  fitted_select_texel(texcoord);
  diffuse_color = fitted_layer(0).rgb;
  specular_color = vec3(1.0);
#endif
  surface_colour_textures(diffuse_color, specular_color);
  float parameter = SH_PARAMETER;
#ifdef SH_PARAMETER_TEXTURE
  parameter *= SH_PARAMETER_TEXTURE().r;
#endif
  vec4 tangent;
  vec3 shading_normal, shading_tangent;
  surface_geometry(normal, tangent, shading_normal, shading_tangent);
#ifdef LAYERING
  surface_layering(shading_normal, diffuse_color, specular_color);
#endif
  vec3 diffuse, specular;
  shade_sh(world_position, shading_normal, shading_tangent, diffuse_color, specular_color, parameter, diffuse,
           specular);
  surface_write(diffuse, specular, normal, tangent);
}
