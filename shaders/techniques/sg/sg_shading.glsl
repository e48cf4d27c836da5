/* Per-pixel SG shading (wang2009 eq. 36-43; HAS_VISIBILITY: with SSDF shadows, eq. 39-43);
 * mirrored line by line by sg_prt_addon/techniques/sg_shading.py.  Needs sg.glsl, hemisphere.glsl,
 * clamped_cosine.glsl, (lights or specular) clamped_cosine_table.glsl and the `clamped_cosine_table`
 * sampler (the clamped cosine of the lobes whose sharpness varies per pixel), (HAS_LIGHTS) lights.glsl,
 * (HAS_SPECULAR) brdf.glsl + warp.glsl,
 * (HAS_ENVIRONMENT and HAS_SPECULAR) env_prefilter.glsl and (HAS_VISIBILITY) ssdf.glsl +
 * lobe_visibility.glsl, plus the `scene` uniform block.  HAS_DIFFUSE / HAS_SPECULAR
 * (sg_parametric.material_terms): without one, its term is left out (its colour is zero, so the full
 * variant's term is exactly zero).  DIFFUSE_VISIBILITY_ROWS (with HAS_VISIBILITY and HAS_DIFFUSE): the
 * broad diffuse lobes' visible fractions come interpolated from the vertices (diffuse_fractions, filled
 * by surface.frag.glsl from the pass of vertex_visibility.frag.glsl).  SHARED_LIGHT_VISIBILITY (with
 * HAS_VISIBILITY, HAS_LIGHTS and HAS_SPECULAR; techniques.sg.sg_shading.shares_light_visibility): every light is narrow on
 * the object, and its products with the slice lobes take its own visibility instead of a decode each.
 * BISCALE (biscale.glsl before this file): the lobes are a bi-scale material's effective lobes (NDF_LOBES of
 * them, iwasaki2012 eq. 15) with their tables' factors and the small-scale M, and the diffuse term is scaled by
 * the tile's D(i, o); no light or environment tail (those are GGX's own). */

#ifdef HAS_VISIBILITY
#define LOBE_VISIBILITY(axis, sharpness) lobe_visibility(axis, sharpness, n)
#define LIGHT_VISIBILITY(axis, sharpness) light_cap_visibility(axis, light_cap_radius(sharpness))
#if defined(HAS_SPECULAR) && !defined(SHARED_LIGHT_VISIBILITY)
#define PRODUCT_VISIBILITY      /* a decode for each NDF lobe's light x slice products */
#endif
#else
#define LOBE_VISIBILITY(axis, sharpness) 1.0
#define LIGHT_VISIBILITY(axis, sharpness) 1.0
#endif
#ifdef DIFFUSE_VISIBILITY_ROWS
/* environment lobe e (the constant world: 0), 4 a row */
vec4 diffuse_fractions[DIFFUSE_VISIBILITY_ROWS];
#define DIFFUSE_VISIBILITY(e, axis, sharpness) diffuse_fractions[(e) / 4][(e) % 4]
#else
#define DIFFUSE_VISIBILITY(e, axis, sharpness) LOBE_VISIBILITY(axis, sharpness)
#endif

#ifdef HAS_SPECULAR
/* NDF lobe k of the model (brdf.glsl's <model>_ndf_lobe, or the anisotropy table), local
 * frame.  p = (roughness, ior, exponent, alpha_x), q = (alpha_y, nu, nv, rf0). */
