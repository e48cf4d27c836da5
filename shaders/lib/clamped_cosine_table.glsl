/* The clamped-cosine integral I(c, lambda) read from its table (one bilinear fetch): GLSL mirror of
 * sg_prt_addon/spherical/clamped_cosine_table.py, whose docstring gives the layout.  Depends on sg.glsl.
 *
 *   clamped_cosine_tabulated            <- clamped_cosine_table.clamped_cosine_from_table
 *   sg_clamped_cosine_integral_tabulated <- clamped_cosine_table.sg_clamped_cosine_integral_tabulated
 *
 * `table` is clamped_cosine_table() uploaded as it is (linear filtering, clamp to edge); its size
 * comes from textureSize, the constants below from the module (checked by the tests).
 */

const float CLAMPED_COSINE_TABLE_LOG_MIN = -9.210340371976182;      /* log(SHARPNESS_RANGE[0]) */
const float CLAMPED_COSINE_TABLE_LOG_MAX = 18.420680743952367;      /* log(SHARPNESS_RANGE[1]) */
const float CLAMPED_COSINE_TABLE_KNEE_WEIGHT = 0.2;
const float CLAMPED_COSINE_TABLE_MIN_SHARPNESS = 1.0e-6;

/* I(c, lambda) with unit amplitude (lambda <= 0 or NaN: pi, the cosine's own integral). */
float clamped_cosine_tabulated(sampler2D table, float cosine, float sharpness)
{
  if (!(sharpness > 0.0)) {
    return SG_PI;
  }
  float lam = max(sharpness, CLAMPED_COSINE_TABLE_MIN_SHARPNESS);
  float c = clamp(cosine, -1.0, 1.0);
  float s = sqrt(lam);
  float t = c * s;
  float y = (c + CLAMPED_COSINE_TABLE_KNEE_WEIGHT * t / (1.0 + abs(t)))
            / (1.0 + CLAMPED_COSINE_TABLE_KNEE_WEIGHT * s / (1.0 + s));
  float x = clamp((log(lam) - CLAMPED_COSINE_TABLE_LOG_MIN)
                  / (CLAMPED_COSINE_TABLE_LOG_MAX - CLAMPED_COSINE_TABLE_LOG_MIN), 0.0, 1.0);
  vec2 size = vec2(textureSize(table, 0));
  vec2 texel = texture(table, (vec2(x, 0.5 + 0.5 * y) * (size - 1.0) + 0.5) / size).xy;  /* centres at the ends */
  return SG_PI / (1.0 + lam * (1.0 / 3.0)) * texel.x * texel.y;
}

/* Integral over the sphere of G(i; p, lambda, mu) max(0, n.i), from the table. */
float sg_clamped_cosine_integral_tabulated(sampler2D table, vec3 axis, float sharpness, float amplitude,
                                           vec3 normal)
{
  float cosine = clamp(dot(safe_normalize(axis), safe_normalize(normal)), -1.0, 1.0);
  return amplitude * clamped_cosine_tabulated(table, cosine, max(sharpness, 0.0));
}
