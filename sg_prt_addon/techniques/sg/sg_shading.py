"""Numpy mirror of the engine's fragment shader (shaders/surface.frag.glsl): the same
equations, per pixel, from plain arrays (a G-buffer, sampled material parameters,
lights and environment data).  wang2009 eq. 36-43 without visibility:

    R(o) = kd/pi * Rd + ks * Rs(o)

    Rd    = sum_lights  I(light SG, n)  +  sum_env_lobes I(L*_k, n)       (eq. 39, 42)
    Rs(o) = sum_j [ sum_lights I(light SG (x) rho*_j, n)                  (eq. 43)
                    + Gamma_L(p_j, lambda_j)/integral * mu_j I(p_j, lambda_j, n) ]   (eq. 41, 35)

I(G, n) is the integral of an SG times the clamped cosine (more accurate than the paper's
single-lobe C*): read from clamped_cosine_table for the lights, the slice lobes and their
products, whose sharpness varies per pixel, and clamped_cosine.py's closed form for the
environment's lobes, whose lambda-only terms the shader gets once a frame; rho*_j are the
model's NDF lobes warped to the view slice (warp.brdf_slice_lobes in
warp.DEFAULT_MODE: one to three lobes per NDF lobe) with the smooth factor M_o at each lobe
centre.  For the environment, the cosine is folded in as the ratio
I(p_j, lambda_j, n) / integral G_j (the clamped cosine averaged over the lobe),
which keeps the horizon behaviour of the accurate integral; a constant world
colour c stands for Gamma / integral = c.

With a visibility bake (``Visibility``: the pixel's interpolated SSDF PCA rows and
SSDF-frame normal, the packed basis), every clamped-cosine integral I(G, n) above is
multiplied by ``lobe_visibility(G)``: the product lobe P = G (x) C*(n) (eq. 40's cosine
lobe), the SSDF theta_d decoded at P's axis in the vertex's local frame
(visibility.decode's lookup), and fh(theta_d, lambda_P) / fh(theta_h, lambda_P) clamped to
[0, 1], theta_h the axis's angle to the SSDF normal's horizon (eq. 30-31: what the
visibility keeps of P relative to what the horizon alone keeps, since I(G, n) clamps
the horizon already).  G is the environment lobe (eq. 39), the light (eq. 42), the
light (x) slice lobe (eq. 43) and the slice lobe (eq. 41); a constant world colour
uses the cosine lobe alone.  When every light is narrow on the object (shares_light_visibility), the
light (x) slice products take the light's own visibility.  Otherwise products below
VISIBILITY_SKIP_FRACTION of the light's own I(G, n) stay unshadowed (the shader skips their decode).
The warped lobes of one NDF lobe (warp.DEFAULT_MODE's nodes, close together) share one visibility:
the centre node's (``visibility_node_indices``), a third of the decodes of split3 for the slice terms.

What the slice lobes miss is added back (each measured in docs/ACCURACY.md, glossy_tails): at each
light's centre the model's own BRDF minus the lobes (light_tail: GGX's theta^-4 glow, the lobes' peak
error); for GGX the lobes capped at and topped up to the model's directional albedo (model_albedo,
environment_tail); lobes sharper than the top prefiltered layer read towards the map itself
(environment_radiance); partly occluded lobes read the environment where their visible part lies
(visible_part_axes).

Everything is computed in float32 like the GPU.  Directions: world space, all
pointing away from the surface.
"""
from dataclasses import dataclass

import numpy as np

from ...lighting import env_prefilter, equirect, lights
from ...reflectance import brdf, ggx_albedo, layering, models
from ...spherical import clamped_cosine, sg, texture_fetch, texture_mips, warp
from .. import surface_layering
from .fitted_texels import FITTED_MODEL, fitted_m_factor, fitted_texel_values

FLOAT = np.float32
# GGX NDF as two SG lobes (ndf_fit.ggx_two_lobes): the one-lobe L2 mapping keeps only 0.77-0.80 of
# GGX's projected area at roughness 0.3-0.5 (its long tail), two lobes 0.93-0.97.
GGX_NDF_LOBES = 2
# GGX's tail lobe of environment light (environment_tail) has this fraction of the broader NDF lobe's sharpness.
TAIL_SHARPNESS_RATIO = 0.25
# Slice lobes up to the first sharpness read the environment weighted by the clamped cosine, handing over to
# their own axis and sharpness at the second (cosine_weighted_lookup); the tail lobe always.  Measured on a
# sphere under courtyard.exr (validation/environment_specular.py): GGX 0.6 relative RMSE 0.25 -> 0.095;
# weighting sharper lobes too made GGX 0.35 worse (0.070 -> 0.101).
COSINE_LOOKUP_SHARPNESS = (4.0, 8.0)
# Light (x) slice products (eq. 43) whose clamped-cosine integral is below this fraction of the light's own
# (away from the highlight) skip the SSDF decode and stay unshadowed (the GLSL branches: it saves decodes).
VISIBILITY_SKIP_FRACTION = 1e-4
# Below this sine of the tangent's angle to the normal, shading_frame takes its fallback tangent.
SHADING_FRAME_MIN_SINE = 1e-3
# Lights narrower than this everywhere on an object (angular radius of the light's cap, radians) lend their
# own SSDF visibility to their products with the slice lobes (shares_light_visibility).  Measured on a glossy
# sphere over a floor (tests/gpu/test_shadows_reference.py): the image moves by 1e-4 relative RMSE up to
# 0.2 rad, 1.6% at 0.3-0.5 rad, 18% beyond.
SHARED_LIGHT_VISIBILITY_MAX_RADIUS = 0.15
# A partly occluded slice lobe reads the environment where its visible part lies (visible_part_axes): towards the
# side where the SSDF grows (lobe_visibility_side) for lobes keeping less than VISIBLE_SIDE_MAX_FRACTION, read off
# its leading VISIBLE_SIDE_LAYERS coefficient rows (the mean and 7 PCA terms: the occluders' broad shape) by forward
# differences VISIBLE_SIDE_STEP radians across the lobe's axis (about two texels of the default 32 x 32 SSDF);
# turned at most VISIBLE_PART_MAX_TURN, narrowed to a visible part's width of at least VISIBLE_PART_MIN_VARIANCE
# (squared widths) across the boundary.  Truth suite ggx035_metal_hdri at 128 px: every row 0.1043, 1, 2 or 3 rows
# 0.0988, 0.0989, 0.0984 (the higher terms' detail turns lobes towards the nearest edge); step 0.04, 0.08, 0.16:
# 0.0988, 0.0989, 0.0992.
VISIBLE_SIDE_STEP = 0.08
VISIBLE_SIDE_MAX_FRACTION = 0.999
VISIBLE_SIDE_LAYERS = 2
VISIBLE_PART_MAX_TURN = 0.5 * np.pi
VISIBLE_PART_MIN_VARIANCE = 0.05


def _clamped_cosine_integral(axis, sharpness, amplitude, normal):
    """I(G, n) of a lobe whose sharpness varies per pixel (lights, slices, their products): from the
    table, as the shader reads it (clamped_cosine_table)."""
    from ...spherical import clamped_cosine_table
    return clamped_cosine_table.sg_clamped_cosine_integral_tabulated(axis, sharpness, amplitude, normal).astype(FLOAT)


@dataclass
class Visibility:
    """Per-pixel SSDF inputs of the visibility variant (shaders: HAS_VISIBILITY).

    rows (N, 4 L): interpolated [1, w_0, ...] (visibility.decode.pack_coefficients layout);
    normal (N, 3): interpolated SSDF-frame normal (the bake's vertex normals, world space);
    basis_texture (L, R, R, 4): visibility.decode.pack_basis_texture;
    diffuse (N, E), optional: the broad diffuse lobes' visible fractions interpolated from the vertices
    (vertex_diffuse_visibility; shaders: DIFFUSE_VISIBILITY_ROWS), in place of per-pixel decodes;
    shared_light: the light x slice products take their light's visibility (shares_light_visibility of the
    object's box; shaders: SHARED_LIGHT_VISIBILITY) instead of a decode each NDF lobe.
    """
    rows: np.ndarray
    normal: np.ndarray
    basis_texture: np.ndarray
    diffuse: np.ndarray = None
    shared_light: bool = False