void model_ndf_lobe(vec4 p, vec4 q, int k, out vec3 axis, out float sharpness, out float amplitude)
{
  axis = vec3(0.0, 0.0, 1.0);
  vec2 lobe = vec2(0.0, 0.0);
#if defined(MODEL_GGX) && NDF_LOBES == 1
  lobe = ggx_ndf_lobe(p.x);
#elif defined(MODEL_GGX)
  ggx_two_lobes(ggx_table, p.x, k, lobe.x, lobe.y);
#elif defined(MODEL_COOK_TORRANCE)
  lobe = cook_torrance_ndf_lobe(p.x);
#elif defined(MODEL_BLINN_PHONG)
  lobe = blinn_phong_ndf_lobe(p.z);
#elif defined(MODEL_WARD_ISO)
  lobe = ward_isotropic_ndf_lobe(p.w);
#endif
  sharpness = lobe.x;
  amplitude = lobe.y;
#if defined(MODEL_WARD_ANISO) || defined(MODEL_GGX_ANISO)
  float ax = max(p.w, 1.0e-6);
  float ay = max(q.x, 1.0e-6);
#if defined(MODEL_GGX_ANISO) && NDF_LOBES > 1
  /* ndf_fit.ggx_anisotropic_lobes: all lobes fitted together to GGX's two sphere-fitted lobes stretched */
  ggx_anisotropic_lobes(anisotropy_table, ax, ay, k, axis, sharpness, amplitude);
#else
  anisotropic_lobes(anisotropy_table, ax, ay, 1.0 / (SG_PI * ax * ay), k, axis, sharpness, amplitude);
#endif
#if defined(MODEL_GGX_ANISO) && NDF_LOBES == 1
  /* one lobe: the table's Gaussian scaled by GGX's one-lobe mapping at the geometric-mean alpha */
  vec2 ggx_scale = isotropic_mapping_ggx(sqrt(ax * ay));
  sharpness *= 0.5 * ggx_scale.x;
  amplitude *= ggx_scale.y;
#endif
#elif defined(MODEL_ASHIKHMIN_SHIRLEY)
  float nu = max(q.y, 0.0);
  float nv = max(q.z, 0.0);
  anisotropic_lobes(anisotropy_table, sqrt(2.0 / max(nu, 1.0e-6)), sqrt(2.0 / max(nv, 1.0e-6)),
                    sqrt((nu + 1.0) * (nv + 1.0)) / (2.0 * SG_PI), k, axis, sharpness, amplitude);
#endif
}

#ifdef MODEL_FITTED
/* The stored lobe fit's texel and shadowing: common/fitted_texels.glsl. */

/* M_o(i) = F_eta(|i.h|) S(o) S(i) / (pi (i.n)(o.n)), S(o) given (once a pixel). */
float fitted_m_factor(vec3 wo, vec3 wi, float eta, float shadowing_o)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  vec3 h = safe_normalize(wo + wi);
  return fresnel_dielectric(dot(wi, h), eta) * shadowing_o * fitted_shadowing_of(wi)
         / (SG_PI * max(wi.z, BRDF_COSINE_EPSILON) * max(wo.z, BRDF_COSINE_EPSILON));   /* grazing: no 0/0 */
}
#endif

/* The NDF's angular widths along the tangent and the bitangent (radians, about the slopes' spread: GGX's and
 * Beckmann's alpha, Blinn-Phong's and Ashikhmin-Shirley's sqrt(2 / (n + 2)) and sqrt(2 / (n + 1)), a fitted
 * lobe's sqrt(2 / lambda), the sharpest); the small-scale BRDF's for a bi-scale material. */
vec2 model_lobe_widths(vec4 p, vec4 q)
{
#if defined(MODEL_FITTED)
  float sharpest = 0.0;
  for (int k = 0; k < FITTED_LOBES; k++) {
    sharpest = max(sharpest, fitted_layer(1 + 2 * k).w);
  }
  return vec2(sqrt(2.0 / max(sharpest, 1.0e-6)));
#elif defined(MODEL_GGX)
  return vec2(ggx_alpha(p.x));
#elif defined(MODEL_COOK_TORRANCE)
  return vec2(p.x);
#elif defined(MODEL_BLINN_PHONG)
  return vec2(sqrt(2.0 / (max(p.z, 0.0) + 2.0)));
#elif defined(MODEL_WARD_ISO)
  return vec2(p.w);
#elif defined(MODEL_WARD_ANISO) || defined(MODEL_GGX_ANISO)
  return vec2(p.w, q.x);
#elif defined(MODEL_ASHIKHMIN_SHIRLEY)
  return sqrt(2.0 / (max(q.yz, vec2(0.0)) + 1.0));
#else
  return vec2(1.0);
#endif
}

/* M_o(i) of the model (brdf.glsl's <model>_m_factor). */
float model_m_factor(vec3 wo, vec3 wi, vec4 p, vec4 q)
{
#if defined(MODEL_GGX)
  return ggx_m_factor(wo, wi, p.x);
#elif defined(MODEL_COOK_TORRANCE)
  return cook_torrance_m_factor(wo, wi, p.x, p.y);
#elif defined(MODEL_BLINN_PHONG)
  return blinn_phong_m_factor(wo, wi, p.z);
#elif defined(MODEL_WARD_ISO)
  return ward_isotropic_m_factor(wo, wi);
#elif defined(MODEL_WARD_ANISO)
  return ward_anisotropic_m_factor(wo, wi);
#elif defined(MODEL_GGX_ANISO)
  return ggx_anisotropic_m_factor(wo, wi, p.w, q.x);
#elif defined(MODEL_ASHIKHMIN_SHIRLEY)
  return ashikhmin_shirley_m_factor(wo, wi, q.y, q.z, q.w);
#elif defined(MODEL_FITTED)
  return fitted_m_factor(wo, wi, p.y, p.z);     /* p.y eta, p.z S(o) (shade_surface) */
#else
  return 0.0;
#endif
}

