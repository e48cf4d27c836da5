/* Shadow-map lookups in the lights' depth atlas, mirroring sg_prt_addon/lighting/shadow_maps.py
 * (tile_visibility, point_visibility, sun_visibility) step for step.  The SHADOW_* constants come from that
 * module (techniques/sg/sg_lobes.py _constants_source).  atlas_info: x tile side (texels), y tiles a row, z the
 * face's share of its tile (inner), w mapped lights. */

/* Window depth of a texel (clamped to its tile). */
float shadow_fetch(sampler2D atlas, ivec2 origin, int size, ivec2 texel)
{
  return texelFetch(atlas, origin + clamp(texel, ivec2(0), ivec2(size - 1)), 0).r;
}

/* Linear depth of a window depth: depth_map x near, y far (a cube face's perspective), or z > 0 the world depth
 * of window depth 1 (a sun's linear map); shadow_window is its inverse. */
float shadow_linear(float window, vec3 depth_map)
{
  if (depth_map.z > 0.0) {
    return window * depth_map.z;
  }
  float ndc = 2.0 * window - 1.0;
  return 2.0 * depth_map.y * depth_map.x / max((depth_map.y + depth_map.x) - ndc * (depth_map.y - depth_map.x),
                                               1.0e-30);
}

float shadow_window(float linear, vec3 depth_map)
{
  if (depth_map.z > 0.0) {
    return linear / depth_map.z;
  }
  float n = depth_map.x;
  float f = depth_map.y;
  return 0.5 * ((f + n) / (f - n) - 2.0 * f * n / ((f - n) * max(linear, 1.0e-30))) + 0.5;
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
 * centre, and a grid over the search square where it spans a texel or more; every tap of that grid blocked: the
 * umbra), then an n x n grid of bilinear comparisons (n = ceil(radius) up to SHADOW_FILTER_TAPS, turned by
 * atan(1/n)) over the penumbra (PCSS).  Comparisons on window depths, the blockers' mean on linear ones.
 * softness: 0 while the penumbra fits the filter, rising to 1 as it reaches the guard band's width (the filter is
 * clamped there: a baked object takes its SSDF visibility in that share). */
vec2 shadow_tile_visibility(sampler2D atlas, vec4 atlas_info, int tile, vec2 ndc, float receiver,
                            float texel_world, vec3 light, vec3 depth_map)
{
  int size = int(atlas_info.x);
  int columns = max(int(atlas_info.y), 1);
  ivec2 origin = ivec2(tile % columns, tile / columns) * size;
  vec2 coords = (0.5 + 0.5 * ndc) * float(size) - 0.5;
  float test = shadow_window(receiver - SHADOW_DEPTH_BIAS * texel_world, depth_map);
  float search = clamp(shadow_penumbra(light, receiver, 0.0) / texel_world, 0.0, SHADOW_MARGIN - 1.0);
  bool wide = search >= 1.0;
  int taps = wide ? SHADOW_SEARCH_TAPS * SHADOW_SEARCH_TAPS + 1 : 1;
  float total = 0.0;
  float count = 0.0;
  for (int t = 0; t < taps; t++) {
    int g = t - 1;
    vec2 offset = t == 0 ? vec2(0.0) : (vec2(float(g % SHADOW_SEARCH_TAPS), float(g / SHADOW_SEARCH_TAPS)) + 0.5) /
                                       float(SHADOW_SEARCH_TAPS) * 2.0 - 1.0;
    float window = shadow_fetch(atlas, origin, size, ivec2(floor(coords + 0.5 + offset * search)));
    if (window < test) {
      total += shadow_linear(window, depth_map);
      count += 1.0;
    }
  }
  if (count == 0.0) {
    return vec2(1.0, 0.0);
  }
  float needed = shadow_penumbra(light, receiver, total / count) / texel_world;
  float softness = clamp(2.0 * needed / (SHADOW_MARGIN - 1.0) - 1.0, 0.0, 1.0);
  if (wide && count >= float(taps)) {
    return vec2(0.0, softness);
  }
  float radius = clamp(needed, 0.5, SHADOW_MARGIN - 1.0);
  int side = clamp(int(ceil(radius)), 1, SHADOW_FILTER_TAPS);
  vec2 turn = vec2(float(side), 1.0) * inversesqrt(float(side * side + 1));
  float lit = 0.0;
  for (int j = 0; j < side; j++) {
    for (int i = 0; i < side; i++) {
      vec2 grid = (vec2(float(i), float(j)) + 0.5) / float(side) * 2.0 - 1.0;
      vec2 offset = vec2(turn.x * grid.x - turn.y * grid.y, turn.y * grid.x + turn.x * grid.y);
      vec2 at = coords + offset * radius;
      vec2 base = floor(at);
      vec2 fraction = at - base;
      ivec2 texel = ivec2(base);
      float c00 = shadow_fetch(atlas, origin, size, texel) >= test ? 1.0 : 0.0;
      float c10 = shadow_fetch(atlas, origin, size, texel + ivec2(1, 0)) >= test ? 1.0 : 0.0;
      float c01 = shadow_fetch(atlas, origin, size, texel + ivec2(0, 1)) >= test ? 1.0 : 0.0;
      float c11 = shadow_fetch(atlas, origin, size, texel + ivec2(1, 1)) >= test ? 1.0 : 0.0;
      float bottom = c00 + (c10 - c00) * fraction.x;
      float top = c01 + (c11 - c01) * fraction.x;
      lit += bottom + (top - bottom) * fraction.y;
    }
  }
  return vec2(lit / float(side * side), softness);
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
  /* axis k and the two after it as one-hot vectors: a vector's component at a computed index is kept in memory
   * by llvmpipe */
  vec3 axis = k == 0 ? vec3(1.0, 0.0, 0.0) : (k == 1 ? vec3(0.0, 1.0, 0.0) : vec3(0.0, 0.0, 1.0));
  float dk = dot(d, axis);
  z = max(abs(dk), 1.0e-30);
  int face = 2 * k + (dk < 0.0 ? 1 : 0);
  vec2 ndc = vec2(dot(d, axis.zxy), dot(d, axis.yzx)) / z * atlas_info.z;
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