def ssdf_decode_packed(rows, basis_texture, local_direction):
    """ssdf.glsl's ssdf_decode in numpy: rows (N, 4L), local directions (N, K, 3) -> (N, K) float32."""
    from ...visibility import decode

    layers, resolution = basis_texture.shape[0], basis_texture.shape[1]
    texcoord, below = decode.texcoord_of(local_direction, resolution)        # (N, K, 2), (N, K)
    images = np.asarray(basis_texture, np.float64).transpose(0, 3, 1, 2).reshape(4 * layers, resolution,
                                                                               resolution)
    samples = texture_fetch.bilinear_channels_first(images, texcoord.reshape(-1, 2)).reshape(
        (4 * layers,) + texcoord.shape[:-1])                                    # (4L, N, K)
    value = np.einsum("cnk,nc->nk", samples, np.asarray(rows, np.float64)[:, :4 * layers])
    return (value - below).astype(FLOAT)


def _ssdf_at(axis, visibility):
    """(local (N, K, 3), theta_d (N, K)): world directions (N, K, 3) in the SSDF's frame of each pixel's normal
    and the SSDF there (lobe_visibility.glsl's `axis * visibility_frame` and ssdf_decode)."""
    from ...visibility import hemisphere_map

    frame = hemisphere_map.local_frame(np.asarray(visibility.normal, np.float64))      # (N, 3, 3)
    local = np.einsum("nij,nkj->nki", frame, np.asarray(axis, np.float64))
    return local, ssdf_decode_packed(visibility.rows, visibility.basis_texture, local)


def _visibility_product(axis, sharpness, n, visibility):
    """(local (N, K, 3), theta_d (N, K), product sharpness (N, K)): eq. 40's product lobe P = G (x) C*(n) of lobes G
    with axis (N, K, 3), sharpness (N, K) on normals n (N, 3), its axis in the SSDF's frame and the SSDF there
    (lobe_visibility.glsl's visibility_product and the decode)."""
    cosine_sharpness, _ = clamped_cosine.clamped_cosine_lobe()
    product_axis, product_sharpness, _ = sg.product(
        np.asarray(axis, FLOAT), np.asarray(sharpness, FLOAT), FLOAT(1),
        np.asarray(n, FLOAT)[:, None, :], FLOAT(cosine_sharpness), FLOAT(1))
    local, theta_d = _ssdf_at(product_axis, visibility)
    return local, theta_d, np.asarray(product_sharpness, FLOAT)


def _product_visible_fraction(theta_d, local, product_sharpness):
    """eq. 30-31's fh(theta_d) / fh(theta_h) of the product lobes, clamped to [0, 1] (lobe_visibility.glsl's
    product_visible_fraction)."""
    from ...spherical import hemisphere

    visible = hemisphere.fh_normalized(theta_d, product_sharpness)
    unshadowed = hemisphere.fh_normalized_from_sine(sg.normalize(local.astype(FLOAT))[..., 2], product_sharpness)
    return np.clip(visible / np.maximum(unshadowed, FLOAT(1e-30)), 0, 1).astype(FLOAT)


def lobe_visibility(axis, sharpness, n, visibility):
    """Visible fraction (N, K) of I(G, n) for lobes G with axis (N, K, 3), sharpness (N, K); n (N, 3)
    (sg_shading.glsl's lobe_visibility)."""
    local, theta_d, product_sharpness = _visibility_product(axis, sharpness, n, visibility)
    return _product_visible_fraction(theta_d, local, product_sharpness)


def lobe_visibility_side(axis, sharpness, n, visibility):
    """(visible (N, K), side (N, K, 3)): lobe_visibility, and for lobes keeping less than VISIBLE_SIDE_MAX_FRACTION
    the side their visible part lies on -- the direction in which the SSDF's leading VISIBLE_SIDE_LAYERS rows grow
    at the product lobe's axis, by forward differences VISIBLE_SIDE_STEP radians across it, as a unit world
    direction perpendicular to the lobe's axis (zero where the lobe is unoccluded or the SSDF flat;
    sg_shading.glsl's lobe_visibility_side)."""
    from ...visibility import hemisphere_map

    axis = np.asarray(axis, FLOAT)
    local, theta_d, product_sharpness = _visibility_product(axis, sharpness, n, visibility)
    local = sg.normalize(local)
    visible = _product_visible_fraction(theta_d, local, product_sharpness)
    layers = min(VISIBLE_SIDE_LAYERS, visibility.basis_texture.shape[0])
    rows, basis = np.asarray(visibility.rows)[:, :4 * layers], visibility.basis_texture[:layers]
    reference = np.where(np.abs(local[..., 2:]) < 0.9, np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]))
    across1 = sg.normalize(np.cross(local, reference))
    across2 = np.cross(local, across1)
    centre = ssdf_decode_packed(rows, basis, local)
    rise = [ssdf_decode_packed(rows, basis, local + VISIBLE_SIDE_STEP * across) - centre for across in (across1, across2)]
    gradient_local = rise[0][..., None] * across1 + rise[1][..., None] * across2
    frame = hemisphere_map.local_frame(np.asarray(visibility.normal, np.float64))      # rows t, b, n
    world = np.einsum("nji,nkj->nki", frame, gradient_local)
    world -= axis * np.sum(axis * world, axis=-1, keepdims=True)
    length = np.linalg.norm(world, axis=-1, keepdims=True)
    side = np.where((length > 1e-12) & (visible[..., None] < VISIBLE_SIDE_MAX_FRACTION),
                    world / np.maximum(length, 1e-30), 0.0)
    return visible, side.astype(FLOAT)


def light_cap_visibility(axis, sharpness, visibility):
    """Visible fraction (N, K) of lights' caps: axis (N, K, 3), sharpness (N, K) of their SGs, whose caps are
    lights.cap_radius wide (lobe_visibility.glsl's light_cap_visibility with sg_shading.glsl's light_cap_radius)."""
    from ...spherical import hemisphere

    local, theta_d = _ssdf_at(axis, visibility)
    radius = lights.cap_radius(sharpness)
    theta_h = np.arcsin(np.clip(sg.normalize(local.astype(FLOAT))[..., 2], -1, 1))
    unshadowed = hemisphere.disc_coverage(theta_h, radius)
    return np.clip(hemisphere.disc_coverage(theta_d, radius) / np.maximum(unshadowed, 1e-30), 0, 1).astype(FLOAT)


def vertex_coverage(vertices):
    """The SSDF's coverage (V, P) at the quadrature points of visibility.broad_lobes at mesh vertices
    (shaders/techniques/sg/vertex_coverage.frag.glsl); vertices: a Visibility of their coefficient rows."""
    from ...visibility import broad_lobes

    rows = np.asarray(vertices.rows, FLOAT)
    points = np.broadcast_to(broad_lobes.quadrature_points().astype(FLOAT), (len(rows), broad_lobes.QUADRATURE_POINTS, 3))
    theta = ssdf_decode_packed(rows, vertices.basis_texture, points)
    return broad_lobes.cell_coverage(theta, broad_lobes.cell_radius()).astype(FLOAT)