#if defined(HAS_LIGHTS) && !defined(MODEL_FITTED) && !defined(BISCALE)
/* What the slice lobes miss of the model's own BRDF at a light's centre (techniques.sg.sg_shading.light_tail) */
#define LIGHT_TAIL

/* rho_s(o, i) = M_o(i) D(h) of the model itself (brdf.glsl), local frame */
float model_specular(vec3 wo, vec3 wi, vec4 p, vec4 q)
{
  vec3 h = safe_normalize(safe_normalize(wo) + safe_normalize(wi));
  float ndf = 0.0;
#if defined(MODEL_GGX)
  ndf = ggx_ndf(h, p.x);
#elif defined(MODEL_COOK_TORRANCE)
  ndf = cook_torrance_ndf(h, p.x);
#elif defined(MODEL_BLINN_PHONG)
  ndf = blinn_phong_ndf(h, p.z);
#elif defined(MODEL_WARD_ISO)
  ndf = ward_isotropic_ndf(h, p.w);
#elif defined(MODEL_WARD_ANISO)
  ndf = ward_anisotropic_ndf(h, p.w, q.x);
#elif defined(MODEL_GGX_ANISO)
  ndf = ggx_anisotropic_ndf(h, p.w, q.x);
#elif defined(MODEL_ASHIKHMIN_SHIRLEY)
  ndf = ashikhmin_shirley_ndf(h, q.y, q.z);
#endif
  return model_m_factor(wo, wi, p, q) * ndf;
}
#endif
#endif




#define SLICE_LOBES (WARP_NODES * NDF_LOBES)

#ifdef BISCALE
/* the bi-scale diffuse factor D(i, o) at a world direction, and its mean A(o) for a constant world */
#define BISCALE_DIFFUSE(world_direction) biscale_diffuse((world_direction) * frame)
#define BISCALE_ALBEDO biscale_albedo()
#else
#define BISCALE_DIFFUSE(world_direction) 1.0
#define BISCALE_ALBEDO 1.0
#endif

#if defined(HAS_VISIBILITY) && defined(HAS_ENVIRONMENT) && defined(HAS_SPECULAR)
/* A partly occluded slice lobe reads the environment where its visible part lies (techniques.sg.sg_shading.
 * visible_part_axes): its visible and occluded parts see different light, which the product of the visible
 * fraction and the radiance at the lobe's axis ignores. */
#define VISIBLE_PART_LOOKUP

/* Phi^-1(p), the standard normal's quantile, for p in (0, 1) (techniques.sg.sg_shading.probit: Abramowitz and
 * Stegun 26.2.23, absolute error below 4.5e-4) */
float probit(float p)
{
  float t = sqrt(-2.0 * log(max(min(p, 1.0 - p), 1.0e-30)));
  float x = t - (2.515517 + t * (0.802853 + t * 0.010328)) / (1.0 + t * (1.432788 + t * (0.189269 + t * 0.001308)));
  return p < 0.5 ? -x : x;
}

/* The part a straight boundary keeps, the fraction v, of a unit Gaussian (techniques.sg.sg_shading.
 * _truncated_moments): its mean beyond the axis m = phi(z) / v, z = Phi^-1(v), and its variance across the
 * boundary, 1 - z m - m^2. */
vec2 truncated_moments(float v)
{
  v = clamp(v, 1.0e-4, 1.0 - 1.0e-6);
  float z = probit(v);
  float m = exp(-0.5 * z * z) * 0.3989422804014327 / v;
  return vec2(m, 1.0 - z * m - m * m);
}

/* Angle, in lobe widths 1/sqrt(lambda), from the axis of a lobe cut by a straight boundary that keeps the
 * fraction v of it to the mean of the kept part (techniques.sg.sg_shading.visible_part_offset). */
float visible_part_offset(float v)
{
  return truncated_moments(v).x;
}

/* Factor on a lobe's sharpness that gives it the width of its visible part (techniques.sg.sg_shading.
 * visible_part_narrowing): the kept part's variance across the boundary (at least VISIBLE_PART_MIN_VARIANCE) and
 * 1 along it, averaged (the lookup is isotropic). */
float visible_part_narrowing(float v)
{
  return 2.0 / (1.0 + clamp(truncated_moments(v).y, VISIBLE_PART_MIN_VARIANCE, 1.0));
}

