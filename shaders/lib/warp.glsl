/* Spherical warp of NDF lobes to the BRDF view slice (wang2009 eq. 17-22):
 * GLSL mirror of sg_prt_addon/spherical/warp.py.  Depends on sg.glsl.
 *
 *   warp_at             <- warp._warp_at (eq. 18-21 at one lobe centre, grazing clamp)
 *   warp_lobes_paper    <- warp.warp_lobes(mode="paper"): one lobe per NDF lobe
 *   warp_split_frame, warp_split_node <- the split branch of warp.warp_lobes
 *   warp_lobes_split2   <- warp.warp_lobes(mode="split2"): two lobes per NDF lobe
 *   warp_lobes_split3   <- warp.warp_lobes(mode="split3") (warp.DEFAULT_MODE): three
 *                          lobes; index j = warp.py's n k + j, in SPLIT_RULES' node
 *                          order (first node offset towards wo)
 *   brdf_slice_amplitude <- the end of warp.brdf_slice_lobes: warped amplitude
 *                          times Mo at the warped axis, 0 where Mo is not finite
 *                          (the caller evaluates Mo with a brdf.glsl *_m_factor)
 *
 * Grazing: tau = 4 max(|h.wo|, WARP_COS_FLOOR) and the warped sharpness is
 * capped at WARP_MAX_WARPED_SHARPNESS, so wo in the tangent plane stays finite.
 */

const float WARP_COS_FLOOR = 1.0e-3;
const float WARP_MAX_WARPED_SHARPNESS = 1.0e6;
const float WARP_MAX_SPLIT_OFFSET = 0.2;
const float WARP_FULL_SPLIT_SHARPNESS = 8.0;

/* psi(h) = 2 (h.wo) h - wo (unit for unit h and wo: no normalize) and
 * lambda / (4 max(|h.wo|, floor) across), capped (across: the split modes' m, 1 for the paper's warp). */
void warp_at(vec3 half_vector, float sharpness, vec3 wo, float signed_cos, float across,
             out vec3 axis, out float warped_sharpness)
{
  axis = 2.0 * signed_cos * half_vector - wo;
  float tau = 4.0 * max(abs(signed_cos), WARP_COS_FLOOR) * across;
  warped_sharpness = min(sharpness / tau, WARP_MAX_WARPED_SHARPNESS);
}

void warp_lobes_paper(vec3 axis, float sharpness, float amplitude, vec3 wo,
                      out vec3 warped_axis, out float warped_sharpness, out float warped_amplitude)
{
  axis = safe_normalize(axis);
  wo = safe_normalize(wo);
  float signed_cos = clamp(dot(axis, wo), -1.0, 1.0);
  warp_at(axis, sharpness, wo, signed_cos, 1.0, warped_axis, warped_sharpness);
  warped_amplitude = amplitude;
}

/* Split modes: Gauss-Hermite nodes along the plane of (axis, wo), spaced by
 * delta = sqrt((1 - c m)/lambda) capped (the cap fades to 0 below lambda =
 * WARP_FULL_SPLIT_SHARPNESS), each warped at its own centre, to a lobe of the true
 * width across the plane where `narrow` (split3: m = max(c, 1 - c); split2: m = 1;
 * warp.split_across).  This prepares the normalised axis and wo, the in-plane
 * direction, delta and m. */
