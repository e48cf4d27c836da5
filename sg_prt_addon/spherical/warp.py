"""Spherical warp of NDF lobes into the lighting domain (wang2009 section 4.3, eq. 15-22).

The NDF D(h) is an SG mixture in the half-vector domain.  For a fixed view
``wo`` the BRDF slice needs D(h(wi)) with h = normalize(wo + wi), i.e. the
NDF pushed through the warp wi = psi(h) = 2 (wo.h) h - wo (eq. 17).

Three modes, all returning ISOTROPIC SGs so that every downstream consumer
(SG x clamped cosine, SSDF visibility fh, the SG-prefiltered environment,
point lights as SGs) takes them unchanged:

``'paper'``  one lobe per NDF lobe, eq. 18-21: axis psi(p), sharpness
             lambda / tau with tau = 4 |p.wo|, amplitude kept.
``'split2'`` two lobes per NDF lobe.  The true warped lobe is
             anisotropic: sharpness lambda/4 in the plane of (p, wo) and
             lambda / (4 c^2) across it (c = p.wo), and it fans out (wider
             where h.wo is larger, i.e. towards the normal).  The paper's
             single lobe has the geometric-mean sharpness lambda / (4 c): too
             narrow in the plane, so at grazing views it sits at the horizon
             and loses most of its cosine-weighted energy, and too wide
             across it.  split2 splits the NDF lobe into two half-amplitude
             lobes offset by +-delta along the plane of incidence (the
             two-point Gauss-Hermite rule) and warps each with the paper's
             rule at its own centre, so each half gets its own Jacobian: the
             fan shape and the energy near the horizon come back.  delta =
             sqrt((1 - c m) / lambda) (m = 1 here) makes the in-plane variance
             of the pair after warping, 4 c m / lambda + 4 delta^2, the true
             4 / lambda.  At normal incidence delta = 0 and split2 equals
             'paper'.  Sub-lobes whose centre is not a valid half vector
             (h.wo <= 0) get zero amplitude: no wi reflects wo about them.
             delta is capped at MAX_SPLIT_OFFSET, and the cap fades to 0 below
             lambda = FULL_SPLIT_SHARPNESS: for broad lobes the split
             overshoots the planar model it comes from, so they stay (nearly)
             'paper'.

``'split3'`` (default) the three-point rule (nodes 0, +-sqrt(3) delta,
             weights 2/3, 1/6, 1/6), three lobes, each of the true ACROSS-plane
             sharpness lambda / (4 c_i m), m = c, with its amplitude over m so
             that the parts keep the warped lobe's integral (the centre node
             fills the middle, so the narrower parts still make one streak).
             Below c = 1/2, m = 1 - c: back to the paper's width at grazing
             views, where parts of the true width across would draw apart
             into separate spots (``split_across``).  Where the offset cap
             bites, m grows back towards 1 to hold the in-plane variance the
             offsets no longer give.  (With m = 1, the paper's width, the
             environment's specular at views of 45-70 degrees read a lobe
             1 / sqrt(c) too wide across the plane.)

Measured (benchmarks/accuracy/warp.py, quadrature of D(h(wi)), lambda = 2 / alpha^2 for alpha 0.05-0.5
and 1..1e4, means; docs/ACCURACY.md "warp"):

| at 30 / 60 / 75 / 85 deg | paper | split2 | split3 |
|---|---|---|---|
| lit: what SG lights as narrow as the lobe is across reflect, relative RMS | 0.028 / 0.154 / 0.289 / 0.496 | 0.024 / 0.169 / 0.418 / 0.739 | 0.011 / 0.105 / 0.234 / 0.292 |
| relative L2 over the sphere | 0.089 / 0.336 / 0.607 / 0.935 | 0.085 / 0.305 / 0.538 / 0.742 | 0.040 / 0.269 / 0.473 / 0.77 |

(split3 with the paper's width across, m = 1: lit 0.024 / 0.149 / 0.261 / 0.277, L2 0.084 / 0.281 / 0.487 /
0.767.)  Cosine-weighted energy ratio at 85 deg for alpha 0.05 / 0.1 / 0.3 / 0.5: paper 0.75 / 0.46 / 0.15 /
0.11, split2 0.98 / 1.03 / 1.05 / 0.56, split3 0.99 / 0.95 / 0.86 / 0.45; split3 overshoots by up to 3.7% at
30 deg for lambda 8-22 (the GGX shader caps the slice's energy at the model's albedo).  The lit errors are
what the prefiltered environment, sphere lights and the visibility products read of the shape; the L2 at
grazing views counts separate parts where the true lobe is one streak.

End to end, eq. 22 with GGX's own SG lobe and Mo (roughness 0.2-0.9), mean |energy ratio - 1| at 60 / 75
/ 85 / 89 deg: paper 0.031 / 0.080 / 0.198 / 0.638, split2 0.021 / 0.152 / 0.130 / 0.336, split3 0.020 /
0.092 / 0.122 / 0.315.  split2 loses at 75 deg because a sub-lobe whose centre falls below the horizon gets
Mo = 0 while part of it is above (split3 gives that node only 1/6 of the weight); evaluating Mo at a lifted
centre (the lobe's mean upper-hemisphere cosine) was measured and is worse.  So split3 is the default;
split2 is the cheaper middle ground.

Not a mode: an anisotropic SG (Xu et al. 2013) with the exact Jacobian at the
centre has a much lower L2 for sharp lobes (mean 0.17 at 60 deg against
split3's 0.27) but no fan, so it loses the grazing energy like 'paper'
(mean |cos-energy - 1| 0.51 at 85 deg), and fh and the isotropic prefiltered
environment cannot take it (measured in the accuracy table).

Grazing clamp: tau = 4 max(|h.wo|, COS_FLOOR) and the warped sharpness is
capped at MAX_WARPED_SHARPNESS, so grazing views (wo.z = 0, wo in the tangent
plane) give large but finite sharpness.  The cap (angular width ~1e-3 rad)
is below any environment texel and only bites for mirror-like lobes within
a fraction of a degree of grazing.

Everything is elementwise (dot products, sqrt, cos/sin, one normalize) so the
GLSL port is line by line.  Reference helpers at the end (``true_slice``,
``lighting_quadrature``) are for tests and accuracy tables, not for shading.
"""
import numpy as np

