/* SSDF visibility of one SG lobe against the clamped cosine (wang2009 eq. 39-43 with eq. 30-31), and of a
 * light's cap, shared by the SG surface shader (techniques/sg/sg_shading.glsl), its per-vertex pass of the
 * broad diffuse lobes (techniques/sg/vertex_visibility.frag.glsl) and the factored technique
 * (techniques/factored); mirrored by techniques/sg/sg_shading.py's lobe_visibility and light_cap_visibility.  Needs
 * sg.glsl, hemisphere.glsl, clamped_cosine.glsl, ssdf.glsl and the `visibility_basis` sampler. */

/* The pixel's (or vertex's) SSDF coefficient rows and the bake's local frame of its SSDF normal
 * (ssdf_local_frame, rows t, b, n): set once by set_visibility_frame(). */
vec4 visibility_rows[SSDF_MAX_LAYERS];
mat3 visibility_frame;

void set_visibility_frame(vec3 ssdf_normal)
{
  vec3 t, b, n;
  ssdf_local_frame(ssdf_normal, t, b, n);
  visibility_frame = mat3(t, b, n);             /* columns: local = world * visibility_frame */
}

/* eq. 40's product lobe P = G (x) C*(n) of a lobe G, its axis in the SSDF's local frame (not normalized) and its
 * sharpness: where lobe_visibility reads the SSDF and how broad the lobe it reads it for is. */
void visibility_product(vec3 axis, float sharpness, vec3 n, out vec3 local, out float product_sharpness)
{
  vec2 cosine_lobe = clamped_cosine_lobe();
  vec3 product_axis;
  float product_amplitude;
  sg_product(axis, sharpness, 1.0, n, cosine_lobe.x, 1.0, product_axis, product_sharpness, product_amplitude);
  local = product_axis * visibility_frame;            /* ssdf_to_local */
}

/* eq. 30-31's visible fraction of the product lobe P (local axis, sharpness lam) at SSDF value theta_d:
 * fh(theta_d, lam) / fh(theta_h, lam), theta_h the axis's angle to the horizon of the SSDF normal -- what
 * eq. 31 keeps of P relative to what the horizon alone keeps (the SSDF includes the horizon, I(G, n) already
 * clamps it).  Unoccluded (theta_d = theta_h) it is 1: the unshadowed shading; clamped to [0, 1].  The two
 * fh_normalized_from_sine (hemisphere.glsl) share k(lambda), erf(k) and e^-lambda. */
float product_visible_fraction(float theta_d, vec3 local, float lam)
{
  lam = max(lam, 0.0);
  float k = fh_k(lam);
  float erf_k = erf_approx(k);
  float lower = exp(-lam);
  float x_d = clamp(sin(clamp(theta_d, -0.5 * SG_PI, 0.5 * SG_PI)), -1.0, 1.0);
  float x_h = clamp(safe_normalize(local).z, -1.0, 1.0);
  float g_d = erf_approx(k * x_d * (1.0 + FH_SHAPE_B * (1.0 - x_d * x_d))) / erf_k;
  float g_h = erf_approx(k * x_h * (1.0 + FH_SHAPE_B * (1.0 - x_h * x_h))) / erf_k;
  float visible = clamp(lower + (1.0 - lower) * (0.5 + 0.5 * g_d), 0.0, 1.0);
  float unshadowed = clamp(lower + (1.0 - lower) * (0.5 + 0.5 * g_h), 0.0, 1.0);
  return clamp(visible / max(unshadowed, 1.0e-30), 0.0, 1.0);
}

/* Visible fraction of the clamped-cosine integral I(G, n) of a lobe G (wang2009 eq. 39-43 with eq. 30-31):
 * the SSDF read at the axis of its product lobe P (visibility_product), theta_d, and P's visible fraction
 * there (product_visible_fraction). */
float lobe_visibility(vec3 axis, float sharpness, vec3 n)
{
  vec3 local;
  float lam;
  visibility_product(axis, sharpness, n, local, lam);
  return product_visible_fraction(ssdf_decode(visibility_basis, visibility_rows, SSDF_MAX_LAYERS, local), local, lam);
}

/* Visible fraction of a light's cap of half-angle `radius` (lighting.lights: the uniform disc its SG stands for,
 * light_cap_radius): the disc's share beyond the SSDF's boundary at its centre (the boundary taken straight,
 * as eq. 30 takes it), over its share above the horizon (I(G, n) clamps the horizon already).  eq. 30's fh
 * of the light's SG would give the Gaussian's penumbra, about 1.3 times as wide as the disc's and with tails
 * past it. */
float light_cap_visibility(vec3 axis, float radius)
{
  vec3 local = axis * visibility_frame;            /* ssdf_to_local */
  float theta_d = ssdf_decode(visibility_basis, visibility_rows, SSDF_MAX_LAYERS, local);
  float theta_h = precise_asin(safe_normalize(local).z);
  float unshadowed = disc_coverage(theta_h, radius);
  return clamp(disc_coverage(theta_d, radius) / max(unshadowed, 1.0e-30), 0.0, 1.0);
}
