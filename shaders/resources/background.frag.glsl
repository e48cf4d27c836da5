/* World behind the surfaces: the world colour, or the sharpest prefiltered layer of the
 * environment texture along the view ray.  Drawn at the far plane after the surfaces. */
void main()
{
#ifdef HAS_ENVIRONMENT
  vec4 far_point = inverse_view_projection * vec4(ndc, 1.0, 1.0);
  vec4 near_point = inverse_view_projection * vec4(ndc, -1.0, 1.0);
  vec3 direction = safe_normalize(far_point.xyz / far_point.w - near_point.xyz / near_point.w);
  vec2 scale_offset[ENV_PREFILTER_MAX_LAYERS];
  for (int k = 0; k < ENV_PREFILTER_MAX_LAYERS; k++) {
    scale_offset[k] = scene.prefilter_scale_offset[k].xy;
  }
  vec3 colour = env_prefilter_lookup(environment_texture, direction, 1.0e30, scene.prefilter_info.x,
                                     scene.prefilter_info.y, scene.counts.w, scale_offset).rgb;
#else
  vec3 colour = scene.world_colour.rgb;
#endif
  out_combined = vec4(colour, background_alpha);
  out_diffuse = vec4(0.0);
  out_specular = vec4(0.0);
}
