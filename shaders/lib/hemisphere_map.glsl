/* The square <-> upper hemisphere map of the SSDF images and the bi-scale tables: GLSL mirror of
 * sg_prt_addon/visibility/hemisphere_map.py (its docstring has the conventions).  Depends on sg.glsl.
 *
 *   hemisphere_map_disc_to_square  <- hemisphere_map.disc_to_square
 *   hemisphere_map_to_square       <- hemisphere_map.hemisphere_to_square
 */

const float HEMISPHERE_MAP_QUARTER_PI = 0.25 * SG_PI;

/* Inverse concentric map (Shirley & Chiu 1997): disc point -> square point. */
vec2 hemisphere_map_disc_to_square(vec2 disc)
{
  /* one atan for both octant cases: selects, not branches (a shader pays for both sides of a branch) */
  float radius = length(disc);
  bool x_major = abs(disc.x) >= abs(disc.y);
  float major = x_major ? disc.x : disc.y;
  float minor = x_major ? disc.y : disc.x;
  float signed_radius = major < 0.0 ? -radius : radius;
  float other = major == 0.0 ? 0.0 : signed_radius * atan(minor / major) / HEMISPHERE_MAP_QUARTER_PI;
  return x_major ? vec2(signed_radius, other) : vec2(other, signed_radius);
}

/* Unit direction with z >= 0 -> square point; the disc point (x, y) / sqrt(1 + z) has no cancellation. */
vec2 hemisphere_map_to_square(vec3 direction)
{
  float z = clamp(direction.z, 0.0, 1.0);
  return hemisphere_map_disc_to_square(direction.xy / sqrt(1.0 + z));
}
