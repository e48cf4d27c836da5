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

/* Blender's XYZ Euler rotation: Z after Y after X */
mat3 node_euler_matrix(vec3 rotation)
{
  vec3 c = cos(rotation), s = sin(rotation);
  /* columns */
  return mat3(vec3(c.y * c.z, c.y * s.z, -s.y),
              vec3(s.y * s.x * c.z - c.x * s.z, s.y * s.x * s.z + c.x * c.z, c.y * s.x),
              vec3(s.y * c.x * c.z + s.x * s.z, s.y * c.x * s.z - s.x * c.z, c.y * c.x));
}

vec3 node_safe_normalize(vec3 a)
{
  float length_a = length(a);
  return length_a != 0.0 ? a / length_a : vec3(0.0);
}

/* mapping_type: 0 POINT, 1 TEXTURE, 2 VECTOR, 3 NORMAL */
vec3 node_mapping(vec3 vector, vec3 location, vec3 rotation, vec3 scale, int mapping_type)
{
  mat3 turn = node_euler_matrix(rotation);
  if (mapping_type == 1) {
    return node_safe_divide(transpose(turn) * (vector - location), scale);
  }
  if (mapping_type == 3) {
    return node_safe_normalize(turn * node_safe_divide(vector, scale));
  }
  vec3 turned = turn * (vector * scale);
  return mapping_type == 0 ? turned + location : turned;
}

vec3 node_vector_cross_product(vec3 a, vec3 b) { return cross(a, b); }
vec3 node_vector_project(vec3 a, vec3 b)
{
  float length2 = dot(b, b);
  return length2 != 0.0 ? b * (dot(a, b) / length2) : vec3(0.0);
}
vec3 node_vector_reflect(vec3 a, vec3 b)
{
  vec3 n = node_safe_normalize(b);
  return a - 2.0 * dot(n, a) * n;
}
vec3 node_vector_dot_product(vec3 a, vec3 b) { return vec3(dot(a, b)); }
vec3 node_vector_distance(vec3 a, vec3 b) { return vec3(distance(a, b)); }
vec3 node_vector_length(vec3 a, vec3 b) { return vec3(length(a)); }
vec3 node_vector_normalize(vec3 a, vec3 b) { return node_safe_normalize(a); }

/* Checker Texture: its Fac on all three, or (colour) its Color */
vec3 node_tex_checker(vec3 vector, vec3 colour1, vec3 colour2, vec3 scale, bool colour)
{
  vec3 p = (vector * scale + 0.000001) * 0.999999;
  ivec3 cells = abs(ivec3(floor(p))) % 2;
  float fac = ((cells.x == cells.y) == (cells.z == 1)) ? 1.0 : 0.0;
  return colour ? (fac == 1.0 ? colour1 : colour2) : vec3(fac);
}

/* Gradient Texture's Fac on all three: gradient_type the index in node_functions.GRADIENTS */
vec3 node_tex_gradient(vec3 p, int gradient_type)
{
  float value;
  if (gradient_type == 0) {
    value = p.x;
  }
  else if (gradient_type == 1) {
    value = max(p.x, 0.0) * max(p.x, 0.0);
  }
  else if (gradient_type == 2) {
    float r = clamp(p.x, 0.0, 1.0);
    value = 3.0 * r * r - 2.0 * r * r * r;
  }
  else if (gradient_type == 3) {
    value = (p.x + p.y) * 0.5;
  }
  else if (gradient_type == 4) {
    /* atan(0, 0) is undefined in GLSL, 0 in C */
    value = (p.x == 0.0 && p.y == 0.0) ? 0.5 : atan(p.y, p.x) / 6.283185307179586 + 0.5;
  }
  else {
    float r = max(0.999999 - length(p), 0.0);
    value = gradient_type == 5 ? r * r : r;
  }
  return vec3(clamp(value, 0.0, 1.0));
}

/* Cycles' Perlin noise and the Noise Texture (node_functions.py's noise section): lookup3's hash on uint,
 * NODE_NOISE_OFFSETS (the texture's five random offsets, computed on the CPU: material_textures.py writes
 * them before this file) */