def vertex_diffuse_visibility(environment, vertices):
    """Visible fractions (V, E) of the broad diffuse lobes at mesh vertices (shaders/techniques/sg/
    vertex_visibility.frag.glsl): the environment's SG mixture, or the constant world's cosine lobe
    (E = 1), by the quadrature of visibility.broad_lobes over the SSDF's coverage, handing over to eq. 30's
    reading (lobe_visibility) for the sharper lobes.  vertices: a Visibility of the vertices (their
    coefficient rows and world SSDF normals), whose normal also stands in for the shading normal."""
    from ...visibility import broad_lobes, hemisphere_map

    coverage = vertex_coverage(vertices)
    if not environment.has_texture:           # the cosine lobe about the SSDF's normal
        return broad_lobes.quadrature_visible_fraction(
            coverage, np.array([[[0.0, 0.0, 1.0]]]), np.zeros((1, 1))).astype(FLOAT)
    n = sg.normalize(np.asarray(vertices.normal, FLOAT))
    count = len(environment.lobe_sharpness)
    axis = np.broadcast_to(np.asarray(environment.lobe_axis, FLOAT)[None], (len(n), count, 3))
    sharpness = np.broadcast_to(np.asarray(environment.lobe_sharpness, FLOAT)[None], (len(n), count))
    frame = hemisphere_map.local_frame(np.asarray(vertices.normal, np.float64))
    local = np.einsum("nij,nkj->nki", frame, axis.astype(np.float64))
    weight = broad_lobes.quadrature_weight(sharpness)
    quadrature = broad_lobes.quadrature_visible_fraction(coverage, local, sharpness)
    return (weight * quadrature + (1.0 - weight) * lobe_visibility(axis, sharpness, n, vertices)).astype(FLOAT)


def probit(p):
    """Phi^-1(p), the standard normal's quantile, for p in (0, 1): Abramowitz and Stegun 26.2.23's rational form in
    t = sqrt(-2 ln min(p, 1 - p)), absolute error below 4.5e-4 (sg_shading.glsl's probit)."""
    p = np.asarray(p, FLOAT)
    tail = np.minimum(p, FLOAT(1) - p)
    t = np.sqrt(FLOAT(-2) * np.log(np.maximum(tail, FLOAT(1e-30))))
    x = t - (FLOAT(2.515517) + t * (FLOAT(0.802853) + t * FLOAT(0.010328))) / (
        FLOAT(1) + t * (FLOAT(1.432788) + t * (FLOAT(0.189269) + t * FLOAT(0.001308))))
    return np.where(p < FLOAT(0.5), -x, x).astype(FLOAT)


def _truncated_moments(visible):
    """(m, variance across) of the part a straight boundary keeps, the fraction ``visible``, of a unit Gaussian:
    z = Phi^-1(v), m = phi(z) / v the kept part's mean beyond the axis, 1 - z m - m^2 its variance across."""
    v = np.clip(np.asarray(visible, FLOAT), FLOAT(1e-4), FLOAT(1 - 1e-6))
    z = probit(v)
    m = np.exp(FLOAT(-0.5) * z * z) * FLOAT(1 / np.sqrt(2 * np.pi)) / v
    return m.astype(FLOAT), (FLOAT(1) - z * m - m * m).astype(FLOAT)


def visible_part_offset(visible):
    """Angle, in lobe widths 1 / sqrt(lambda), from the axis of a Gaussian lobe cut by a straight boundary
    that keeps the fraction ``visible`` of it to the mean of the kept part: phi(z) / v, z = Phi^-1(v)
    (probit)."""
    return _truncated_moments(visible)[0]


def visible_part_narrowing(visible):
    """Factor on a lobe's sharpness that gives it the width of its visible part (sg_shading.glsl's
    visible_part_narrowing): the part a straight boundary keeps of a Gaussian has variance 1 - z m - m^2 (in
    squared widths; _truncated_moments) across the boundary, at least VISIBLE_PART_MIN_VARIANCE, and 1 along it;
    2 / (1 + that), their mean, since the lookup is isotropic."""
    across = np.clip(_truncated_moments(visible)[1], FLOAT(VISIBLE_PART_MIN_VARIANCE), FLOAT(1))
    return (FLOAT(2) / (FLOAT(1) + across)).astype(FLOAT)


def _turn(axis, side, angle):
    """Unit axes (..., 3) turned by angle (...) towards unit directions ``side`` perpendicular to them."""
    angle = np.asarray(angle, FLOAT)[..., None]
    return (axis * np.cos(angle) + side * np.sin(angle)).astype(FLOAT)


def visible_part_axes(slice_axis, slice_sharpness, slice_visible, side, centre, nodes):
    """Where and how sharp each slice lobe reads the environment when the SSDF occludes part of it
    (sg_shading.glsl's VISIBLE_PART_LOOKUP): (axis (N, J, 3), sharpness (N, J)).  Its NDF lobe's nodes are turned
    together towards the visible side of the centre node (lobe_visibility_side: where the SSDF grows) by
    visible_part_offset of the centre node's visible fraction, in its widths (at most VISIBLE_PART_MAX_TURN), and
    sharpened by visible_part_narrowing.  The visible and the occluded part of a lobe see different light (a lobe
    pointing into a floor: its visible part sees the horizon; one below Suzanne's ear: the sky past the ear),
    which the product of the visible fraction and the radiance at the lobe's axis ignores."""
    axis = slice_axis[:, centre]                                                             # (N, K, 3)
    pivot = np.cross(axis, side)                  # unit: side is perpendicular to the axis (or zero)
    turn = np.minimum(visible_part_offset(slice_visible) / np.sqrt(np.maximum(slice_sharpness[:, centre], FLOAT(1e-6))),
                      FLOAT(VISIBLE_PART_MAX_TURN))
    pivot, turn = np.repeat(pivot, nodes, axis=1), np.repeat(turn, nodes, axis=1)[..., None]
    c, s = np.cos(turn), np.sin(turn)
    rotated = slice_axis * c + np.cross(pivot, slice_axis) * s + pivot * (np.sum(pivot * slice_axis, -1, keepdims=True)
                                                                          * (FLOAT(1) - c))
    sharpness = slice_sharpness * np.repeat(visible_part_narrowing(slice_visible), nodes, axis=1)
    return rotated.astype(FLOAT), sharpness.astype(FLOAT)


def model_albedo(model, params, view_local):
    """The model's directional albedo E(o) per pixel (N,) where the engine tabulates it (GGX:
    reflectance.ggx_albedo's table, one bilinear fetch, as sg_shading.glsl's ENVIRONMENT_TAIL; anisotropic GGX:
    the same table at its equivalent roughness (alpha_x alpha_y)^(1/4), as Cycles reads its own), else None."""
    if model == "GGX":
        roughness = np.asarray(params["roughness"], FLOAT)
    elif model == "GGX_ANISO":         # Cycles' equivalent roughness (sg_shading.glsl)
        roughness = np.sqrt(np.sqrt(np.maximum(np.asarray(params["alpha_x"], FLOAT), FLOAT(1e-6))
                                    * np.maximum(np.asarray(params["alpha_y"], FLOAT), FLOAT(1e-6))))
    else:
        return None
    table = ggx_albedo.albedo_table()[..., None]
    s, t = ggx_albedo.table_coordinates(np.asarray(view_local, FLOAT)[:, 2], roughness)
    return sample_texture(table, np.stack([s, t], axis=-1))[:, 0]


def environment_tail(albedo, slice_axis, slice_sharpness, slice_cosine, warp_mode=None):
    """GGX's energy beyond its slice lobes, as a broad lobe of environment light (sg_shading.glsl's
    ENVIRONMENT_TAIL): (albedo (N,), axis (N, 3), sharpness (N,)).  The albedo is max(0, E(o) - sum_j
    I(S_j, n)), E(o) the model's exact directional albedo (model_albedo), the sum the slice lobes' own
    clamped-cosine integrals (unshadowed); the lobe lies on the broader NDF lobe's centre node with
    TAIL_SHARPNESS_RATIO of its sharpness (GGX's tail is wider than either lobe); with visibility it takes
    its own (_add_environment), read where that node's visible part is."""
    node = visibility_node_indices(slice_sharpness.shape[1], warp_mode)[0]
    missing = np.maximum(albedo - np.sum(slice_cosine, axis=1), FLOAT(0))
    return missing.astype(FLOAT), slice_axis[:, node], (slice_sharpness[:, node] * FLOAT(TAIL_SHARPNESS_RATIO))


