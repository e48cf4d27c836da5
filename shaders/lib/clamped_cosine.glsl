/* The clamped cosine max(0, n.i) against SGs: GLSL mirror of
 * sg_prt_addon/core/clamped_cosine.py.  Depends on sg.glsl and hemisphere.glsl (erf_approx).
 *
 *   clamped_cosine_lobe                 <- clamped_cosine.clamped_cosine_lobe (vec2(sharpness, amplitude))
 *   clamped_cosine_lobe_evaluate        <- clamped_cosine.clamped_cosine_lobe_evaluate
 *   sg_clamped_cosine_integral_paper    <- clamped_cosine.sg_clamped_cosine_integral_paper (eq. 39-40)
 *   clamped_cosine_pole_integrals       <- clamped_cosine._pole_integrals (vec2(upper, lower))
 *   clamped_cosine_from_cosine          <- clamped_cosine._clamped_cosine_from_cosine
 *   sg_clamped_cosine_integral          <- clamped_cosine.sg_clamped_cosine_integral
 *
 * Float32 differences from the numpy code (same values to float32 rounding):
 * the pole-integral series run up to lambda < 0.25 (numpy: < 0.01) with more
 * terms, so 1 - (1 - e^-l)/l never cancels in float32; and 0 < lambda < 1e-6
 * is evaluated at 1e-6 (the integral is pi to 1e-6 there), so that
 * 2 pi / lambda cannot overflow.
 */

const float CLAMPED_COSINE_SHARPNESS = 2.133;
const float CLAMPED_COSINE_AMPLITUDE = 1.170;
/* w(lambda)^2 = 1 / (lambda + W_OFFSET): width of the Gaussian model of n.i */
const float CLAMPED_COSINE_W_OFFSET = 1.0;
const float CLAMPED_COSINE_MIN_SHARPNESS = 1.0e-6;

vec2 clamped_cosine_lobe()
{
  return vec2(CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE);
}

/* C*(i; n) = G(i; n, 2.133, 1.170) of wang2009 eq. 40 */
float clamped_cosine_lobe_evaluate(vec3 direction, vec3 normal)
{
  return sg_evaluate(direction, normal, CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE);
}

/* eq. 39-40: SG inner product of the light lobe with the eq. 40 lobe */
float sg_clamped_cosine_integral_paper(vec3 axis, float sharpness, float amplitude, vec3 normal)
{
  return sg_inner_product(safe_normalize(axis), sharpness, amplitude, safe_normalize(normal),
                          CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE);
}

/* (I_up, I_low) / (2 pi / lambda): normal on the lobe axis, and opposite to it.
 * upper = 1 - (1 - e^-l)/l, lower = e^-l (1 - e^-l (1 + l))/l. */
vec2 clamped_cosine_pole_integrals(float sharpness)
{
  float l = sharpness;
  float upper, lower_moment;
  if (l < 0.25) {
    /* Taylor series, truncation < 4e-9 relative at l = 0.25 */
    upper = 0.5 * l * (1.0 - l * (1.0 / 3.0 - l * (1.0 / 12.0 - l * (1.0 / 60.0 - l * (1.0 / 360.0
            - l * (1.0 / 2520.0 - l / 20160.0))))));
    lower_moment = 0.5 * l * (1.0 - l * (2.0 / 3.0 - l * (1.0 / 4.0 - l * (1.0 / 15.0 - l * (1.0 / 72.0
                   - l * (1.0 / 420.0 - l / 2880.0))))));
  }
  else {
    upper = 1.0 - one_minus_exp_over_x(l);
    lower_moment = one_minus_exp_over_x(l) - exp(-l);
  }
  return vec2(upper, exp(-l) * lower_moment);
}

/* I(c, lambda) with unit amplitude, c = n.p: I_low + (I_up - I_low) s(c) with
 * s = c Phi(c / sigma) + sigma phi(c / sigma), sigma = sqrt(1 - c^2) w(lambda). */
float clamped_cosine_from_cosine(float cosine, float sharpness)
{
  if (!(sharpness > 0.0)) {
    return SG_PI;  /* lambda -> 0: the cosine's own integral */
  }
  float l = max(sharpness, CLAMPED_COSINE_MIN_SHARPNESS);
  vec2 poles = clamped_cosine_pole_integrals(l);
  float width = 1.0 / sqrt(l + CLAMPED_COSINE_W_OFFSET);
  float sigma = sqrt(max(1.0 - cosine * cosine, 0.0)) * width;
  float ratio = cosine / max(sigma, 1.17549435e-38);
  float positive_mean = cosine * 0.5 * (1.0 + erf_approx(ratio * 0.7071067811865476))
                        + sigma * 0.3989422804014327 * exp(-0.5 * min(ratio * ratio, 1.0e4));
  float scaled = poles.y + (poles.x - poles.y) * clamp(positive_mean, 0.0, 1.0);
  return SG_TWO_PI / l * scaled;
}

/* Integral over the sphere of G(i; p, lambda, mu) max(0, n.i) (closed form). */
float sg_clamped_cosine_integral(vec3 axis, float sharpness, float amplitude, vec3 normal)
{
  float cosine = clamp(dot(safe_normalize(axis), safe_normalize(normal)), -1.0, 1.0);
  return amplitude * clamped_cosine_from_cosine(cosine, max(sharpness, 0.0));
}
