/* Local and distant lights as single SGs (wang2009 section 6, eq. 32-33):
 * GLSL mirror of sg_prt_addon/lighting/lights.py.  Depends on sg.glsl.
 *
 *   blender_point_light_intensity <- lights.blender_point_light_intensity
 *   light_cap                     <- lights.light_cap_extent (sphere, or Soft Falloff's disk)
 *   soft_light_sg                 <- lights.sphere_light_sg(model="energy", soft_falloff)
 *   sphere_light_sg               <- lights.sphere_light_sg(model="energy")
 *   sphere_light_sg_paper         <- lights.sphere_light_sg(model="paper")
 *   point_light_sg                <- lights.point_light_sg (energy model)
 *   spot_light_sg                 <- lights.spot_light_sg (energy model)
 *   directional_light_sg          <- lights.directional_light_sg(model="energy")
 *   light_emission_factor         <- lights.emission_factor (spots' cones, area lights' patches)
 *   light_cap_radius              <- lights.cap_radius
 *
 * Lobes come back in out parameters (axis, sharpness, amplitude); intensity
 * and irradiance are scalars: for a colour pass 1 and multiply.  lights.py
 * works in float64 internally; here float32 positions limit the accuracy of
 * the light direction to ~1e-7 of the scene scale over the distance.
 */

const float LIGHT_MAX_SHARPNESS = 1.0e6;
const float LIGHT_LN10 = 2.302585092994046;
/* lights._finite: amplitudes saturate at float32 max * 1e-6 instead of overflowing */
const float LIGHT_MAX_AMPLITUDE = 3.4028235e32;

float blender_point_light_intensity(float power)
{
  return power / SG_FOUR_PI;
}

/* Cap of sin^2(theta) = sin2 (0 = a point): sharpness fa^-1(2 pi sin^2) = ln(10)/sin^2,
 * capped at LIGHT_MAX_SHARPNESS; amplitude so that the sphere integral is energy. */
void light_cap_energy_lobe(float sin2, float energy, out float sharpness, out float amplitude)
{
  sharpness = sin2 > 0.0 ? min(LIGHT_LN10 / sin2, LIGHT_MAX_SHARPNESS) : LIGHT_MAX_SHARPNESS;
  amplitude = min(energy / sg_sphere_integral(sharpness, 1.0), LIGHT_MAX_AMPLITUDE);
}

/* Half-angle of the cap a light's SG stands for (the inverse of light_cap_energy_lobe's sharpness). */
float light_cap_radius(float sharpness)
{
  return precise_asin(sqrt(clamp(LIGHT_LN10 / max(sharpness, 1.0e-30), 0.0, 1.0)));
}

/* The cap a point-like light of radius r covers: returns sin^2 of it and writes effective2 (lights.light_cap_extent:
 * max(d^2, r^2) for a sphere, d^2 + r^2 for Soft Falloff's disk facing the point; floored at 1e-12 max(r^2, 1))
 * and the axis. */
float light_cap(vec3 shading_position, vec3 light_position, float radius, bool soft_falloff,
                out float effective2, out vec3 axis)
{
  vec3 to_light = light_position - shading_position;
  float distance2 = dot(to_light, to_light);
  float radius2 = radius * radius;
  effective2 = max(soft_falloff ? distance2 + radius2 : max(distance2, radius2), 1.0e-12 * max(radius2, 1.0));
  axis = safe_normalize(to_light);
  return radius2 / effective2;
}

/* Geometry shared by both sphere-light models: light_cap of a sphere. */
float sphere_light_cap(vec3 shading_position, vec3 light_position, float radius,
                       out float effective2, out vec3 axis)
{
  return light_cap(shading_position, light_position, radius, false, effective2, axis);
}

/* A light of radius r and intensity I [W/sr] (use blender_point_light_intensity), energy model: sphere integral =
 * cap radiance integral 2 I / (effective2 (1 + cos)); a sphere, or with soft_falloff Blender's disk. */
void soft_light_sg(vec3 shading_position, vec3 light_position, float radius, bool soft_falloff, float intensity,
                   out vec3 axis, out float sharpness, out float amplitude)
{
  float effective2;
  float sin2 = light_cap(shading_position, light_position, radius, soft_falloff, effective2, axis);
  float cos_half = sqrt(max(1.0 - sin2, 0.0));
  float energy = 2.0 / (effective2 * (1.0 + cos_half));
  light_cap_energy_lobe(sin2, energy, sharpness, amplitude);
  amplitude = clamp(amplitude * intensity, -LIGHT_MAX_AMPLITUDE, LIGHT_MAX_AMPLITUDE);
}

