/* Lookup in the SG-prefiltered environment (wang2009 eq. 34-35): GLSL mirror
 * of the lookup half of sg_prt_addon/lighting/env_prefilter.py.  Depends on sg.glsl.
 *
 *   env_sign_not_zero              <- env_prefilter._sign_not_zero
 *   oct_encode                     <- env_prefilter.oct_encode
 *   env_prefilter_blend_parameter  <- env_prefilter.blend_parameter
 *   env_prefilter_lookup           <- env_prefilter.lookup
 *   env_prefilter_lookup_integral  <- env_prefilter.lookup_integral
 *
 * The PrefilteredEnvironment's fields are passed explicitly: `layers` is the
 * 2D texture array (uploaded as is, linear filtering, clamp to edge),
 * log2_min_sharpness and levels_per_octave its level spacing, layer_count =
 * len(sharpness), texcoord_scale_offset[k] = (texcoord_scale[k],
 * texcoord_offset[k]) and mean_radiance (RGB, A unused) the lambda = 0 limit.  Define ENV_PREFILTER_MAX_LAYERS before this file to
 * change the array size (the default levels 0.125..4096, 2 per octave, are 31).
 * Returns vec4: the layers' channels (RGB, A unused).
 */

#ifndef ENV_PREFILTER_MAX_LAYERS
#define ENV_PREFILTER_MAX_LAYERS 32
#endif

const float ENV_FLOAT_TINY = 1.17549435e-38;

vec2 env_sign_not_zero(vec2 x)
{
  return vec2(x.x >= 0.0 ? 1.0 : -1.0, x.y >= 0.0 ? 1.0 : -1.0);
}

/* Unit direction -> octahedral coordinates in [-1, 1]^2, z- folded to the corners. */
vec2 oct_encode(vec3 direction)
{
  vec3 d = direction / max(abs(direction.x) + abs(direction.y) + abs(direction.z), ENV_FLOAT_TINY);
  if (d.z < 0.0) {
    return (1.0 - abs(d.yx)) * env_sign_not_zero(d.xy);
  }
  return d.xy;
}

/* Continuous layer index (log2(lambda) - log2(lambda_0)) * levels_per_octave, clamped to the levels. */
float env_prefilter_blend_parameter(float sharpness, float log2_min_sharpness, float levels_per_octave,
                                    int layer_count)
{
  float position = (log2(max(sharpness, ENV_FLOAT_TINY)) - log2_min_sharpness) * levels_per_octave;
  if (isnan(position)) {
    position = 0.0;
  }
  return clamp(position, 0.0, float(layer_count - 1));
}

/* SG-weighted average radiance around axis for kernel sharpness: octahedral
 * coords, per-layer scale/offset, two hardware-bilinear fetches, linear blend
 * in log2 sharpness; below the broadest level (lambda_0 = 2^log2_min_sharpness)
 * linear in lambda towards mean_radiance, the exact lambda = 0 value. */
vec4 env_prefilter_lookup(sampler2DArray layers, vec3 axis, float sharpness,
                          float log2_min_sharpness, float levels_per_octave, int layer_count,
                          vec2 texcoord_scale_offset[ENV_PREFILTER_MAX_LAYERS], vec4 mean_radiance)
{
  vec2 coords = oct_encode(safe_normalize(axis));
  float position = env_prefilter_blend_parameter(sharpness, log2_min_sharpness, levels_per_octave, layer_count);
  int last = layer_count - 1;
  int lower = min(int(floor(position)), max(last - 1, 0));
  int upper = min(lower + 1, last);
  float fraction = position - float(lower);
  vec2 lower_transform = texcoord_scale_offset[lower];
  vec2 upper_transform = texcoord_scale_offset[upper];
  vec4 lower_value = texture(layers, vec3(coords * lower_transform.x + lower_transform.y, float(lower)));
  vec4 upper_value = texture(layers, vec3(coords * upper_transform.x + upper_transform.y, float(upper)));
  vec4 value = lower_value + (upper_value - lower_value) * fraction;
  float below = isnan(sharpness) ? 0.0 : clamp(sharpness / exp2(log2_min_sharpness), 0.0, 1.0);
  return mean_radiance + (value - mean_radiance) * below;
}

/* <G(axis, sharpness, amplitude), L> = amplitude Gamma_L (eq. 35): the lookup times the SG's integral. */
vec4 env_prefilter_lookup_integral(sampler2DArray layers, vec3 axis, float sharpness, float amplitude,
                                   float log2_min_sharpness, float levels_per_octave, int layer_count,
                                   vec2 texcoord_scale_offset[ENV_PREFILTER_MAX_LAYERS], vec4 mean_radiance)
{
  return env_prefilter_lookup(layers, axis, sharpness, log2_min_sharpness, levels_per_octave, layer_count,
                              texcoord_scale_offset, mean_radiance) * sg_sphere_integral(sharpness, amplitude);
}
