/* What every surface technique shares (techniques/sg_lobes.py and techniques/factored.py include it after
 * shaders/lib): the shading frame, the normal map and tangent rotation (mirrored by techniques.sg_shading's
 * shading_frame, apply_normal_map, rotate_tangent) and, with HAS_LIGHTS, the scene's lights as SGs
 * (lights.glsl; mirrored by sg_shading.point_light_sgs).  Needs sg.glsl and the `scene` block. */

/* Unit normal, tangent by Gram-Schmidt (fallback if parallel), bitangent n x t. */
void shading_frame(vec3 normal, vec3 tangent, out vec3 n, out vec3 t, out vec3 b)
{
  n = safe_normalize(normal);
  vec3 unit_tangent = safe_normalize(tangent, vec3(0.0));
  t = unit_tangent - n * dot(n, unit_tangent);
  /* within 0.06 degrees of the normal (or zero) what is left is rounding: take the fallback
   * (1e-6 = techniques.sg_shading.SHADING_FRAME_MIN_SINE squared) */
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

vec3 rotate_tangent(vec3 normal, vec3 tangent, float rotation)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  return cos(rotation) * t + sin(rotation) * b;
}

#ifdef HAS_LIGHTS
/* Light l (point/spot first, then suns) as an SG at the shading position. */
void scene_light_sg(int l, vec3 position, out vec3 axis, out float sharpness, out vec3 amplitude)
{
  if (l < scene.counts.x) {
    float scalar_amplitude;
    if (scene.spot_direction_size[l].w >= 0.0) {
      spot_light_sg(position, scene.point_position_radius[l].xyz, scene.spot_direction_size[l].xyz,
                    scene.spot_direction_size[l].w, scene.spot_blend[l].x, 1.0, scene.point_position_radius[l].w,
                    axis, sharpness, scalar_amplitude);
    }
    else {
      sphere_light_sg(position, scene.point_position_radius[l].xyz, scene.point_position_radius[l].w, 1.0,
                      axis, sharpness, scalar_amplitude);
    }
    amplitude = scalar_amplitude * scene.point_intensity[l].rgb;
  }
  else {
    int s = l - scene.counts.x;
    axis = scene.sun_axis_sharpness[s].xyz;
    sharpness = scene.sun_axis_sharpness[s].w;
    amplitude = scene.sun_amplitude[s].rgb;
  }
}
#endif
