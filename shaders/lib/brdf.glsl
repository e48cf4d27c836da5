/* Microfacet BRDF models split as rho_s(o, i) = M_o(i) D(h) (wang2009 eq. 9):
 * GLSL mirror of sg_prt_addon/reflectance/brdf.py.  Depends on sg.glsl (safe_normalize, SG_PI).
 *
 * Local frame: normal z+, tangent x+; wo towards the viewer, wi towards the light.
 * Per model <m>: <m>_ndf(h, ...) <- Model.ndf, <m>_m_factor(wo, wi, ...) <- Model.m_factor,
 * and for isotropic models <m>_ndf_lobe(...) <- Model.ndf_lobes (one lobe, axis z+),
 * returned as vec2(sharpness, amplitude).  Parameters follow the dataclass fields.
 *
 *   brdf_half_vector          <- brdf.half_vector
 *   reflect_about             <- brdf.reflect (2 (o.h) h - o; GLSL's reflect is the opposite sign)
 *   brdf_theta                <- brdf._theta
 *   brdf_log_cosine           <- np.log of a cosine, accurate near 1 (see below)
 *   fresnel_dielectric        <- brdf.fresnel_dielectric (eq. 14)
 *   fresnel_schlick           <- brdf.fresnel_schlick
 *   shadowing_cook_torrance   <- brdf.shadowing_cook_torrance
 *   isotropic_mapping_<kind>  <- brdf.isotropic_mapping(kind, width), kind in
 *                                BECKMANN, BLINN_PHONG, WARD_ISO, GGX
 *   beckmann_ndf              <- brdf._beckmann_ndf
 *   cook_torrance_*           <- CookTorrance (eq. 10-12)
 *   cook_torrance_beckmann_*  <- CookTorranceBeckmann
 *   blinn_phong_*             <- BlinnPhong
 *   ward_anisotropic_*        <- WardAnisotropic (ndf, m_factor; its lobes come from a table)
 *   ggx_anisotropic_*         <- GGXAnisotropic (ndf, smith_lambda, m_factor; lobes from the same table)
 *   ward_isotropic_*          <- WardIsotropic
 *   ashikhmin_shirley_*       <- AshikhminShirley (ndf, m_factor; lobes from a table)
 *   ggx_*                     <- GGX (Blender conventions: alpha = roughness^2,
 *                                height-correlated Smith, no Fresnel); ggx_alpha <- GGX._alpha,
 *                                ggx_smith_lambda <- GGX.smith_lambda
 *   beckmann_*                <- Beckmann (Blender's Glossy BSDF: alpha = roughness^2, height-correlated
 *                                Smith with Walter's rational Lambda, no Fresnel; ndf_lobe, smith_lambda,
 *                                m_factor; its NDF is beckmann_ndf)
 *   lambert_m_factor          <- Lambert.m_factor
 * beckmann_ndf, ward_anisotropic_ndf and ggx_ndf normalise h first (brdf.py takes
 * h as given): a tiny non-unit h would overflow float32 there.
 * Sampling and pdfs are for the Monte Carlo reference only and are not ported.
 * The mapping polynomials must equal brdf.ISOTROPIC_MAPPINGS (tests compare).
 */

const float BRDF_COSINE_EPSILON = 1.0e-7;
const float BRDF_FLOAT_TINY = 1.17549435e-38;

vec3 brdf_half_vector(vec3 wo, vec3 wi)
{
  return safe_normalize(safe_normalize(wo) + safe_normalize(wi));
}

vec3 reflect_about(vec3 wo, vec3 h)
{
  return 2.0 * dot(wo, h) * h - wo;
}

/* polar angle of h by atan2: accurate near the pole, where acos(h.z) is not */
float brdf_theta(vec3 h)
{
  return atan(sqrt(h.x * h.x + h.y * h.y), h.z);
}

/* log(z) for a cosine z in (0, 1]: near 1 llvmpipe's log loses ~2e-8 absolute,
 * which (n.h)^n with n ~ 1e4 turns into 2e-4 relative; there a log1p series
 * of the exact z - 1 (truncation < 1e-9 relative) is used instead. */
float brdf_log_cosine(float z)
{
  float x = z - 1.0;
  if (abs(x) < 0.0625) {
    return x * (1.0 - x * (1.0 / 2.0 - x * (1.0 / 3.0 - x * (1.0 / 4.0 - x * (1.0 / 5.0 - x * (1.0 / 6.0 - x * (1.0 / 7.0 - x / 8.0)))))));
  }
  return log(z);
}