uint node_rot(uint x, uint k) { return (x << k) | (x >> (32u - k)); }

/* lookup3's final mixing of (a, b, c): c is the hash */
uint node_hash_final(uint a, uint b, uint c)
{
  c ^= b; c -= node_rot(b, 14u);
  a ^= c; a -= node_rot(c, 11u);
  b ^= a; b -= node_rot(a, 25u);
  c ^= b; c -= node_rot(b, 16u);
  a ^= c; a -= node_rot(c, 4u);
  b ^= a; b -= node_rot(a, 14u);
  c ^= b; c -= node_rot(b, 24u);
  return c;
}

uint node_hash_uint3(uint kx, uint ky, uint kz)
{
  uint start = 0xDEADBEEFu + (3u << 2u) + 13u;
  return node_hash_final(start + kx, start + ky, start + kz);
}

uint node_hash_uint1(uint kx)
{
  uint start = 0xDEADBEEFu + (1u << 2u) + 13u;
  return node_hash_final(start + kx, start, start);
}

uint node_hash_uint2(uint kx, uint ky)
{
  uint start = 0xDEADBEEFu + (2u << 2u) + 13u;
  return node_hash_final(start + kx, start + ky, start);
}

/* lookup3 of four keys: the first three mixed in before the fourth */
uint node_hash_uint4(uint kx, uint ky, uint kz, uint kw)
{
  uint start = 0xDEADBEEFu + (4u << 2u) + 13u;
  uint a = start + kx, b = start + ky, c = start + kz;
  a -= c; a ^= node_rot(c, 4u); c += b;
  b -= a; b ^= node_rot(a, 6u); a += c;
  c -= b; c ^= node_rot(b, 8u); b += a;
  a -= c; a ^= node_rot(c, 16u); c += b;
  b -= a; b ^= node_rot(a, 19u); a += c;
  c -= b; c ^= node_rot(b, 4u); b += a;
  return node_hash_final(a + kw, b, c);
}

/* Cycles' hash_float<n>_to_float: the hash of the floats' bits over 0xFFFFFFFF */
float node_hash_to_float(uint hash) { return float(hash) / float(0xFFFFFFFFu); }
float node_hash_float1(float x) { return node_hash_to_float(node_hash_uint1(floatBitsToUint(x))); }
float node_hash_float2(float x, float y)
{
  return node_hash_to_float(node_hash_uint2(floatBitsToUint(x), floatBitsToUint(y)));
}
float node_hash_float3(float x, float y, float z)
{
  return node_hash_to_float(node_hash_uint3(floatBitsToUint(x), floatBitsToUint(y), floatBitsToUint(z)));
}
float node_hash_float4(float x, float y, float z, float w)
{
  return node_hash_to_float(node_hash_uint4(floatBitsToUint(x), floatBitsToUint(y), floatBitsToUint(z),
                                            floatBitsToUint(w)));
}

