/* Spherical Gaussian algebra: GLSL mirror of sg_prt_addon/spherical/sg.py.
 *
 * G(v; p, lambda, mu) = mu exp(lambda (v.p - 1)); a lobe is passed as
 * (vec3 axis, float sharpness, float amplitude) in the order of sg.py.
 * Colour amplitudes: pass amplitude 1 and multiply the result by the colour.
 *
 *   one_minus_exp_over_x   <- sg.one_minus_exp_over_x
 *   precise_asin           <- numpy.arcsin
 *   safe_normalize         <- sg.normalize (GLSL's normalize is a builtin)
 *   sg_evaluate            <- sg.evaluate
 *   sg_product             <- sg.product (results in out parameters)
 *   sg_sphere_integral     <- sg.sphere_integral
 *   sg_axis_hemisphere_integral <- sg.axis_hemisphere_integral
 *   sg_inner_product       <- sg.inner_product
 *   sg_rotate              <- sg.rotate
 *   sg_support_area        <- sg.support_area
 *   sg_sharpness_from_area <- sg.sharpness_from_area
 * (sg.mixture_evaluate is a loop the caller writes over its own arrays.)
 *
 * float32 safety for sharpness in [0, 1e6]: no exp of a positive argument,
 * no difference of nearly equal large numbers, no division by zero.
 * Depends on nothing; every other file in shaders/lib depends on this one.
 */

const float SG_PI = 3.14159265358979;
const float SG_TWO_PI = 6.28318530717959;
const float SG_FOUR_PI = 12.5663706143592;
/* Below this the product's summed axis is treated as zero (sg.product's float32 threshold). */
const float SG_TINY_LENGTH = 1.0e-34;

/* (1 - exp(-x)) / x for x >= 0.  GLSL has no expm1: below 0.25 a Taylor
 * series (truncation < 2e-9 relative) avoids the cancellation of 1 - exp(-x). */
float one_minus_exp_over_x(float x)
{
  if (x < 0.25) {
    return 1.0 - x / 2.0 * (1.0 - x / 3.0 * (1.0 - x / 4.0 * (1.0 - x / 5.0 * (1.0 - x / 6.0 * (1.0 - x / 7.0)))));
  }
  return (1.0 - exp(-x)) / x;
}

/* asin(x), x clamped to [-1, 1], to about 3e-6 and with small arguments' relative precision: llvmpipe's asin
 * and acos are polynomials of 1e-4 to 4e-4 absolute error (a small light's whole angular radius), its atan is
 * good to 3e-6.  Below 0.25 a Taylor series (truncation < 1e-7 relative), above it atan2. */
float precise_asin(float x)
{
  float y = clamp(x, -1.0, 1.0);
  if (abs(y) < 0.25) {
    float y2 = y * y;
    return y * (1.0 + y2 * (1.0 / 6.0 + y2 * (3.0 / 40.0 + y2 * (5.0 / 112.0 + y2 * (35.0 / 1152.0)))));
  }
  return atan(y, sqrt(max((1.0 - y) * (1.0 + y), 0.0)));
}

/* Unit vector along v; zero or non-finite v gives fallback.  Dividing by the
 * largest component first keeps dot(v, v) in float32 range for |v| in
 * [1e-38, 3e38], as sg.normalize does in float64. */
vec3 safe_normalize(vec3 v, vec3 fallback)
{
  vec3 a = abs(v);
  float largest = max(a.x, max(a.y, a.z));
  if (!(largest > 0.0) || isinf(largest)) {
    return fallback;
  }
  vec3 scaled = v / largest;
  return scaled / sqrt(dot(scaled, scaled));
}

vec3 safe_normalize(vec3 v)
{
  return safe_normalize(v, vec3(0.0, 0.0, 1.0));
}

/* mu exp(-lambda/2 |v - p|^2): equal to mu exp(lambda (v.p - 1)) for unit
 * vectors, without the cancellation of v.p - 1 near the axis. */
float sg_evaluate(vec3 direction, vec3 axis, float sharpness, float amplitude)
{
  vec3 d = direction - axis;
  return amplitude * exp(-0.5 * sharpness * dot(d, d));
}

vec3 sg_evaluate(vec3 direction, vec3 axis, float sharpness, vec3 amplitude)
{
  return amplitude * sg_evaluate(direction, axis, sharpness, 1.0);
}

/* G1 (x) G2 (wang2009 eq. 5).  lambda_m = |l1 p1 + l2 p2|; the log amplitude
 * lambda_m - l1 - l2 is -l1 l2 |p1 - p2|^2 / (lambda_m + l1 + l2).  When the
 * summed axis vanishes the product is constant and axis1 is returned. */
void sg_product(vec3 axis1, float sharpness1, float amplitude1,
                vec3 axis2, float sharpness2, float amplitude2,
                out vec3 axis, out float sharpness, out float amplitude)
{
  vec3 summed = sharpness1 * axis1 + sharpness2 * axis2;
  sharpness = sqrt(dot(summed, summed));
  vec3 diff = axis1 - axis2;
  float denominator = sharpness + sharpness1 + sharpness2;
  float log_amplitude = -sharpness1 * sharpness2 * dot(diff, diff) /
                        (denominator > 0.0 ? denominator : 1.0);
  amplitude = amplitude1 * amplitude2 * exp(log_amplitude);
  axis = sharpness > SG_TINY_LENGTH ? summed / sharpness : axis1;
}

/* Integral of G over the sphere: 4 pi mu (1 - exp(-2 lambda)) / (2 lambda). */
float sg_sphere_integral(float sharpness, float amplitude)
{
  return SG_FOUR_PI * amplitude * one_minus_exp_over_x(2.0 * sharpness);
}

/* Integral over the hemisphere centred on the lobe's own axis:
 * 2 pi mu (1 - e^-lambda) / lambda = fh(pi/2, lambda) (wang2009 eq. 31). */
float sg_axis_hemisphere_integral(float sharpness, float amplitude)
{
  return SG_TWO_PI * amplitude * one_minus_exp_over_x(sharpness);
}

/* Integral of G1 G2 over the sphere (wang2009 eq. 4) as the sphere integral
 * of the product lobe: never forms sinh(d) exp(-(l1 + l2)). */
float sg_inner_product(vec3 axis1, float sharpness1, float amplitude1,
                       vec3 axis2, float sharpness2, float amplitude2)
{
  vec3 axis;
  float sharpness, amplitude;
  sg_product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2,
             axis, sharpness, amplitude);
  return sg_sphere_integral(sharpness, amplitude);
}

vec3 sg_rotate(vec3 axis, mat3 rotation)
{
  return rotation * axis;
}

/* fa(lambda) of wang2009 eq. 3: solid angle where G(v; z, lambda, 1) >= epsilon. */
float sg_support_area(float sharpness, float epsilon)
{
  return -SG_TWO_PI * log(epsilon) / sharpness;
}

float sg_sharpness_from_area(float area, float epsilon)
{
  return -SG_TWO_PI * log(epsilon) / area;
}