from . import sg

# Gauss-Hermite rules (nodes in units of the offset delta, weights) for the split modes
SPLIT_RULES = {
    "split2": ((1.0, -1.0), (0.5, 0.5)),
    "split3": ((np.sqrt(3.0), 0.0, -np.sqrt(3.0)), (1 / 6, 2 / 3, 1 / 6)),
}
MODES = ("paper",) + tuple(SPLIT_RULES)
DEFAULT_MODE = "split3"
COS_FLOOR = 1e-3                # floor of |h.wo| in tau = 4 |h.wo| (eq. 21)
MAX_WARPED_SHARPNESS = 1e6      # cap of lambda / tau
MAX_SPLIT_OFFSET = 0.2          # cap of delta (rad): the split overshoots for wide lobes (lambda < ~25)
FULL_SPLIT_SHARPNESS = 8.0      # below this lambda the cap shrinks linearly to 0 (alpha 0.5 is lambda 8)


def nodes_per_lobe(mode=None):
    """Warped lobes a mode makes of each NDF lobe (1 for the paper's warp); None: DEFAULT_MODE, read when
    called."""
    mode = mode or DEFAULT_MODE
    return 1 if mode == "paper" else len(SPLIT_RULES[mode][0])


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _warp_at(half, sharpness, wo, signed_cos, across=1.0):
    """Paper's per-lobe warp (eq. 18-21) of lobes centred at ``half``.

    Returns the reflected axis psi(half) = 2 (wo.h) h - wo (unit for unit h and
    wo: |psi|^2 = 4 c^2 - 4 c^2 + 1, so no normalize) and the sharpness
    lambda / tau with tau = 4 |half.wo| clamped below by 4 COS_FLOOR, times
    ``across`` (the split modes' m, 1 for the paper's warp).
    """
    axis = 2 * signed_cos[..., None] * half - wo
    tau = 4 * np.maximum(np.abs(signed_cos), COS_FLOOR) * across
    warped_sharpness = np.minimum(sharpness / tau, MAX_WARPED_SHARPNESS)
    return axis, warped_sharpness


