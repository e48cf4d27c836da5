/* The clamped cosine max(0, n.i) against SGs: GLSL mirror of
 * sg_prt_addon/spherical/clamped_cosine.py.  Depends on sg.glsl and hemisphere.glsl (erf_approx).
 *
 *   clamped_cosine_lobe                 <- clamped_cosine.clamped_cosine_lobe (vec2(sharpness, amplitude))
 *   clamped_cosine_lobe_evaluate        <- clamped_cosine.clamped_cosine_lobe_evaluate
 *   sg_clamped_cosine_integral_paper    <- clamped_cosine.sg_clamped_cosine_integral_paper (eq. 39-40)
 *   clamped_cosine_pole_integrals       <- clamped_cosine._pole_integrals (vec2(upper, lower))
 *   clamped_cosine_langevin_moments     <- clamped_cosine._langevin_moments (vec2(L, V))
 *   clamped_cosine_gaussian_positive_mean <- clamped_cosine._gaussian_positive_mean
 *   clamped_cosine_sharpness_terms      <- clamped_cosine.sharpness_terms (two vec4)
 *   clamped_cosine_from_terms           <- clamped_cosine.clamped_cosine_from_terms
 *   clamped_cosine_from_cosine          <- clamped_cosine.clamped_cosine_from_cosine
 *   sg_clamped_cosine_integral          <- clamped_cosine.sg_clamped_cosine_integral
 *
 * Float32 differences from the numpy code (same values to float32 rounding):
 * the pole-integral series run up to lambda < 0.25 (numpy: < 0.01) with more
 * terms, so 1 - (1 - e^-l)/l never cancels in float32; and 0 < lambda < 1e-6
 * is evaluated at 1e-6 (the integral is pi to 1e-6 there), so that
 * 2 pi / lambda cannot overflow; 1 - e^-2l is formed as 2l one_minus_exp_over_x(2l).
 */

const float CLAMPED_COSINE_SHARPNESS = 2.133;
const float CLAMPED_COSINE_AMPLITUDE = 1.170;
/* fitted constants of the Gaussian model: variance scale
 * f = 1 + (F1 lambda + F0) / (lambda^2 + F3 lambda + F2), tail blend beta = lambda^P / (lambda^P + B) */
const float CLAMPED_COSINE_VARIANCE_F1 = 0.35459;
const float CLAMPED_COSINE_VARIANCE_F0 = -0.96364;
const float CLAMPED_COSINE_VARIANCE_F3 = -2.42236;
const float CLAMPED_COSINE_VARIANCE_F2 = 4.64645;
const float CLAMPED_COSINE_TAIL_POWER = 2.94198;
const float CLAMPED_COSINE_TAIL_OFFSET = 43.2488;
const float CLAMPED_COSINE_MIN_SHARPNESS = 1.0e-6;
const float CLAMPED_COSINE_MAX_SHARPNESS = 1.0e6;

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

/* (L, V): mean and variance of cos(theta) under the normalized SG (von Mises-Fisher),
 * L = coth(lambda) - 1/lambda, V = 1/lambda^2 - 1/sinh(lambda)^2 = dL/dlambda.
 * Below 0.5 (numpy: 0.2) Laurent series to lambda^12, truncation < 1e-9: at 0.2
 * the closed forms cancel by a factor 75, ~4e-5 relative in float32. */
vec2 clamped_cosine_langevin_moments(float sharpness)
{
  float l = sharpness;
  float q = l * l;
  if (l < 0.5) {
    float mean = l * (1.0 / 3.0 - q * (1.0 / 45.0 - q * (2.0 / 945.0 - q * (1.0 / 4725.0 - q * (2.0 / 93555.0
                 - q * (1382.0 / 638512875.0))))));
    float variance = 1.0 / 3.0 - q * (1.0 / 15.0 - q * (2.0 / 189.0 - q * (1.0 / 675.0 - q * (2.0 / 10395.0
                     - q * (1382.0 / 58046625.0 - q * (4.0 / 1403325.0))))));
    return vec2(mean, variance);
  }
  float decay = exp(-2.0 * l);
  float one_minus_decay = 2.0 * l * one_minus_exp_over_x(2.0 * l);
  float mean = (1.0 + decay) / one_minus_decay - 1.0 / l;
  float variance = 1.0 / q - 4.0 * decay / (one_minus_decay * one_minus_decay);
  return vec2(mean, max(variance, 0.0));
}

