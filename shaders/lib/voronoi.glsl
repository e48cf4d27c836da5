/* The Voronoi Texture in 3D (mirror: sg_prt_addon/reflectance/voronoi.py, Cycles' kernel/svm/voronoi.h):
 * feature points jittered in each unit cell by PCG 3D of the cell, the features under each metric, the fractal
 * sum of octaves.  feature: index in voronoi.FEATURES, metric in METRICS, output_kind in OUTPUTS. */

vec3 voronoi_cell_hash(ivec3 cell)
{
  ivec3 v = cell * 1664525 + 1013904223;
  v.x += v.y * v.z;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v = v ^ (v >> 16);
  v.x += v.y * v.z;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  return vec3(v & 0x7FFFFFFF) * (1.0 / 2147483648.0);
}

float voronoi_distance(vec3 a, vec3 b, int metric, float exponent)
{
  vec3 d = abs(a - b);
  if (metric == 0) {
    return sqrt(dot(d, d));
  }
  if (metric == 1) {
    return d.x + d.y + d.z;
  }
  if (metric == 2) {
    return max(max(d.x, d.y), d.z);
  }
  return pow(pow(d.x, exponent) + pow(d.y, exponent) + pow(d.z, exponent), 1.0 / exponent);
}

/* F1 (second: F2): distance, colour and position of the nearest (second nearest) point */
void voronoi_f1_f2(vec3 coord, int metric, float exponent, float randomness, bool second, out float dist,
                   out vec3 colour, out vec3 position)
{
  vec3 cell_floor = floor(coord);
  ivec3 cell = ivec3(cell_floor);
  vec3 local_position = coord - cell_floor;
  float d1 = 3.40282347e+38, d2 = 3.40282347e+38;
  vec3 p1 = vec3(0.0), p2 = vec3(0.0);
  ivec3 c1 = ivec3(0), c2 = ivec3(0);
  for (int k = -1; k <= 1; k++) {
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        ivec3 offset = ivec3(i, j, k);
        vec3 point_position = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness;
        float d = voronoi_distance(point_position, local_position, metric, exponent);
        if (d < d1) {
          d2 = d1;
          p2 = p1;
          c2 = c1;
          d1 = d;
          p1 = point_position;
          c1 = cell + offset;
        }
        else if (d < d2) {
          d2 = d;
          p2 = point_position;
          c2 = cell + offset;
        }
      }
    }
  }
  dist = second ? d2 : d1;
  colour = voronoi_cell_hash(second ? c2 : c1);
  position = (second ? p2 : p1) + cell_floor;
}

void voronoi_smooth_f1(vec3 coord, int metric, float exponent, float randomness, float smoothness,
                       out float dist, out vec3 colour, out vec3 position)
{
  vec3 cell_floor = floor(coord);
  ivec3 cell = ivec3(cell_floor);
  vec3 local_position = coord - cell_floor;
  float smooth_distance = 0.0;
  vec3 smooth_colour = vec3(0.0), smooth_position = vec3(0.0);
  float h = -1.0;
  for (int k = -2; k <= 2; k++) {
    for (int j = -2; j <= 2; j++) {
      for (int i = -2; i <= 2; i++) {
        ivec3 offset = ivec3(i, j, k);
        vec3 point_position = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness;
        float d = voronoi_distance(point_position, local_position, metric, exponent);
        if (h == -1.0) {
          h = 1.0;
        }
        else {
          float t = clamp(0.5 + 0.5 * (smooth_distance - d) / smoothness, 0.0, 1.0);
          h = t * t * (3.0 - 2.0 * t);
        }
        float correction = smoothness * h * (1.0 - h);
        smooth_distance = smooth_distance + (d - smooth_distance) * h - correction;
        correction /= 1.0 + 3.0 * smoothness;
        smooth_colour = smooth_colour + (voronoi_cell_hash(cell + offset) - smooth_colour) * h - correction;
        smooth_position = smooth_position + (point_position - smooth_position) * h - correction;
      }
    }
  }
  dist = smooth_distance;
  colour = smooth_colour;
  position = cell_floor + smooth_position;
}

float voronoi_distance_to_edge(vec3 coord, float randomness)
{
  vec3 cell_floor = floor(coord);
  ivec3 cell = ivec3(cell_floor);
  vec3 local_position = coord - cell_floor;
  vec3 closest = vec3(0.0);
  float least = 3.40282347e+38;
  for (int k = -1; k <= 1; k++) {
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        ivec3 offset = ivec3(i, j, k);
        vec3 to_point = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness - local_position;
        float d = dot(to_point, to_point);
        if (d < least) {
          least = d;
          closest = to_point;
        }
      }
    }
  }
  least = 3.40282347e+38;
  for (int k = -1; k <= 1; k++) {
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        ivec3 offset = ivec3(i, j, k);
        vec3 to_point = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness - local_position;
        vec3 perpendicular = to_point - closest;
        if (dot(perpendicular, perpendicular) > 0.0001) {
          least = min(least, dot((closest + to_point) / 2.0, normalize(perpendicular)));
        }
      }
    }
  }
  return least;
}