/* Unpolarized dielectric Fresnel (eq. 14); g - c formed as (eta^2 - 1)/(g + c). */
float fresnel_dielectric(float cos_theta, float eta)
{
  float c = abs(cos_theta);
  float g2 = eta * eta + c * c - 1.0;
  float g = sqrt(max(g2, 0.0));
  float g_plus_c = g + c;
  if (g2 <= 0.0 || c <= 0.0) {
    return 1.0;  /* total internal reflection, or grazing */
  }
  float g_minus_c = (eta * eta - 1.0) / g_plus_c;
  float ratio = (c * g_plus_c - 1.0) / (c * g_minus_c + 1.0);
  float term = g_minus_c / g_plus_c;
  return min(0.5 * term * term * (1.0 + ratio * ratio), 1.0);
}

float fresnel_schlick(float cos_theta, float rf0)
{
  float c = clamp(abs(cos_theta), 0.0, 1.0);
  float m = 1.0 - c;
  return rf0 + (1.0 - rf0) * (m * m) * (m * m) * m;
}

/* V-cavity shadowing min(1, 2 (n.h)(n.o)/(o.h), 2 (n.h)(n.i)/(o.h)), clamped to [0, 1]. */
float shadowing_cook_torrance(vec3 wo, vec3 wi, vec3 h)
{
  float oh = max(abs(dot(wo, h)), BRDF_COSINE_EPSILON);
  float nh = h.z;
  return clamp(min(2.0 * nh * wo.z / oh, 2.0 * nh * wi.z / oh), 0.0, 1.0);
}

/* ---- frozen L2 single-lobe mappings: vec2(sharpness * w^2, amplitude / D(n)), clamped at 0 ---- */

const float BECKMANN_SHARPNESS[8] = float[8](2.0002526198839767, -0.018562042324853516, -0.7087810352685576, -1.780493452401246, 7.795476534850792, -5.224441602950464, -1.8573600001154729, 1.8313186768538343);
const float BECKMANN_AMPLITUDE[8] = float[8](1.0000788099487423, -0.00562487537421968, 0.45936658759780197, -0.4782415853046627, 1.8768790206320416, -0.723505986830146, -1.093140907789823, 0.6774600689844926);
const float BLINN_PHONG_SHARPNESS[8] = float[8](2.001247483300024, -0.0704030099405333, 1.8252868204860242, -3.7366710387171747, 7.990337405162444, -7.976517234021651, 3.6090854215670936, -0.6165165884429983);
const float BLINN_PHONG_AMPLITUDE[8] = float[8](1.0001482120242338, -0.009229085969026461, 0.24259176162034488, -0.5769981443748883, 1.304434552867832, -1.4708046288958752, 0.7476278795213421, -0.1413828848427673);
const float WARD_ISO_SHARPNESS[8] = float[8](2.0000452113496068, -0.002050309015127145, 3.0147624933803696, 0.02079098217477974, -1.5775218851571589, 1.4289044928620722, -0.4515437794950395, 0.0);
const float WARD_ISO_AMPLITUDE[8] = float[8](1.0000361029442135, -0.002018784963236324, 0.39782446238486135, -0.08061386777996582, -0.513448758758516, 0.5383190127812337, -0.17224374461564965, 0.0);
const float GGX_SHARPNESS[8] = float[8](2.2949071322803056, -1.8169547610727137, 17.634426696713284, -89.52143467300904, 162.11135492098055, -126.49092884708091, 35.775580872045374, 0.0);
const float GGX_AMPLITUDE[8] = float[8](0.868594309075077, -0.47084346810594657, 5.078988403062825, -20.927444128961213, 34.85993749976531, -24.56259538488302, 6.147831356435162, 0.0);

/* Horner evaluation of a (sharpness, amplitude) polynomial pair in the lobe width (degree 7;
 * the degree-6 tables carry a zero top coefficient). Clamped at 0: GGX's sharpness dips to
 * -1e-3 at alpha = 1. */
vec2 isotropic_polynomial(float sharpness[8], float amplitude[8], float width)
{
  vec2 r = vec2(sharpness[7], amplitude[7]);
  for (int k = 6; k >= 0; k--) {
    r = r * width + vec2(sharpness[k], amplitude[k]);
  }
  return max(r, vec2(0.0));
}