def cosine_weighted_lookup(axis, sharpness, n, always=False):
    """Where and how sharp to read the environment for lobes (axis (..., 3), sharpness (...)) on a surface of
    normal n (broadcast to axis): the product of the lobe with the clamped cosine's SG (wang2009 eq. 40,
    sharpness 2.133 about n) for lobes broader than COSINE_LOOKUP_SHARPNESS[0] (or ``always``), handing over
    linearly to the lobe itself at COSINE_LOOKUP_SHARPNESS[1] (sg_shading.glsl's cosine_weighted_lookup).  A
    broad lobe's light is weighted by the cosine, which it crosses from its peak to the horizon: read at its
    own axis it also averages the light below the horizon."""
    axis = np.asarray(axis, FLOAT)
    sharpness = np.asarray(sharpness, FLOAT)
    cosine_sharpness, _ = clamped_cosine.clamped_cosine_lobe()
    product_axis, product_sharpness, _ = sg.product(axis, sharpness, FLOAT(1), np.asarray(n, FLOAT),
                                                    FLOAT(cosine_sharpness), FLOAT(1))
    full, none = COSINE_LOOKUP_SHARPNESS
    weight = FLOAT(1) if always else np.clip((FLOAT(none) - sharpness) / FLOAT(none - full), 0, 1)
    lookup_axis = sg.normalize(axis + (product_axis - axis) * np.asarray(weight, FLOAT)[..., None])
    return lookup_axis.astype(FLOAT), (sharpness + (product_sharpness - sharpness) * weight).astype(FLOAT)


def environment_radiance(environment, axis, sharpness):
    """Gamma_L / integral G of slice lobes (sg_shading.glsl's environment_radiance): the prefiltered
    lookup, and for lobes sharper than its top layer a blend in log2(lambda) towards the map's own radiance
    (bilinear, as the GPU samples the equirect texture), reached where the lobe's width 1 / sqrt(lambda) is
    one map row (lambda = (rows / pi)^2).  The top layer alone blurs such lobes by its own width: a GGX
    roughness 0.1 slice (lambda about 5000) read a layer of lambda 660 at the default layer size."""
    prefiltered = environment.prefiltered
    value = env_prefilter.lookup(prefiltered, axis, sharpness)
    if environment.radiance is None:
        return value
    log2_top = FLOAT(prefiltered.log2_min_sharpness + (len(prefiltered.sharpness) - 1) / prefiltered.levels_per_octave)
    rows = FLOAT(environment.radiance.shape[0])
    log2_raw = np.maximum(FLOAT(2) * np.log2(rows / FLOAT(np.pi)), log2_top + FLOAT(1))
    beyond = np.clip((np.log2(np.maximum(np.asarray(sharpness, FLOAT), FLOAT(1e-30))) - log2_top)
                     / (log2_raw - log2_top), 0, 1)[..., None]
    u, v = equirect.direction_to_uv(sg.normalize(np.asarray(axis, FLOAT)))
    uv = np.stack([u, v], axis=-1).astype(FLOAT)
    image = np.asarray(environment.radiance, FLOAT)[::-1, :, :3]          # the texture's rows: t = 0 at the bottom
    raw = sample_texture(image, uv.reshape(-1, 2)).reshape(uv.shape[:-1] + (3,))
    return (value + (raw - value) * beyond).astype(FLOAT)


def point_light_sgs(position, light_data):
    """(axis (N, P, 3), sharpness (N, P), amplitude (N, P, 3)) of every point/spot light at every pixel
    (lights.sphere_light_sg / spot_light_sg with unit intensity, times the colour intensity)."""
    position = np.asarray(position, FLOAT)[:, None, :]
    axis, sharpness, amplitude = lights.sphere_light_sg(
        position, light_data.point_position[None], light_data.point_radius[None], FLOAT(1),
        soft_falloff=light_data.soft_falloff[None])
    amplitude = (amplitude * point_light_emission(axis, light_data))[..., None] * light_data.point_intensity[None]
    return axis.astype(FLOAT), sharpness.astype(FLOAT), amplitude.astype(FLOAT)


def point_light_emission(axis, light_data):
    """(N, P) emission factor of every point-like light toward the points that see it along axis (N, P, 3):
    spots' cones, area lights' patches (lights.emission_factor; the shaders' scene_light_emission)."""
    cos_angle = np.sum(-axis * sg.normalize(light_data.spot_direction)[None], axis=-1).astype(FLOAT)
    emitter = light_data.point_emitter
    return lights.emission_factor(cos_angle, light_data.spot_size[None], light_data.spot_blend[None],
                                  emitter[None, :, 0] > 0.5, emitter[None, :, 1], emitter[None, :, 2])


def world_bounds(positions, matrix_world):
    """(2, 3) min and max corner of the world-space box around the local box of ``positions`` (N, 3)."""
    positions = np.asarray(positions, np.float64).reshape(-1, 3)
    low, high = positions.min(axis=0), positions.max(axis=0)
    corners = np.array([[high[i] if bit & (1 << i) else low[i] for i in range(3)] for bit in range(8)])
    matrix = np.asarray(matrix_world, np.float64)
    world = corners @ matrix[:3, :3].T + matrix[:3, 3]
    return np.stack([world.min(axis=0), world.max(axis=0)])


def shares_light_visibility(light_data, bounds):
    """Whether every light is narrower than SHARED_LIGHT_VISIBILITY_MAX_RADIUS from every point of the box
    ``bounds`` (world_bounds).  Then a light x slice product worth shading lies within the light's own
    lobe, and takes the light's visibility (one SSDF decode a light) in place of a decode of its own; for
    a point light (radius 0) that is the visibility along the light, as the exact integral has it."""
    limit = np.sin(SHARED_LIGHT_VISIBILITY_MAX_RADIUS) ** 2
    position = np.asarray(light_data.point_position, np.float64).reshape(-1, 3)
    nearest = np.clip(position, bounds[0], bounds[1])             # the box's point nearest each light
    distance2 = np.sum((position - nearest) ** 2, axis=-1)
    radius2 = np.asarray(light_data.point_radius, np.float64) ** 2
    # lights.sphere_light_sg's cap, and the suns' cap sharpness ln(10) / sin^2
    sin2 = radius2 / lights.light_cap_extent(distance2, radius2, light_data.soft_falloff)
    suns_narrow = np.asarray(light_data.sun_sharpness, np.float64) >= np.log(10.0) / limit
    return bool(np.all(sin2 <= limit) and np.all(suns_narrow))


def view_directions(position, view_origin, is_perspective):
    """Unit directions (N, 3) float32 from pixels at position (N, 3) to the camera: towards its position
    (perspective), or against its forward axis (orthographic), as the shaders take them."""
    if is_perspective:
        return sg.normalize(np.asarray(view_origin, FLOAT)[None] - position)
    return np.broadcast_to(-sg.normalize(np.asarray(view_origin, FLOAT)), np.shape(position))


def shading_frame(normal, tangent):
    """Unit normal, tangent (Gram-Schmidt; fallback if parallel), bitangent = n x t."""
    n = sg.normalize(np.asarray(normal, FLOAT))
    t = sg.normalize(np.asarray(tangent, FLOAT)[..., :3], fallback=(0.0, 0.0, 0.0))
    t = t - n * np.sum(n * t, axis=-1, keepdims=True)
    # within 0.06 degrees of the normal (or zero) what is left is rounding: take the fallback
    fallback = np.cross(n, np.where(np.abs(n[..., :1]) < 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])).astype(FLOAT)
    degenerate = np.sum(t * t, axis=-1, keepdims=True) < FLOAT(SHADING_FRAME_MIN_SINE) ** 2
    t = sg.normalize(np.where(degenerate, fallback, t))
    t = sg.normalize(t - n * np.sum(n * t, axis=-1, keepdims=True))    # a second pass takes out the rounding
    return n, t, np.cross(n, t).astype(FLOAT)


def apply_normal_map(normal, tangent, sample, strength):
    """Mapped normal: tangent-space (OpenGL +Y) sample in [0, 1], mixed with the mesh normal by strength."""
    n = sg.normalize(np.asarray(normal, FLOAT))
    t = np.asarray(tangent, FLOAT)
    b = t[..., 3:4] * np.cross(n, t[..., :3])
    m = 2 * np.asarray(sample, FLOAT)[..., :3] - 1
    mapped = sg.normalize(t[..., :3] * m[..., 0:1] + b * m[..., 1:2] + n * m[..., 2:3])
    return sg.normalize(n + (mapped - n) * np.asarray(strength, FLOAT))