float node_fade(float t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

float node_grad3(uint hash, float x, float y, float z)
{
  uint h = hash & 15u;
  float u = h < 8u ? x : y;
  float vt = (h == 12u || h == 14u) ? x : z;
  float v = h < 4u ? y : vt;
  return ((h & 1u) != 0u ? -u : u) + ((h & 2u) != 0u ? -v : v);
}

float node_perlin_3d(vec3 p)
{
  vec3 cell = floor(p);
  vec3 f = p - cell;
  uvec3 c = uvec3(ivec3(cell));
  float u = node_fade(f.x), v = node_fade(f.y), w = node_fade(f.z);
  float v0 = node_grad3(node_hash_uint3(c.x, c.y, c.z), f.x, f.y, f.z);
  float v1 = node_grad3(node_hash_uint3(c.x + 1u, c.y, c.z), f.x - 1.0, f.y, f.z);
  float v2 = node_grad3(node_hash_uint3(c.x, c.y + 1u, c.z), f.x, f.y - 1.0, f.z);
  float v3 = node_grad3(node_hash_uint3(c.x + 1u, c.y + 1u, c.z), f.x - 1.0, f.y - 1.0, f.z);
  float v4 = node_grad3(node_hash_uint3(c.x, c.y, c.z + 1u), f.x, f.y, f.z - 1.0);
  float v5 = node_grad3(node_hash_uint3(c.x + 1u, c.y, c.z + 1u), f.x - 1.0, f.y, f.z - 1.0);
  float v6 = node_grad3(node_hash_uint3(c.x, c.y + 1u, c.z + 1u), f.x, f.y - 1.0, f.z - 1.0);
  float v7 = node_grad3(node_hash_uint3(c.x + 1u, c.y + 1u, c.z + 1u), f.x - 1.0, f.y - 1.0, f.z - 1.0);
  float x1 = 1.0 - u, y1 = 1.0 - v, z1 = 1.0 - w;
  return z1 * (y1 * (v0 * x1 + v1 * u) + v * (v2 * x1 + v3 * u)) +
         w * (y1 * (v4 * x1 + v5 * u) + v * (v6 * x1 + v7 * u));
}

float node_snoise_3d(vec3 p)
{
  p = p - trunc(p / 100000.0) * 100000.0 + mix(vec3(0.0), vec3(0.5), greaterThanEqual(abs(p), vec3(1e6)));
  return 0.982 * node_perlin_3d(p);
}

/* noise_type: the index in node_functions.NOISE_TYPES */
float node_noise_fractal(vec3 p, float detail, float roughness, float lacunarity, float offset, float gain,
                         int noise_type, bool normalize)
{
  int octaves = int(detail);
  float remainder = detail - floor(detail);
  if (noise_type == 0) {
    float fscale = 1.0, amp = 1.0, maxamp = 0.0, sum = 0.0;
    for (int i = 0; i <= octaves; i++) {
      sum += node_snoise_3d(p * fscale) * amp;
      maxamp += amp;
      amp *= roughness;
      fscale *= lacunarity;
    }
    float low = normalize ? 0.5 * sum / maxamp + 0.5 : sum;
    if (remainder != 0.0) {
      float sum2 = sum + node_snoise_3d(p * fscale) * amp;
      float high = normalize ? 0.5 * sum2 / (maxamp + amp) + 0.5 : sum2;
      return low + remainder * (high - low);
    }
    return low;
  }
  if (noise_type == 1) {
    float value = 1.0, power = 1.0;
    for (int i = 0; i <= octaves; i++) {
      value *= power * node_snoise_3d(p) + 1.0;
      power *= roughness;
      p *= lacunarity;
    }
    return remainder != 0.0 ? value * (remainder * power * node_snoise_3d(p) + 1.0) : value;
  }
  if (noise_type == 4) {
    float power = roughness;
    float value = offset + node_snoise_3d(p);
    p *= lacunarity;
    for (int i = 1; i <= octaves; i++) {
      value += (node_snoise_3d(p) + offset) * power * value;
      power *= roughness;
      p *= lacunarity;
    }
    return remainder != 0.0 ? value + remainder * (node_snoise_3d(p) + offset) * power * value : value;
  }
  if (noise_type == 2) {
    float power = 1.0, value = 0.0, weight = 1.0;
    for (int i = 0; weight > 0.001 && i <= octaves; i++) {
      weight = min(weight, 1.0);
      float signal = (node_snoise_3d(p) + offset) * power;
      power *= roughness;
      value += weight * signal;
      weight *= gain * signal;
      p *= lacunarity;
    }
    if (remainder != 0.0 && weight > 0.001) {
      value += remainder * min(weight, 1.0) * (node_snoise_3d(p) + offset) * power;
    }
    return value;
  }
  float power = roughness;
  float signal = offset - abs(node_snoise_3d(p));
  signal *= signal;
  float value = signal;
  for (int i = 1; i <= octaves; i++) {
    p *= lacunarity;
    float weight = clamp(signal * gain, 0.0, 1.0);
    signal = offset - abs(node_snoise_3d(p));
    signal *= signal;
    signal *= weight;
    value += signal * power;
    power *= roughness;
  }
  return value;
}

/* The Noise Texture in 3D: its Fac on all three, or (colour) its Color */
vec3 node_tex_noise(vec3 vector, vec3 scale, vec3 detail, vec3 roughness, vec3 lacunarity, vec3 offset, vec3 gain,
                    vec3 distortion, int noise_type, bool normalize, bool colour)
{
  float d = clamp(detail.x, 0.0, 15.0), r = max(roughness.x, 0.0);
  vec3 p = vector * scale.x;
  if (distortion.x != 0.0) {
    p += vec3(node_snoise_3d(p + NODE_NOISE_OFFSETS[0]), node_snoise_3d(p + NODE_NOISE_OFFSETS[1]),
              node_snoise_3d(p + NODE_NOISE_OFFSETS[2])) * distortion.x;
  }
  float value = node_noise_fractal(p, d, r, lacunarity.x, offset.x, gain.x, noise_type, normalize);
  if (!colour) {
    return vec3(value);
  }
  return vec3(value,
              node_noise_fractal(p + NODE_NOISE_OFFSETS[3], d, r, lacunarity.x, offset.x, gain.x, noise_type,
                                 normalize),
              node_noise_fractal(p + NODE_NOISE_OFFSETS[4], d, r, lacunarity.x, offset.x, gain.x, noise_type,
                                 normalize));
}

/* The Wave Texture's Fac on all three: wave_type 0 BANDS, 1 RINGS; directions the index in
 * node_functions.WAVE_DIRECTIONS, profile in WAVE_PROFILES */
vec3 node_tex_wave(vec3 vector, vec3 scale, vec3 distortion, vec3 detail, vec3 detail_scale, vec3 detail_roughness,
                   vec3 phase, int wave_type, int bands_direction, int rings_direction, int profile)
{
  vec3 p = (vector * scale.x + 0.000001) * 0.999999;
  float n;
  if (wave_type == 0) {
    n = bands_direction == 3 ? (p.x + p.y + p.z) * 10.0 : p[bands_direction] * 20.0;
  }
  else {
    vec3 keep = rings_direction == 0 ? vec3(0.0, 1.0, 1.0) : rings_direction == 1 ? vec3(1.0, 0.0, 1.0) :
                rings_direction == 2 ? vec3(1.0, 1.0, 0.0) : vec3(1.0);
    n = length(p * keep) * 20.0;
  }
  n += phase.x;
  if (distortion.x != 0.0) {
    float fbm = node_noise_fractal(p * detail_scale.x, detail.x, detail_roughness.x, 2.0, 0.0, 0.0, 0, true);
    n += distortion.x * (fbm * 2.0 - 1.0);
  }
  float value;
  if (profile == 0) {
    value = 0.5 + 0.5 * sin(n - 1.5707963267948966);
  }
  else {
    n /= 6.283185307179586;
    value = profile == 1 ? n - floor(n) : abs(n - floor(n + 0.5)) * 2.0;
  }
  return vec3(value);
}

/* The Magic Texture: its Color, or (not colour) its Fac, the colour's mean, on all three */
vec3 node_tex_magic(vec3 vector, vec3 scale, vec3 distortion, int depth, bool colour)
{
  vec3 p = vector * scale.x;
  float d = distortion.x;
  float x = sin((p.x + p.y + p.z) * 5.0);
  float y = cos((-p.x + p.y - p.z) * 5.0);
  float z = -cos((-p.x - p.y + p.z) * 5.0);
  if (depth > 0) {
    x *= d;
    y *= d;
    z *= d;
    y = -cos(x - y + z) * d;
    if (depth > 1) {
      x = cos(x - y - z) * d;
      if (depth > 2) {
        z = sin(-x - y - z) * d;
        if (depth > 3) {
          x = -cos(-x + y - z) * d;
          if (depth > 4) {
            y = -sin(-x + y + z) * d;
            if (depth > 5) {
              y = -cos(-x + y + z) * d;
              if (depth > 6) {
                x = cos(x + y + z) * d;
                if (depth > 7) {
                  z = sin(x + y - z) * d;
                  if (depth > 8) {
                    x = -cos(-x - y + z) * d;
                    if (depth > 9) {
                      y = -sin(x - y + z) * d;
                    }
                  }
                }
              }
            }
          }
        }
      }
    }
  }
  float divisor = d != 0.0 ? d * 2.0 : 1.0;
  vec3 result = vec3(0.5) - vec3(x, y, z) / divisor;
  return colour ? result : vec3((result.x + result.y + result.z) * (1.0 / 3.0));
}

/* A dielectric's Fresnel reflectance at |cosine| for the relative index eta (total internal reflection: 1) */
float node_fresnel_dielectric_cos(float cosine, float eta)
{
  float c = abs(cosine);
  float g = eta * eta - 1.0 + c * c;
  if (g <= 0.0) {
    return 1.0;
  }
  g = sqrt(g);
  float a = (g - c) / (g + c);
  float b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
  return 0.5 * a * a * (1.0 + b * b);
}

/* The Fresnel node (incoming: toward the viewer) */
vec3 node_fresnel(vec3 ior, vec3 normal, vec3 incoming)
{
  float cosine = dot(normal, incoming);
  float eta = max(ior.x, 1e-5);
  return vec3(node_fresnel_dielectric_cos(cosine, cosine < 0.0 ? 1.0 / eta : eta));
}

/* The Layer Weight node's Fresnel or (not fresnel) Facing */
vec3 node_layer_weight(vec3 blend, vec3 normal, vec3 incoming, bool fresnel)
{
  float cosine = dot(normal, incoming);
  if (fresnel) {
    float eta = max(1.0 - blend.x, 1e-5);
    return vec3(node_fresnel_dielectric_cos(cosine, cosine < 0.0 ? eta : 1.0 / eta));
  }
  float clamped = clamp(blend.x, 0.0, 1.0 - 1e-5);
  float exponent = clamped < 0.5 ? 2.0 * clamped : 0.5 / (1.0 - clamped);
  return vec3(1.0 - (blend.x != 0.5 ? pow(abs(cosine), exponent) : abs(cosine)));
}

/* The Mix node's HSV blends (node_functions._mix_hsv): Hue takes b's hue, Color its hue and saturation, where b
 * has a hue */
vec3 node_mix_hue_of(vec3 t, vec3 a, vec3 b, bool saturation)
{
  vec3 hsv_b = node_rgb_to_hsv(b);
  if (hsv_b.y == 0.0) {
    return a;
  }
  vec3 hsv = node_rgb_to_hsv(a);
  hsv.x = hsv_b.x;
  hsv.y = saturation ? hsv_b.y : hsv.y;
  return mix(a, node_hsv_to_rgb(hsv), t.x);
}
vec3 node_mix_hue(vec3 t, vec3 a, vec3 b) { return node_mix_hue_of(t, a, b, false); }
vec3 node_mix_color(vec3 t, vec3 a, vec3 b) { return node_mix_hue_of(t, a, b, true); }
vec3 node_mix_saturation(vec3 t, vec3 a, vec3 b)
{
  vec3 hsv = node_rgb_to_hsv(a);
  if (hsv.y == 0.0) {
    return a;
  }
  hsv.y = (1.0 - t.x) * hsv.y + t.x * node_rgb_to_hsv(b).y;
  return node_hsv_to_rgb(hsv);
}
vec3 node_mix_value(vec3 t, vec3 a, vec3 b)
{
  vec3 hsv = node_rgb_to_hsv(a);
  hsv.z = (1.0 - t.x) * hsv.z + t.x * node_rgb_to_hsv(b).z;
  return node_hsv_to_rgb(hsv);
}

/* The White Noise Texture (dimensions: index in node_functions.NOISE_DIMENSIONS): its Value on all three, or
 * (colour) its Color */
vec3 node_tex_white_noise(vec3 vector, vec3 w, int dimensions, bool colour)
{
  float x = vector.x, y = vector.y, z = vector.z, t = w.x;
  if (dimensions == 0) {
    float value = node_hash_float1(t);
    return colour ? vec3(value, node_hash_float2(t, 1.0), node_hash_float2(t, 2.0)) : vec3(value);
  }
  if (dimensions == 1) {
    float value = node_hash_float2(x, y);
    return colour ? vec3(value, node_hash_float3(x, y, 1.0), node_hash_float3(x, y, 2.0)) : vec3(value);
  }
  if (dimensions == 2) {
    float value = node_hash_float3(x, y, z);
    return colour ? vec3(value, node_hash_float4(x, y, z, 1.0), node_hash_float4(x, y, z, 2.0)) : vec3(value);
  }
  float value = node_hash_float4(x, y, z, t);
  return colour ? vec3(value, node_hash_float4(z, x, t, y), node_hash_float4(t, z, y, x)) : vec3(value);
}

/* The Bump node's normal (node_functions.bump_normal) from the height's and the position's differences across
 * the pixel */
vec3 node_bump_normal(vec3 strength, vec3 distance, float height_dx, float height_dy, vec3 position_dx,
                      vec3 position_dy, vec3 normal, bool invert)
{
  vec3 rx = cross(position_dy, normal), ry = cross(normal, position_dx);
  float det = dot(position_dx, rx);
  vec3 gradient = height_dx * rx + height_dy * ry;
  float d = invert ? -distance.x : distance.x;
  float s = clamp(strength.x, 0.0, 1.0);
  vec3 bumped = node_safe_normalize(abs(det) * normal - d * sign(det) * gradient);
  return node_safe_normalize(s * bumped + (1.0 - s) * normal);
}

/* The Bump node in a fragment shader: the differences across the pixel its derivatives (the height's first
 * channel, the surface position) */
vec3 node_bump(vec3 strength, vec3 distance, vec3 height, vec3 normal, vec3 position, bool invert)
{
  return node_bump_normal(strength, distance, dFdx(height.x), dFdy(height.x), dFdx(position), dFdy(position),
                          normal, invert);
}

/* The Brick Texture's integer noise (node_functions.brick_noise) */
float node_brick_noise(uint n)
{
  n = (n + 1013u) & 0x7FFFFFFFu;
  n = (n >> 13u) ^ n;
  uint nn = (n * (n * n * 60493u + 19990303u) + 1376312589u) & 0x7FFFFFFFu;
  return 0.5 * (float(nn) / 1073741824.0);
}

/* The Brick Texture (node_functions.tex_brick): its Color, or (not colour) its Fac on all three */
vec3 node_tex_brick(vec3 vector, vec3 colour1, vec3 colour2, vec3 mortar, vec3 scale, vec3 mortar_size,
                    vec3 mortar_smooth, vec3 bias, vec3 brick_width, vec3 row_height, float offset_amount,
                    int offset_frequency, float squash_amount, int squash_frequency, bool colour)
{
  vec3 p = vector * scale.x;
  float width = brick_width.x, height = row_height.x, offset = 0.0;
  int row = int(floor(p.y / height));
  if (offset_frequency != 0 && squash_frequency != 0) {
    /* C's remainder is nonzero where |row|'s is (GLSL's % of a negative operand is undefined) */
    width *= (abs(row) % squash_frequency) != 0 ? 1.0 : squash_amount;
    offset = (abs(row) % offset_frequency) != 0 ? 0.0 : width * offset_amount;
  }
  int brick = int(floor((p.x + offset) / width));
  float x = (p.x + offset) - width * float(brick);
  float y = p.y - height * float(row);
  float tint = clamp(node_brick_noise(uint((row << 16) + (brick & 0xFFFF))) + bias.x, 0.0, 1.0);
  float nearest = min(min(x, y), min(width - x, height - y));
  float fac;
  if (nearest >= mortar_size.x) {
    fac = 0.0;
  }
  else if (mortar_smooth.x == 0.0) {
    fac = 1.0;
  }
  else {
    float ramp = 1.0 - nearest / mortar_size.x;
    float t = ramp / mortar_smooth.x;
    fac = ramp < mortar_smooth.x ? t * t * (3.0 - 2.0 * t) : 1.0;
  }
  if (!colour) {
    return vec3(fac);
  }
  vec3 tinted = fac != 1.0 ? (1.0 - tint) * colour1 + tint * colour2 : colour1;
  return tinted * (1.0 - fac) + mortar * fac;
}
