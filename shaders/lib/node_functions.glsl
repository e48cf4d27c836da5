/* Blender's shader-node functions that are not sums of products, on vec3 (a scalar socket: its value on all
 * three channels); each mirrors sg_prt_addon/reflectance/node_functions.py (node_math_<op> its MATH[op],
 * node_<name> its <name>).  techniques/material_textures.py writes the calls. */

vec3 node_safe_divide(vec3 a, vec3 b)
{
  return mix(vec3(0.0), a / mix(vec3(1.0), b, notEqual(b, vec3(0.0))), notEqual(b, vec3(0.0)));
}

/* pow of a negative base is undefined in GLSL: its sign from the integer exponent's parity */
float node_signed_pow(float a, float b)
{
  float magnitude = pow(abs(a), b);
  return (a < 0.0 && mod(b, 2.0) == 1.0) ? -magnitude : magnitude;
}

vec3 node_math_power(vec3 a, vec3 b, vec3 c)
{
  vec3 out_value;
  for (int k = 0; k < 3; k++) {
    if (b[k] == 0.0) {
      out_value[k] = 1.0;        /* pow(0, 0) is undefined in GLSL, 1 in C */
    }
    else if (a[k] >= 0.0) {
      out_value[k] = pow(a[k], b[k]);
    }
    else {
      float fraction = mod(abs(b[k]), 1.0);
      out_value[k] = (fraction > 0.999 || fraction < 0.001) ? node_signed_pow(a[k], floor(b[k] + 0.5)) : 0.0;
    }
  }
  return out_value;
}

vec3 node_math_divide(vec3 a, vec3 b, vec3 c) { return node_safe_divide(a, b); }
vec3 node_math_logarithm(vec3 a, vec3 b, vec3 c)
{
  bvec3 ok = bvec3(vec3(greaterThan(a, vec3(0.0))) * vec3(greaterThan(b, vec3(0.0))));
  return mix(vec3(0.0), log2(max(a, vec3(1e-38))) / log2(mix(vec3(2.0), b, ok)), ok);
}
vec3 node_math_sqrt(vec3 a, vec3 b, vec3 c) { return sqrt(max(a, vec3(0.0))); }
vec3 node_math_inverse_sqrt(vec3 a, vec3 b, vec3 c)
{
  return mix(vec3(0.0), inversesqrt(max(a, vec3(1e-38))), greaterThan(a, vec3(0.0)));
}
vec3 node_math_absolute(vec3 a, vec3 b, vec3 c) { return abs(a); }
vec3 node_math_exponent(vec3 a, vec3 b, vec3 c) { return exp(a); }
vec3 node_math_minimum(vec3 a, vec3 b, vec3 c) { return min(a, b); }
vec3 node_math_maximum(vec3 a, vec3 b, vec3 c) { return max(a, b); }
vec3 node_math_less_than(vec3 a, vec3 b, vec3 c) { return vec3(lessThan(a, b)); }
vec3 node_math_greater_than(vec3 a, vec3 b, vec3 c) { return vec3(greaterThan(a, b)); }
vec3 node_math_sign(vec3 a, vec3 b, vec3 c) { return sign(a); }
vec3 node_math_compare(vec3 a, vec3 b, vec3 c) { return vec3(lessThanEqual(abs(a - b), max(c, vec3(1e-5)))); }
vec3 node_smooth_min(vec3 a, vec3 b, vec3 c)
{
  vec3 h = max(c - abs(a - b), vec3(0.0)) / mix(vec3(1.0), c, notEqual(c, vec3(0.0)));
  return mix(min(a, b), min(a, b) - h * h * h * c * (1.0 / 6.0), notEqual(c, vec3(0.0)));
}
vec3 node_math_smooth_min(vec3 a, vec3 b, vec3 c) { return node_smooth_min(a, b, c); }
vec3 node_math_smooth_max(vec3 a, vec3 b, vec3 c) { return -node_smooth_min(-a, -b, c); }
vec3 node_math_round(vec3 a, vec3 b, vec3 c) { return floor(a + 0.5); }
vec3 node_math_floor(vec3 a, vec3 b, vec3 c) { return floor(a); }
vec3 node_math_ceil(vec3 a, vec3 b, vec3 c) { return ceil(a); }
vec3 node_math_trunc(vec3 a, vec3 b, vec3 c) { return trunc(a); }
vec3 node_math_fract(vec3 a, vec3 b, vec3 c) { return a - floor(a); }
/* C's fmod: the sign of a */
vec3 node_math_modulo(vec3 a, vec3 b, vec3 c)
{
  vec3 safe = mix(vec3(1.0), b, notEqual(b, vec3(0.0)));
  return mix(vec3(0.0), a - safe * trunc(a / safe), notEqual(b, vec3(0.0)));
}
vec3 node_math_floored_modulo(vec3 a, vec3 b, vec3 c)
{
  vec3 safe = mix(vec3(1.0), b, notEqual(b, vec3(0.0)));
  return mix(vec3(0.0), a - floor(a / safe) * safe, notEqual(b, vec3(0.0)));
}
vec3 node_math_wrap(vec3 a, vec3 b, vec3 c)
{
  vec3 span = b - c;
  vec3 safe = mix(vec3(1.0), span, notEqual(span, vec3(0.0)));
  return mix(c, a - span * floor((a - c) / safe), notEqual(span, vec3(0.0)));
}
vec3 node_math_snap(vec3 a, vec3 b, vec3 c) { return floor(node_safe_divide(a, b)) * b; }
vec3 node_math_pingpong(vec3 a, vec3 b, vec3 c)
{
  vec3 safe = mix(vec3(1.0), b, notEqual(b, vec3(0.0)));
  vec3 f = (a - safe) / (safe * 2.0);
  return mix(vec3(0.0), abs((f - floor(f)) * safe * 2.0 - safe), notEqual(b, vec3(0.0)));
}
vec3 node_math_sine(vec3 a, vec3 b, vec3 c) { return sin(a); }
vec3 node_math_cosine(vec3 a, vec3 b, vec3 c) { return cos(a); }
vec3 node_math_tangent(vec3 a, vec3 b, vec3 c) { return tan(a); }
vec3 node_math_sinh(vec3 a, vec3 b, vec3 c) { return sinh(a); }
vec3 node_math_cosh(vec3 a, vec3 b, vec3 c) { return cosh(a); }
vec3 node_math_tanh(vec3 a, vec3 b, vec3 c) { return tanh(a); }
/* Cycles clamps the argument (EEVEE gives 0 beyond [-1, 1]); through atan: llvmpipe's asin is 4e-4 off */
vec3 node_math_arcsine(vec3 a, vec3 b, vec3 c)
{
  vec3 x = clamp(a, -1.0, 1.0);
  return atan(x, sqrt(max(1.0 - x * x, vec3(0.0))));
}
vec3 node_math_arccosine(vec3 a, vec3 b, vec3 c)
{
  vec3 x = clamp(a, -1.0, 1.0);
  return atan(sqrt(max(1.0 - x * x, vec3(0.0))), x);
}
vec3 node_math_arctangent(vec3 a, vec3 b, vec3 c) { return atan(a); }
vec3 node_math_arctan2(vec3 a, vec3 b, vec3 c)
{
  bvec3 both_zero = bvec3(vec3(equal(a, vec3(0.0))) * vec3(equal(b, vec3(0.0))));
  return mix(atan(a, mix(b, vec3(1.0), both_zero)), vec3(0.0), both_zero);
}
vec3 node_math_radians(vec3 a, vec3 b, vec3 c) { return radians(a); }
vec3 node_math_degrees(vec3 a, vec3 b, vec3 c) { return degrees(a); }

