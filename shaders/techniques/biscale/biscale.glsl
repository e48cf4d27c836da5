/* Bi-scale materials (iwasaki2012 eq. 15): the effective BRDF's lobes and factors, mirrored by
 * sg_prt_addon/techniques/biscale/biscale_shading.py.  Needs sg.glsl, hemisphere_map.glsl, the mask's
 * texture_value_biscale_mask() (techniques/material_textures.py); with HAS_SPECULAR, brdf.glsl, (MODEL_GGX) ggx_two_lobes.glsl and the ggx_table sampler, and
 * sg_models.glsl before this file (its model_ndf_lobe and model_m_factor); and:
 *   biscale_lobes  (sampler2D, J x 1): texel j = (axis xyz in the local frame, sharpness) of BVNDF lobe j;
 *   biscale_tables (sampler2DArray, R^2 x R^2 RGBA32F, linear filtering): the node pair (i, o) of the lattice
 *     (biscale/bvndf.py, R = BISCALE_RESOLUTION) at texel (o_a R + i_a, o_b R + i_b); layer t, channel c:
 *     mu_j(i, o) per unit cos(theta_i) of lobe j = 4 t + c; layer BISCALE_LOBE_LAYERS: (D(i, o), A(o)) of the
 *     first tile and of the second: the diffuse factor and its cosine-weighted mean over i.
 * MODEL_FITTED: the small-scale BRDF is the stored lobe fit at the pixel's texel (sg_models.glsl's fitted_*
 *     functions: its lobes about the facet normal, their RGB amplitudes, its M with S(o) in each facet's frame).
 * HAS_TEXTURE_BISCALE_MASK: two tiles (biscale.bvndf.MaskedTiles), lobes [0, BISCALE_FIRST_LOBES) the first's,
 *     chosen per pixel by the mask texture's red channel m: the first's amplitudes and diffuse weighted 1 - m,
 *     the second's m.
 * The sampler interpolates i inside an o node's block; o's four nodes are blended here (biscale_set_view:
 * once a pixel, the view is fixed).  It is the bi-scale technique's lobe source (at the end of this file). */

const float BISCALE_R = float(BISCALE_RESOLUTION);
vec2 biscale_view_corner[4];
float biscale_view_weight[4];
float biscale_mask = 0.0;

/* Continuous lattice coordinates in [0, R - 1] of a local direction (clamped to the hemisphere). */
vec2 biscale_lattice(vec3 direction)
{
  vec3 clamped = safe_normalize(vec3(direction.xy, max(direction.z, 0.0)));
  return clamp((hemisphere_map_to_square(clamped) + 1.0) * (0.5 * (BISCALE_R - 1.0)), 0.0, BISCALE_R - 1.0);
}

void biscale_set_view(vec3 view_local)
{
  vec2 c = biscale_lattice(view_local);
  vec2 low = min(floor(c), vec2(BISCALE_R - 2.0));
  vec2 f = c - low;
  biscale_view_corner[0] = low;
  biscale_view_corner[1] = low + vec2(1.0, 0.0);
  biscale_view_corner[2] = low + vec2(0.0, 1.0);
  biscale_view_corner[3] = low + vec2(1.0, 1.0);
  biscale_view_weight[0] = (1.0 - f.x) * (1.0 - f.y);
  biscale_view_weight[1] = f.x * (1.0 - f.y);
  biscale_view_weight[2] = (1.0 - f.x) * f.y;
  biscale_view_weight[3] = f.x * f.y;
#ifdef HAS_TEXTURE_BISCALE_MASK
  biscale_mask = clamp(texture_value_biscale_mask().r, 0.0, 1.0);
#endif
}

/* The weight of BVNDF lobe j's tile at this pixel. */
float biscale_tile_weight(int j)
{
#ifdef HAS_TEXTURE_BISCALE_MASK
  return j < BISCALE_FIRST_LOBES ? 1.0 - biscale_mask : biscale_mask;
#else
  return 1.0;
#endif
}

