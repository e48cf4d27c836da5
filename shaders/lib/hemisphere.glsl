/* SG over a hemisphere at any angle (wang2009's fh): GLSL mirror of the fast
 * forms in sg_prt_addon/spherical/hemisphere.py.  Depends on sg.glsl.
 *
 *   erf_approx                    <- hemisphere.erf_approx
 *   fh_k                          <- hemisphere.fh_k
 *   fh_normalized_from_sine       <- hemisphere.fh_normalized_from_sine
 *   fh_normalized                 <- hemisphere.fh_normalized
 *   fh                            <- hemisphere.fh
 *   hemisphere_integral           <- hemisphere.hemisphere_integral
 *   visibility_product_amplitude  <- hemisphere.visibility_product (its amplitude;
 *                                    axis and sharpness pass through unchanged)
 *   visibility_product_integral_preserving_amplitude
 *                                 <- hemisphere.visibility_product_integral_preserving (amplitude)
 *   disc_coverage                 <- hemisphere.disc_coverage
 *
 * fh_hat = e^-lambda + (1 - e^-lambda) (1 + g) / 2,
 * g = erf(k x (1 - (1 - x^2)/9)) / erf(k), x = sin(theta_d) = p.m.
 * The constants below must equal hemisphere.py's (tests/gpu/test_glsl_hemisphere.py
 * compares the two on random inputs).
 */

const float ERF_APPROX_A = 0.1478;
const float FH_SHAPE_B = -1.0 / 9.0;
const float FH_K2_SLOPE = 81.0 / 128.0;
const float FH_K2_C0 = -0.3975;
const float FH_K2_C1 = -1.893;
const float FH_K2_C2 = 3.341;
const float FH_K2_C3 = 0.3843;
const float FH_K2_C4 = 4.419;
const float FH_MAX_SHARPNESS = 1.0e8;

/* erf(y) ~ sign(y) sqrt(1 - exp(-y^2 (4/pi + a y^2) / (1 + a y^2))), max abs error 1.1e-4.
 * 1 - exp(-e) is formed as e * one_minus_exp_over_x(e): no cancellation for small y. */
float erf_approx(float y)
{
  float y_abs = min(abs(y), 6.0);
  float y2 = y_abs * y_abs;
  float exponent = y2 * (4.0 / SG_PI + ERF_APPROX_A * y2) / (1.0 + ERF_APPROX_A * y2);
  return sign(y) * sqrt(exponent * one_minus_exp_over_x(exponent));
}

/* Steepness k(lambda) >= 0.598 of the fast form. */
float fh_k(float sharpness)
{
  float lam = clamp(sharpness, 0.0, FH_MAX_SHARPNESS);
  float rational = (FH_K2_C1 * lam + FH_K2_C2) / (lam * lam + FH_K2_C3 * lam + FH_K2_C4);
  return sqrt(FH_K2_SLOPE * lam + FH_K2_C0 + rational);
}

/* fh_hat given sin(theta_d) = p.m (no trig): the form shaders use; in [0, 1]. */
float fh_normalized_from_sine(float sine_theta_d, float sharpness)
{
  float x = clamp(sine_theta_d, -1.0, 1.0);
  float lam = max(sharpness, 0.0);
  float k = fh_k(lam);
  float warped = x * (1.0 + FH_SHAPE_B * (1.0 - x * x));
  float g = erf_approx(k * warped) / erf_approx(k);
  float lower = exp(-lam);
  return clamp(lower + (1.0 - lower) * (0.5 + 0.5 * g), 0.0, 1.0);
}

/* fh_hat(theta_d, lambda) = fh / fh(pi/2) (wang2009 eq. 46), theta_d clamped to +-pi/2. */
float fh_normalized(float theta_d, float sharpness)
{
  return fh_normalized_from_sine(sin(clamp(theta_d, -0.5 * SG_PI, 0.5 * SG_PI)), sharpness);
}

/* fh(theta_d, lambda) = fh_hat * (2 pi / lambda)(1 - e^-lambda). */
float fh(float theta_d, float sharpness)
{
  return fh_normalized(theta_d, sharpness) * sg_axis_hemisphere_integral(sharpness, 1.0);
}

/* Integral of G(i; p, lambda, mu) over {i : i.n >= 0}, sin(theta_d) = p.n. */
float hemisphere_integral(vec3 axis, float sharpness, float amplitude, vec3 normal)
{
  float sine = clamp(dot(safe_normalize(axis), safe_normalize(normal)), -1.0, 1.0);
  return amplitude * fh_normalized_from_sine(sine, sharpness) * sg_axis_hemisphere_integral(sharpness, 1.0);
}

/* G (x) V ~ G(i; p, lambda, mu fh(theta_d) / fh(pi/2)) (wang2009 eq. 31): the new amplitude. */
float visibility_product_amplitude(float sharpness, float amplitude, float theta_d)
{
  return amplitude * fh_normalized(theta_d, sharpness);
}

/* eq. 31 normalised as its text intends: the lobe's sphere integral is mu fh(theta_d),
 * i.e. mu fh_hat / (1 + e^-lambda) (the printed form over-counts by 1 + e^-lambda). */
float visibility_product_integral_preserving_amplitude(float sharpness, float amplitude, float theta_d)
{
  return amplitude * fh_normalized(theta_d, sharpness) / (1.0 + exp(-max(sharpness, 0.0)));
}

/* Visible share of a disc of angular `radius` whose centre lies `signed_distance` (+ visible) from a
 * straight boundary: its area beyond a chord.  Written as the smaller segment's share, (t - sin t) / 2 pi for
 * the chord's angle t, with a series for thin segments: the direct form's asin(x) + x sqrt(1 - x^2) cancels
 * near the edge (|x| -> 1), where a shadow's penumbra starts, and llvmpipe's asin is good to 4e-4 only. */
float disc_coverage(float signed_distance, float radius)
{
  float x = clamp(signed_distance / max(radius, 1.0e-30), -1.0, 1.0);
  float a = abs(x);
  /* acos(a), from the side where its argument keeps its precision in float32 */
  float half_chord = a < 0.7 ? 0.5 * SG_PI - precise_asin(a) : precise_asin(sqrt(max((1.0 - a) * (1.0 + a), 0.0)));
  float t = 2.0 * half_chord;
  float t2 = t * t;
  float segment = t < 0.5 ? t * t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0)))
                          : t - sin(t);
  segment = clamp(segment / (2.0 * SG_PI), 0.0, 0.5);
  return x >= 0.0 ? 1.0 - segment : segment;
}
