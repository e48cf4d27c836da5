/* Fetch from the SG-prefiltered environment: port of env_prefilter.lookup.
 * Layers of a sampler2DArray, octahedral coords scaled/offset per layer, two
 * bilinear fetches blended linearly in log2(sharpness).  Needs sg.glsl. */

vec2 oct_encode(vec3 direction)
{
  vec3 d = direction / max(abs(direction.x) + abs(direction.y) + abs(direction.z), 1.17549435e-38);
  if (d.z < 0.0) {
    vec2 s = vec2(d.x >= 0.0 ? 1.0 : -1.0, d.y >= 0.0 ? 1.0 : -1.0);
    return vec2((1.0 - abs(d.y)) * s.x, (1.0 - abs(d.x)) * s.y);
  }
  return d.xy;
}

/* Continuous layer position of a sharpness, split into the two layers to blend. */
void environment_layers(float sharpness, float log2_min_sharpness, float levels_per_octave, int last_layer,
                        out int lower, out int upper, out float fraction)
{
  float position = (log2(max(sharpness, 1.17549435e-38)) - log2_min_sharpness) * levels_per_octave;
  position = isnan(position) ? 0.0 : clamp(position, 0.0, float(last_layer));
  lower = min(int(floor(position)), max(last_layer - 1, 0));
  upper = min(lower + 1, last_layer);
  fraction = position - float(lower);
}

/* SG-weighted mean radiance around axis: two bilinear fetches (scale_offset_*: per-layer
 * texcoord scale in x, offset in y) blended by fraction. */
vec3 environment_fetch(sampler2DArray layers, vec3 axis, int lower, int upper, float fraction,
                       vec2 scale_offset_lower, vec2 scale_offset_upper)
{
  vec2 coords = oct_encode(safe_normalize(axis));
  vec2 st_lower = coords * scale_offset_lower.x + scale_offset_lower.y;
  vec2 st_upper = coords * scale_offset_upper.x + scale_offset_upper.y;
  vec3 a = texture(layers, vec3(st_lower, float(lower))).rgb;
  vec3 b = texture(layers, vec3(st_upper, float(upper))).rgb;
  return a + (b - a) * fraction;
}