def rotate_tangent(normal, tangent, rotation):
    """Tangent rotated about the normal by ``rotation`` radians (after projection)."""
    n, t, b = shading_frame(normal, tangent)
    c, s = np.cos(np.float32(rotation)), np.sin(np.float32(rotation))
    return (c * t + s * b).astype(FLOAT)


def ndf_lobes(model, params, lobe_count=1):
    """The model's SG NDF lobes in the local frame: axis (N, K, 3), sharpness (N, K), amplitude (N, K)."""
    instance = brdf.model_from_name(model, **params)
    if model in models.ANISOTROPIC:
        return instance.ndf_lobes(lobe_count)
    if model == "GGX":
        return instance.ndf_lobes(GGX_NDF_LOBES)
    return instance.ndf_lobes()


def fitted_slice(params, view_local, warp_mode=None):
    """Slice lobes of the stored fit: its NDF lobes (amplitude 1) warped to the view, times its M_o(i); the RGB
    lobe amplitudes come separately."""
    axis = params["axis"]
    sharpness, amplitude = spread_lobes(params["sharpness"], np.ones_like(params["sharpness"]),
                                        params.get("normal_spread"))
    return warp.brdf_slice_lobes(axis, sharpness, amplitude, view_local,
                                 lambda wo, wi: fitted_m_factor(params, wo, wi), mode=warp_mode or warp.DEFAULT_MODE)