/* Sphere light of radius r and intensity I [W/sr] (use blender_point_light_intensity),
 * energy model: sphere integral = cap radiance integral 2 I / (max(d, r)^2 (1 + cos)). */
void sphere_light_sg(vec3 shading_position, vec3 light_position, float radius, float intensity,
                     out vec3 axis, out float sharpness, out float amplitude)
{
  soft_light_sg(shading_position, light_position, radius, false, intensity, axis, sharpness, amplitude);
}

/* eq. 32 as printed: sharpness ln(10) d^2 / r^2, amplitude I / d^2 (comparison only). */
void sphere_light_sg_paper(vec3 shading_position, vec3 light_position, float radius, float intensity,
                           out vec3 axis, out float sharpness, out float amplitude)
{
  float effective2;
  float sin2 = sphere_light_cap(shading_position, light_position, radius, effective2, axis);
  sharpness = sin2 > 0.0 ? min(LIGHT_LN10 / sin2, LIGHT_MAX_SHARPNESS) : LIGHT_MAX_SHARPNESS;
  amplitude = clamp(intensity / effective2, -LIGHT_MAX_AMPLITUDE, LIGHT_MAX_AMPLITUDE);
}

void point_light_sg(vec3 shading_position, vec3 light_position, float intensity, float radius,
                    out vec3 axis, out float sharpness, out float amplitude)
{
  sphere_light_sg(shading_position, light_position, radius, intensity, axis, sharpness, amplitude);
}

/* The factor on a point-like light's intensity toward the shading point, seen along axis (from the point to the
 * light): an area light's patch (area) emits one-sided along direction with the cosine, times Cycles' soft-box
 * spread attenuation max((tan_half_spread - tan a) normalization, 0) where normalization > 0; a spot
 * (spot_size >= 0) its cone's smoothstep; anything else 1. */
float light_emission_factor(vec3 axis, vec3 direction, float spot_size, float spot_blend, bool area,
                            float tan_half_spread, float spread_normalization)
{
  float cos_angle = clamp(dot(-axis, safe_normalize(direction)), -1.0, 1.0);
  if (area) {
    float facing = max(cos_angle, 0.0);
    if (spread_normalization <= 0.0) {
      return facing;
    }
    float tan_angle = sqrt(max(1.0 - facing * facing, 0.0)) / max(facing, 1.0e-30);
    return facing * max((tan_half_spread - tan_angle) * spread_normalization, 0.0);
  }
  if (spot_size < 0.0) {
    return 1.0;
  }
  float cos_half = cos(0.5 * spot_size);
  float width = max((1.0 - cos_half) * spot_blend, 1.0e-12);
  float t = clamp((cos_angle - cos_half) / width, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

/* Point light times the cone falloff smoothstep((cos a - cos(size/2)) / ((1 - cos(size/2)) blend)). */
void spot_light_sg(vec3 shading_position, vec3 light_position, vec3 spot_direction, float spot_size,
                   float spot_blend, float intensity, float radius,
                   out vec3 axis, out float sharpness, out float amplitude)
{
  sphere_light_sg(shading_position, light_position, radius, intensity, axis, sharpness, amplitude);
  amplitude *= light_emission_factor(axis, spot_direction, spot_size, spot_blend, false, 0.0, 0.0);
}

/* Distant disc light (eq. 33), e.g. Blender's sun: angular_radius = sun.angle / 2,
 * irradiance = sun strength; energy 2 S / (1 + cos(angular_radius)). */
void directional_light_sg(vec3 direction, float angular_radius, float irradiance,
                          out vec3 axis, out float sharpness, out float amplitude)
{
  float half_angle = clamp(angular_radius, 0.0, 0.5 * SG_PI);
  float sine = sin(half_angle);
  float energy = 2.0 / (1.0 + cos(half_angle));
  light_cap_energy_lobe(sine * sine, energy, sharpness, amplitude);
  amplitude = clamp(amplitude * irradiance, -LIGHT_MAX_AMPLITUDE, LIGHT_MAX_AMPLITUDE);
  axis = safe_normalize(direction);
}