/* lobe_visibility, and the side of the lobe its visible part lies on (techniques.sg.sg_shading.
 * lobe_visibility_side): the direction in which the SSDF's leading VISIBLE_SIDE_LAYERS rows (the occluders'
 * broad shape, not the nearest edge's detail) grow at the product lobe's axis, by forward differences
 * VISIBLE_SIDE_STEP radians across it (two more decodes of those rows), as a world direction perpendicular to
 * `axis` (unit; zero for an unoccluded lobe, or where the SSDF is flat). */
float lobe_visibility_side(vec3 axis, float sharpness, vec3 n, out vec3 side)
{
  vec3 local;
  float lam;
  visibility_product(axis, sharpness, n, local, lam);
  local = safe_normalize(local);
  float centre;
  float visible = product_visible_fraction(ssdf_decode_leading(visibility_basis, visibility_rows, SSDF_MAX_LAYERS,
                                                               VISIBLE_SIDE_LAYERS, local, centre), local, lam);
  side = vec3(0.0);
  if (visible < VISIBLE_SIDE_MAX_FRACTION) {
    int layers = min(SSDF_MAX_LAYERS, VISIBLE_SIDE_LAYERS);
    vec3 across1 = safe_normalize(cross(local, abs(local.z) < 0.9 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0)));
    vec3 across2 = cross(local, across1);
    float rise1 = ssdf_decode(visibility_basis, visibility_rows, layers, local + VISIBLE_SIDE_STEP * across1) - centre;
    float rise2 = ssdf_decode(visibility_basis, visibility_rows, layers, local + VISIBLE_SIDE_STEP * across2) - centre;
    vec3 world = visibility_frame * (rise1 * across1 + rise2 * across2);
    world -= axis * dot(axis, world);
    float world_length = length(world);
    side = world_length > 1.0e-12 ? world / world_length : vec3(0.0);
  }
  return visible;
}
#endif
#if defined(HAS_ENVIRONMENT) && defined(HAS_SPECULAR)
/* Where and how sharp to read the environment for a lobe: its product with the clamped cosine's SG for lobes
 * broader than COSINE_LOOKUP_FULL (or always), handing over to the lobe itself at COSINE_LOOKUP_NONE
 * (techniques.sg.sg_shading.cosine_weighted_lookup): a broad lobe crosses the cosine from its peak to the horizon. */
void cosine_weighted_lookup(inout vec3 axis, inout float sharpness, vec3 n, bool always)
{
  vec3 product_axis;
  float product_sharpness, product_amplitude;
  sg_product(axis, sharpness, 1.0, n, CLAMPED_COSINE_SHARPNESS, 1.0, product_axis, product_sharpness,
             product_amplitude);
  float weight = always ? 1.0 : clamp((COSINE_LOOKUP_NONE - sharpness) / (COSINE_LOOKUP_NONE - COSINE_LOOKUP_FULL),
                                      0.0, 1.0);
  axis = safe_normalize(axis + (product_axis - axis) * weight);
  sharpness += (product_sharpness - sharpness) * weight;
}
#endif

/* The warped lobes of one NDF lobe lie close together: they share the visibility of the centre one
 * (techniques.sg.sg_shading.visibility_node_indices), a third of the slice terms' SSDF decodes for split3; split2 has
 * no centre node and takes node 0, the one towards the viewer (a valid half vector whenever the lobe's
 * centre is; the other can fall below the view's horizon at grazing views). */
#define VISIBILITY_NODE ((WARP_NODES - 1) / 2)

/* Diffuse (kd/pi times irradiance) and specular radiance towards the viewer.  Without HAS_DIFFUSE
 * the irradiance stays 0, without HAS_SPECULAR the radiance (the variant's colour is zero); without
 * with_environment_diffuse the environment's irradiance is left out (shade_footprint's specular samples). */
void shade_surface(vec3 position, vec3 normal, vec3 tangent, vec4 p, vec4 q,
                   vec3 diffuse_color, vec3 specular_color, bool with_environment_diffuse,
                   out vec3 diffuse, out vec3 specular)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  vec3 irradiance = vec3(0.0);
  vec3 radiance = vec3(0.0);

#if defined(HAS_SPECULAR) || defined(BISCALE)
  vec3 view = scene.camera.w > 0.5 ? safe_normalize(scene.camera.xyz - position)
                                   : -safe_normalize(scene.camera.xyz);
  mat3 frame = mat3(t, b, n);                    /* local -> world */
  vec3 view_local = view * frame;                /* transpose(frame) * view */
#endif
#ifdef BISCALE
  biscale_set_view(view_local);