def split_across(cosine, mode):
    """m of a split mode at c = |p.wo|: its parts are lambda / (4 c_i m) sharp (module doc).  split3: m = c
    (the true width across the plane) down to c = 1/2, then back towards the paper's m = 1 as c -> 0;
    split2: m = 1 (its two parts, narrowed, would draw apart into two spots: relative L2 at 60 degrees 0.42
    against the paper's 0.34)."""
    if mode == "split2":
        return np.ones_like(cosine)
    return np.maximum(cosine, 1 - cosine)


def warp_lobes(axis, sharpness, amplitude, wo, mode=DEFAULT_MODE):
    """Warp NDF lobes (half-vector domain) to slice lobes (lighting domain).

    axis (..., K, 3), sharpness (..., K), amplitude (..., K); wo (..., 3)
    broadcast over K.  Returns (axis, sharpness, amplitude) with K lobes for
    mode 'paper' (wang2009 eq. 18-21), n K for the split modes (n = 2, 3; the
    parts of NDF lobe k at indices n k ... n k + n - 1, in the order of
    SPLIT_RULES' nodes).  dtype follows the inputs.
    """
    if mode not in MODES:
        raise ValueError(f"unknown warp mode {mode!r}, expected one of {MODES}")
    axis = sg.normalize(axis)
    dtype = axis.dtype
    sharpness = np.asarray(sharpness).astype(dtype, copy=False)
    amplitude = np.asarray(amplitude).astype(dtype, copy=False)
    wo = sg.normalize(np.asarray(wo).astype(dtype, copy=False))[..., None, :]
    wo = np.broadcast_to(wo, np.broadcast_shapes(wo.shape, axis.shape))
    sharpness, amplitude = np.broadcast_arrays(sharpness, amplitude)
    signed_cos = np.clip(_dot(axis, wo), -1, 1)

    if mode == "paper":
        warped_axis, warped_sharpness = _warp_at(axis, sharpness, wo, signed_cos)
        return warped_axis, warped_sharpness, np.broadcast_to(amplitude, warped_sharpness.shape).copy()

    # split modes: Gauss-Hermite nodes along the plane of (axis, wo), spaced by delta
    in_plane = wo - signed_cos[..., None] * axis
    # wo along the axis: no plane of incidence (delta = 0 there anyway), take any perpendicular
    helper = np.where(np.abs(axis[..., :1]) < 0.9, np.array([1, 0, 0], dtype), np.array([0, 1, 0], dtype))
    degenerate = _dot(in_plane, in_plane)[..., None] < 1e-12
    in_plane = sg.normalize(np.where(degenerate, np.cross(axis, helper), in_plane))
    # wo near -axis: wo - c axis cancels, so restore orthogonality (the error left is second order)
    in_plane = in_plane - _dot(in_plane, axis)[..., None] * axis
    safe_sharpness = np.where(sharpness > 0, sharpness, 1)
    cosine = np.maximum(np.abs(signed_cos), COS_FLOOR)
    across = split_across(cosine, mode)
    offset_squared = np.where(sharpness > 0, (1 - signed_cos * across) / safe_sharpness, np.inf)
    # broad lobes: the split overshoots the planar model it is derived from, fade back to 'paper'
    offset_cap = MAX_SPLIT_OFFSET * np.minimum(sharpness * (1 / FULL_SPLIT_SHARPNESS), 1)
    uncapped = np.sqrt(offset_squared)
    offset = np.minimum(uncapped, offset_cap)
    # where the cap bites, wider parts hold the in-plane variance the offsets no longer give (m -> 1: 'paper')
    across = np.where(offset_cap < uncapped, np.clip((1 - safe_sharpness * offset * offset) / cosine, across, 1),
                      across)
    nodes, weights = (np.array(r, dtype) for r in SPLIT_RULES[mode])   # node > 0: towards wo
    node_offset = offset[..., None] * nodes                               # (..., K, n)
    half = (np.cos(node_offset)[..., None] * axis[..., None, :]
            + np.sin(node_offset)[..., None] * in_plane[..., None, :])    # (..., K, n, 3)
    half_cos = _dot(half, wo[..., None, :])
    warped_axis, warped_sharpness = _warp_at(half, sharpness[..., None], wo[..., None, :], half_cos,
                                             across[..., None])
    # amplitude over m: the narrower parts keep the warped lobe's integral
    warped_amplitude = np.where(half_cos > 0, weights * (amplitude / across)[..., None], 0).astype(dtype)
    shape = warped_sharpness.shape[:-2] + (len(nodes) * warped_sharpness.shape[-2],)
    return (warped_axis.reshape(shape + (3,)), warped_sharpness.reshape(shape),
            warped_amplitude.reshape(shape))


