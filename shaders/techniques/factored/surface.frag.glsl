/* Material colours (property x texture), normal map and tangent frame (common/surface_io.glsl), then
 * shade_factored (factored_shading.glsl).  Writes the passes as the SG techniques' surface does. */
void main()
{
  surface_coverage();
  vec3 normal = surface_facing_normal();
#ifdef HAS_VISIBILITY
  set_visibility_frame(world_vertex_normal);     /* the bake's frame: not flipped for back faces */
  load_per_vertex_rows();
#endif
  vec3 diffuse_color = material.diffuse_color.rgb;
  vec3 specular_color = material.specular_color.rgb;
  surface_colour_textures(diffuse_color, specular_color);
  vec4 tangent;
  vec3 shading_normal, shading_tangent;
  surface_geometry(normal, tangent, shading_normal, shading_tangent);
#ifdef LAYERING
  surface_layering(shading_normal, diffuse_color, specular_color);
#endif
  vec3 diffuse, specular;
  shade_factored(world_position, shading_normal, shading_tangent, diffuse_color, specular_color, diffuse, specular);
  surface_write(diffuse, specular, normal, tangent);
}
