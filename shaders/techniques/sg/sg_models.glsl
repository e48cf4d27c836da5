/* The BRDF models of the SG techniques, chosen by the variant's MODEL_* define (sg_lobes.py): each model's NDF
 * lobes, its M_o(i) (wang2009 eq. 9-14; MODEL_FITTED: a stored lobe fit's, eq. 13), its lobes' angular widths (for
 * Specular Anti-Aliasing) and, for the light tail, its own rho_s.  Needs brdf.glsl, and (anisotropic models)
 * anisotropic_lobes.glsl, (GGX's two lobes) ggx_two_lobes.glsl, (MODEL_FITTED) common/fitted_texels.glsl. */

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
#elif defined(MODEL_BECKMANN)
  lobe = beckmann_ndf_lobe(p.x);
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
#elif defined(MODEL_BECKMANN)
  return vec2(beckmann_alpha(p.x));
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
#elif defined(MODEL_BECKMANN)
  return beckmann_m_factor(wo, wi, p.x);
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
#elif defined(MODEL_BECKMANN)
  ndf = beckmann_ndf(h, beckmann_alpha(p.x), beckmann_alpha(p.x));
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