vec3 node_clamp(vec3 value, vec3 low, vec3 high) { return min(max(value, low), high); }
vec3 node_clamp_range(vec3 value, vec3 low, vec3 high) { return node_clamp(value, min(low, high), max(low, high)); }

/* Map Range of a float: interpolation 0 LINEAR, 1 STEPPED, 2 SMOOTHSTEP, 3 SMOOTHERSTEP; clamped (LINEAR,
 * STEPPED) to the target range where `clamped` */
vec3 node_map_range(vec3 value, vec3 from_min, vec3 from_max, vec3 to_min, vec3 to_max, vec3 steps,
                    int interpolation, bool clamped)
{
  vec3 factor = node_safe_divide(value - from_min, from_max - from_min);
  if (interpolation == 1) {
    factor = mix(vec3(0.0), floor(factor * (steps + 1.0)) / mix(vec3(1.0), steps, greaterThan(steps, vec3(0.0))),
                 greaterThan(steps, vec3(0.0)));
  }
  else if (interpolation >= 2) {
    vec3 low = min(from_min, from_max);
    vec3 t = clamp(node_safe_divide(value - low, max(from_min, from_max) - low), 0.0, 1.0);
    t = interpolation == 2 ? t * t * (3.0 - 2.0 * t) : t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    factor = mix(t, 1.0 - t, greaterThan(from_min, from_max));
  }
  vec3 result = to_min + factor * (to_max - to_min);
  if (clamped && interpolation < 2) {
    result = mix(clamp(result, to_min, to_max), clamp(result, to_max, to_min), greaterThan(to_min, to_max));
  }
  return result;
}