#endif
#ifdef HAS_SPECULAR

  /* BRDF slice: NDF lobes warped to the view (WARP_NODES per NDF lobe) times M_o at their centres, in world space */
  vec3 slice_axis[SLICE_LOBES];
  float slice_sharpness[SLICE_LOBES];
  float slice_amplitude[SLICE_LOBES];
  vec3 slice_colour[SLICE_LOBES];              /* RGB lobe amplitude of the fit, else 1 */
#ifdef MODEL_FITTED
  p.z = fitted_shadowing_of(view_local);       /* S(o), for model_m_factor */
#endif
#ifdef BISCALE
  biscale_set_small_lobes(p, q);
#endif
  for (int k = 0; k < NDF_LOBES; k++) {
    vec3 ndf_axis;
    float ndf_sharpness, ndf_amplitude;
#ifdef BISCALE
    float bvndf_sharpness;      /* eta_j, for the product axis of M */
    biscale_lobe(k, ndf_axis, ndf_sharpness, ndf_amplitude, bvndf_sharpness);
    biscale_set_lobe_amplitude(k, ndf_axis, safe_normalize(view_local));
#ifdef MODEL_FITTED
    vec3 colour = biscale_small_colour[k % BISCALE_SMALL_LOBES];
#else
    vec3 colour = vec3(1.0);
#endif
#elif defined(MODEL_FITTED)
    vec4 fitted_lobe = fitted_layer(1 + 2 * k);
    ndf_axis = safe_normalize(fitted_lobe.xyz);
    ndf_sharpness = fitted_lobe.w;
    ndf_amplitude = 1.0;
    vec3 colour = fitted_layer(2 + 2 * k).rgb;
#else
    model_ndf_lobe(p, q, k, ndf_axis, ndf_sharpness, ndf_amplitude);
    vec3 colour = vec3(1.0);
#endif
    /* warp.DEFAULT_MODE: WARP_FUNCTION with WARP_NODES lobes per NDF lobe (defines from the variant) */
    vec3 warped_axis[WARP_NODES];
    float warped_sharpness[WARP_NODES], warped_amplitude[WARP_NODES];
#if WARP_NODES == 1
    WARP_FUNCTION(ndf_axis, ndf_sharpness, ndf_amplitude, view_local,
                  warped_axis[0], warped_sharpness[0], warped_amplitude[0]);
#else
    WARP_FUNCTION(ndf_axis, ndf_sharpness, ndf_amplitude, view_local,
                  warped_axis, warped_sharpness, warped_amplitude);
#endif
    for (int node = 0; node < WARP_NODES; node++) {
      int j = WARP_NODES * k + node;
#ifdef BISCALE
      slice_amplitude[j] = brdf_slice_amplitude(warped_amplitude[node],
                                                biscale_m_factor(k, ndf_axis, bvndf_sharpness, view_local,
                                                                 warped_axis[node], p, q));
#else
      slice_amplitude[j] = brdf_slice_amplitude(warped_amplitude[node],
                                                model_m_factor(view_local, warped_axis[node], p, q));
#endif
      slice_axis[j] = frame * warped_axis[node];
      slice_colour[j] = colour;
      slice_sharpness[j] = warped_sharpness[node];
    }
  }
  /* I(S_j, n) of the slice lobes, unshadowed: their albedo, and the environment's weights below */
  float slice_cosines[SLICE_LOBES];
  float slice_albedo = 0.0;
  for (int j = 0; j < SLICE_LOBES; j++) {
    slice_cosines[j] = sg_clamped_cosine_integral_tabulated(clamped_cosine_table, slice_axis[j], slice_sharpness[j],
                                                            slice_amplitude[j], n);
    slice_albedo += slice_cosines[j];
  }
#ifdef ENVIRONMENT_TAIL
  /* GGX's exact albedo (reflectance.ggx_albedo): the lobes keep at most it (at grazing views they overshoot it
   * several times over), and the environment tail returns what they miss of it (techniques.sg.sg_shading.model_albedo) */
#ifdef MODEL_GGX_ANISO
  float albedo_roughness = sqrt(sqrt(max(p.w, 1.0e-6) * max(q.x, 1.0e-6)));   /* Cycles' equivalent roughness */
#else
  float albedo_roughness = p.x;
#endif
  vec2 albedo_coords = (clamp(vec2(view_local.z, albedo_roughness), 0.0, 1.0) * float(GGX_ALBEDO_SIZE - 1) + 0.5) /
                       float(GGX_ALBEDO_SIZE);
  float model_albedo = texture(ggx_albedo_table, albedo_coords).r;
  float energy_scale = min(1.0, model_albedo / max(slice_albedo, 1.0e-30));
  for (int j = 0; j < SLICE_LOBES; j++) {
    slice_amplitude[j] *= energy_scale;
    slice_cosines[j] *= energy_scale;
  }
  slice_albedo *= energy_scale;
