/* Per-pixel SG shading (wang2009 eq. 36-43; HAS_VISIBILITY: with SSDF shadows, eq. 39-43) in named stages:
 * slice_lobes (the BRDF slice), shade_lights, environment_specular, environment_irradiance, summed by
 * shade_surface, averaged over the pixel by shade_footprint.  The lobes come from the technique's lobe source,
 * included before this file (lobes_model.glsl: the interface; lobes_fitted.glsl; biscale.glsl), the models from
 * sg_models.glsl.  Mirrored by sg_prt_addon/techniques/sg/sg_shading.py.  Needs sg.glsl, hemisphere.glsl,
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
 * BISCALE (biscale.glsl the lobe source): the lobes are a bi-scale material's effective lobes (NDF_LOBES of
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

#define SLICE_LOBES (WARP_NODES * NDF_LOBES)


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

#ifdef HAS_SPECULAR
/* The BRDF slice of the pixel, in world space: the lobe source's NDF lobes warped to the view (WARP_NODES per NDF
 * lobe) times M_o at their centres, their RGB amplitudes (a fit's; else 1), I(S_j, n) of each unshadowed and their
 * sum (with ENVIRONMENT_TAIL, kept within the model's exact albedo, model_albedo).  Set by slice_lobes, read by the
 * stages after it. */
vec3 slice_axis[SLICE_LOBES];
float slice_sharpness[SLICE_LOBES];
float slice_amplitude[SLICE_LOBES];
vec3 slice_colour[SLICE_LOBES];
float slice_cosines[SLICE_LOBES];
float slice_albedo;
float model_albedo;
/* What a normal map's spread leaves of the model's peak: its sharpest NDF lobe's narrowing, by which the light
 * tail fades (techniques.sg.sg_shading.normal_spread_peak). */
float normal_spread_peak;

void slice_lobes(vec4 p, vec4 q, vec3 view_local, mat3 frame, vec3 n)
{
  normal_spread_peak = 1.0;
  for (int k = 0; k < NDF_LOBES; k++) {
    vec3 ndf_axis, colour;
    float ndf_sharpness, ndf_amplitude;
    lobes_ndf(k, p, q, view_local, ndf_axis, ndf_sharpness, ndf_amplitude, colour);
    normal_spread_peak = min(normal_spread_peak, 1.0 / (1.0 + ndf_sharpness * normal_map_spread));
    spread_lobe(ndf_sharpness, ndf_amplitude, normal_map_spread);
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
      slice_amplitude[j] = brdf_slice_amplitude(warped_amplitude[node],
                                                lobes_m_factor(k, ndf_axis, view_local, warped_axis[node], p, q));
      slice_axis[j] = frame * warped_axis[node];
      slice_colour[j] = colour;
      slice_sharpness[j] = warped_sharpness[node];
    }
  }
  /* I(S_j, n) of the slice lobes, unshadowed: their albedo, and the environment's weights below */
  slice_albedo = 0.0;
  for (int j = 0; j < SLICE_LOBES; j++) {
    slice_cosines[j] = sg_clamped_cosine_integral_tabulated(clamped_cosine_table, slice_axis[j], slice_sharpness[j],
                                                            slice_amplitude[j], n);
    slice_albedo += slice_cosines[j];
  }
  model_albedo = 0.0;
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
  model_albedo = texture(ggx_albedo_table, albedo_coords).r;
  float energy_scale = min(1.0, model_albedo / max(slice_albedo, 1.0e-30));
  for (int j = 0; j < SLICE_LOBES; j++) {
    slice_amplitude[j] *= energy_scale;
    slice_cosines[j] *= energy_scale;
  }
  slice_albedo *= energy_scale;
#endif
}
#endif

#ifdef HAS_LIGHTS
/* The lights (eq. 42-43): the irradiance they give (HAS_DIFFUSE) and the radiance their products with the slice
 * lobes reflect (HAS_SPECULAR), each light shadowed by its map or the bake. */