def slice_colours(model, params, slice_count):
    """(N, J, 3) RGB factor of each slice lobe: the fit's lobe amplitudes (WARP nodes of lobe k at
    nodes k .. nodes k + nodes - 1), else 1."""
    if model != FITTED_MODEL:
        return None
    colour = np.asarray(params["colour"], FLOAT)
    return np.repeat(colour, slice_count // colour.shape[1], axis=1)


def specular_slice(model, params, lobe_count, view_local, warp_mode=None):
    """BRDF slice lobes (local frame) for the view: NDF lobes warped by ``warp_mode`` (spherical.warp's; None:
    its default) times M_o at their centres."""
    if model == FITTED_MODEL:
        return fitted_slice(params, view_local, warp_mode)
    axis, sharpness, amplitude = ndf_lobes(model, params, lobe_count)
    sharpness, amplitude = spread_lobes(sharpness, amplitude, params.get("normal_spread"))
    # brdf_slice_lobes calls m_factor with the lobe index leading, so per-pixel parameters broadcast
    instance = brdf.model_from_name(model, **{k: np.asarray(v, FLOAT) for k, v in params.items()})
    return warp.brdf_slice_lobes(axis, sharpness, amplitude, view_local, instance.m_factor,
                                 mode=warp_mode or warp.DEFAULT_MODE)


def visibility_node_indices(slice_count, mode=None):
    """Indices of the slice lobes whose visibility the NDF lobe's warped nodes share: the centre node
    of each group ((nodes - 1) // 2: split3's middle one, node 0 of the paper's one-node warp, and split2's
    node 0, the one towards the viewer, which stays a valid half vector at grazing views)."""
    nodes = warp.nodes_per_lobe(mode or warp.DEFAULT_MODE)
    return np.arange(slice_count // nodes) * nodes + (nodes - 1) // 2


def light_tail(model, params, view_local, frame, light_axis, light_sharpness, light_cosine,
               slice_axis, slice_sharpness, slice_amplitude, spread_peak=None):
    """What the slice lobes miss of the model's own BRDF at each light's centre, (N, P): the long tail of
    GGX (an SG falls off as exp(-lambda theta^2 / 2), GGX as theta^-4) and the lobes' error at the
    peak.  The residual rho_s(o, i_c) - sum_j S_j(i_c) times the light's clamped-cosine integral (what
    the light delivers at its centre, horizon included) is exact for a point light and stands for the
    light's average of the residual where the residual is smooth across the light; so it is weighted by
    how narrow the light is against the BRDF's local scale at its centre,

        w = lambda_L s^2 / (1 + lambda_L s^2),   s^2 = min_j (1 / lambda_j + 2 (1 - p_j . i_c)),

    s^2 the squared angular scale of the nearest slice lobe around its axis (its own width, or the
    distance to it: the tail varies on the scale of its distance from the peak), 1 / lambda_L the
    light's: a point light keeps all of it (w -> 1); a broad light on the peak of a sharp lobe, where the
    SG products integrate the lobes exactly and the peak residual would be multiplied by the light's whole
    solid angle, none of it.  Light (N, P, 3) / (N, P), slices world (N, J, 3) / (N, J).  spread_peak (N,):
    what a normal map's spread leaves of the model's peak (normal_spread_peak): the slice lobes are then the
    spread BRDF's and the model's own is not, so the tail fades by it."""
    light_axis = np.asarray(light_axis, FLOAT)
    cosine = np.einsum("npc,njc->npj", light_axis, slice_axis)                             # (N, P, J)
    slice_value = np.sum(slice_amplitude[:, None] * np.exp(slice_sharpness[:, None] * (cosine - FLOAT(1))), axis=-1)
    scale2 = np.min(FLOAT(1) / np.maximum(slice_sharpness[:, None], FLOAT(1e-6)) + FLOAT(2) * (FLOAT(1) - cosine),
                    axis=-1)
    light_local = np.einsum("nji,npj->npi", frame, light_axis).astype(FLOAT)
    instance = brdf.model_from_name(model, **{k: np.asarray(v, FLOAT)[:, None] for k, v in params.items()})
    exact = instance.specular(np.broadcast_to(view_local[:, None, :], light_local.shape), light_local)
    narrow = scale2 * light_sharpness / (FLOAT(1) + scale2 * light_sharpness)
    if spread_peak is not None:
        narrow = narrow * spread_peak[:, None]
    return (narrow * light_cosine * (exact - slice_value)).astype(FLOAT)


@dataclass
class _Pixels:
    """What every term of shade() reads: the pixels' frame and view, and their BRDF slice lobes (warped,
    capped at the model's albedo), with the visibility of lobes when there is a bake."""
    position: np.ndarray
    n: np.ndarray
    frame: np.ndarray           # local -> world: columns t, b, n
    view: np.ndarray
    view_local: np.ndarray
    model: str
    params: dict
    visibility: object
    warp_mode: object
    slice_axis: np.ndarray
    slice_sharpness: np.ndarray
    slice_amplitude: np.ndarray
    slice_colour: np.ndarray
    slice_cosine: np.ndarray    # I(S_j, n), unshadowed
    albedo: object              # the model's directional albedo where it is tabulated, else None
    lobes: object = None        # the lobe source (ModelLobes, or a technique's own)
    spread_peak: object = None  # (N,) normal_spread_peak where a normal map spreads the lobes and a light tail reads it

    def diffuse_factor(self, world_axis):
        """The lobe source's diffuse factor at world directions (N, P, 3) (1: none)."""
        if not self.lobes.scales_diffuse:
            return FLOAT(1)
        local = np.einsum("nji,npj->npi", self.frame, np.asarray(world_axis, FLOAT))
        return self.lobes.diffuse_factor(local, self.view_local)

    def visible(self, axis, sharpness):
        if self.visibility is None:
            return FLOAT(1)
        shape = np.shape(sharpness)
        flat_axis = np.asarray(axis, FLOAT).reshape(shape[0], -1, 3)
        flat_sharpness = np.broadcast_to(np.asarray(sharpness, FLOAT), shape).reshape(shape[0], -1)
        return lobe_visibility(flat_axis, flat_sharpness, self.n, self.visibility).reshape(shape)

    def light_visible(self, axis, sharpness):
        """Lights' visible fractions (N, P) (LIGHT_VISIBILITY), 1 without visibility."""
        if self.visibility is None:
            return FLOAT(1)
        return light_cap_visibility(axis, sharpness, self.visibility)

    @property
    def nodes(self):
        return warp.nodes_per_lobe(self.warp_mode)

    @property
    def centre(self):
        return visibility_node_indices(self.slice_sharpness.shape[1], self.warp_mode)

    def per_node(self, group_values):   # (..., K) -> (..., K * nodes): each NDF lobe's to its warped nodes
        return np.repeat(group_values, self.nodes, axis=-1)


class ModelLobes:
    """The lobe source of the parametric and fitted SG techniques (lobes_model.glsl, lobes_fitted.glsl): the
    model's own NDF lobes, or a stored fit's, warped to the view.  A technique with lobes of its own gives shade()
    an object with the same methods (biscale_shading.BiScaleLobes)."""
    scales_diffuse = False      # diffuse_factor() is 1 everywhere
    glossy_layer = True         # the material's glossy layer (Fresnel, layered diffuse) applies

    def slice(self, model, params, lobe_count, view_local, warp_mode):
        """(axis (N, J, 3) local, sharpness (N, J), amplitude (N, J)) of the view's BRDF slice."""
        return specular_slice(model, params, lobe_count, view_local, warp_mode)

    def colours(self, model, params, slice_count, warp_mode):
        """(N, J, 3) RGB amplitudes of the slice lobes, or None (1)."""
        return slice_colours(model, params, slice_count)

    def albedo(self, model, params, view_local):
        """The model's directional albedo the slice is kept within and its tail returns (None: no tail)."""
        return model_albedo(model, params, view_local)

    def light_tail(self, model):
        return model != FITTED_MODEL

    def diffuse_factor(self, local, view_local):
        return FLOAT(1)

    def world_albedo(self, view_local):
        """What scales a constant world's irradiance: 1."""
        return FLOAT(1)


MODEL_LOBES = ModelLobes()


def _pixels(position, normal, tangent, view_origin, is_perspective, model, params, lobe_count, visibility,
            warp_mode, lobes=MODEL_LOBES):
    position = np.asarray(position, FLOAT)
    n, t, b = shading_frame(normal, tangent)
    view = view_directions(position, view_origin, is_perspective)
    frame = np.stack([t, b, n], axis=-1)                          # local -> world: columns t, b, n
    view_local = np.einsum("nji,nj->ni", frame, view).astype(FLOAT)

    slice_axis, slice_sharpness, slice_amplitude = lobes.slice(model, params, lobe_count, view_local, warp_mode)
    slice_axis = np.einsum("nij,nkj->nki", frame, slice_axis).astype(FLOAT)    # to world
    slice_sharpness = slice_sharpness.astype(FLOAT)
    slice_amplitude = slice_amplitude.astype(FLOAT)
    slice_colour = lobes.colours(model, params, slice_sharpness.shape[1], warp_mode)
    if slice_colour is None:
        slice_colour = np.ones(slice_sharpness.shape + (3,), FLOAT)

    # I(S_j, n) unshadowed: the lobes' albedo, capped at the model's own where it is known (GGX: the lobes
    # overshoot it several times over at grazing views), and the environment's weights below
    slice_cosine = _clamped_cosine_integral(slice_axis, slice_sharpness, slice_amplitude, n[:, None, :])  # (N, J)
    albedo = lobes.albedo(model, params, view_local)
    if albedo is not None:
        scale = np.minimum(FLOAT(1), albedo / np.maximum(np.sum(slice_cosine, axis=1), FLOAT(1e-30)))[:, None]
        slice_amplitude = (slice_amplitude * scale).astype(FLOAT)
        slice_cosine = (slice_cosine * scale).astype(FLOAT)
    spread_peak = None
    if "normal_spread" in params and lobes.light_tail(model):
        spread_peak = normal_spread_peak(ndf_lobes(model, params, lobe_count)[1], params["normal_spread"])
    return _Pixels(position, n, frame, view, view_local, model, params, visibility, warp_mode, slice_axis,
                   slice_sharpness, slice_amplitude, slice_colour, slice_cosine, albedo, lobes, spread_peak)


def _light_sets(position, light_data):
    """(axis (N, P, 3), sharpness (N, P), amplitude (N, P, 3)) of the point/spot lights, then of the suns."""
    light_sets = []
    if len(light_data.point_radius):
        light_sets.append(point_light_sgs(position, light_data))
    if len(light_data.sun_sharpness):
        count = len(light_data.sun_sharpness)
        light_sets.append((np.broadcast_to(light_data.sun_axis[None], (len(position), count, 3)),
                           np.broadcast_to(light_data.sun_sharpness[None], (len(position), count)),
                           np.broadcast_to(light_data.sun_amplitude[None], (len(position), count, 3))))
    return light_sets


def _add_lights(px, light_axis, light_sharpness, light_amplitude, irradiance, specular, shadow=None):
    """Lights' diffuse (eq. 42) and specular (eq. 43) terms, added to irradiance and specular in place.
    shadow: (N, P, 2) the lights' shadow-map (visible fraction, softness), NaN without a map, or None."""
    n = px.n
    visibility = px.visibility
    light_cosine = _clamped_cosine_integral(light_axis, light_sharpness, FLOAT(1), n[:, None, :])    # (N, P)
    light_visible = np.broadcast_to(px.light_visible(light_axis, light_sharpness), light_sharpness.shape)
    mapped = np.zeros(light_sharpness.shape, bool)
    if shadow is not None:      # a mapped light: its map's, blended to the SSDF's by the softness (the shader's)
        mapped = ~np.isnan(shadow[..., 0])
        fraction, softness = np.nan_to_num(shadow[..., 0], nan=1.0), np.nan_to_num(shadow[..., 1], nan=0.0)
        blended = fraction + (light_visible - fraction) * softness if visibility is not None else fraction
        light_visible = np.where(mapped, blended, light_visible).astype(FLOAT)
    irradiance += np.sum(light_amplitude * (light_cosine * light_visible * px.diffuse_factor(light_axis))[..., None],
                         axis=1)
    # (N, P, 1) x (N, 1, J): every light against every slice lobe
    axis_m, sharpness_m, amplitude_m = sg.product(
        light_axis[:, :, None, :], light_sharpness[:, :, None], FLOAT(1),
        px.slice_axis[:, None, :, :], px.slice_sharpness[:, None, :], px.slice_amplitude[:, None, :])
    weight = _clamped_cosine_integral(axis_m, sharpness_m, amplitude_m, n[:, None, None, :])
    if visibility is not None and visibility.shared_light:
        weight = weight * light_visible[..., None]
    else:
        if visibility is not None:    # one decode per NDF lobe, if any of its products is not negligible
            centre = px.centre
            above = weight > FLOAT(VISIBILITY_SKIP_FRACTION) * light_cosine[..., None]
            decoded = px.per_node(above.reshape(above.shape[:2] + (-1, px.nodes)).any(axis=-1)) & ~mapped[..., None]
            weight = np.where(decoded, weight * px.per_node(px.visible(axis_m[:, :, centre],
                                                                       sharpness_m[:, :, centre])), weight)
        weight = np.where(mapped[..., None], weight * light_visible[..., None], weight)
    weight = np.sum(weight[..., None] * px.slice_colour[:, None], axis=2)                          # (N, P, 3)
    if px.lobes.light_tail(px.model):
        tail = light_tail(px.model, px.params, px.view_local, px.frame, light_axis, light_sharpness, light_cosine,
                          px.slice_axis, px.slice_sharpness, px.slice_amplitude, px.spread_peak)
        weight = np.maximum(weight + (tail * light_visible)[..., None], FLOAT(0))
    specular += np.sum(light_amplitude * weight, axis=1)


def _add_environment(px, environment, irradiance, specular):
    """The environment's (or the world colour's) diffuse (eq. 39) and specular (eq. 41) terms, with GGX's
    tail, added to irradiance and specular in place."""
    n, visibility = px.n, px.visibility
    n_lobe = n[:, None, :]
    slice_cosine, slice_colour = px.slice_cosine, px.slice_colour
    tail = None if px.albedo is None else environment_tail(px.albedo, px.slice_axis, px.slice_sharpness,
                                                           slice_cosine, px.warp_mode)
    lookup_axis, lookup_sharpness = px.slice_axis, px.slice_sharpness
    if visibility is not None:
        centre = px.centre
        # the first NDF lobe's visible side (GGX's broader), shared with the others (they see the same occluders)
        # and the tail
        broad_visible, broad_side = lobe_visibility_side(px.slice_axis[:, centre[:1]], px.slice_sharpness[:, centre[:1]],
                                                         n, visibility)                         # (N, 1), (N, 1, 3)
        slice_visible = np.concatenate([broad_visible, px.visible(px.slice_axis[:, centre[1:]],
                                                                  px.slice_sharpness[:, centre[1:]])], axis=1)
        side = px.slice_axis[:, centre]
        side = sg.normalize(broad_side - side * np.sum(broad_side * side, axis=-1, keepdims=True),
                            fallback=(0.0, 0.0, 0.0)).astype(FLOAT)
        slice_cosine = slice_cosine * px.per_node(slice_visible)
        if environment.has_texture:
            lookup_axis, lookup_sharpness = visible_part_axes(px.slice_axis, px.slice_sharpness, slice_visible, side,
                                                              centre, px.nodes)
        if tail is not None:     # the tail's own visibility: broader than the slice lobe, it sees past more
            tail_visible = px.visible(tail[1][:, None], tail[2][:, None])[:, 0]
            tail_axis = tail[1]
            if environment.has_texture:    # its own visible part: turned by its offset to the node's visible side
                tail_axis = _turn(tail_axis, side[:, 0], np.minimum(
                    visible_part_offset(tail_visible) / np.sqrt(np.maximum(tail[2], FLOAT(1e-6))),
                    FLOAT(VISIBLE_PART_MAX_TURN)))
            tail = (tail[0] * tail_visible, tail_axis, tail[2])
    if environment.has_texture:
        if len(environment.lobe_sharpness):
            lobe_count_env = len(environment.lobe_sharpness)
            env_axis = np.broadcast_to(environment.lobe_axis[None], (len(n), lobe_count_env, 3))
            env_sharpness = np.broadcast_to(environment.lobe_sharpness[None], (len(n), lobe_count_env))
            env_visible = px.visible(env_axis, env_sharpness) if visibility is None or visibility.diffuse is None \
                else np.asarray(visibility.diffuse, FLOAT)[:, :lobe_count_env]
            # the closed form, as the shader evaluates it from the lobes' sharpness terms (scene block)
            irradiance += np.sum(environment.lobe_amplitude[None] * (clamped_cosine.sg_clamped_cosine_integral(
                environment.lobe_axis[None], environment.lobe_sharpness[None], FLOAT(1), n_lobe) *
                env_visible * px.diffuse_factor(sg.normalize(env_axis)))[..., None], axis=1)
        radiance = environment_radiance(environment, *cosine_weighted_lookup(lookup_axis, lookup_sharpness,
                                                                             n_lobe))            # (N, J, 3)
        specular += np.sum(radiance * (slice_cosine[..., None] * slice_colour), axis=1)
        if tail is not None:
            tail_axis, tail_sharpness = cosine_weighted_lookup(tail[1], tail[2], n, always=True)
            specular += tail[0][:, None] * environment_radiance(environment, tail_axis, tail_sharpness)
        return
    colour = np.asarray(environment.colour, FLOAT)
    # a lobe source that scales the diffuse (a bi-scale tile) has the constant world seen through its mean factor
    lit = colour if not px.lobes.scales_diffuse else colour * px.lobes.world_albedo(px.view_local)[:, None]
    if visibility is None:
        irradiance += np.pi * lit
    elif visibility.diffuse is not None:
        irradiance += np.pi * lit * np.asarray(visibility.diffuse, FLOAT)[:, :1]
    else:       # the cosine lobe alone: a zero-sharpness G at the normal
        irradiance += np.pi * lit * px.visible(n_lobe, np.zeros((len(n), 1), FLOAT))
    specular += np.sum(slice_cosine[..., None] * slice_colour, axis=1) * colour
    if tail is not None:
        specular += tail[0][:, None] * colour


def shade(position, normal, tangent, view_origin, is_perspective, model, params, diffuse_color, specular_color,
          light_data, environment, lobe_count=1, visibility=None, warp_mode=None, lobes=MODEL_LOBES, light_shadow=None):
    """Diffuse and specular radiance (N, 3) each, float32, for pixels with world ``position`` (N, 3),
    ``normal`` (N, 3) (final: normal map applied), ``tangent`` (N, 3) (final direction, rotation
    applied), per-pixel model ``params`` (dict of (N,) arrays) and colours (N, 3).

    view_origin: camera position (perspective) or the camera's forward direction (orthographic).
    visibility: a Visibility (the SSDF shadows of the HAS_VISIBILITY variant) or None (unshadowed).
    warp_mode: spherical.warp's mode of the view slice (the material's view warp; None: the default).
    lobes: the lobe source (MODEL_LOBES: the model's or the fit's; a bi-scale material's BiScaleLobes, whose
    model is its small-scale model).
    light_shadow: (N, lights, 2) the lights' shadow maps at the pixels (lighting.shadow_maps.light_visibility:
    point lights then suns, NaN without a map), or None (no maps).
    """
    px = _pixels(position, normal, tangent, view_origin, is_perspective, model, params, lobe_count, visibility,
                 warp_mode, lobes)
    irradiance = np.zeros(px.position.shape, FLOAT)
    specular = np.zeros(px.position.shape, FLOAT)
    first = 0
    for light_axis, light_sharpness, light_amplitude in _light_sets(px.position, light_data):
        count = light_sharpness.shape[1]
        shadow = None if light_shadow is None else np.asarray(light_shadow, FLOAT)[:, first:first + count]
        _add_lights(px, light_axis, light_sharpness, light_amplitude, irradiance, specular, shadow)
        first += count
    _add_environment(px, environment, irradiance, specular)
    diffuse = np.asarray(diffuse_color, FLOAT) * FLOAT(1 / np.pi) * irradiance
    return diffuse.astype(FLOAT), (np.asarray(specular_color, FLOAT) * specular).astype(FLOAT)


def sample_texture(image, uv):
    """A table or map (H, W, C) read as the GPU's sampler reads it (bilinear, clamped to the edge), float32."""
    return texture_fetch.bilinear(image, np.asarray(uv, FLOAT)).astype(FLOAT)


def sample_material_texture(image, uv):
    """A material texture (H, W, C) at the surface's texture coordinates, as common/material_textures.glsl's
    material_texture reads it (repeating as Blender's Image Texture does): float32 (N, C).  uv (N, 2), or (N, 3)
    with the G-buffer's footprint (its uv.w - 1) third: trilinear in the image's mip levels at it
    (spherical.texture_mips.sample); without it, bilinear in the image.  A node tree's computed slot
    (texture_expression.BoundExpression) samples each of its images so (texture_value_<slot>)."""
    uv = np.asarray(uv, FLOAT)
    footprint = uv[:, 2] if uv.shape[-1] > 2 else None
    if hasattr(image, "sample"):
        return image.sample(uv[:, :2], footprint).astype(FLOAT)
    return texture_mips.sample(image, uv[:, :2], footprint).astype(FLOAT)


def material_uv(material, uv):
    """The surface's texture coordinates (N, 2) float32: the UV map through the material's affine
    uv_transform (u' = a u + b v + c, v' = d u + e v + f), as mesh.vert.glsl computes texcoord."""
    a, b, c, d, e, f = (FLOAT(value) for value in getattr(material, "uv_transform", IDENTITY_UV_TRANSFORM))
    uv = np.asarray(uv, FLOAT)
    return np.stack([a * uv[:, 0] + b * uv[:, 1] + c, d * uv[:, 0] + e * uv[:, 1] + f], axis=-1)


IDENTITY_UV_TRANSFORM = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)


SCALAR_SLOTS = {"roughness": "roughness", "ior": "ior", "exponent": "exponent", "alpha_x": "alpha_x",
                "alpha_y": "alpha_y", "nu": "nu", "nv": "nv"}


def surface_colours(material, textures, uv, count):
    """(diffuse, specular) colours (N, 3) float32 of fragments, as common/surface_io.glsl gives them: the
    material's, times their textures."""
    diffuse_color = np.broadcast_to(np.asarray(material.diffuse_color, FLOAT), (count, 3))
    specular_color = np.broadcast_to(np.asarray(material.specular_color, FLOAT), (count, 3))
    if "diffuse_color" in textures:
        diffuse_color = diffuse_color * sample_material_texture(textures["diffuse_color"], uv)[:, :3]
    if "specular_color" in textures:
        specular_color = specular_color * sample_material_texture(textures["specular_color"], uv)[:, :3]
    return diffuse_color, specular_color


def surface_geometry(material, textures, normal, tangent, uv):
    """(shading normal, shading tangent) (N, 3) float32, as common/surface_io.glsl's surface_geometry: the
    normal map, then the tangent turned about the shading normal."""
    shading_normal = np.asarray(normal, FLOAT)
    tangent = np.asarray(tangent, FLOAT)
    if "normal_map" in textures:
        mapped, _ = normal_map_sample(textures["normal_map"], uv)
        shading_normal = apply_normal_map(shading_normal, tangent, mapped, FLOAT(material.normal_strength))
    return shading_normal, rotate_tangent(shading_normal, tangent[:, :3], material.tangent_rotation)


def normal_map_sample(image, uv):
    """(RGB (N, 3), mip level (N,)) of a normal map at uv (N, 2), or (N, 3) with the footprint (level 0
    without): its normals made unit before the levels are made, as the renderer uploads it."""
    uv = np.asarray(uv, FLOAT)
    image = texture_mips.unit_normals(image)
    if uv.shape[-1] > 2:
        level = texture_mips.level_of(uv[:, 2], image.shape[1], image.shape[0],
                                      texture_mips.level_count(image.shape[1], image.shape[0]))
    else:
        level = np.zeros(len(uv), FLOAT)
    return sample_material_texture(image, uv)[:, :3], level


def normal_spread(mean, level, strength):
    """common/surface_common.glsl's normal_spread: 1 / kappa of the normals averaged into ``mean`` (N, 3)."""
    r = np.minimum(np.linalg.norm(np.asarray(mean, FLOAT), axis=-1), FLOAT(1.0))
    return (np.minimum(level, FLOAT(1.0)) * FLOAT(strength) ** 2 * (1 - r * r)
            / np.maximum(3 * r - r * r * r, FLOAT(1e-6))).astype(FLOAT)


def normal_map_spread(material, textures, uv):
    """The normal map's spread (N,) at uv (0 without one), as surface_io.glsl's normal_map_spread."""
    if "normal_map" not in textures:
        return None
    mapped, level = normal_map_sample(textures["normal_map"], uv)
    return normal_spread(2 * mapped - 1, level, material.normal_strength)


def normal_spread_peak(ndf_sharpness, spread):
    """(N,) what the normals' spread leaves of the model's peak: its sharpest NDF lobe's narrowing,
    1 / (1 + max_k lambda_k spread) (sg_shading.glsl's normal_spread_peak, by which the light tail fades)."""
    sharpest = np.max(np.asarray(ndf_sharpness, FLOAT).reshape(len(spread), -1), axis=1)
    return (FLOAT(1) / (FLOAT(1) + sharpest * np.asarray(spread, FLOAT))).astype(FLOAT)


def spread_lobes(sharpness, amplitude, spread):
    """surface_common.glsl's spread_lobe of NDF lobes (N, K) by the normals' spread (N,)."""
    if spread is None:
        return sharpness, amplitude
    narrowing = FLOAT(1) / (FLOAT(1) + np.asarray(sharpness, FLOAT) * np.asarray(spread, FLOAT)[:, None])
    return sharpness * narrowing, amplitude * narrowing


def surface_layers(material, roughness_texture, uv, diffuse_color, specular_color, shading_normal, position,
                   view_origin, is_perspective):
    """(diffuse, specular) colours (N, 3) after the material's layering, as common/surface_layering.glsl's
    surface_layering() gives them (unchanged without layering: techniques.surface_layering.flags);
    roughness_texture: the image scaling the layer's roughness where the variant applies it, or None."""
    layering_flags = surface_layering.flags(material)
    if not layering_flags:
        return diffuse_color, specular_color
    roughness = np.full(len(position), surface_layering.layer_roughness(material), FLOAT)
    if roughness_texture is not None:
        roughness = roughness * sample_material_texture(roughness_texture, uv)[:, 0]
    view = view_directions(np.asarray(position, FLOAT), view_origin, is_perspective)
    cos_o = np.sum(np.asarray(shading_normal, FLOAT) * view, axis=-1)
    specular, diffuse_factor = layering.factors(
        np.asarray(specular_color, FLOAT), FLOAT(getattr(material, "layered_f0", layering.NO_LAYER)), cos_o,
        roughness, "fresnel" in layering_flags, "multiscatter" in layering_flags)
    return diffuse_color * diffuse_factor[:, None], specular


def shade_fragments(material, textures, position, normal, tangent, uv, view_origin,
                    is_perspective, light_data, environment, visibility=None, light_shadow=None, lobes=MODEL_LOBES):
    """Mirror of surface.frag.glsl's main(): per-fragment inputs as the G-buffer holds them.

    material: an object with export.MaterialParams' fields; textures: slot name -> (H, W, 4)
    float32 image (Blender's row order) for the slots the material uses; normal: interpolated
    world normal (already flipped for back faces); tangent (N, 4): the tangent input (the UV
    map's world tangent and sign, or the object axis in world space); uv (N, 2).
    visibility: per-fragment Visibility (HAS_VISIBILITY variant) or None; light_shadow: the lights' shadow maps at
    the fragments (shade's), or None; lobes: the lobe source (shade's).
    Returns (diffuse, specular), each (N, 3) float32.
    """
    count = len(position)
    fitted = getattr(material, "fitted", None)
    if fitted is not None:         # the stored lobe fit (MODEL_FITTED): only a normal map (and a bi-scale mask) apply
        model_params, diffuse_color = fitted_texel_values(fitted, uv)
        shading_normal, shading_tangent = surface_geometry(material, textures, normal, tangent, uv)
        if "normal_map" in textures:
            model_params["normal_spread"] = normal_map_spread(material, textures, uv)
        return shade(position, shading_normal, shading_tangent, view_origin, is_perspective, FITTED_MODEL,
                     model_params, diffuse_color, np.ones((count, 3), FLOAT), light_data, environment,
                     visibility=visibility, warp_mode=getattr(material, "warp_mode", None), lobes=lobes,
                     light_shadow=light_shadow)
    diffuse_color, specular_color = surface_colours(material, textures, uv, count)
    params = {}
    for name in SCALAR_SLOTS:
        value = np.full(count, getattr(material, name), FLOAT)
        if name in textures:
            value = value * sample_material_texture(textures[name], uv)[:, 0]
        params[name] = value
    shading_normal, shading_tangent = surface_geometry(material, textures, normal, tangent, uv)
    if lobes.glossy_layer:      # a bi-scale material's variant has none (sg_biscale)
        roughness_texture = textures["roughness"] if surface_layering.textured_roughness(material.model, textures) \
            else None
        diffuse_color, specular_color = surface_layers(material, roughness_texture, uv, diffuse_color, specular_color,
                                                       shading_normal, position, view_origin, is_perspective)
    model = material.model
    model_params = {key: params[key] for key in models.BY_NAME[model].parameters}
    if "normal_map" in textures:
        model_params["normal_spread"] = normal_map_spread(material, textures, uv)
    return shade(position, shading_normal, shading_tangent, view_origin, is_perspective, model, model_params,
                 diffuse_color, specular_color, light_data, environment,
                 lobe_count=material.lobe_count if model in models.ANISOTROPIC else 1,
                 visibility=visibility, warp_mode=getattr(material, "warp_mode", None), lobes=lobes,
                 light_shadow=light_shadow)