/* E[max(0, X)] for X ~ N(mean, variance) = mu Phi(mu / sigma) + sigma phi(mu / sigma). */
float clamped_cosine_gaussian_positive_mean(float mean, float variance)
{
  float sigma = sqrt(variance);
  float ratio = clamp(mean / max(sigma, 1.17549435e-38), -1.0e4, 1.0e4);
  return mean * 0.5 * (1.0 + erf_approx(ratio * 0.7071067811865476))
         + sigma * 0.3989422804014327 * exp(-0.5 * ratio * ratio);
}

/* The parts of I(c, lambda) that depend on lambda alone (clamped_cosine.SHARPNESS_TERMS):
 * poles_moments = (the pole integrals (I_up, I_low) / (2 pi / lambda), the Langevin moments (L, V)),
 * shape = (variance scale f, tail blend beta, L / lambda, E[max(0, X)] at c = -1).
 * lambda > 0 (clamped to [MIN, MAX]_SHARPNESS). */
void clamped_cosine_sharpness_terms(float sharpness, out vec4 poles_moments, out vec4 shape)
{
  float lam = clamp(sharpness, CLAMPED_COSINE_MIN_SHARPNESS, CLAMPED_COSINE_MAX_SHARPNESS);
  vec2 poles = clamped_cosine_pole_integrals(lam);
  vec2 moments = clamped_cosine_langevin_moments(lam);
  float scale = 1.0 + (CLAMPED_COSINE_VARIANCE_F1 * lam + CLAMPED_COSINE_VARIANCE_F0)
                      / (lam * lam + CLAMPED_COSINE_VARIANCE_F3 * lam + CLAMPED_COSINE_VARIANCE_F2);
  float lam_power = pow(lam, CLAMPED_COSINE_TAIL_POWER);
  float beta = lam_power / (lam_power + CLAMPED_COSINE_TAIL_OFFSET);
  float tangential = moments.x / lam;  /* E[sin^2 theta] / 2 = L / lambda */
  float at_bottom = clamped_cosine_gaussian_positive_mean(-moments.x, scale * (moments.y + 0.5 * beta * tangential));
  poles_moments = vec4(poles, moments);
  shape = vec4(scale, beta, tangential, at_bottom);
}

/* I(c, lambda) with unit amplitude given lambda's clamped_cosine_sharpness_terms (lambda <= 0: pi). */
float clamped_cosine_from_terms(float cosine, float sharpness, vec4 poles_moments, vec4 shape)
{
  if (!(sharpness > 0.0)) {
    return SG_PI;  /* lambda -> 0: the cosine's own integral */
  }
  float c = clamp(cosine, -1.0, 1.0);
  float lam = clamp(sharpness, CLAMPED_COSINE_MIN_SHARPNESS, CLAMPED_COSINE_MAX_SHARPNESS);
  float mean_cos = poles_moments.z;
  float sin_alpha = sqrt(max(1.0 - c * c, 0.0));
  float across = (1.0 - shape.y) * (1.0 - c * c) + shape.y * 0.5 * (1.0 + sin_alpha);
  float positive = clamped_cosine_gaussian_positive_mean(c * mean_cos,
                                                         shape.x * (c * c * poles_moments.w + across * shape.z));
  float fraction = mean_cos > 0.0 ? clamp((positive - shape.w) / mean_cos, 0.0, 1.0) : 0.5 * (1.0 + c);
  return SG_TWO_PI / lam * (poles_moments.y + (poles_moments.x - poles_moments.y) * fraction);
}

/* I(c, lambda) with unit amplitude, c = n.p: I_low + (I_up - I_low) s(c), s from a
 * Gaussian model of X = n.i with the Langevin moments, a fitted variance scale and
 * a fitted tail blend (clamped_cosine.py's module docstring). */
float clamped_cosine_from_cosine(float cosine, float sharpness)
{
  if (!(sharpness > 0.0)) {
    return SG_PI;  /* lambda -> 0: the cosine's own integral */
  }
  vec4 poles_moments, shape;
  clamped_cosine_sharpness_terms(sharpness, poles_moments, shape);
  return clamped_cosine_from_terms(cosine, sharpness, poles_moments, shape);
}

/* Integral over the sphere of G(i; p, lambda, mu) max(0, n.i) (closed form). */
float sg_clamped_cosine_integral(vec3 axis, float sharpness, float amplitude, vec3 normal)
{
  float cosine = clamp(dot(safe_normalize(axis), safe_normalize(normal)), -1.0, 1.0);
  return amplitude * clamped_cosine_from_cosine(cosine, max(sharpness, 0.0));
}
