/* The lobe source of the fitted SG technique (sg_fitted; the interface: lobes_model.glsl): a stored lobe fit's
 * lobes at the pixel's texel (common/fitted_texels.glsl), their RGB amplitudes, and its M_o with S(o) set once a
 * pixel (p.z). */
#define DIFFUSE_FACTOR(world_direction) 1.0
#define DIFFUSE_ALBEDO 1.0

void lobes_begin(inout vec4 p, vec4 q, vec3 view_local)
{
#ifdef HAS_SPECULAR
  p.z = fitted_shadowing_of(view_local);       /* S(o), for model_m_factor */
#endif
}

#ifdef HAS_SPECULAR
void lobes_ndf(int k, vec4 p, vec4 q, vec3 view_local, out vec3 axis, out float sharpness, out float amplitude,
               out vec3 colour)
{
  vec4 fitted_lobe = fitted_layer(1 + 2 * k);
  axis = safe_normalize(fitted_lobe.xyz);
  sharpness = fitted_lobe.w;
  amplitude = 1.0;
  colour = fitted_layer(2 + 2 * k).rgb;
}

float lobes_m_factor(int k, vec3 ndf_axis, vec3 view_local, vec3 wi, vec4 p, vec4 q)
{
  return model_m_factor(view_local, wi, p, q);
}
#endif
