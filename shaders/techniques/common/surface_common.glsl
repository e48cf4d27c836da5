/* What every surface technique shares (techniques/sg/sg_lobes.py and techniques/homomorphic/factored.py include it after
 * shaders/lib): the shading frame, the normal map and tangent rotation (mirrored by techniques.sg.sg_shading's
 * shading_frame, apply_normal_map, rotate_tangent) and, with HAS_LIGHTS, the scene's lights as SGs
 * (lights.glsl; mirrored by sg_shading.point_light_sgs) and, with HAS_ENVIRONMENT and HAS_SPECULAR, the
 * prefiltered environment's radiance for a lobe (env_prefilter.glsl and the environment_texture and
 * equirect_texture samplers; mirrored by sg_shading.environment_radiance).  Needs sg.glsl and the
 * `scene` block. */

/* Unit normal, tangent by Gram-Schmidt (fallback if parallel), bitangent n x t. */
void shading_frame(vec3 normal, vec3 tangent, out vec3 n, out vec3 t, out vec3 b)
{
  n = safe_normalize(normal);
  vec3 unit_tangent = safe_normalize(tangent, vec3(0.0));
  t = unit_tangent - n * dot(n, unit_tangent);
  /* within 0.06 degrees of the normal (or zero) what is left is rounding: take the fallback
   * (1e-6 = techniques.sg.sg_shading.SHADING_FRAME_MIN_SINE squared) */
  if (dot(t, t) < 1.0e-6) {
    t = cross(n, abs(n.x) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0));
  }
  t = safe_normalize(t);
  t = safe_normalize(t - n * dot(n, t));     /* a second pass takes the first one's rounding out */
  b = cross(n, t);
}

vec3 apply_normal_map(vec3 normal, vec4 tangent, vec3 sample_value, float strength)
{
  vec3 n = safe_normalize(normal);
  vec3 b = tangent.w * cross(n, tangent.xyz);
  vec3 m = 2.0 * sample_value - 1.0;
  vec3 mapped = safe_normalize(tangent.xyz * m.x + b * m.y + n * m.z);
  return safe_normalize(n + (mapped - n) * strength);
}

/* The spread 1 / kappa of the normals a minified normal map averaged into `mean` (decoded, unit texels: its
 * length r < 1): the von Mises-Fisher concentration of mean length r, kappa ~ (3 r - r^3) / (1 - r^2) (Banerjee
 * et al. 2005), the map's strength squared scaling the variance; faded in over the first mip level, so a
 * magnified map's bilinear blend of texels adds none (mirror: techniques.sg.sg_shading.normal_spread). */
float normal_spread(vec3 mean, float level, float strength)
{
  float r = min(length(mean), 1.0);
  return min(level, 1.0) * strength * strength * (1.0 - r * r) / max(3.0 * r - r * r * r, 1.0e-6);
}

/* An NDF lobe convolved with the normals' spread (an SG of sharpness 1 / spread): sharpness
 * lambda / (1 + lambda spread), its integral kept (mirror: techniques.sg.sg_shading.spread_lobes). */
void spread_lobe(inout float sharpness, inout float amplitude, float spread)
{
  float narrowing = 1.0 / (1.0 + sharpness * spread);
  sharpness *= narrowing;
  amplitude *= narrowing;
}

vec3 rotate_tangent(vec3 normal, vec3 tangent, float rotation)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  return cos(rotation) * t + sin(rotation) * b;
}

#ifdef HAS_LIGHTS
/* Point-like light l's emission toward a point that sees it along axis (lights.glsl light_emission_factor). */
float scene_light_emission(int l, vec3 axis)
{
  vec4 blend = scene.spot_blend[l];
  return light_emission_factor(axis, scene.spot_direction_size[l].xyz, scene.spot_direction_size[l].w, blend.x,
                               blend.y > 0.5, blend.z, blend.w);
}

/* Light l (point/spot/area patch first, then suns) as an SG at the shading position. */
void scene_light_sg(int l, vec3 position, out vec3 axis, out float sharpness, out vec3 amplitude)
{
  if (l < scene.counts.x) {
    float scalar_amplitude;
    soft_light_sg(position, scene.point_position_radius[l].xyz, scene.point_position_radius[l].w,
                  scene.point_intensity[l].a > 0.5, 1.0, axis, sharpness, scalar_amplitude);
    amplitude = scalar_amplitude * scene_light_emission(l, axis) * scene.point_intensity[l].rgb;
  }
  else {
    int s = l - scene.counts.x;
    axis = scene.sun_axis_sharpness[s].xyz;
    sharpness = scene.sun_axis_sharpness[s].w;
    amplitude = scene.sun_amplitude[s].rgb;
  }
}

#ifdef LIGHT_SHADOW_MAPS
/* Each mapped light's visible fraction and softness at the pixel by shadow slot (shadow_maps_evaluate): the
 * lookups are made once a pixel, not once for each of shade_footprint's samples.  Four to a vec4 and picked by
 * component, not an array: llvmpipe keeps a dynamically indexed array in memory, which cost the frame of a diffuse
 * scene 2.3x (measured: 0.027 s at 128 x 128).  Needs shadow_maps.glsl and the `shadow_atlas` sampler; mirrored by
 * lighting.shadow_maps.light_visibility. */
