/* The factored BRDF (mccool2001 eq. 9, and the 1D Fresnel factor r(o.h) of its section 5) per pixel, lit by
 * the scene's lights (eq. 20: f(o, i) times each light's clamped-cosine integral, the light taken at its
 * SG's axis) and the environment (beyond the paper: diffuse from its SG mixture, glossy as the factored
 * BRDF's directional albedo times the prefiltered radiance around the mirror direction).  Mirrored by
 * techniques/homomorphic/factored_shading.py.  Needs sg.glsl, hemisphere.glsl, clamped_cosine.glsl, surface_common.glsl,
 * (HAS_LIGHTS) lights.glsl, (HAS_ENVIRONMENT) env_prefilter.glsl, (HAS_VISIBILITY: every lobe shadowed by
 * its SSDF visibility) ssdf.glsl and common/lobe_visibility.glsl, and the samplers factor_p, factor_q,
 * (FACTOR_R) factor_r and factored_albedo; factor_scale: rgb = alpha A (eq. 20, eq. 6), w = the sharpness
 * of the glossy environment lookup.  The maps hold log-factors, interpolated and then exponentiated:
 * what the factorization fitted. */

/* Parabolic map coordinates of a local direction; below the horizon the rim point of its azimuth. */
vec2 parabolic_uv(vec3 d)
{
  d = safe_normalize(d);
  vec2 xy = d.z >= 0.0 ? d.xy : d.xy / max(length(d.xy), 1.0e-30);
  return 0.5 * (xy / (1.0 + max(d.z, 0.0)) + 1.0);
}

vec3 factored_brdf(vec3 o, vec3 i)
{
  vec3 h = safe_normalize(o + i, vec3(0.0, 0.0, 1.0));
  vec3 log_f = texture(factor_p, parabolic_uv(o)).rgb + texture(factor_q, parabolic_uv(h)).rgb;
#ifdef FACTOR_P_LIGHT
  log_f += texture(factor_p, parabolic_uv(i)).rgb;
#endif
#ifdef FACTOR_R
  log_f += texture(factor_r, vec2(clamp(dot(safe_normalize(o), h), 0.0, 1.0), 0.5)).rgb;
#endif
  return factor_scale.rgb * exp(log_f);
}

#ifdef HAS_VISIBILITY
#define FACTORED_VISIBILITY(axis, sharpness) lobe_visibility(axis, sharpness, n)
#define FACTORED_LIGHT_VISIBILITY(axis, sharpness) light_cap_visibility(axis, light_cap_radius(sharpness))
#else
#define FACTORED_VISIBILITY(axis, sharpness) 1.0
#define FACTORED_LIGHT_VISIBILITY(axis, sharpness) 1.0
#endif
#ifdef DIFFUSE_VISIBILITY_ROWS
/* the broad diffuse lobes' visible fractions from the vertices (the SG techniques' per-vertex pass:
 * environment lobe e, the constant world's 0), 4 a row */
vec4 diffuse_fractions[DIFFUSE_VISIBILITY_ROWS];
#define FACTORED_DIFFUSE_VISIBILITY(e, axis, sharpness) diffuse_fractions[(e) / 4][(e) % 4]
#else
#define FACTORED_DIFFUSE_VISIBILITY(e, axis, sharpness) FACTORED_VISIBILITY(axis, sharpness)
#endif

void shade_factored(vec3 position, vec3 normal, vec3 tangent, vec3 diffuse_color, vec3 specular_color,
                    out vec3 diffuse, out vec3 specular)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  vec3 view = scene.camera.w > 0.5 ? safe_normalize(scene.camera.xyz - position) : -safe_normalize(scene.camera.xyz);
  mat3 frame = mat3(t, b, n);                   /* local -> world */
  vec3 o = view * frame;                        /* world -> local: the rows */
  vec3 irradiance = vec3(0.0);
  vec3 radiance = vec3(0.0);
#ifdef HAS_LIGHTS
  for (int l = 0; l < scene.counts.x + scene.counts.y; l++) {
    vec3 light_axis;
    float light_sharpness;
    vec3 light_amplitude;
    scene_light_sg(l, position, light_axis, light_sharpness, light_amplitude);
    vec3 light_energy = light_amplitude * (sg_clamped_cosine_integral(light_axis, light_sharpness, 1.0, n) *
                                           FACTORED_LIGHT_VISIBILITY(light_axis, light_sharpness));
    irradiance += light_energy;
    radiance += light_energy * factored_brdf(o, light_axis * frame);      /* eq. 20 */
  }
#endif
  vec3 albedo = factor_scale.rgb * texture(factored_albedo, parabolic_uv(o)).rgb;
  vec3 mirror = 2.0 * dot(n, view) * n - view;
#ifdef HAS_ENVIRONMENT
  for (int e = 0; e < scene.counts.z; e++) {
    vec3 env_axis = scene.env_axis_sharpness[e].xyz;
    float env_sharpness = scene.env_axis_sharpness[e].w;
    irradiance += scene.env_amplitude[e].rgb * (sg_clamped_cosine_integral(env_axis, env_sharpness, 1.0, n) *
                                                FACTORED_DIFFUSE_VISIBILITY(e, env_axis, env_sharpness));
  }
  radiance += albedo * environment_radiance(mirror, factor_scale.w) * FACTORED_VISIBILITY(mirror, factor_scale.w);
#else
  irradiance += SG_PI * scene.world_colour.rgb * FACTORED_DIFFUSE_VISIBILITY(0, n, 0.0);
  radiance += albedo * scene.world_colour.rgb * FACTORED_VISIBILITY(mirror, factor_scale.w);
#endif
  diffuse = diffuse_color * (1.0 / SG_PI) * irradiance;
  specular = specular_color * radiance;
}
