/* Spherical warp of NDF lobes to the BRDF view slice (wang2009 eq. 17-22):
 * GLSL mirror of sg_prt_addon/core/warp.py.  Depends on sg.glsl.
 *
 *   warp_at             <- warp._warp_at (eq. 18-21 at one lobe centre, grazing clamp)
 *   warp_lobes_paper    <- warp.warp_lobes(mode="paper"): one lobe per NDF lobe
 *   warp_lobes_split2   <- warp.warp_lobes(mode="split2") (warp.DEFAULT_MODE): two
 *                          half-amplitude lobes per NDF lobe, index 0 = warp.py's 2k
 *                          (offset towards wo), index 1 = 2k + 1
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

/* psi(h) = 2 (h.wo) h - wo and lambda / (4 max(|h.wo|, floor)), capped. */
void warp_at(vec3 half_vector, float sharpness, vec3 wo, float signed_cos,
             out vec3 axis, out float warped_sharpness)
{
  axis = safe_normalize(2.0 * signed_cos * half_vector - wo);
  float tau = 4.0 * max(abs(signed_cos), WARP_COS_FLOOR);
  warped_sharpness = min(sharpness / tau, WARP_MAX_WARPED_SHARPNESS);
}

void warp_lobes_paper(vec3 axis, float sharpness, float amplitude, vec3 wo,
                      out vec3 warped_axis, out float warped_sharpness, out float warped_amplitude)
{
  axis = safe_normalize(axis);
  wo = safe_normalize(wo);
  float signed_cos = clamp(dot(axis, wo), -1.0, 1.0);
  warp_at(axis, sharpness, wo, signed_cos, warped_axis, warped_sharpness);
  warped_amplitude = amplitude;
}

/* Split the NDF lobe into two half-amplitude lobes offset by +-delta in the
 * plane of (axis, wo), delta = sqrt((1 - c)/lambda) capped (the cap fades to 0
 * below lambda = WARP_FULL_SPLIT_SHARPNESS), then warp each at its own centre.
 * A sub-lobe whose centre is not a valid half vector (h.wo <= 0) gets amplitude 0. */
void warp_lobes_split2(vec3 axis, float sharpness, float amplitude, vec3 wo,
                       out vec3 warped_axis[2], out float warped_sharpness[2], out float warped_amplitude[2])
{
  axis = safe_normalize(axis);
  wo = safe_normalize(wo);
  float signed_cos = clamp(dot(axis, wo), -1.0, 1.0);
  vec3 in_plane = safe_normalize(wo - signed_cos * axis, vec3(1.0, 0.0, 0.0));
  in_plane = in_plane - dot(in_plane, axis) * axis;  /* the fallback may not be orthogonal */
  in_plane = safe_normalize(in_plane, vec3(0.0, 1.0, 0.0));
  float offset_cap = WARP_MAX_SPLIT_OFFSET * min(sharpness * (1.0 / WARP_FULL_SPLIT_SHARPNESS), 1.0);
  float offset = sharpness > 0.0 ? min(sqrt((1.0 - signed_cos) / sharpness), offset_cap) : offset_cap;
  float cos_offset = cos(offset);
  float sin_offset = sin(offset);
  for (int k = 0; k < 2; k++) {
    float sign_k = k == 0 ? 1.0 : -1.0;  /* +: towards wo */
    vec3 half_vector = cos_offset * axis + (sign_k * sin_offset) * in_plane;
    float half_cos = dot(half_vector, wo);
    warp_at(half_vector, sharpness, wo, half_cos, warped_axis[k], warped_sharpness[k]);
    warped_amplitude[k] = half_cos > 0.0 ? 0.5 * amplitude : 0.0;
  }
}

/* eq. 22: Mo evaluated at the warped lobe centre scales the amplitude; non-finite Mo -> 0. */
float brdf_slice_amplitude(float warped_amplitude, float m_factor)
{
  return (isinf(m_factor) || isnan(m_factor)) ? 0.0 : warped_amplitude * m_factor;
}
