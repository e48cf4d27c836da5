/* ndf_fit.ggx_two_lobes on the GPU: two SG lobes of GGX from the fitted table (a texture,
 * texel (k, row) = (log alpha, sharpness * alpha^2, amplitude / D(n), 0), rows log-spaced in
 * alpha), linearly interpolated in log alpha like np.interp.  The single-lobe L2 mapping
 * keeps 0.77-0.80 of GGX's projected area at roughness 0.3-0.5; two lobes keep 0.93-0.97. */
void ggx_two_lobes(sampler2D table, float roughness, int k, out float sharpness, out float amplitude)
{
  int rows = textureSize(table, 0).y;
  float log_min = texelFetch(table, ivec2(0, 0), 0).x;
  float log_max = texelFetch(table, ivec2(0, rows - 1), 0).x;
  float alpha = ggx_alpha(roughness);
  float log_alpha = log(clamp(alpha, exp(log_min), exp(log_max)));
  float position = clamp((log_alpha - log_min) / (log_max - log_min) * float(rows - 1), 0.0, float(rows - 1));
  int low = clamp(int(floor(position)), 0, rows - 2);
  float fraction = position - float(low);
  vec4 entry = (1.0 - fraction) * texelFetch(table, ivec2(k, low), 0)
             + fraction * texelFetch(table, ivec2(k, low + 1), 0);
  sharpness = entry.y / (alpha * alpha);
  amplitude = entry.z / (SG_PI * alpha * alpha);
}