#endif
#endif

#ifdef HAS_LIGHTS
  for (int l = 0; l < scene.counts.x + scene.counts.y; l++) {
    vec3 light_axis;
    float light_sharpness;
    vec3 light_amplitude;
    scene_light_sg(l, position, light_axis, light_sharpness, light_amplitude);
#if defined(HAS_DIFFUSE) || defined(PRODUCT_VISIBILITY) || defined(LIGHT_TAIL)
    float light_cosine = sg_clamped_cosine_integral_tabulated(clamped_cosine_table, light_axis, light_sharpness,
                                                              1.0, n);
#endif
#ifdef LIGHT_SHADOW_MAPS
    /* a light with a shadow map: its visible fraction at the pixel, for its products too (a map is made for
     * point, spot and sun lights, narrow on the object), blended to the SSDF's as far as its penumbra passed
     * the map's filter (the softness); the others: the SSDF's */
    int shadow_slot = light_shadow_slot(l);
    bool mapped = shadow_slot >= 0;
    vec2 shadow = mapped ? light_shadow_of(shadow_slot) : vec2(1.0, 1.0);    /* unmapped: the SSDF's alone */
#ifdef HAS_VISIBILITY
    float light_visibility = 1.0;
    if (shadow.y > 0.0) {
      light_visibility = LIGHT_VISIBILITY(light_axis, light_sharpness);
    }
    light_visibility = mix(shadow.x, light_visibility, shadow.y);
#else
    float light_visibility = shadow.x;
#endif
#elif defined(HAS_DIFFUSE) || defined(SHARED_LIGHT_VISIBILITY) || defined(LIGHT_TAIL)
    float light_visibility = LIGHT_VISIBILITY(light_axis, light_sharpness);
#endif
#ifdef HAS_DIFFUSE
    irradiance += light_amplitude * (light_cosine * light_visibility * BISCALE_DIFFUSE(light_axis));   /* eq. 42 */
#endif
#ifdef HAS_SPECULAR
    vec3 weight = vec3(0.0);
    for (int k = 0; k < NDF_LOBES; k++) {
      vec3 lobe_weight = vec3(0.0);
#ifdef PRODUCT_VISIBILITY
      bool decode = false;
      vec3 centre_axis = vec3(0.0, 0.0, 1.0);
      float centre_sharpness = 0.0;
#endif
      for (int node = 0; node < WARP_NODES; node++) {
        int j = WARP_NODES * k + node;
        vec3 product_axis;
        float product_sharpness, product_amplitude;
        sg_product(light_axis, light_sharpness, 1.0, slice_axis[j], slice_sharpness[j], slice_amplitude[j],
                   product_axis, product_sharpness, product_amplitude);
        float product_cosine = sg_clamped_cosine_integral_tabulated(clamped_cosine_table, product_axis,
                                                                    product_sharpness, product_amplitude, n);
        lobe_weight += product_cosine * slice_colour[j];
#ifdef PRODUCT_VISIBILITY
        /* products negligible next to the light's irradiance (away from the highlight) need no decode:
         * left unshadowed, at most VISIBILITY_SKIP_FRACTION of the light's cosine integral each */
        decode = decode || product_cosine > VISIBILITY_SKIP_FRACTION * light_cosine;
        if (node == VISIBILITY_NODE) {
          centre_axis = product_axis;
          centre_sharpness = product_sharpness;
        }
#endif
      }
#ifdef PRODUCT_VISIBILITY
#ifdef LIGHT_SHADOW_MAPS
      decode = decode && !mapped;
#endif
      if (decode) {               /* eq. 43, one decode an NDF lobe: at its centre node's product */
        lobe_weight *= lobe_visibility(centre_axis, centre_sharpness, n);
      }
#endif
      weight += lobe_weight;
    }
#ifdef SHARED_LIGHT_VISIBILITY
    weight *= light_visibility;   /* eq. 43 for a narrow light: its products lie inside it */
#elif defined(LIGHT_SHADOW_MAPS)
    if (mapped) {
      weight *= light_visibility;
    }
#endif
#ifdef LIGHT_TAIL
    /* the model's BRDF minus the slice lobes at the light's centre, times what the light delivers there,
     * weighted by how narrow the light is against the BRDF's local scale s^2 (techniques.sg.sg_shading.light_tail) */
    float slice_value = 0.0;
    float scale2 = 1.0e30;
    for (int j = 0; j < SLICE_LOBES; j++) {
      float c = dot(light_axis, slice_axis[j]);
      slice_value += slice_amplitude[j] * exp(slice_sharpness[j] * (c - 1.0));
      scale2 = min(scale2, 1.0 / max(slice_sharpness[j], 1.0e-6) + 2.0 * (1.0 - c));
    }
    float narrow = scale2 * light_sharpness / (1.0 + scale2 * light_sharpness);
    float tail = narrow * light_cosine * (model_specular(view_local, light_axis * frame, p, q) - slice_value);
    weight = max(weight + tail * light_visibility, vec3(0.0));
#endif
    radiance += light_amplitude * weight;
#endif
  }