vec2 isotropic_mapping_beckmann(float width)
{
  return isotropic_polynomial(BECKMANN_SHARPNESS, BECKMANN_AMPLITUDE, clamp(width, 0.0, 1.0));
}

vec2 isotropic_mapping_blinn_phong(float width)
{
  return isotropic_polynomial(BLINN_PHONG_SHARPNESS, BLINN_PHONG_AMPLITUDE, clamp(width, 0.0, 1.5));
}

vec2 isotropic_mapping_ward_iso(float width)
{
  return isotropic_polynomial(WARD_ISO_SHARPNESS, WARD_ISO_AMPLITUDE, clamp(width, 0.0, 1.0));
}

vec2 isotropic_mapping_ggx(float width)
{
  return isotropic_polynomial(GGX_SHARPNESS, GGX_AMPLITUDE, clamp(width, 0.0, 1.0));
}

/* ---- shared pieces ---- */

/* Normalized anisotropic Beckmann D (integral of D (n.h) = 1), in log space. */
float beckmann_ndf(vec3 h, float alpha_x, float alpha_y)
{
  h = safe_normalize(h, vec3(0.0));  /* tiny h would overflow 1/z^4; zero h gives 0 */
  float z = max(h.z, BRDF_COSINE_EPSILON);
  float u = h.x / alpha_x;
  float v = h.y / alpha_y;
  float exponent = -(u * u + v * v) / (z * z);
  float value = exp(exponent - 4.0 * log(z)) / (SG_PI * alpha_x * alpha_y);
  return h.z > 0.0 ? value : 0.0;
}

/* ---- Cook-Torrance as in wang2009 eq. 10-12 ---- */

float cook_torrance_ndf(vec3 h, float roughness)
{
  float m = max(roughness, 1.0e-6);
  float t = brdf_theta(h) / m;
  return h.z > 0.0 ? exp(-t * t) : 0.0;
}

float cook_torrance_m_factor(vec3 wo, vec3 wi, float roughness, float ior)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  vec3 h = safe_normalize(wo + wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float no = max(wo.z, BRDF_COSINE_EPSILON);
  float ni = max(wi.z, BRDF_COSINE_EPSILON);
  float fresnel = fresnel_dielectric(dot(wi, h), ior);
  return fresnel * shadowing_cook_torrance(wo, wi, h) / (SG_PI * ni * no);
}

/* eq. 12: G(h; n, 2/m^2, 1) */
vec2 cook_torrance_ndf_lobe(float roughness)
{
  float m = max(roughness, 1.0e-6);
  return vec2(2.0 / (m * m), 1.0);
}

/* ---- Cook-Torrance with the normalized Beckmann NDF ---- */

float cook_torrance_beckmann_ndf(vec3 h, float roughness)
{
  float m = max(roughness, 1.0e-6);
  return beckmann_ndf(h, m, m);
}

float cook_torrance_beckmann_m_factor(vec3 wo, vec3 wi, float roughness, float ior)
{
  return cook_torrance_m_factor(wo, wi, roughness, ior) * (SG_PI / 4.0);
}

vec2 cook_torrance_beckmann_ndf_lobe(float roughness)
{
  float m = max(roughness, 1.0e-6);
  vec2 mapping = isotropic_mapping_beckmann(m);
  return vec2(mapping.x / (m * m), mapping.y / (SG_PI * m * m));
}

/* ---- Blinn-Phong, V-cavity shadowing, no Fresnel ---- */

float blinn_phong_ndf(vec3 h, float exponent)
{
  float n = max(exponent, 0.0);
  float value = (n + 2.0) / (2.0 * SG_PI) * exp(n * brdf_log_cosine(max(h.z, BRDF_FLOAT_TINY)));
  return h.z > 0.0 ? value : 0.0;
}

float blinn_phong_m_factor(vec3 wo, vec3 wi, float exponent)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  vec3 h = safe_normalize(wo + wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float no = max(wo.z, BRDF_COSINE_EPSILON);
  float ni = max(wi.z, BRDF_COSINE_EPSILON);
  return shadowing_cook_torrance(wo, wi, h) / (4.0 * ni * no);
}