float voronoi_n_sphere_radius(vec3 coord, float randomness)
{
  vec3 cell_floor = floor(coord);
  ivec3 cell = ivec3(cell_floor);
  vec3 local_position = coord - cell_floor;
  vec3 closest = vec3(0.0);
  ivec3 closest_offset = ivec3(0);
  float least = 3.40282347e+38;
  for (int k = -1; k <= 1; k++) {
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        ivec3 offset = ivec3(i, j, k);
        vec3 point_position = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness;
        float d = distance(point_position, local_position);
        if (d < least) {
          least = d;
          closest = point_position;
          closest_offset = offset;
        }
      }
    }
  }
  least = 3.40282347e+38;
  vec3 nearest_to_closest = vec3(0.0);
  for (int k = -1; k <= 1; k++) {
    for (int j = -1; j <= 1; j++) {
      for (int i = -1; i <= 1; i++) {
        if (i == 0 && j == 0 && k == 0) {
          continue;
        }
        ivec3 offset = ivec3(i, j, k) + closest_offset;
        vec3 point_position = vec3(offset) + voronoi_cell_hash(cell + offset) * randomness;
        float d = distance(closest, point_position);
        if (d < least) {
          least = d;
          nearest_to_closest = point_position;
        }
      }
    }
  }
  return distance(nearest_to_closest, closest) / 2.0;
}

void voronoi_octave(vec3 coord, int feature, int metric, float exponent, float randomness, float smoothness,
                    out float dist, out vec3 colour, out vec3 position)
{
  if (feature == 2 && smoothness != 0.0) {
    voronoi_smooth_f1(coord, metric, exponent, randomness, smoothness, dist, colour, position);
  }
  else {
    voronoi_f1_f2(coord, metric, exponent, randomness, feature == 1, dist, colour, position);
  }
}

vec3 node_tex_voronoi(vec3 vector, vec3 scale_in, vec3 detail_in, vec3 roughness_in, vec3 lacunarity_in,
                      vec3 smoothness_in, vec3 exponent_in, vec3 randomness_in, int feature, int metric,
                      bool normalized, int output_kind)
{
  float scale_value = scale_in.x, lacunarity = lacunarity_in.x, exponent = exponent_in.x;
  float detail = clamp(detail_in.x, 0.0, 15.0), roughness = clamp(roughness_in.x, 0.0, 1.0);
  float randomness = clamp(randomness_in.x, 0.0, 1.0), smoothness = clamp(smoothness_in.x / 2.0, 0.0, 0.5);
  vec3 coord = vector * scale_value;
  float half_cell = 0.5 + 0.5 * randomness;
  if (feature == 4) {
    return output_kind == 3 ? vec3(voronoi_n_sphere_radius(coord, randomness)) : vec3(0.0);
  }
  bool zero_input = detail == 0.0 || roughness == 0.0;
  float remainder = detail - floor(detail);
  float amplitude = 1.0, scale = 1.0;
  if (feature == 3) {
    float max_amplitude = half_cell, dist = 8.0;
    for (int i = 0; float(i) <= ceil(detail); i++) {
      float octave = voronoi_distance_to_edge(coord * scale, randomness);
      if (zero_input) {
        dist = octave;
        break;
      }
      float nearer = mix(dist, min(dist, octave / scale), amplitude);
      float lerp_amplitude = mix(max_amplitude, half_cell / scale, amplitude);
      if (float(i) <= detail) {
        max_amplitude = lerp_amplitude;
        dist = nearer;
        scale *= lacunarity;
        amplitude *= roughness;
      }
      else if (remainder != 0.0) {
        max_amplitude = mix(max_amplitude, lerp_amplitude, remainder);
        dist = mix(dist, min(dist, nearer), remainder);
      }
    }
    return output_kind == 0 ? vec3(normalized ? dist / max_amplitude : dist) : vec3(0.0);
  }
  float max_distance = voronoi_distance(vec3(0.0), vec3(half_cell), metric, exponent) * (feature == 1 ? 2.0 : 1.0);
  float max_amplitude = 0.0, dist = 0.0;
  vec3 colour = vec3(0.0), position = vec3(0.0);
  for (int i = 0; float(i) <= ceil(detail); i++) {
    float octave_distance;
    vec3 octave_colour, octave_position;
    voronoi_octave(coord * scale, feature, metric, exponent, randomness, smoothness, octave_distance, octave_colour,
                   octave_position);
    if (zero_input) {
      max_amplitude = 1.0;
      dist = octave_distance;
      colour = octave_colour;
      position = octave_position;
      break;
    }
    vec3 blended_position = mix(position, octave_position / scale, amplitude);
    if (float(i) <= detail) {
      max_amplitude += amplitude;
      dist += octave_distance * amplitude;
      colour += octave_colour * amplitude;
      position = blended_position;
      scale *= lacunarity;
      amplitude *= roughness;
    }
    else if (remainder != 0.0) {
      max_amplitude = mix(max_amplitude, max_amplitude + amplitude, remainder);
      dist = mix(dist, dist + octave_distance * amplitude, remainder);
      colour = mix(colour, colour + octave_colour * amplitude, remainder);
      position = mix(position, blended_position, remainder);
    }
  }
  if (normalized) {
    dist /= max_amplitude * max_distance;
    colour /= max_amplitude;
  }
  position = scale_value != 0.0 ? position / scale_value : vec3(0.0);
  return output_kind == 0 ? vec3(dist) : output_kind == 1 ? colour : output_kind == 2 ? position : vec3(0.0);
}