#endif

#ifdef HAS_SPECULAR
  vec3 tail_axis = slice_axis[VISIBILITY_NODE];
#ifdef VISIBLE_PART_LOOKUP
  /* the first NDF lobe's visible side (GGX's broader), shared with the others (they see the same occluders) and
   * the tail; out of the loop over the lobes (llvmpipe's frame: 1.1 times that of the call inside it) */
  vec3 visible_side;
  float first_visibility = lobe_visibility_side(slice_axis[VISIBILITY_NODE], slice_sharpness[VISIBILITY_NODE], n,
                                                visible_side);                                          /* eq. 41 */
#endif
  for (int k = 0; k < NDF_LOBES; k++) {
    int centre = WARP_NODES * k + VISIBILITY_NODE;
#ifdef VISIBLE_PART_LOOKUP
    /* the environment is read where the visible part of the lobe lies: its nodes turned together towards the
     * visible side by the part's mean, and narrowed to its width */
    float visibility = first_visibility;
    if (k > 0) {
      visibility = LOBE_VISIBILITY(slice_axis[centre], slice_sharpness[centre]);                       /* eq. 41 */
    }
    vec3 side = safe_normalize(visible_side - slice_axis[centre] * dot(visible_side, slice_axis[centre]), vec3(0.0));
    vec3 pivot = cross(slice_axis[centre], side);      /* unit (or zero): side is perpendicular to the axis */
    float turn = min(visible_part_offset(visibility) * inversesqrt(max(slice_sharpness[centre], 1.0e-6)),
                     VISIBLE_PART_MAX_TURN);
    float turn_cos = cos(turn);
    float turn_sin = sin(turn);
    float narrowing = visible_part_narrowing(visibility);
#else
    float visibility = LOBE_VISIBILITY(slice_axis[centre], slice_sharpness[centre]);      /* eq. 41 */
#endif
    for (int node = 0; node < WARP_NODES; node++) {
      int j = WARP_NODES * k + node;
      float slice_cosine = slice_cosines[j] * visibility;
      vec3 lookup_axis = slice_axis[j];
#ifdef VISIBLE_PART_LOOKUP
      lookup_axis = lookup_axis * turn_cos + cross(pivot, lookup_axis) * turn_sin +
                    pivot * (dot(pivot, lookup_axis) * (1.0 - turn_cos));
#endif
#ifdef HAS_ENVIRONMENT
      float lookup_sharpness = slice_sharpness[j];
#ifdef VISIBLE_PART_LOOKUP
      lookup_sharpness *= narrowing;
#endif
      cosine_weighted_lookup(lookup_axis, lookup_sharpness, n, false);
      radiance += slice_cosine * slice_colour[j] * environment_radiance(lookup_axis, lookup_sharpness);
#else
      radiance += slice_cosine * slice_colour[j] * scene.world_colour.rgb;
#endif
    }
  }
#ifdef ENVIRONMENT_TAIL
  /* GGX's energy beyond its slice lobes: its exact albedo minus theirs, as a broad lobe on the broader NDF
   * lobe's centre node (techniques.sg.sg_shading.environment_tail), with its own visibility (broader than the
   * node's, it sees past more of an occluder), read where its own visible part lies: turned by its offset
   * towards the node's visible side */
  float tail_sharpness = slice_sharpness[VISIBILITY_NODE] * TAIL_SHARPNESS_RATIO;
  float tail_visibility = LOBE_VISIBILITY(slice_axis[VISIBILITY_NODE], tail_sharpness);
  float tail_albedo = max(model_albedo - slice_albedo, 0.0) * tail_visibility;
#ifdef VISIBLE_PART_LOOKUP
  float tail_turn = min(visible_part_offset(tail_visibility) * inversesqrt(max(tail_sharpness, 1.0e-6)),
                        VISIBLE_PART_MAX_TURN);
  tail_axis = tail_axis * cos(tail_turn) + visible_side * sin(tail_turn);
