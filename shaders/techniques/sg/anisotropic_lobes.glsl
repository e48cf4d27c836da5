/* ndf_fit.anisotropic_lobes and ggx_anisotropic_lobes on the GPU: K SG lobes of an anisotropic NDF from a
 * normalized anisotropy table (a texture, texel (k, row) = (log ratio, offset along the long axis / width,
 * sharpness * width^2, amplitude / D(n)), rows log-spaced in ratio), linearly interpolated in log ratio like
 * np.interp; anisotropic GGX's table stacks GGX_ANISOTROPY_ALPHAS such blocks, one an alpha, interpolated in
 * log sqrt(alpha_x alpha_y) too.  Needs sg.glsl. */

/* The entry of lobe k at a ratio, from the block of `rows` rows starting at row `first`. */
vec4 anisotropy_entry(sampler2D table, int first, int rows, float ratio, int k)
{
  float log_min = texelFetch(table, ivec2(0, first), 0).x;
  float log_max = texelFetch(table, ivec2(0, first + rows - 1), 0).x;
  float position = clamp((log(max(ratio, exp(log_min))) - log_min) / (log_max - log_min) * float(rows - 1),
                         0.0, float(rows - 1));
  int low = clamp(int(floor(position)), 0, rows - 2);
  float fraction = position - float(low);
  return (1.0 - fraction) * texelFetch(table, ivec2(k, first + low), 0)
       + fraction * texelFetch(table, ivec2(k, first + low + 1), 0);
}

/* An entry scaled back from slopes / the long width: axis = normalize(offset * width along the long axis, 0
 * across, 1), sharpness = s / width^2, amplitude = a D(n). */
void lobe_of_entry(vec4 entry, bool long_is_x, float long_width, float peak,
                   out vec3 axis, out float sharpness, out float amplitude)
{
  float slope = entry.y * long_width;
  axis = long_is_x ? vec3(slope, 0.0, 1.0) : vec3(0.0, slope, 1.0);
  axis = axis / length(axis);
  sharpness = entry.z / (long_width * long_width);
  amplitude = entry.w * peak;
}

/* Short / long width (<= 1), which axis is the long one and its width. */
float anisotropy_ratio(float width_x, float width_y, out bool long_is_x, out float long_width)
{
  long_is_x = width_x >= width_y;
  long_width = max(long_is_x ? width_x : width_y, 1.0e-12);
  return min((long_is_x ? width_y : width_x) / long_width, 1.0);
}

void anisotropic_lobes(sampler2D table, float width_x, float width_y, float peak, int k,
                       out vec3 axis, out float sharpness, out float amplitude)
{
  bool long_is_x;
  float long_width;
  float ratio = anisotropy_ratio(width_x, width_y, long_is_x, long_width);
  vec4 entry = anisotropy_entry(table, 0, textureSize(table, 0).y, ratio, k);
  lobe_of_entry(entry, long_is_x, long_width, peak, axis, sharpness, amplitude);
}

#ifdef GGX_ANISOTROPY_ALPHAS
void ggx_anisotropic_lobes(sampler2D table, float alpha_x, float alpha_y, int k,
                           out vec3 axis, out float sharpness, out float amplitude)
{
  alpha_x = max(alpha_x, 1.0e-6);   /* D(n) = 1 / (pi ax ay) stays finite */
  alpha_y = max(alpha_y, 1.0e-6);
  int rows = textureSize(table, 0).y / GGX_ANISOTROPY_ALPHAS;
  bool long_is_x;
  float long_width;
  float ratio = anisotropy_ratio(alpha_x, alpha_y, long_is_x, long_width);
  float position = clamp((log(sqrt(alpha_x * alpha_y)) - GGX_ANISOTROPY_LOG_ALPHA_MIN)
                         / (GGX_ANISOTROPY_LOG_ALPHA_MAX - GGX_ANISOTROPY_LOG_ALPHA_MIN)
                         * float(GGX_ANISOTROPY_ALPHAS - 1), 0.0, float(GGX_ANISOTROPY_ALPHAS - 1));
  int low = clamp(int(floor(position)), 0, GGX_ANISOTROPY_ALPHAS - 2);
  float fraction = position - float(low);
  vec4 entry = (1.0 - fraction) * anisotropy_entry(table, low * rows, rows, ratio, k)
             + fraction * anisotropy_entry(table, (low + 1) * rows, rows, ratio, k);
  lobe_of_entry(entry, long_is_x, long_width, 1.0 / (SG_PI * alpha_x * alpha_y), axis, sharpness, amplitude);
}
#endif