/* The tables of one layer at the local incident direction wi and the pixel's view. */
vec4 biscale_fetch(int layer, vec3 wi)
{
  vec2 ci = biscale_lattice(wi);
  vec4 value = vec4(0.0);
  for (int k = 0; k < 4; k++) {
    vec2 texel = biscale_view_corner[k] * BISCALE_R + ci + 0.5;
    value += biscale_view_weight[k] * texture(biscale_tables, vec3(texel / (BISCALE_R * BISCALE_R), float(layer)));
  }
  return value;
}

float biscale_amplitude(int lobe, vec3 wi)
{
  return biscale_fetch(lobe / 4, wi)[lobe % 4];
}

/* D(i, o): the Lambertian term's factor at a local incident direction (0 below the horizon). */
float biscale_diffuse(vec3 wi)
{
  vec4 tiles = biscale_fetch(BISCALE_LOBE_LAYERS, wi);
  return wi.z > 0.0 ? mix(tiles.x, tiles.z, biscale_mask) : 0.0;
}

/* A(o): the diffuse factor's cosine-weighted mean over the incident hemisphere (a constant world). */
float biscale_albedo()
{
  vec4 tiles = biscale_fetch(BISCALE_LOBE_LAYERS, vec3(0.0, 0.0, 1.0));
  return mix(tiles.y, tiles.w, biscale_mask);
}

#ifdef HAS_SPECULAR
#ifdef MODEL_FITTED
vec3 biscale_small_colour[BISCALE_SMALL_LOBES];     /* the fit's RGB lobe amplitudes */
#endif

/* The small-scale model's NDF lobes around the facet normal, (sharpness, amplitude) each, their projected
 * mass made 1 (spherical.sg.axis_cosine_integral: 2 pi (1 - (1 - e^-s) / s) / s): GGX's two-lobe fit
 * (NDF_LOBES is never 1 here), one lobe for the others; a fit's lobes as they are (amplitude 1, their colours
 * apart: the fit is the BRDF, tail included).  Set once a pixel by biscale_set_small_lobes. */
vec2 biscale_small[BISCALE_SMALL_LOBES];

void biscale_set_small_lobes(vec4 p, vec4 q)
{
#ifdef MODEL_FITTED
  for (int s = 0; s < BISCALE_SMALL_LOBES; s++) {
    biscale_small[s] = vec2(max(fitted_layer(1 + 2 * s).w, 0.0), 1.0);
    biscale_small_colour[s] = fitted_layer(2 + 2 * s).rgb;
  }
#else
  float mass = 0.0;
  for (int s = 0; s < BISCALE_SMALL_LOBES; s++) {
    vec3 axis;
    float sharpness, amplitude;
    model_ndf_lobe(p, q, s, axis, sharpness, amplitude);
    sharpness = max(sharpness, 0.0);
    mass += amplitude * (sharpness > 1.0e-3 ? 2.0 * SG_PI * (1.0 - (1.0 - exp(-sharpness)) / sharpness) / sharpness
                                            : 2.0 * SG_PI * (0.5 - sharpness / 6.0));
    biscale_small[s] = vec2(sharpness, amplitude);
  }
  for (int s = 0; s < BISCALE_SMALL_LOBES; s++) {
    biscale_small[s].y /= max(mass, 1.0e-30);
  }
#endif
}

/* Effective lobe k = j S + s (eq. 14-15): BVNDF lobe j (xi_j, eta_j) convolved with small-scale lobe s
 * (eta_s, mu_s): axis xi_j, sharpness eta_j eta_s / (eta_j + eta_s), amplitude 2 pi mu_s / (eta_j + eta_s). */
void biscale_lobe(int k, out vec3 axis, out float sharpness, out float amplitude, out float ndf_sharpness)
{
  vec4 lobe = texelFetch(biscale_lobes, ivec2(k / BISCALE_SMALL_LOBES, 0), 0);
  vec2 small = biscale_small[k % BISCALE_SMALL_LOBES];
  axis = safe_normalize(lobe.xyz);
  ndf_sharpness = lobe.w;
  float total = max(ndf_sharpness + small.x, 1.0e-30);
  sharpness = ndf_sharpness * small.x / total;
  amplitude = 2.0 * SG_PI * small.y / total;
}