vec2 blinn_phong_ndf_lobe(float exponent)
{
  float n = max(exponent, 0.0);
  float width = sqrt(2.0 / max(n, 1.0e-6));
  vec2 mapping = isotropic_mapping_blinn_phong(width);
  float w = clamp(width, 0.0, 1.5);
  return vec2(mapping.x / (w * w), mapping.y * (n + 2.0) / (2.0 * SG_PI));
}

/* ---- Ward ---- */

float ward_anisotropic_ndf(vec3 h, float alpha_x, float alpha_y)
{
  float ax = max(alpha_x, 1.0e-6);
  float ay = max(alpha_y, 1.0e-6);
  h = safe_normalize(h, vec3(0.0));  /* zero h gives 0 */
  float z = max(h.z, BRDF_COSINE_EPSILON);
  float u = h.x / ax;
  float v = h.y / ay;
  float value = exp(-(u * u + v * v) / (z * z)) / (SG_PI * ax * ay);
  return h.z > 0.0 ? value : 0.0;
}

/* M_o(i) = 1/(4 sqrt((n.i)(n.o))): independent of h */
float ward_anisotropic_m_factor(vec3 wo, vec3 wi)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  return 0.25 / sqrt(max(wi.z, BRDF_COSINE_EPSILON) * max(wo.z, BRDF_COSINE_EPSILON));
}

float ward_isotropic_ndf(vec3 h, float alpha)
{
  return ward_anisotropic_ndf(h, alpha, alpha);
}

float ward_isotropic_m_factor(vec3 wo, vec3 wi)
{
  return ward_anisotropic_m_factor(wo, wi);
}

vec2 ward_isotropic_ndf_lobe(float alpha_x)
{
  float alpha = max(alpha_x, 1.0e-6);
  vec2 mapping = isotropic_mapping_ward_iso(alpha);
  return vec2(mapping.x / (alpha * alpha), mapping.y / (SG_PI * alpha * alpha));
}

/* ---- Ashikhmin-Shirley ---- */

float ashikhmin_shirley_ndf(vec3 h, float nu, float nv)
{
  nu = max(nu, 0.0);
  nv = max(nv, 0.0);
  float sin2 = h.x * h.x + h.y * h.y;
  float weighted = nu * h.x * h.x + nv * h.y * h.y;
  float exponent = sin2 > 0.0 ? weighted / sin2 : nu;
  float log_hz = brdf_log_cosine(max(h.z, BRDF_FLOAT_TINY));
  float value = sqrt((nu + 1.0) * (nv + 1.0)) / (2.0 * SG_PI) * exp(exponent * log_hz);
  return h.z > 0.0 ? value : 0.0;
}

float ashikhmin_shirley_m_factor(vec3 wo, vec3 wi, float nu, float nv, float rf0)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  vec3 h = safe_normalize(wo + wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float no = max(wo.z, BRDF_COSINE_EPSILON);
  float ni = max(wi.z, BRDF_COSINE_EPSILON);
  float kh = max(abs(dot(wi, h)), BRDF_COSINE_EPSILON);
  return fresnel_schlick(kh, rf0) / (4.0 * kh * max(ni, no));
}

/* ---- GGX with Blender's conventions ---- */

/* alpha = roughness^2 >= 1e-9 keeps 1/(pi alpha^2) finite in float32 */
float ggx_alpha(float roughness)
{
  return max(roughness * roughness, 1.0e-9);
}

/* alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2) without forming alpha^4 */
float ggx_ndf(vec3 h, float roughness)
{
  float alpha = ggx_alpha(roughness);
  h = safe_normalize(h, vec3(0.0));  /* tiny h would underflow scaled to 0; zero h gives 0 */
  float scaled = (h.x * h.x + h.y * h.y) / (alpha * alpha) + h.z * h.z;
  return h.z > 0.0 ? 1.0 / (SG_PI * alpha * alpha * scaled * scaled) : 0.0;
}

/* Lambda(w) = (sqrt(1 + alpha^2 tan^2) - 1)/2 in cancellation-free form */
float ggx_smith_lambda(vec3 w, float alpha)
{
  float z = max(w.z, BRDF_COSINE_EPSILON);
  float a = alpha * alpha * (w.x * w.x + w.y * w.y) / (z * z);
  return a / (2.0 * (1.0 + sqrt(1.0 + a)));
}