#endif
#ifdef HAS_ENVIRONMENT
  cosine_weighted_lookup(tail_axis, tail_sharpness, n, true);
  radiance += tail_albedo * environment_radiance(tail_axis, tail_sharpness);
#else
  radiance += tail_albedo * scene.world_colour.rgb;
#endif
#endif
#endif

#ifdef HAS_DIFFUSE
#ifdef HAS_ENVIRONMENT
  for (int e = 0; with_environment_diffuse && e < scene.counts.z; e++) {
    irradiance += scene.env_amplitude[e].rgb *
                  (clamped_cosine_from_terms(dot(safe_normalize(scene.env_axis_sharpness[e].xyz), n),
                                             scene.env_axis_sharpness[e].w, scene.env_cosine_terms[2 * e],
                                             scene.env_cosine_terms[2 * e + 1]) *
                   DIFFUSE_VISIBILITY(e, scene.env_axis_sharpness[e].xyz, scene.env_axis_sharpness[e].w) *
                   BISCALE_DIFFUSE(safe_normalize(scene.env_axis_sharpness[e].xyz)));   /* eq. 39 */
  }
#else
  /* a constant world: the cosine lobe alone (a zero-sharpness G) */
  irradiance += float(with_environment_diffuse) * SG_PI * scene.world_colour.rgb * DIFFUSE_VISIBILITY(0, n, 0.0) *
                BISCALE_ALBEDO;
#endif
#endif

  diffuse = diffuse_color * (1.0 / SG_PI) * irradiance;
  specular = specular_color * radiance;
}

#ifdef HAS_SPECULAR
/* shade_footprint's grid: a sample a side for each 4/3 of an NDF width the normal turns across the footprint, at
 * most 4 (benchmarks/specular_aa.py, relative RMSE against the box filter on ggx030_point: 0.29 at this rate,
 * 0.46 at a sample for two widths, for 3.4x and 2.3x the frame), and at most scene.shading_footprint.y */
#define SPECULAR_AA_RATE 0.75
#define SPECULAR_AA_MAX_SIDE 4
#endif

/* shade_surface averaged over the pixel's footprint (scene.shading_footprint.x pixels a side): where the normal
 * turns across it by more than two NDF widths, a highlight narrower than the pixel would be caught or missed
 * whole at its centre; the specular is shaded at the centres of a side x side grid instead, the position and
 * normal moved along their screen derivatives (exact inside a triangle, whose attributes are affine there).
 * Must be called in uniform control flow (the derivatives). */
void shade_footprint(vec3 position, vec3 normal, vec3 tangent, vec4 p, vec4 q, vec3 diffuse_color,
                     vec3 specular_color, out vec3 diffuse, out vec3 specular)
{
  float footprint = scene.shading_footprint.x;
  vec3 dpdx = footprint * dFdx(position);
  vec3 dpdy = footprint * dFdy(position);
  vec3 dndx = footprint * dFdx(normal);
  vec3 dndy = footprint * dFdy(normal);
  int side = 1;
#ifdef HAS_SPECULAR
  if (footprint > 0.0) {
    /* the turn in NDF widths, each axis of the shading frame by its own (anisotropic lobes) */
    vec3 n, t, b;
    shading_frame(normal, tangent, n, t, b);
    vec2 widths = max(model_lobe_widths(p, q), vec2(1.0e-4));
    vec2 turn_x = vec2(dot(dndx, t), dot(dndx, b)) / widths;
    vec2 turn_y = vec2(dot(dndy, t), dot(dndy, b)) / widths;
    float turn = sqrt(dot(turn_x, turn_x) + dot(turn_y, turn_y));
    side = clamp(int(ceil(SPECULAR_AA_RATE * turn)), 1,
                 clamp(int(scene.shading_footprint.y), 1, SPECULAR_AA_MAX_SIDE));
  }
#endif
  shade_surface(position, normal, tangent, p, q, diffuse_color, specular_color, true, diffuse, specular);
  if (side == 1) {
    return;
  }
  /* the diffuse term is smooth across the pixel: the centre's; the grid's samples shade the specular */
  specular = vec3(0.0);
  for (int y = 0; y < side; y++) {
    for (int x = 0; x < side; x++) {
      vec2 offset = (vec2(x, y) + 0.5) / float(side) - 0.5;
      vec3 sample_diffuse, sample_specular;
      shade_surface(position + offset.x * dpdx + offset.y * dpdy,
                    safe_normalize(normal + offset.x * dndx + offset.y * dndy), tangent, p, q,
                    diffuse_color, specular_color, false, sample_diffuse, sample_specular);
      specular += sample_specular;
    }
  }
  specular *= 1.0 / float(side * side);
}
