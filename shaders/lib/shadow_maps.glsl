/* Shadow-map lookups in the lights' depth atlas, mirroring sg_prt_addon/lighting/shadow_maps.py
 * (tile_visibility, point_visibility, sun_visibility) step for step.  The SHADOW_* constants come from that
 * module (techniques/sg_lobes.py _constants_source).  atlas_info: x tile side (texels), y tiles a row, z the
 * face's share of its tile (inner), w mapped lights. */

/* Linear depth of a texel: depth_map x near, y far (a cube face's perspective window depth), or z > 0 the
 * world depth of window depth 1 (a sun's linear map). */
float shadow_fetch(sampler2D atlas, ivec2 origin, int size, ivec2 texel, vec3 depth_map)
{
  float window = texelFetch(atlas, origin + clamp(texel, ivec2(0), ivec2(size - 1)), 0).r;
  if (depth_map.z > 0.0) {
    return window * depth_map.z;
  }
  float ndc = 2.0 * window - 1.0;
  return 2.0 * depth_map.y * depth_map.x / max((depth_map.y + depth_map.x) - ndc * (depth_map.y - depth_map.x),
                                               1.0e-30);
}

/* World radius of the penumbra at the receiver behind a blocker: light x its radius, y 1 a sphere (z its map's
 * near plane) or 0 a sun (x the tangent of its angular radius). */
float shadow_penumbra(vec3 light, float receiver, float blocker)
{
  if (light.y > 0.5) {
    return light.x * (receiver - blocker) / max(blocker, light.z);
  }
  return light.x * (receiver - blocker);
}

/* (visible fraction, softness) at tile-space ndc of a receiver at linear depth `receiver`: the blocker search (the
 * centre and a grid over the search square), then SHADOW_FILTER_TAPS^2 bilinear comparisons over the penumbra
 * (PCSS; the grid turned by SHADOW_FILTER_TURN).  softness: 0 while the penumbra fits the filter, rising to 1 as it reaches the guard band's width (the
 * filter is clamped there: a baked object takes its SSDF visibility in that share). */
vec2 shadow_tile_visibility(sampler2D atlas, vec4 atlas_info, int tile, vec2 ndc, float receiver,
                             float texel_world, vec3 light, vec3 depth_map)
{
  int size = int(atlas_info.x);
  int columns = max(int(atlas_info.y), 1);
  ivec2 origin = ivec2(tile % columns, tile / columns) * size;
  vec2 coords = (0.5 + 0.5 * ndc) * float(size) - 0.5;
  float test = receiver - SHADOW_DEPTH_BIAS * texel_world;
  float search = clamp(shadow_penumbra(light, receiver, 0.0) / texel_world, 0.0, SHADOW_MARGIN - 1.0);
  float total = 0.0;
  float count = 0.0;
  for (int t = -1; t < SHADOW_SEARCH_TAPS * SHADOW_SEARCH_TAPS; t++) {
    vec2 offset = t < 0 ? vec2(0.0) : (vec2(float(t % SHADOW_SEARCH_TAPS), float(t / SHADOW_SEARCH_TAPS)) + 0.5) /
                                      float(SHADOW_SEARCH_TAPS) * 2.0 - 1.0;
    float depth = shadow_fetch(atlas, origin, size, ivec2(floor(coords + 0.5 + offset * search)), depth_map);
    if (depth < test) {
      total += depth;
      count += 1.0;
    }
  }
  if (count == 0.0) {
    return vec2(1.0, 0.0);
  }
  float needed = shadow_penumbra(light, receiver, total / count) / texel_world;
  float radius = clamp(needed, 0.5, SHADOW_MARGIN - 1.0);
  float lit = 0.0;
  for (int j = 0; j < SHADOW_FILTER_TAPS; j++) {
    for (int i = 0; i < SHADOW_FILTER_TAPS; i++) {
      vec2 grid = (vec2(float(i), float(j)) + 0.5) / float(SHADOW_FILTER_TAPS) * 2.0 - 1.0;
      vec2 offset = vec2(SHADOW_FILTER_TURN.x * grid.x - SHADOW_FILTER_TURN.y * grid.y,
                         SHADOW_FILTER_TURN.y * grid.x + SHADOW_FILTER_TURN.x * grid.y);
      vec2 at = coords + offset * radius;
      vec2 base = floor(at);
      vec2 fraction = at - base;
      ivec2 texel = ivec2(base);
      float c00 = shadow_fetch(atlas, origin, size, texel, depth_map) >= test ? 1.0 : 0.0;
      float c10 = shadow_fetch(atlas, origin, size, texel + ivec2(1, 0), depth_map) >= test ? 1.0 : 0.0;
      float c01 = shadow_fetch(atlas, origin, size, texel + ivec2(0, 1), depth_map) >= test ? 1.0 : 0.0;
      float c11 = shadow_fetch(atlas, origin, size, texel + ivec2(1, 1), depth_map) >= test ? 1.0 : 0.0;
      float bottom = c00 + (c10 - c00) * fraction.x;
      float top = c01 + (c11 - c01) * fraction.x;
      lit += bottom + (top - bottom) * fraction.y;
    }
  }
  return vec2(lit / float(SHADOW_FILTER_TAPS * SHADOW_FILTER_TAPS),
              clamp(2.0 * needed / (SHADOW_MARGIN - 1.0) - 1.0, 0.0, 1.0));
}