void warp_split_frame(vec3 axis, float sharpness, vec3 wo, bool narrow,
                      out vec3 unit_axis, out vec3 unit_wo, out vec3 in_plane, out float offset, out float across)
{
  unit_axis = safe_normalize(axis);
  unit_wo = safe_normalize(wo);
  float signed_cos = clamp(dot(unit_axis, unit_wo), -1.0, 1.0);
  in_plane = unit_wo - signed_cos * unit_axis;
  if (dot(in_plane, in_plane) < 1.0e-12) {
    /* wo along the axis: no plane of incidence (delta = 0 there anyway), any perpendicular */
    vec3 helper = abs(unit_axis.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    in_plane = cross(unit_axis, helper);
  }
  in_plane = safe_normalize(in_plane);
  /* wo near -axis: wo - c axis cancels, so restore orthogonality (second-order error left) */
  in_plane = in_plane - dot(in_plane, unit_axis) * unit_axis;
  float cosine = max(abs(signed_cos), WARP_COS_FLOOR);
  across = narrow ? max(cosine, 1.0 - cosine) : 1.0;
  float offset_cap = WARP_MAX_SPLIT_OFFSET * min(sharpness * (1.0 / WARP_FULL_SPLIT_SHARPNESS), 1.0);
  float uncapped = sharpness > 0.0 ? sqrt((1.0 - signed_cos * across) / sharpness) : 1.0e30;
  offset = min(uncapped, offset_cap);
  if (offset_cap < uncapped) {
    /* where the cap bites, wider parts hold the in-plane variance the offsets no longer give */
    across = clamp((1.0 - sharpness * offset * offset) / cosine, across, 1.0);
  }
}

/* One node (in units of delta, > 0 towards wo) of weight `weight`; a node whose
 * centre is not a valid half vector (h.wo <= 0) gets amplitude 0; amplitude over m
 * keeps the warped lobe's integral. */
void warp_split_node(vec3 unit_axis, vec3 in_plane, vec3 unit_wo, float offset, float across, float node,
                     float weight, float sharpness, float amplitude,
                     out vec3 warped_axis, out float warped_sharpness, out float warped_amplitude)
{
  float node_offset = offset * node;
  vec3 half_vector = cos(node_offset) * unit_axis + sin(node_offset) * in_plane;
  float half_cos = dot(half_vector, unit_wo);
  warp_at(half_vector, sharpness, unit_wo, half_cos, across, warped_axis, warped_sharpness);
  warped_amplitude = half_cos > 0.0 ? weight * amplitude / across : 0.0;
}

/* Two-point rule: nodes +-1, weights 1/2 (index 0 = warp.py's n k, towards wo). */
void warp_lobes_split2(vec3 axis, float sharpness, float amplitude, vec3 wo,
                       out vec3 warped_axis[2], out float warped_sharpness[2], out float warped_amplitude[2])
{
  vec3 unit_axis, unit_wo, in_plane;
  float offset, across;
  warp_split_frame(axis, sharpness, wo, false, unit_axis, unit_wo, in_plane, offset, across);
  warp_split_node(unit_axis, in_plane, unit_wo, offset, across, 1.0, 0.5, sharpness, amplitude,
                  warped_axis[0], warped_sharpness[0], warped_amplitude[0]);
  warp_split_node(unit_axis, in_plane, unit_wo, offset, across, -1.0, 0.5, sharpness, amplitude,
                  warped_axis[1], warped_sharpness[1], warped_amplitude[1]);
}

/* Three-point rule (warp.DEFAULT_MODE): nodes sqrt(3), 0, -sqrt(3), weights 1/6, 2/3, 1/6. */
void warp_lobes_split3(vec3 axis, float sharpness, float amplitude, vec3 wo,
                       out vec3 warped_axis[3], out float warped_sharpness[3], out float warped_amplitude[3])
{
  vec3 unit_axis, unit_wo, in_plane;
  float offset, across;
  warp_split_frame(axis, sharpness, wo, true, unit_axis, unit_wo, in_plane, offset, across);
  warp_split_node(unit_axis, in_plane, unit_wo, offset, across, 1.7320508075688772, 1.0 / 6.0, sharpness, amplitude,
                  warped_axis[0], warped_sharpness[0], warped_amplitude[0]);
  warp_split_node(unit_axis, in_plane, unit_wo, offset, across, 0.0, 2.0 / 3.0, sharpness, amplitude,
                  warped_axis[1], warped_sharpness[1], warped_amplitude[1]);
  warp_split_node(unit_axis, in_plane, unit_wo, offset, across, -1.7320508075688772, 1.0 / 6.0, sharpness, amplitude,
                  warped_axis[2], warped_sharpness[2], warped_amplitude[2]);
}

/* eq. 22: Mo evaluated at the warped lobe centre scales the amplitude; non-finite Mo -> 0. */
float brdf_slice_amplitude(float warped_amplitude, float m_factor)
{
  return (isinf(m_factor) || isnan(m_factor)) ? 0.0 : warped_amplitude * m_factor;
}
