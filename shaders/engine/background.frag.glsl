/* World behind the surfaces: the world colour, or the environment texture itself along
 * the view ray (Blender's equirect mapping, as lighting/equirect.py).  Drawn at the far plane
 * after the surfaces, so the depth test keeps it behind them. */
void main()
{
#ifdef HAS_ENVIRONMENT
  vec4 far_point = inverse_view_projection * vec4(ndc, 1.0, 1.0);
  vec4 near_point = inverse_view_projection * vec4(ndc, -1.0, 1.0);
  vec3 direction = safe_normalize(far_point.xyz / far_point.w - near_point.xyz / near_point.w);
  float u = 0.5 - atan(direction.y, direction.x) / (2.0 * SG_PI);
  float v = 0.5 + atan(direction.z, length(direction.xy)) / SG_PI;
  vec3 colour = texture(equirect_texture, vec2(u, v)).rgb;
#else
  vec3 colour = scene.world_colour.rgb;
#endif
  out_combined = vec4(colour, 1.0) * background_alpha;     /* premultiplied: a transparent film is (0, 0, 0, 0) */
  out_diffuse = vec4(0.0);
  out_specular = vec4(0.0);
}