float ggx_m_factor(vec3 wo, vec3 wi, float roughness)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float alpha = ggx_alpha(roughness);
  float shadowing = 1.0 / (1.0 + ggx_smith_lambda(wo, alpha) + ggx_smith_lambda(wi, alpha));
  return shadowing / (4.0 * max(wi.z, BRDF_COSINE_EPSILON) * max(wo.z, BRDF_COSINE_EPSILON));
}

/* ---- Beckmann with Blender's conventions (Beckmann) ---- */

float beckmann_alpha(float roughness)
{
  return max(roughness * roughness, 1.0e-6);
}

/* Walter et al. 2007's rational Lambda, a = 1 / (alpha tan theta), as Cycles; not below 0 (it dips 2e-5 under
 * near a = 1.6) */
float beckmann_smith_lambda(vec3 w, float alpha)
{
  float z = max(w.z, BRDF_COSINE_EPSILON);
  float a = z / max(alpha * length(w.xy), 1.0e-30);
  return a < 1.6 ? max((1.0 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a), 0.0) : 0.0;
}

float beckmann_m_factor(vec3 wo, vec3 wi, float roughness)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float alpha = beckmann_alpha(roughness);
  float shadowing = 1.0 / (1.0 + beckmann_smith_lambda(wo, alpha) + beckmann_smith_lambda(wi, alpha));
  return shadowing / (4.0 * max(wi.z, BRDF_COSINE_EPSILON) * max(wo.z, BRDF_COSINE_EPSILON));
}

vec2 beckmann_ndf_lobe(float roughness)
{
  float alpha = beckmann_alpha(roughness);
  vec2 mapping = isotropic_mapping_beckmann(alpha);
  return vec2(mapping.x / (alpha * alpha), mapping.y / (SG_PI * alpha * alpha));
}

/* ---- anisotropic GGX (GGXAnisotropic): alpha_x along the tangent, alpha_y along the bitangent ---- */

float ggx_anisotropic_ndf(vec3 h, float alpha_x, float alpha_y)
{
  float ax = max(alpha_x, 1.0e-6);
  float ay = max(alpha_y, 1.0e-6);
  h = safe_normalize(h, vec3(0.0));
  float u = h.x / ax;
  float v = h.y / ay;
  float scaled = u * u + v * v + h.z * h.z;
  return h.z > 0.0 ? 1.0 / (SG_PI * ax * ay * scaled * scaled) : 0.0;
}

float ggx_anisotropic_smith_lambda(vec3 w, float alpha_x, float alpha_y)
{
  float z = max(w.z, BRDF_COSINE_EPSILON);
  /* capped: a non-unit or grazing w overflows a to Inf, and Inf / Inf is NaN (found by test_glsl_stress) */
  float a = min(((alpha_x * w.x) * (alpha_x * w.x) + (alpha_y * w.y) * (alpha_y * w.y)) / (z * z), 1.0e30);
  return a / (2.0 * (1.0 + sqrt(1.0 + a)));
}

float ggx_anisotropic_m_factor(vec3 wo, vec3 wi, float alpha_x, float alpha_y)
{
  wo = safe_normalize(wo);
  wi = safe_normalize(wi);
  if (!(wo.z > 0.0 && wi.z > 0.0)) {
    return 0.0;
  }
  float ax = max(alpha_x, 1.0e-6);
  float ay = max(alpha_y, 1.0e-6);
  float shadowing = 1.0 / (1.0 + ggx_anisotropic_smith_lambda(wo, ax, ay) + ggx_anisotropic_smith_lambda(wi, ax, ay));
  return shadowing / (4.0 * max(wi.z, BRDF_COSINE_EPSILON) * max(wo.z, BRDF_COSINE_EPSILON));
}

vec2 ggx_ndf_lobe(float roughness)
{
  float alpha = ggx_alpha(roughness);
  vec2 mapping = isotropic_mapping_ggx(alpha);
  return vec2(mapping.x / (alpha * alpha), mapping.y / (SG_PI * alpha * alpha));
}

/* ---- Lambert kd/pi (an SG of sharpness 0 in the same protocol) ---- */

float lambert_m_factor(vec3 wo, vec3 wi, float kd)
{
  wo = safe_normalize(wo);  /* a zero vector counts as z+, as in brdf._unit */
  wi = safe_normalize(wi);
  return (wo.z > 0.0 && wi.z > 0.0) ? kd / SG_PI : 0.0;
}