void shade_lights(vec3 position, vec3 n, vec3 view_local, mat3 frame, vec4 p, vec4 q,
                  inout vec3 irradiance, inout vec3 radiance)
{
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
    irradiance += light_amplitude * (light_cosine * light_visibility * DIFFUSE_FACTOR(light_axis));   /* eq. 42 */
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
    /* a normal map's spread: the slice lobes are the spread BRDF's, the model's own is not; the tail fades */
    float tail = normal_spread_peak * narrow * light_cosine
                 * (model_specular(view_local, light_axis * frame, p, q) - slice_value);
    weight = max(weight + tail * light_visibility, vec3(0.0));
#endif
    radiance += light_amplitude * weight;
#endif
  }
}
#endif

#ifdef HAS_SPECULAR
/* The environment's light the slice lobes reflect (eq. 41), each NDF lobe shadowed at its centre node (read where
 * its visible part lies, VISIBLE_PART_LOOKUP), and (ENVIRONMENT_TAIL) GGX's energy beyond the lobes. */
vec3 environment_specular(vec3 n)
{
  vec3 radiance = vec3(0.0);
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
  return radiance;
}
#endif

#ifdef HAS_DIFFUSE
/* The environment's irradiance (eq. 39): its SG lobes' clamped-cosine integrals, each shadowed; a constant world's
 * cosine lobe alone. */
vec3 environment_irradiance(vec3 n, mat3 frame)
{
  vec3 irradiance = vec3(0.0);
#ifdef HAS_ENVIRONMENT
  for (int e = 0; e < scene.counts.z; e++) {
    irradiance += scene.env_amplitude[e].rgb *
                  (clamped_cosine_from_terms(dot(safe_normalize(scene.env_axis_sharpness[e].xyz), n),
                                             scene.env_axis_sharpness[e].w, scene.env_cosine_terms[2 * e],
                                             scene.env_cosine_terms[2 * e + 1]) *
                   DIFFUSE_VISIBILITY(e, scene.env_axis_sharpness[e].xyz, scene.env_axis_sharpness[e].w) *
                   DIFFUSE_FACTOR(safe_normalize(scene.env_axis_sharpness[e].xyz)));   /* eq. 39 */
  }
#else
  /* a constant world: the cosine lobe alone (a zero-sharpness G) */
  irradiance += SG_PI * scene.world_colour.rgb * DIFFUSE_VISIBILITY(0, n, 0.0) * DIFFUSE_ALBEDO;
#endif
  return irradiance;
}
#endif

/* Diffuse (kd/pi times irradiance) and specular radiance towards the viewer, in stages: the lobe source's setup,
 * the BRDF slice, the lights, the environment.  Without HAS_DIFFUSE the irradiance stays 0, without HAS_SPECULAR
 * the radiance (the variant's colour is zero); without with_environment_diffuse the environment's irradiance is
 * left out (shade_footprint's specular samples). */
void shade_surface(vec3 position, vec3 normal, vec3 tangent, vec4 p, vec4 q,
                   vec3 diffuse_color, vec3 specular_color, bool with_environment_diffuse,
                   out vec3 diffuse, out vec3 specular)
{
  vec3 n, t, b;
  shading_frame(normal, tangent, n, t, b);
  vec3 irradiance = vec3(0.0);
  vec3 radiance = vec3(0.0);
  vec3 view = scene.camera.w > 0.5 ? safe_normalize(scene.camera.xyz - position)
                                   : -safe_normalize(scene.camera.xyz);
  mat3 frame = mat3(t, b, n);                    /* local -> world */
  vec3 view_local = view * frame;                /* transpose(frame) * view */
  lobes_begin(p, q, view_local);
#ifdef HAS_SPECULAR
  slice_lobes(p, q, view_local, frame, n);
#endif
#ifdef HAS_LIGHTS
  shade_lights(position, n, view_local, frame, p, q, irradiance, radiance);
#endif
#ifdef HAS_SPECULAR
  radiance += environment_specular(n);
#endif
#ifdef HAS_DIFFUSE
  if (with_environment_diffuse) {
    irradiance += environment_irradiance(n, frame);
  }
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
