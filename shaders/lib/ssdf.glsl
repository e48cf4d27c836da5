/* SSDF visibility (wang2009 eq. 23-31): GLSL mirror of sg_prt_addon/visibility/decode.py and
 * visibility/hemisphere_map.py.  Depends on sg.glsl, hemisphere.glsl and hemisphere_map.glsl.
 *
 *   ssdf_horizon_lookup            <- hemisphere_map.horizon_lookup (vec3(square.xy, angle below horizon))
 *   ssdf_local_frame, ssdf_to_local <- hemisphere_map.local_frame (default tangent)
 *   ssdf_decode                    <- decode.decode, in the packed layout of decode.pack_basis_texture
 *   ssdf_decode_leading            <- the same, and decode.decode of the leading rows alone
 *   ssdf_visibility_amplitude      <- hemisphere.visibility_product_integral_preserving (its amplitude)
 *   ssdf_shadowed_integral         <- decode.shadowed_integral
 *
 * Layout: `basis` is an RGBA32F sampler2DArray holding the images [mean, B_0, B_1, ...] four to a
 * layer (linear filtering, clamp-to-edge: a GPU texture from Python); `coefficients[l]` holds the
 * vertex-interpolated [1, w_0, w_1, ...] four to a vec4.  The R x R stored samples lie on the lattice
 * -1 + 2 k / (R - 1) of the square (outer rows on the horizon), at the texel centres: square (a, b) ->
 * texture coordinates (((a, b) + 1) / 2 (R - 1) + 1 / 2) / R (hemisphere_map.sample_texcoord).
 * #define SSDF_MAX_LAYERS (the vec4 rows a vertex, at most visibility.per_vertex.MAX_ROWS) before
 * this file: the engine defines it from the bake's layers.
 *
 * Use: theta_d = ssdf_decode(basis, coefficients, layers, ssdf_to_local(product_axis, normal)), then
 * ssdf_visibility_amplitude on the final product lobe (e.g. C* (x) L* for eq. 39).
 */

#ifndef SSDF_MAX_LAYERS
#error "SSDF_MAX_LAYERS: define the coefficient rows a vertex before ssdf.glsl"
#endif

const vec3 SSDF_FRAME_REFERENCE_AXIS = vec3(0.2672612419124244, 0.5345224838248488, 0.8017837257372732);
const vec3 SSDF_FRAME_FALLBACK_AXIS = vec3(0.8017837257372732, -0.2672612419124244, -0.5345224838248488);

/* Square point of a local direction and the angle below the horizon (0 above it): below, the
 * horizon point of the same azimuth (straight down: azimuth 0). */
vec3 ssdf_horizon_lookup(vec3 direction)
{
  /* one square lookup for both cases (selects, not branches) */
  bool below = direction.z < 0.0;
  float horizontal = length(direction.xy);
  vec3 on_horizon = horizontal > 0.0 ? vec3(direction.xy / horizontal, 0.0) : vec3(1.0, 0.0, 0.0);
  return vec3(hemisphere_map_to_square(below ? on_horizon : direction),
              below ? atan(-direction.z, horizontal) : 0.0);
}

/* The bake's local frame of a normal: tangent = reference axis projected on the tangent plane. */
void ssdf_local_frame(vec3 normal, out vec3 tangent, out vec3 bitangent, out vec3 unit_normal)
{
  unit_normal = safe_normalize(normal);
  vec3 reference = abs(dot(unit_normal, SSDF_FRAME_REFERENCE_AXIS)) > 0.99995 ? SSDF_FRAME_FALLBACK_AXIS
                                                                               : SSDF_FRAME_REFERENCE_AXIS;
  tangent = normalize(reference - dot(reference, unit_normal) * unit_normal);
  bitangent = cross(unit_normal, tangent);
}

/* World direction -> the SSDF's local frame of `normal`. */
vec3 ssdf_to_local(vec3 world_direction, vec3 normal)
{
  vec3 t, b, n;
  ssdf_local_frame(normal, t, b, n);
  return vec3(dot(world_direction, t), dot(world_direction, b), dot(world_direction, n));
}

/* SSDF value (radians, + visible) at a local direction (normalized here; zero -> +z): one bilinear
 * fetch per four PCA images; and in `leading` the same from the first `leading_layers` rows alone (the
 * mean and the leading PCA terms: the SSDF's broad shape), on the way. */
float ssdf_decode_leading(sampler2DArray basis, vec4 coefficients[SSDF_MAX_LAYERS], int layer_count, int leading_layers,
                          vec3 local_direction, out float leading)
{
  vec3 lookup = ssdf_horizon_lookup(safe_normalize(local_direction));
  float resolution = float(textureSize(basis, 0).x);
  vec2 texcoord = ((lookup.xy + 1.0) * (0.5 * (resolution - 1.0)) + 0.5) / resolution;
  int first = min(leading_layers, layer_count);
  float value = 0.0;
  for (int layer = 0; layer < first; ++layer) {
    value += dot(texture(basis, vec3(texcoord, float(layer))), coefficients[layer]);
  }
  leading = value - lookup.z;
  for (int layer = first; layer < layer_count; ++layer) {
    value += dot(texture(basis, vec3(texcoord, float(layer))), coefficients[layer]);
  }
  return value - lookup.z;
}

float ssdf_decode(sampler2DArray basis, vec4 coefficients[SSDF_MAX_LAYERS], int layer_count, vec3 local_direction)
{
  float leading;
  return ssdf_decode_leading(basis, coefficients, layer_count, layer_count, local_direction, leading);
}

/* eq. 31, integral-preserving: the lobe's amplitude after the product with the SSDF visibility
 * (apply to the final product lobe). */
float ssdf_visibility_amplitude(float sharpness, float amplitude, float theta_d)
{
  float lam = max(sharpness, 0.0);
  return amplitude * fh_normalized(theta_d, lam) / (1.0 + exp(-lam));
}

/* Integral of G(i; p, lambda, mu) V(i) over the sphere ~ mu fh(V_d(p), lambda) (eq. 30); p local. */
float ssdf_shadowed_integral(vec3 axis_local, float sharpness, float amplitude, sampler2DArray basis,
                             vec4 coefficients[SSDF_MAX_LAYERS], int layer_count)
{
  return amplitude * fh(ssdf_decode(basis, coefficients, layer_count, axis_local), sharpness);
}
