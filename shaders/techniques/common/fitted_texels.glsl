/* A stored lobe fit's texel and shadowing (blender.lobe_fit format 1, export.FittedLobes), what the techniques
 * rendering a fit share (SG_FITTED and a bi-scale material's fitted small scale through sg_shading.glsl, SH's
 * fitted tables through sh_shading.glsl); mirrored by techniques/sg/fitted_texels.py.  fitted_layers: 0 base
 * (kd RGB, eta), 1 + 2k lobe k (axis xyz local, sharpness), 2 + 2k lobe k amplitude RGB, 1 + 2K + j shadowing
 * PCA coefficients 4j..4j+3 (K = FITTED_LOBES: NDF_LOBES, or a bi-scale material's small-scale lobes); read
 * with texelFetch at the nearest texel of the UV (the paper's per-texel free-axis lobes).
 * fitted_shadowing: S x (C + 2) texels, R: row 0 theta_s, row 1 the mean, rows 2.. the basis.  Needs sg.glsl
 * (SG_PI, safe_normalize) and the defines FITTED_LOBES, FITTED_COMPONENTS, FITTED_SHADOWING_LAYERS. */
ivec2 fitted_texel;
float fitted_coefficients[4 * FITTED_SHADOWING_LAYERS];

vec4 fitted_layer(int layer)
{
  return texelFetch(fitted_layers, ivec3(fitted_texel, layer), 0);
}

void fitted_select_texel(vec2 uv)
{
  ivec2 size = textureSize(fitted_layers, 0).xy;
  fitted_texel = clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1);
  for (int j = 0; j < FITTED_SHADOWING_LAYERS; j++) {
    vec4 c = fitted_layer(1 + 2 * FITTED_LOBES + j);
    fitted_coefficients[4 * j] = c.x;
    fitted_coefficients[4 * j + 1] = c.y;
    fitted_coefficients[4 * j + 2] = c.z;
    fitted_coefficients[4 * j + 3] = c.w;
  }
}

/* Node s of the shadowing grid (svbrdf_table.shadowing_with_horizon: a node S(pi/2) = 0 after the
 * stored ones when they stop short of the horizon). */
float fitted_node_theta(int s, int stored)
{
  return s >= stored ? 0.5 * SG_PI : texelFetch(fitted_shadowing, ivec2(s, 0), 0).x;
}

float fitted_node_value(int s, int stored)
{
  if (s >= stored) {
    return 0.0;
  }
  float value = texelFetch(fitted_shadowing, ivec2(s, 1), 0).x;
  for (int c = 0; c < FITTED_COMPONENTS; c++) {
    value += fitted_coefficients[c] * texelFetch(fitted_shadowing, ivec2(s, 2 + c), 0).x;
  }
  return max(value, 0.0);       /* microfacet_fit.decompress_shadowing */
}

/* S(theta) of the texel: linear between nodes (binary search), clamped below the first
 * (svbrdf_table.interpolate_shadowing). */
float fitted_shadowing_at(float theta)
{
  int stored = textureSize(fitted_shadowing, 0).x;
  int nodes = stored + (fitted_node_theta(stored - 1, stored) < 0.5 * SG_PI - 1.0e-6 ? 1 : 0);
  if (theta <= fitted_node_theta(0, stored)) {
    return fitted_node_value(0, stored);
  }
  int low = 0;
  int high = nodes - 1;
  float theta_high = fitted_node_theta(high, stored);
  if (theta >= theta_high) {
    return fitted_node_value(high, stored);
  }
  while (high - low > 1) {
    int middle = (low + high) / 2;
    if (fitted_node_theta(middle, stored) <= theta) {
      low = middle;
    }
    else {
      high = middle;
    }
  }
  float theta_low = fitted_node_theta(low, stored);
  float t = (theta - theta_low) / (fitted_node_theta(high, stored) - theta_low);
  return (1.0 - t) * fitted_node_value(low, stored) + t * fitted_node_value(high, stored);
}

float fitted_shadowing_of(vec3 w)
{
  w = safe_normalize(w);
  return fitted_shadowing_at(atan(length(w.xy), max(w.z, 0.0)));
}
