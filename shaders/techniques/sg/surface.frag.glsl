/* Material parameters (property x texture over the active UV map), normal map, tangent
 * frame (common/surface_io.glsl), then shade_surface over the pixel's footprint (sg_shading.glsl
 * shade_footprint).  Writes Combined, Diffuse and Specular; the GBUFFER variant writes Diffuse, Specular and the shading inputs for the numpy mirror. */
void main()
{
  surface_coverage();
  vec3 normal = surface_facing_normal();
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
  surface_colour_textures(diffuse_color, specular_color);
#ifdef HAS_TEXTURE_ROUGHNESS
  p.x *= texture_value_roughness().r;
#endif
#ifdef HAS_TEXTURE_IOR
  p.y *= texture_value_ior().r;
#endif
#ifdef HAS_TEXTURE_EXPONENT
  p.z *= texture_value_exponent().r;
#endif
#ifdef HAS_TEXTURE_ALPHA_X
  p.w *= texture_value_alpha_x().r;
#endif
#ifdef HAS_TEXTURE_ALPHA_Y
  q.x *= texture_value_alpha_y().r;
#endif
#ifdef HAS_TEXTURE_NU
  q.y *= texture_value_nu().r;
#endif
#ifdef HAS_TEXTURE_NV
  q.z *= texture_value_nv().r;
#endif
  vec4 tangent;
  vec3 shading_normal, shading_tangent;
  surface_geometry(normal, tangent, shading_normal, shading_tangent);
#ifdef LAYERING
  surface_layering(shading_normal, diffuse_color, specular_color);
#endif
#ifdef LIGHT_SHADOW_MAPS
  shadow_maps_evaluate(world_position, normal);
#endif
  vec3 diffuse, specular;
  shade_footprint(world_position, shading_normal, shading_tangent, p, q, diffuse_color, specular_color,
                  diffuse, specular);
  surface_write(diffuse, specular, normal, tangent);
}