def brdf_slice_lobes(axis, sharpness, amplitude, wo, m_factor, mode=DEFAULT_MODE):
    """BRDF view slice as SG lobes in the lighting domain (wang2009 eq. 22).

    Warped lobes (warp_lobes) with amplitude multiplied by Mo(psi(p)), the
    smooth factor of the BRDF evaluated at each warped lobe centre (eq. 22
    assumes it constant over the lobe).  ``m_factor(wo, wi)`` takes
    broadcastable (..., 3) directions.  Non-finite Mo (e.g. 1/(n.wi) at a
    centre on the horizon) is replaced by 0.

    m_factor is called with the lobe index as the LEADING axis, directions
    (K', ..., 3), so model parameters shaped like the pixels (...) broadcast
    (reflectance.brdf models with spatially varying roughness).
    """
    warped_axis, warped_sharpness, warped_amplitude = warp_lobes(axis, sharpness, amplitude, wo, mode)
    wo_lobes = np.broadcast_to(sg.normalize(np.asarray(wo).astype(warped_axis.dtype, copy=False))[..., None, :],
                               warped_axis.shape)
    with np.errstate(all="ignore"):
        mo = np.asarray(m_factor(np.moveaxis(wo_lobes, -2, 0), np.moveaxis(warped_axis, -2, 0)))
    mo = np.moveaxis(np.broadcast_to(mo, warped_axis.shape[-2:-1] + warped_axis.shape[:-2]), 0, -1)
    mo = np.where(np.isfinite(mo), mo, 0).astype(warped_axis.dtype, copy=False)
    return warped_axis, warped_sharpness, warped_amplitude * mo


# ---------------------------------------------------------------- reference


def true_slice(direction, wo, ndf_axis, ndf_sharpness, ndf_amplitude=1.0):
    """Exact slice D(h(wi)) of an SG-mixture NDF, h = normalize(wo + wi).

    direction (..., 3); NDF lobes along the last axis of ndf_sharpness.
    """
    half = sg.normalize(np.asarray(direction) + np.asarray(wo))
    return sg.mixture_evaluate(half, ndf_axis, ndf_sharpness, ndf_amplitude)


