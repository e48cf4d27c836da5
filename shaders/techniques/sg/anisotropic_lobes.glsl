/* ndf_fit.anisotropic_lobes on the GPU: K SG lobes of an anisotropic NDF from the
 * normalized anisotropy table (a texture, texel (k, row) = (log ratio, offset along the
 * long axis / width, sharpness * width^2, amplitude / D(n)), rows log-spaced in ratio),
 * linearly interpolated in log ratio like np.interp.  Needs sg.glsl. */
void anisotropic_lobes(sampler2D table, float width_x, float width_y, float peak, int k,
                       out vec3 axis, out float sharpness, out float amplitude)
{
  int rows = textureSize(table, 0).y;
  float log_min = texelFetch(table, ivec2(0, 0), 0).x;
  float log_max = texelFetch(table, ivec2(0, rows - 1), 0).x;
  bool long_is_x = width_x >= width_y;
  float long_width = max(long_is_x ? width_x : width_y, 1.0e-12);
  float ratio = clamp((long_is_x ? width_y : width_x) / long_width, exp(log_min), 1.0);
  float position = clamp((log(ratio) - log_min) / (log_max - log_min) * float(rows - 1), 0.0, float(rows - 1));
  int low = clamp(int(floor(position)), 0, rows - 2);
  float fraction = position - float(low);
  vec4 entry = (1.0 - fraction) * texelFetch(table, ivec2(k, low), 0)
             + fraction * texelFetch(table, ivec2(k, low + 1), 0);
  float slope = entry.y * long_width;
  axis = long_is_x ? vec3(slope, 0.0, 1.0) : vec3(0.0, slope, 1.0);
  axis = axis / length(axis);
  sharpness = entry.z / (long_width * long_width);
  amplitude = entry.w * peak;
}