#if SGPRT_MAX_SHADOW_MAPS != 8
#error "light_shadow_of holds 8 shadow slots"
#endif
vec4 shadow_fraction_low = vec4(1.0);
vec4 shadow_fraction_high = vec4(1.0);
vec4 shadow_softness_low = vec4(0.0);
vec4 shadow_softness_high = vec4(0.0);

void shadow_maps_evaluate(vec3 position, vec3 normal)
{
  for (int s = 0; s < SGPRT_MAX_SHADOW_MAPS; s++) {
    if (s >= int(scene.shadow_atlas.w)) {
      break;
    }
    int l = int(scene.shadow_slot_light[s / 4][s % 4]);
    vec2 shadow;
    if (l < scene.counts.x) {
      vec4 info = scene.point_shadow[l];
      shadow = shadow_point_visibility(shadow_atlas, scene.shadow_atlas, scene.point_position_radius[l].xyz,
                                       scene.point_position_radius[l].w, int(info.y), info.zw, position, normal);
    }
    else {
      int sun = l - scene.counts.x;
      vec4 info = scene.sun_shadow[sun];
      shadow = shadow_sun_visibility(shadow_atlas, scene.shadow_atlas, scene.sun_shadow_rows[3 * sun],
                                     scene.sun_shadow_rows[3 * sun + 1], scene.sun_shadow_rows[3 * sun + 2],
                                     int(info.y), info.z, info.w, scene.sun_shadow_radius[sun].x, position, normal);
    }
    vec4 low = vec4(equal(ivec4(s), ivec4(0, 1, 2, 3)));
    vec4 high = vec4(equal(ivec4(s), ivec4(4, 5, 6, 7)));
    shadow_fraction_low = mix(shadow_fraction_low, vec4(shadow.x), low);
    shadow_fraction_high = mix(shadow_fraction_high, vec4(shadow.x), high);
    shadow_softness_low = mix(shadow_softness_low, vec4(shadow.y), low);
    shadow_softness_high = mix(shadow_softness_high, vec4(shadow.y), high);
  }
}

/* (visible fraction, softness) of shadow slot `slot` */
vec2 light_shadow_of(int slot)
{
  vec4 low = vec4(equal(ivec4(slot), ivec4(0, 1, 2, 3)));
  vec4 high = vec4(equal(ivec4(slot), ivec4(4, 5, 6, 7)));
  return vec2(dot(shadow_fraction_low, low) + dot(shadow_fraction_high, high),
              dot(shadow_softness_low, low) + dot(shadow_softness_high, high));
}

/* Light l's shadow slot (point lights first, then suns), -1 without a map */
int light_shadow_slot(int l)
{
  return int(l < scene.counts.x ? scene.point_shadow[l].x : scene.sun_shadow[l - scene.counts.x].x);
}
#endif
#endif

#if defined(HAS_ENVIRONMENT) && defined(HAS_SPECULAR)
/* env_prefilter_lookup (env_prefilter.glsl) step for step, with the per-layer texcoord
 * transforms read from the scene block in place: passing them as the library's array
 * argument copies the whole array for every lobe of every fragment. */
vec3 environment_radiance(vec3 axis, float sharpness)
{
  vec2 coords = oct_encode(safe_normalize(axis));
  int layer_count = scene.counts.w;
  float position = env_prefilter_blend_parameter(sharpness, scene.prefilter_info.x, scene.prefilter_info.y,
                                                 layer_count);
  int last = layer_count - 1;
  int lower = min(int(floor(position)), max(last - 1, 0));
  int upper = min(lower + 1, last);
  float fraction = position - float(lower);
  vec2 lower_transform = scene.prefilter_scale_offset[lower].xy;
  vec2 upper_transform = scene.prefilter_scale_offset[upper].xy;
  vec4 lower_value = texture(environment_texture, vec3(coords * lower_transform.x + lower_transform.y, float(lower)));
  vec4 upper_value = texture(environment_texture, vec3(coords * upper_transform.x + upper_transform.y, float(upper)));
  vec3 value = (lower_value + (upper_value - lower_value) * fraction).rgb;
  /* sharper than the top layer: towards the map's own radiance, reached where a lobe's width is one map row
   * (env_prefilter.lookup's beyond_top_layer) */
  float log2_top = scene.prefilter_info.x + float(last) / scene.prefilter_info.y;
  float rows = float(textureSize(equirect_texture, 0).y);
  float log2_raw = max(2.0 * log2(rows / SG_PI), log2_top + 1.0);
  float beyond = clamp((log2(max(sharpness, 1.0e-30)) - log2_top) / (log2_raw - log2_top), 0.0, 1.0);
  if (beyond > 0.0) {
    vec3 d = safe_normalize(axis);
    vec2 uv = vec2(0.5 - atan(d.y, d.x) / (2.0 * SG_PI), 0.5 + atan(d.z, length(d.xy)) / SG_PI);
    value += (texture(equirect_texture, uv).rgb - value) * beyond;
  }
  /* below the broadest level: affine in lambda towards the mean radiance (world_colour.rgb when
   * world_colour.w is 1) at lambda = 0 */
  float below = clamp((isnan(sharpness) ? 0.0 : sharpness) / exp2(scene.prefilter_info.x), 0.0, 1.0);
  return scene.world_colour.w > 0.5 ? scene.world_colour.rgb + (value - scene.world_colour.rgb) * below : value;
}
#endif