/* A point or spot light (radius light_radius) of six faces from first_tile, near_far its maps' planes. */
vec2 shadow_point_visibility(sampler2D atlas, vec4 atlas_info, vec3 light_position, float light_radius,
                              int first_tile, vec2 near_far, vec3 position, vec3 normal)
{
  float inner_texels = atlas_info.x * atlas_info.z;
  vec3 d = position - light_position;
  vec3 a = abs(d);
  float z = max(a.x, max(a.y, a.z));
  vec3 towards = dot(normal, -d) < 0.0 ? -normal : normal;
  d += towards * (SHADOW_NORMAL_OFFSET * 2.0 * z / inner_texels);
  a = abs(d);
  int k = (a.x >= a.y && a.x >= a.z) ? 0 : (a.y >= a.z ? 1 : 2);
  z = max(a[k], 1.0e-30);
  int face = 2 * k + (d[k] < 0.0 ? 1 : 0);
  vec2 ndc = vec2(d[(k + 1) % 3], d[(k + 2) % 3]) / z * atlas_info.z;
  return shadow_tile_visibility(atlas, atlas_info, first_tile + face, ndc, z, 2.0 * z / inner_texels,
                                vec3(light_radius, 1.0, near_far.x), vec3(near_far, 0.0));
}

/* A sun: its tile's rows (ndc x, ndc y, depth01 of (p, 1)), a texel's world size, the depth range and the
 * tangent of its angular radius.  Outside its tile: lit. */
vec2 shadow_sun_visibility(sampler2D atlas, vec4 atlas_info, vec4 row_x, vec4 row_y, vec4 row_z, int tile,
                            float texel, float depth_range, float tan_radius, vec3 position, vec3 normal)
{
  vec3 forward = row_z.xyz * depth_range;
  vec3 towards = dot(normal, forward) > 0.0 ? -normal : normal;
  vec4 moved = vec4(position + towards * (SHADOW_NORMAL_OFFSET * texel), 1.0);
  vec2 ndc = vec2(dot(row_x, moved), dot(row_y, moved));
  if (abs(ndc.x) > 1.0 || abs(ndc.y) > 1.0) {
    return vec2(1.0, 0.0);
  }
  return shadow_tile_visibility(atlas, atlas_info, tile, ndc, dot(row_z, moved) * depth_range, texel,
                                vec3(tan_radius, 0.0, 0.0), vec3(0.0, 0.0, depth_range));
}