def _frame(centre):
    helper = np.array([1.0, 0.0, 0.0]) if abs(centre[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    first = np.cross(centre, helper)
    first /= np.linalg.norm(first)
    return first, np.cross(centre, first)


def lighting_quadrature(centre, finest_scale, azimuths=1024, panels=30, nodes=10):
    """Quadrature over the whole sphere in polar coordinates around ``centre``.

    Returns directions (T, P, 3) and solid-angle weights (T, P).  The polar
    angle uses Gauss-Legendre panels with geometrically growing widths from
    ``finest_scale`` / 1000 to pi (resolves a lobe of angular width
    ``finest_scale`` at the centre and the whole sphere); the azimuth is
    uniform (trapezoid, spectrally accurate for periodic integrands).
    """
    centre = np.asarray(centre, float) / np.linalg.norm(centre)
    edges = np.concatenate([[0.0], np.geomspace(finest_scale * 1e-3, np.pi, panels)])
    x, w = np.polynomial.legendre.leggauss(nodes)
    widths = (edges[1:] - edges[:-1])[:, None]
    polar = (widths * (x + 1) / 2 + edges[:-1, None]).ravel()
    polar_weight = (widths * w / 2).ravel() * np.sin(polar)
    azimuth = np.arange(azimuths) * (2 * np.pi / azimuths)
    first, second = _frame(centre)
    ring = np.cos(azimuth)[:, None] * first + np.sin(azimuth)[:, None] * second       # (P, 3)
    directions = np.cos(polar)[:, None, None] * centre + np.sin(polar)[:, None, None] * ring
    weights = polar_weight[:, None] * np.full(azimuths, 2 * np.pi / azimuths)
    return directions, weights


def slice_errors(wo, ndf_axis, ndf_sharpness, mode, azimuths=1024, panels=30, nodes=10):
    """Errors of the warped slice of one SG NDF lobe (amplitude 1) for view wo.

    Returns dict: energy_sphere (integral ratio approx / true over the
    sphere), energy_cosine (same, weighted by max(0, wi.z)), l2 (relative L2
    error over the sphere), l2_cosine (relative L2 error weighted by the
    clamped cosine), lit (the relative RMS error of what the slice reflects of
    SG lights as narrow as the true lobe is across (sharpness lambda / (4 c^2)),
    on a 5 x 5 grid of axes one width apart in and across the plane of
    incidence around the true centre, cosine-weighted: what a consumer that
    integrates the slice against light -- the prefiltered environment, sphere
    lights -- sees of its shape).
    """
    wo = np.asarray(wo, float) / np.linalg.norm(wo)
    ndf_axis = np.asarray(ndf_axis, float) / np.linalg.norm(ndf_axis)
    cosine_view = wo @ ndf_axis
    centre = 2 * cosine_view * ndf_axis - wo
    # finest feature: the across-plane width of the true lobe, 2 c / sqrt(lambda)
    finest = 2 * max(abs(cosine_view), 0.02) / np.sqrt(max(ndf_sharpness, 1.0))
    directions, weights = lighting_quadrature(centre, finest, azimuths, panels, nodes)
    exact = true_slice(directions, wo, ndf_axis[None], np.array([ndf_sharpness]))
    lobes = warp_lobes(ndf_axis[None], np.array([ndf_sharpness]), np.array([1.0]), wo, mode)
    approx = sg.mixture_evaluate(directions, *lobes)
    cosine = np.maximum(directions[..., 2], 0)
    out = {}
    for name, w in (("sphere", weights), ("cosine", weights * cosine)):
        out["energy_" + name] = float(np.sum(approx * w) / np.sum(exact * w))
        l2 = np.sqrt(np.sum((approx - exact) ** 2 * w) / np.sum(exact ** 2 * w))
        out["l2" if name == "sphere" else "l2_cosine"] = float(l2)
    out["lit"] = _lit_error(centre, wo, finest, exact, approx, directions, weights * cosine)
    return out


def _lit_error(centre, wo, finest, exact, approx, directions, weights):
    """slice_errors' ``lit``: relative RMS over a 5 x 5 grid of SG lights of width ``finest`` (see there)."""
    in_plane = wo - (wo @ centre) * centre
    in_plane = in_plane / np.linalg.norm(in_plane) if np.linalg.norm(in_plane) > 1e-9 else _frame(centre)[0]
    across = np.cross(centre, in_plane)
    light_sharpness = 1.0 / finest ** 2
    steps = np.arange(-2, 3) * finest
    responses = []
    for u in steps:
        for v in steps:
            axis = sg.normalize(centre + np.tan(u) * in_plane + np.tan(v) * across)
            light = np.exp(light_sharpness * (directions @ axis - 1)) * weights
            responses.append((np.sum(light * approx), np.sum(light * exact)))
    approx_response, exact_response = np.array(responses).T
    return float(np.sqrt(np.sum((approx_response - exact_response) ** 2) / np.sum(exact_response ** 2)))