/* mu_j at BVNDF lobe j's mirror direction 2 (o.xi_j) xi_j - o, the centre of its warped lobes (iwasaki2012's
 * mu'_j(xi'_j, o)): one table read for the lobe's small-scale lobes and warped nodes, set by the shading loop
 * at each j's first effective lobe. */
float biscale_lobe_amplitude;

void biscale_set_lobe_amplitude(int k, vec3 axis, vec3 wo)
{
  if (k % BISCALE_SMALL_LOBES == 0) {
    int j = k / BISCALE_SMALL_LOBES;
    biscale_lobe_amplitude = biscale_amplitude(j, 2.0 * dot(wo, axis) * axis - wo) * biscale_tile_weight(j);
  }
}

/* That amplitude times the small-scale M at the product axis n* = normalize(eta_j xi_j + eta_s h) of effective
 * lobe k = j S + s, directions in n*'s frame (the models are isotropic: any tangent). */
float biscale_m_factor(int k, vec3 axis, float ndf_sharpness, vec3 wo, vec3 wi, vec4 p, vec4 q)
{
  float small_sharpness = biscale_small[k % BISCALE_SMALL_LOBES].x;
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  vec3 facet = safe_normalize(ndf_sharpness * axis + small_sharpness * safe_normalize(wo + wi));
  vec3 helper = abs(facet.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  vec3 t = normalize(cross(helper, facet));
  vec3 b = cross(facet, t);
  mat3 to_facet = transpose(mat3(t, b, facet));
#ifdef MODEL_FITTED
  vec3 facet_wo = to_facet * wo;     /* S(o) in the facet's frame, not the pixel's p.z */
  return biscale_lobe_amplitude * fitted_m_factor(facet_wo, to_facet * wi, p.y, fitted_shadowing_of(facet_wo));
#else
  return biscale_lobe_amplitude * model_m_factor(to_facet * wo, to_facet * wi, p, q);
#endif
}
#endif

/* The lobe source of the bi-scale technique (the interface: lobes_model.glsl): the effective lobes, their M with
 * the BVNDF's amplitude, and the tile's diffuse factor D(i, o) at a world direction (its mean A(o) for a constant
 * world). */
#define DIFFUSE_FACTOR(world_direction) biscale_diffuse((world_direction) * frame)
#define DIFFUSE_ALBEDO biscale_albedo()

void lobes_begin(inout vec4 p, vec4 q, vec3 view_local)
{
  biscale_set_view(view_local);
#ifdef HAS_SPECULAR
#ifdef MODEL_FITTED
  p.z = fitted_shadowing_of(view_local);       /* S(o), for model_m_factor */
#endif
  biscale_set_small_lobes(p, q);
#endif
}

#ifdef HAS_SPECULAR
float biscale_ndf_sharpness;       /* eta_j of the lobe lobes_ndf gave last, for the product axis of its M */

void lobes_ndf(int k, vec4 p, vec4 q, vec3 view_local, out vec3 axis, out float sharpness, out float amplitude,
               out vec3 colour)
{
  biscale_lobe(k, axis, sharpness, amplitude, biscale_ndf_sharpness);
  biscale_set_lobe_amplitude(k, axis, safe_normalize(view_local));
#ifdef MODEL_FITTED
  colour = biscale_small_colour[k % BISCALE_SMALL_LOBES];
#else
  colour = vec3(1.0);
#endif
}

float lobes_m_factor(int k, vec3 ndf_axis, vec3 view_local, vec3 wi, vec4 p, vec4 q)
{
  return biscale_m_factor(k, ndf_axis, biscale_ndf_sharpness, view_local, wi, p, q);
}
#endif