vec3 node_rgb_to_hsv(vec3 rgb)
{
  float high = max(rgb.r, max(rgb.g, rgb.b));
  float delta = high - min(rgb.r, min(rgb.g, rgb.b));
  float s = high != 0.0 ? delta / high : 0.0;
  float h = 0.0;
  if (s != 0.0) {
    vec3 c = (vec3(high) - rgb) / delta;
    h = rgb.r == high ? c.b - c.g : (rgb.g == high ? 2.0 + c.r - c.b : 4.0 + c.g - c.r);
    h /= 6.0;
    h = h < 0.0 ? h + 1.0 : h;
  }
  return vec3(h, s, high);
}

vec3 node_hsv_to_rgb(vec3 hsv)
{
  float v = hsv.z;
  if (hsv.y == 0.0) {
    return vec3(v);
  }
  float h = (hsv.x - floor(hsv.x)) * 6.0;
  float i = floor(h);
  float f = h - i;
  float p = v * (1.0 - hsv.y), q = v * (1.0 - hsv.y * f), t = v * (1.0 - hsv.y * (1.0 - f));
  int index = int(clamp(i, 0.0, 5.0));
  return index == 0 ? vec3(v, t, p) : index == 1 ? vec3(q, v, p) : index == 2 ? vec3(p, v, t) :
         index == 3 ? vec3(p, q, v) : index == 4 ? vec3(t, p, v) : vec3(v, p, q);
}

vec3 node_hue_saturation_value(vec3 colour, vec3 hue, vec3 saturation, vec3 value, vec3 factor)
{
  vec3 hsv = node_rgb_to_hsv(colour);
  float h = hsv.x + hue.x + 0.5;
  vec3 result = node_hsv_to_rgb(vec3(h - floor(h), clamp(hsv.y * saturation.x, 0.0, 1.0), hsv.z * value.x));
  return max(colour + factor * (result - colour), vec3(0.0));
}

vec3 node_gamma(vec3 colour, vec3 exponent)
{
  return mix(colour, pow(max(colour, vec3(1e-38)), exponent), greaterThan(colour, vec3(0.0)));
}

vec3 node_brightness_contrast(vec3 colour, vec3 bright, vec3 contrast)
{
  return max((1.0 + contrast) * colour + bright - contrast * 0.5, vec3(0.0));
}

vec3 node_mix_screen(vec3 t, vec3 a, vec3 b) { return 1.0 - (1.0 - t + t * (1.0 - b)) * (1.0 - a); }
vec3 node_mix_overlay(vec3 t, vec3 a, vec3 b)
{
  return mix(1.0 - (1.0 - t + 2.0 * t * (1.0 - b)) * (1.0 - a), a * (1.0 - t + 2.0 * t * b), lessThan(a, vec3(0.5)));
}
vec3 node_mix_divide(vec3 t, vec3 a, vec3 b)
{
  return mix(a, (1.0 - t) * a + t * a / mix(vec3(1.0), b, notEqual(b, vec3(0.0))), notEqual(b, vec3(0.0)));
}
vec3 node_mix_difference(vec3 t, vec3 a, vec3 b) { return a + t * (abs(a - b) - a); }
vec3 node_mix_exclusion(vec3 t, vec3 a, vec3 b) { return max(a + t * (b - 2.0 * a * b), vec3(0.0)); }
vec3 node_mix_darken(vec3 t, vec3 a, vec3 b) { return a + t * (min(a, b) - a); }
vec3 node_mix_lighten(vec3 t, vec3 a, vec3 b) { return a + t * (max(a, b) - a); }
vec3 node_mix_dodge(vec3 t, vec3 a, vec3 b)
{
  vec3 divisor = 1.0 - t * b;
  vec3 dodged = mix(vec3(1.0), min(a / mix(vec3(1.0), divisor, greaterThan(divisor, vec3(0.0))), vec3(1.0)),
                    greaterThan(divisor, vec3(0.0)));
  return mix(a, dodged, notEqual(a, vec3(0.0)));
}
vec3 node_mix_burn(vec3 t, vec3 a, vec3 b)
{
  vec3 divisor = 1.0 - t + t * b;
  vec3 burnt = clamp(1.0 - (1.0 - a) / mix(vec3(1.0), divisor, greaterThan(divisor, vec3(0.0))), 0.0, 1.0);
  return mix(vec3(0.0), burnt, greaterThan(divisor, vec3(0.0)));
}
vec3 node_mix_soft_light(vec3 t, vec3 a, vec3 b)
{
  vec3 screen = 1.0 - (1.0 - b) * (1.0 - a);
  return (1.0 - t) * a + t * ((1.0 - a) * b * a + a * screen);
}
vec3 node_mix_linear_light(vec3 t, vec3 a, vec3 b) { return a + t * (2.0 * b - 1.0); }
