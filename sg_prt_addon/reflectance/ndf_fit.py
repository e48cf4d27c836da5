"""SG-mixture fits of normal distribution functions (wang2009 section 4.1-4.2).

* ``fit_isotropic``: 1-2 lobes around z+ fitted to an isotropic NDF D(theta) by
  Levenberg-Marquardt (scipy least_squares, method 'lm') on the hemisphere L2
  error, lobes sorted by increasing sharpness (the paper's order for texture
  interpolation).  ``fit_isotropic_batch``: the same, vectorized over many rows
  (per-pixel measured NDFs on one theta grid), agreeing with it to 1e-6.
* ``fit_anisotropic``: K free-axis lobes fitted to any NDF sampled on a
  hemisphere quadrature by L-BFGS-B (the paper's solver) with an analytic
  gradient, grown greedily (each new lobe starts at the largest residual).
  ``fit_ndf``: front end for a callable D(h) or an isotropic table.
* ``anisotropy_table`` / ``anisotropic_lobes``: the fast per-pixel path for
  spatially-varying anisotropic models.  In the small-angle limit both Ward
  (exp(-(x^2/ax^2 + y^2/ay^2)), x, y the slopes) and Ashikhmin-Shirley
  ((n.h)^e ~ exp(-(nu x^2 + nv y^2)/2), widths sqrt(2/nu), sqrt(2/nv)) are the
  normalized target T(x, y) = exp(-(x^2 + y^2/r^2)) after dividing the slopes
  by the long-axis width, with r = short width / long width <= 1.  T is fitted
  once per r (a log-spaced grid of ANISOTROPY_RATIO_COUNT ratios from
  ANISOTROPY_RATIO_MIN to 1; smaller r is clamped) by a symmetric row of
  isotropic Gaussians along the long axis, with the L2 error in closed form
  (Gaussian integrals), amplitudes by non-negative least squares and an exact
  gradient (TNC).  The table (R, K, 3) holds (offset along the long axis in
  widths, sharpness * width^2, amplitude / D(n)), interpolated linearly in
  log r; ``anisotropy_table_array`` packs it as float32 (R, K, 4) with log r
  first, for upload.  Scaling back: sharpness = s / w^2, axis = normalize(offset
  * w along the long axis, 1 along z), amplitude = a D(n).  Built lazily per K
  (about 0.2-1 s).  ``weighting`` chooses the error a row is fitted to: the
  plain L2 (PLANE_L2) or mostly the L2 after a blur, what an environment shows
  (LIGHT_WEIGHTED).  The target may be any mixture of centred Gaussians, so the
  fit stays closed-form.  The scale step is exact only for
  narrow lobes: measured relative L2 of D with 4 lobes, A-S (75, 1200) 0.178
  (direct sphere fit 0.178), Ward (0.3, 0.05) 0.303 (0.302), but Ward (0.8, 0.4) 0.28 where a sphere fit
  reaches 0.035; the optional broad-lobe correction (``mapping_kind``) brings
  that to 0.15.  A table over (ratio, width) fitted on the sphere would close
  the rest.
* ``ggx_anisotropy_table`` / ``ggx_anisotropic_lobes``: anisotropic GGX's own
  table over (alpha, ratio), every lobe fitted at once (LIGHT_WEIGHTED) to GGX's
  two sphere-fitted isotropic lobes stretched to the ratio (ggx_composed_target):
  isotropic rows are exact wherever the two-lobe fit is, at any alpha, which the
  small-angle GGX 1/(1 + x^2 + y^2/r^2)^2 as a target is not (alpha 0.6: relative
  L2 of D 0.36 against 0.02).  About 3-8 s a lobe count, cached on disk.
* ``ggx_two_lobe_table``: 2-lobe L2 fits of GGX over log alpha (alpha-normalized).
* ``derive_isotropic_mapping``: the L2-optimal 1-lobe fit over a width grid and
  a polynomial through it (the frozen coefficients of ISOTROPIC_MAPPINGS).
* ``ndf_l2_error`` / ``brdf_relative_rmse``: the two error measures the tests
  and benchmarks/accuracy/ndf_fit.py report.
"""
import dataclasses
import functools
import itertools

import numpy as np

HALF_PI = 0.5 * np.pi
ANISOTROPY_RATIO_MIN = 1.0 / 64.0
ANISOTROPY_RATIO_COUNT = 25
MAX_LOBES = 8
# What an anisotropy table's fit weighs, as (blur variance in the table's widths squared, weight) terms of
# _plane_fit.  PLANE_L2: the L2 of D, what a point light's highlight shows.  LIGHT_WEIGHTED: mostly the error
# blurred by a Gaussian of variance 0.25 alpha_x^2, what an environment's highlight shows (its power falls with
# frequency, so a row's ripple between lobes matters less than where the row puts its energy), the plain L2 kept
# small so the row cannot hide sharp spikes under the blur.  Anisotropic GGX's table (ggx_anisotropy_table) is
# fitted to it; measured in docs/ACCURACY.md.
PLANE_L2 = ((0.0, 1.0),)
LIGHT_WEIGHTED = ((0.0, 0.05), (0.25, 1.0))


def _optimize():
    """scipy.optimize, imported when a fit runs: rendering never fits, and the import costs every process
    (a batch job is one a frame) about 0.15 s."""
    import scipy.optimize
    return scipy.optimize


# ----------------------------------------------------------------------------- quadrature

def polar_quadrature(widths, nodes_per_segment=48, theta_max=HALF_PI):
    """Gauss-Legendre nodes in theta on [0, theta_max], with segment breaks at
    multiples of the lobe widths so peaks of any sharpness are resolved.

    Returns (theta (M,), weight (M,)) with weight = sin(theta) dtheta (multiply by
    2 pi for an isotropic integrand, or by the phi step).
    """
    widths = np.atleast_1d(np.asarray(widths, np.float64))
    breaks = {0.0, float(theta_max)}
    for w in widths:
        for multiple in (0.5, 1, 2, 4, 8, 16):
            if 0 < multiple * w < theta_max:
                breaks.add(float(multiple * w))
    breaks = np.array(sorted(breaks))
    x, w = np.polynomial.legendre.leggauss(nodes_per_segment)
    lo, hi = breaks[:-1, None], breaks[1:, None]
    theta = (0.5 * (hi - lo) * x + 0.5 * (hi + lo)).ravel()
    weight = (0.5 * (hi - lo) * w).ravel() * np.sin(theta)
    return theta, weight


def hemisphere_quadrature(widths, nodes_per_segment=32, phi_count=192):
    """Directions (M, 3) and solid-angle weights (M,) on the upper hemisphere."""
    theta, weight = polar_quadrature(widths, nodes_per_segment)
    phi = (np.arange(phi_count) + 0.5) * (2 * np.pi / phi_count)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    directions = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    weights = np.repeat(weight * (2 * np.pi / phi_count), phi_count)
    return directions, weights


def relative_l2(exact, approximation, weights):
    """sqrt(sum w (approx - exact)^2 / sum w exact^2) along the last axis."""
    return np.sqrt(np.sum(weights * (approximation - exact) ** 2, axis=-1)
                   / np.maximum(np.sum(weights * exact ** 2, axis=-1), 1e-300))


# ----------------------------------------------------------------------------- isotropic fits

def _isotropic_model(params, one_minus_cos):
    # clipped logs: a redundant lobe may drift towards 0 or infinite sharpness
    log_sharpness, log_amplitude = np.split(np.clip(params, -40, 40), 2)
    sharpness, amplitude = np.exp(log_sharpness), np.exp(log_amplitude)
    lobes = amplitude[:, None] * np.exp(-sharpness[:, None] * one_minus_cos[None, :])
    return sharpness, amplitude, lobes


def _initial_isotropic(values, theta, lobe_count):
    """Peak height and the curvature at half maximum: a Gaussian exp(-theta^2/s^2) guess."""
    peak = max(values[0], 1e-30)
    below = np.nonzero(values < 0.5 * peak)[0]
    half_width = theta[below[0]] if len(below) else theta[-1]
    sharpness = 2 * np.log(2) / max(half_width * half_width, 1e-12)  # exp(-lambda theta^2/2)
    if lobe_count == 1:
        return np.log([sharpness, peak])
    return np.log([sharpness / 3, 3 * sharpness, 0.3 * peak, 0.7 * peak])


def fit_isotropic(ndf_values, theta, weights, lobe_count=1, initial=None):
    """L2 fit of 1-2 SG lobes around z+ to an isotropic NDF (wang2009 section 4.2).

    ndf_values (M,) or (B, M) sampled at polar angles theta (M,) with solid-angle
    weights (from polar_quadrature).  Minimizes sum w (sum_k mu_k exp(lambda_k
    (cos theta - 1)) - D)^2 by Levenberg-Marquardt over log lambda, log mu.
    initial (2K,) or (B, 2K) of (sharpness..., amplitude...) warm-starts the fit.

    Returns (sharpness (..., K), amplitude (..., K), relative_l2 (...)), lobes sorted
    by increasing sharpness.
    """
    values = np.asarray(ndf_values, np.float64)
    batched = values.ndim == 2
    values = np.atleast_2d(values)
    theta = np.asarray(theta, np.float64)
    one_minus_cos = 2 * np.sin(0.5 * theta) ** 2  # 1 - cos without cancellation
    root_w = np.sqrt(np.asarray(weights, np.float64))
    out_sharpness = np.empty((len(values), lobe_count))
    out_amplitude = np.empty((len(values), lobe_count))
    out_error = np.empty(len(values))
    if initial is not None:
        initial = np.atleast_2d(np.asarray(initial, np.float64))
    for row, target in enumerate(values):
        scale = max(np.sqrt(np.sum(root_w ** 2 * target ** 2)), 1e-300)
        if initial is not None:
            start = np.log(np.maximum(initial[min(row, len(initial) - 1)], 1e-12))
        else:
            start = _initial_isotropic(target, theta, lobe_count)

        def residual(params):
            return root_w * (_isotropic_model(params, one_minus_cos)[2].sum(0) - target) / scale

        def jacobian(params):
            sharpness, _, lobes = _isotropic_model(params, one_minus_cos)
            d_log_sharpness = -(lobes * sharpness[:, None] * one_minus_cos[None, :])
            return (root_w[:, None] * np.concatenate([d_log_sharpness, lobes]).T) / scale

        result = _optimize().least_squares(residual, start, jac=jacobian, method="lm", xtol=1e-12, ftol=1e-12)
        sharpness, amplitude, _ = _isotropic_model(result.x, one_minus_cos)
        order = np.argsort(sharpness)
        out_sharpness[row], out_amplitude[row] = sharpness[order], amplitude[order]
        out_error[row] = np.sqrt(np.sum(result.fun ** 2))
    if not batched:
        return out_sharpness[0], out_amplitude[0], out_error[0]
    return out_sharpness, out_amplitude, out_error


def fit_isotropic_batch(ndf_values, theta, weights, lobe_count=1, iterations=60, chunk=2048):
    """Vectorized Levenberg-Marquardt version of fit_isotropic for many rows at once
    (per-pixel NDFs of a measured SVBRDF tabulated on one shared theta grid).

    Same model and objective as fit_isotropic (log-parametrized lobes around z+),
    every row damped independently; rows are processed ``chunk`` at a time to bound
    memory.  Returns (sharpness (B, K), amplitude (B, K), relative_l2 (B,)), lobes
    sorted by increasing sharpness.
    """
    values = np.atleast_2d(np.asarray(ndf_values, np.float64))
    theta = np.asarray(theta, np.float64)
    one_minus_cos = 2 * np.sin(0.5 * theta) ** 2
    root_w = np.sqrt(np.asarray(weights, np.float64))
    sharpness_out = np.empty((len(values), lobe_count))
    amplitude_out = np.empty((len(values), lobe_count))
    error_out = np.empty(len(values))
    for start in range(0, len(values), chunk):
        target = values[start:start + chunk]
        scale = np.maximum(np.sqrt(np.sum(root_w ** 2 * target ** 2, axis=1)), 1e-300)[:, None]
        params = np.stack([_initial_isotropic(row, theta, lobe_count) for row in target])

        def residual_and_jacobian(params):
            clipped = np.clip(params, -40, 40)
            sharpness = np.exp(clipped[:, :lobe_count])[:, :, None]
            lobes = np.exp(clipped[:, lobe_count:])[:, :, None] * np.exp(-sharpness * one_minus_cos)  # (B, K, M)
            residual = root_w * (lobes.sum(1) - target) / scale
            jacobian = np.concatenate([-lobes * sharpness * one_minus_cos, lobes], axis=1)  # (B, P, M)
            return residual, jacobian * (root_w / scale)[:, None, :]

        residual, jacobian = residual_and_jacobian(params)
        cost = np.sum(residual ** 2, axis=1)
        damping = np.full(len(target), 1e-3)
        identity = np.eye(2 * lobe_count)
        for _ in range(iterations):
            normal = jacobian @ jacobian.transpose(0, 2, 1)
            gradient = np.einsum("bpm,bm->bp", jacobian, residual)
            diagonal = np.einsum("bpp->bp", normal)[:, :, None] * identity + 1e-30 * identity
            step = np.linalg.solve(normal + damping[:, None, None] * diagonal, -gradient[:, :, None])[:, :, 0]
            trial = params + step
            trial_residual, trial_jacobian = residual_and_jacobian(trial)
            trial_cost = np.sum(trial_residual ** 2, axis=1)
            better = np.isfinite(trial_cost) & (trial_cost < cost)
            params = np.where(better[:, None], trial, params)
            residual = np.where(better[:, None], trial_residual, residual)
            jacobian = np.where(better[:, None, None], trial_jacobian, jacobian)
            cost = np.where(better, trial_cost, cost)
            damping = np.clip(np.where(better, damping / 3, damping * 4), 1e-12, 1e12)
        sharpness = np.exp(np.clip(params[:, :lobe_count], -40, 40))
        amplitude = np.exp(np.clip(params[:, lobe_count:], -40, 40))
        order = np.argsort(sharpness, axis=1)
        sharpness_out[start:start + chunk] = np.take_along_axis(sharpness, order, 1)
        amplitude_out[start:start + chunk] = np.take_along_axis(amplitude, order, 1)
        error_out[start:start + chunk] = np.sqrt(cost)
    return sharpness_out, amplitude_out, error_out


def derive_isotropic_mapping(ndf_of_width, peak_of_width, widths, degree=5, endpoint_weight=1.0):
    """L2-optimal single lobe over a width grid and polynomials through it.

    ndf_of_width(theta, width) -> D; peak_of_width(width) -> D(n).  The fitted
    quantities are sharpness * width^2 and amplitude / D(n), polynomials in width
    (lowest order first), as stored in ISOTROPIC_MAPPINGS.
    Returns (sharpness_coefficients, amplitude_coefficients, table (W, 3) of
    width, scaled sharpness, relative amplitude).
    """
    rows = []
    previous = None
    for width in np.asarray(widths, np.float64):
        theta, weights = polar_quadrature([width])
        peak = peak_of_width(width)
        sharpness, amplitude, _ = fit_isotropic(ndf_of_width(theta, width) / peak, theta, weights, 1,
                                                initial=previous)
        previous = np.concatenate([sharpness, amplitude])
        rows.append((width, sharpness[0] * width * width, amplitude[0]))
    table = np.array(rows)
    # endpoint_weight pins the ends of the range (GGX at alpha = 1 is a constant: sharpness 0)
    fit_weights = np.ones(len(table))
    fit_weights[[0, -1]] = endpoint_weight
    sharpness_coefficients = np.polynomial.polynomial.polyfit(table[:, 0], table[:, 1], degree, w=fit_weights)
    amplitude_coefficients = np.polynomial.polynomial.polyfit(table[:, 0], table[:, 2], degree, w=fit_weights)
    return sharpness_coefficients, amplitude_coefficients, table


def _polynomial(coefficients, x):
    """sum_k c_k x^k by Horner (coefficients lowest order first)."""
    result = np.zeros_like(x) + coefficients[-1]
    for c in coefficients[-2::-1]:
        result = result * x + c
    return result


# L2-optimal single SG lobe of an isotropic NDF, as a function of the lobe width w
# (the model's angular width: m, alpha, or sqrt(2/exponent)):
#   sharpness = SHARPNESS(w) / w^2,  amplitude = AMPLITUDE(w) * D(h = n).
# Fitted by derive_isotropic_mapping on 101 widths (degree 7, 7, 6, 6); the
# tests check the mapping's relative L2 error exceeds the numerically optimal single
# lobe's by at most 0.002 (GGX: 0.006) anywhere in width_range (measured: <= 1e-5,
# 2e-4, 3e-6, 0.0055 at alpha = 1).  shaders/lib/brdf.glsl copies these numbers.
# (derive_isotropic_mapping(..., endpoint_weight=30) gives GGX an excess <= 3e-4;
# switch this table and brdf.glsl together if adopted.)  Small widths tend to the
# Gaussian limit (2, 1); GGX's heavy tails give (2.29, 0.87) instead.
# fmt: off
ISOTROPIC_MAPPINGS = {
    "BECKMANN": {"width_range": (0.0, 1.0),
        "sharpness": (2.0002526198839767, -0.018562042324853516, -0.7087810352685576, -1.780493452401246, 7.795476534850792, -5.224441602950464, -1.8573600001154729, 1.8313186768538343),
        "amplitude": (1.0000788099487423, -0.00562487537421968, 0.45936658759780197, -0.4782415853046627, 1.8768790206320416, -0.723505986830146, -1.093140907789823, 0.6774600689844926)},
    "BLINN_PHONG": {"width_range": (0.0, 1.5),
        "sharpness": (2.001247483300024, -0.0704030099405333, 1.8252868204860242, -3.7366710387171747, 7.990337405162444, -7.976517234021651, 3.6090854215670936, -0.6165165884429983),
        "amplitude": (1.0001482120242338, -0.009229085969026461, 0.24259176162034488, -0.5769981443748883, 1.304434552867832, -1.4708046288958752, 0.7476278795213421, -0.1413828848427673)},
    "WARD_ISO": {"width_range": (0.0, 1.0),
        "sharpness": (2.0000452113496068, -0.002050309015127145, 3.0147624933803696, 0.02079098217477974, -1.5775218851571589, 1.4289044928620722, -0.4515437794950395),
        "amplitude": (1.0000361029442135, -0.002018784963236324, 0.39782446238486135, -0.08061386777996582, -0.513448758758516, 0.5383190127812337, -0.17224374461564965)},
    "GGX": {"width_range": (0.0, 1.0),
        "sharpness": (2.2949071322803056, -1.8169547610727137, 17.634426696713284, -89.52143467300904, 162.11135492098055, -126.49092884708091, 35.775580872045374),
        "amplitude": (0.868594309075077, -0.47084346810594657, 5.078988403062825, -20.927444128961213, 34.85993749976531, -24.56259538488302, 6.147831356435162)},
}
# fmt: on


def isotropic_mapping(kind, width):
    """(sharpness * width^2, amplitude / D(n)) of the frozen L2 mapping for ``kind``."""
    mapping = ISOTROPIC_MAPPINGS[kind]
    w = np.clip(width, *mapping["width_range"])
    # the GGX polynomial dips to -1e-3 at alpha = 1, where the fit is a constant (sharpness 0)
    zero = np.zeros_like(w)
    return np.maximum(_polynomial(mapping["sharpness"], w), zero), np.maximum(_polynomial(mapping["amplitude"], w), zero)


def _ggx_normalized(theta, alpha):
    """GGX D / D(n) = 1 / (sin^2/alpha^2 + cos^2)^2."""
    scaled = (np.sin(theta) / alpha) ** 2 + np.cos(theta) ** 2
    return 1 / (scaled * scaled)


GGX_TABLE_ALPHAS = np.geomspace(1e-3, 1.0, 31)


@functools.lru_cache(maxsize=None)
def ggx_two_lobe_table():
    """(alpha (A,), table (A, 2, 2)): per alpha, lobes (sharpness * alpha^2, amplitude / D(n)),
    sorted by increasing sharpness.  Fitted from the smoothest alpha (where GGX is
    scale-invariant) up to alpha = 1, warm-started from the previous row."""
    table = np.empty((len(GGX_TABLE_ALPHAS), 2, 2))
    previous = None
    for index, alpha in enumerate(GGX_TABLE_ALPHAS):
        theta, weights = polar_quadrature([alpha])
        if previous is not None:
            previous = previous * np.array([(alpha / GGX_TABLE_ALPHAS[index - 1]) ** -2] * 2 + [1, 1])
        sharpness, amplitude, _ = fit_isotropic(_ggx_normalized(theta, alpha), theta, weights, 2,
                                                initial=previous)
        previous = np.concatenate([sharpness, amplitude])
        table[index, :, 0] = sharpness * alpha * alpha
        table[index, :, 1] = amplitude
    table.setflags(write=False)
    return GGX_TABLE_ALPHAS, table


def _ggx_two_lobe_entry(alpha):
    """ggx_two_lobe_table's entry (..., 2, 2) at any (array) alpha, linear in log alpha, in float64."""
    alphas, table = ggx_two_lobe_table()
    low, fraction = _interpolation(np.clip(alpha, alphas[0], alphas[-1]), alphas)
    return (1 - fraction) * table[low] + fraction * table[low + 1]


def ggx_two_lobes(alpha):
    """Two SG lobes around z+ for GGX of any (array) alpha, by linear interpolation in log alpha."""
    alpha = np.asarray(alpha)
    dtype = np.result_type(alpha, np.float32)
    entry = _ggx_two_lobe_entry(alpha)
    alpha = alpha.astype(dtype)
    sharpness = (entry[..., 0] / (alpha * alpha)[..., None]).astype(dtype)
    amplitude = (entry[..., 1] / (np.pi * alpha * alpha)[..., None]).astype(dtype)
    axis = np.zeros(sharpness.shape + (3,), dtype)
    axis[..., 2] = 1
    return axis, sharpness, amplitude


# ----------------------------------------------------------------------------- anisotropic free-axis fit

def _unpack_anisotropic(params, lobe_count):
    params = params.reshape(lobe_count, 5)
    raw_axis = params[:, :3]
    length = np.maximum(np.linalg.norm(raw_axis, axis=1, keepdims=True), 1e-12)
    return raw_axis / length, length, np.exp(params[:, 3]), np.exp(params[:, 4])


def _anisotropic_objective(params, lobe_count, directions, weights, target, scale2):
    axis, length, sharpness, amplitude = _unpack_anisotropic(params, lobe_count)
    cosine = directions @ axis.T  # (M, K)
    lobes = amplitude * np.exp(sharpness * np.minimum(cosine - 1, 0))
    residual = lobes.sum(1) - target
    weighted = 2 * weights * residual / scale2
    d_log_amplitude = weighted @ lobes
    d_log_sharpness = weighted @ (lobes * sharpness * (cosine - 1))
    d_axis = (weighted[:, None] * lobes * sharpness).T @ directions  # (K, 3)
    # gradient through axis = raw / |raw|
    d_raw = (d_axis - np.sum(d_axis * axis, 1, keepdims=True) * axis) / length
    gradient = np.concatenate([d_raw, d_log_sharpness[:, None], d_log_amplitude[:, None]], axis=1)
    return np.sum(weights * residual ** 2) / scale2, gradient.ravel()


def fit_anisotropic(ndf_values, directions, weights, lobe_count, initial=None, max_iterations=400,
                    method="L-BFGS-B"):
    """K free-axis SG lobes fitted to an NDF on a hemisphere quadrature (wang2009 section 4.2,
    L-BFGS-B as in the paper).

    ndf_values (M,) at directions (M, 3) with solid-angle weights (M,).  Without
    ``initial`` (axis (K,3), sharpness (K,), amplitude (K,)) the mixture is grown
    one lobe at a time, each new lobe placed at the largest residual and all
    lobes refitted.  Returns (axis (K, 3), sharpness (K,), amplitude (K,),
    relative_l2), lobes sorted by increasing sharpness.  method "TNC" (also bounded, with
    the same gradient) avoids scipy L-BFGS-B's multi-threaded BLAS calls, which run
    several times slower on a busy machine.
    """
    target = np.asarray(ndf_values, np.float64)
    directions = np.asarray(directions, np.float64)
    weights = np.asarray(weights, np.float64)
    scale2 = max(np.sum(weights * target ** 2), 1e-300)

    def optimize(start, count):
        options = {"maxiter": max_iterations} if method == "L-BFGS-B" else {"maxfun": 10 * max_iterations}
        result = _optimize().minimize(_anisotropic_objective, start.ravel(), jac=True, method=method,
                          args=(count, directions, weights, target, scale2),
                          bounds=([(None, None)] * 3 + [(-10, 16), (-60, 60)]) * count, options=options)
        return result.x.reshape(count, 5), result.fun

    if initial is not None:
        axis, sharpness, amplitude = (np.asarray(a, np.float64) for a in initial)
        start = np.concatenate([axis, np.log(np.maximum(sharpness, 1e-4))[:, None],
                                np.log(np.maximum(amplitude, 1e-30))[:, None]], axis=1)
        params, value = optimize(start, lobe_count)
    else:
        peak_index = np.argmax(target)
        mean_sharpness = 1 / max(np.sum(weights * target * 2 * (1 - directions[:, 2])) / np.sum(weights * target), 1e-6)
        params = np.array([[*directions[peak_index], np.log(mean_sharpness), np.log(max(target[peak_index], 1e-30))]])
        params, value = optimize(params, 1)
        for count in range(2, lobe_count + 1):
            axis, _, sharpness, amplitude = _unpack_anisotropic(params.ravel(), count - 1)
            current = (amplitude * np.exp(sharpness * (directions @ axis.T - 1))).sum(1)
            worst = np.argmax(target - current)
            new = [*directions[worst], np.log(np.max(sharpness)), np.log(max(target[worst] - current[worst], 1e-30))]
            params, value = optimize(np.vstack([params, new]), count)
    axis, _, sharpness, amplitude = _unpack_anisotropic(params.ravel(), lobe_count)
    order = np.argsort(sharpness)
    return axis[order], sharpness[order], amplitude[order], float(np.sqrt(value))


def fit_ndf(ndf, lobe_count, width_hint=0.1, isotropic=None):
    """Convenience front end: SG mixture of a callable or tabulated NDF.

    ndf: a callable D(h) on unit vectors (M, 3) (a model's ``ndf`` for instance), or an
    isotropic table (theta (T,), values (T,)) in radians, interpolated linearly (0
    beyond the table).  width_hint: the NDF's angular width(s), which place the
    quadrature breaks.  isotropic (default: True for tables, False for callables)
    selects fit_isotropic (lobes on z+, K <= 2) or fit_anisotropic (free axes).

    Returns (axis (K, 3), sharpness (K,), amplitude (K,), relative_l2).
    """
    tabulated = isinstance(ndf, tuple)
    if isotropic is None:
        isotropic = tabulated
    if tabulated:
        table_theta, table_values = (np.asarray(a, np.float64) for a in ndf)

        def evaluate(directions):
            theta = np.arctan2(np.hypot(directions[..., 0], directions[..., 1]), directions[..., 2])
            return np.interp(theta, table_theta, table_values, right=0.0)
    else:
        evaluate = ndf
    if isotropic:
        theta, weights = polar_quadrature(width_hint)
        directions = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=-1)
        sharpness, amplitude, error = fit_isotropic(evaluate(directions), theta, weights * 2 * np.pi, lobe_count)
        axis = np.zeros((lobe_count, 3))
        axis[:, 2] = 1
        return axis, sharpness, amplitude, float(error)
    directions, weights = hemisphere_quadrature(width_hint)
    return fit_anisotropic(evaluate(directions), directions, weights, lobe_count)


@functools.lru_cache(maxsize=256)
def _refined_lobes(model_class, parameters, lobe_count, mapping_kind):
    model = model_class(**dict(parameters))
    widths = model.ndf_widths()
    width_x, width_y = widths if len(widths) == 2 else widths * 2
    peak = float(model.ndf(np.array([0.0, 0.0, 1.0])))
    start = anisotropic_lobes(np.float64(width_x), np.float64(width_y), peak, lobe_count, mapping_kind)
    directions, weights = hemisphere_quadrature(widths, 16, 160)
    target = model.ndf(directions)
    # near-isotropic rows stack their lobes on one axis, a saddle the gradient cannot leave:
    # also start from the lobes spread on a small ring and keep the better fit
    angle = 2 * np.pi * (np.arange(lobe_count) + 0.25) / lobe_count
    spread = 0.3 * np.sqrt(width_x * width_y) * np.stack([np.cos(angle), np.sin(angle), np.zeros(lobe_count)], -1)
    best = None
    for axes in (start[0], start[0] + spread):
        fit = fit_anisotropic(target, directions, weights, lobe_count, initial=(axes, start[1], start[2]),
                              max_iterations=100, method="TNC")
        if best is None or fit[3] < best[3]:
            best = fit
    return best[:3]


def refined_anisotropic_lobes(model, lobe_count, mapping_kind=None):
    """Lobes of a uniform-parameter anisotropic model refined on the sphere: the table's lobes
    (as they are, and spread on a small ring) warm-start fit_anisotropic on the exact D
    (TNC, about 1-4 s, cached by parameter values and K).
    For materials without textured parameters, where the table's small-angle scaling
    is poor (broad lobes): Ward (0.8, 0.4), 4 lobes, 0.28 -> 0.035 relative L2."""
    # keyed by value (the models compare by identity): equal materials share one fit
    parameters = tuple((field.name, float(getattr(model, field.name))) for field in dataclasses.fields(model)
                       if getattr(model, field.name) is not None)
    axis, sharpness, amplitude = _refined_lobes(type(model), parameters, lobe_count, mapping_kind)
    return axis.copy(), sharpness.copy(), amplitude.copy()


# ----------------------------------------------------------------------------- normalized anisotropy table

def _row_layout(lobe_count, centres=None):
    """Symmetric row: pairs at +-offset (one shared sharpness and amplitude) and ``centres`` lobes at offset 0
    (default: one if K is odd), each its own."""
    centres = lobe_count % 2 if centres is None else centres
    pairs = (lobe_count - centres) // 2
    group = np.concatenate([np.repeat(np.arange(pairs), 2), pairs + np.arange(centres)]).astype(int)
    sign = np.concatenate([np.tile([1.0, -1.0], pairs), np.zeros(centres)])
    return pairs, pairs + centres, group, sign


def gaussian_target(ratio):
    """T = exp(-(x^2 + y^2/r^2)), Ward's and Ashikhmin-Shirley's normalized NDF in slopes / the long-axis
    width, as the Gaussian mixture _plane_fit takes: (weights (N,), x precisions (N,), y precisions (N,))."""
    return np.ones(1), np.ones(1), np.array([1.0 / (ratio * ratio)])


def _plane_fit(params, target, lobe_count, weighting=PLANE_L2, centres=None):
    """Closed-form error of a row of Gaussians mu exp(-b ((x - p)^2 + y^2)) against a target T over the plane,
    amplitudes by NNLS: the L2 error after blurring both with a Gaussian of variance v per axis, summed over
    ``weighting``'s (v, weight) terms, each relative to |T|^2 blurred alike (PLANE_L2: the plain L2).  T is a
    mixture of axis-aligned Gaussians centred at 0, target = (weights, x precisions, y precisions)
    (gaussian_target, ggx_composed_target), so every overlap is a Gaussian integral.

    Returns (E, its gradient w.r.t. params, p (K,), b (K,), mu (K,)).  The gradient holds the amplitudes
    fixed: at the NNLS optimum that is exact (envelope theorem).
    """
    pairs, unique, group, sign = _row_layout(lobe_count, centres)
    offsets = np.concatenate([params[:pairs], [0.0] * (unique - pairs)])
    b_unique = np.exp(params[pairs:pairs + unique])
    p, b = sign * offsets[group], b_unique[group]
    membership = np.zeros((unique, lobe_count))
    membership[group, np.arange(lobe_count)] = 1
    target_weight, target_x, target_y = (np.asarray(a, np.float64)[:, None] for a in target)   # (N, 1)
    b_product = b[:, None] * b[None, :]
    separation = p[:, None] - p[None, :]
    terms = []
    for variance, weight in weighting:
        # both blurred by variance v: their overlap sees the kernel twice (variance 2 v), and the precision
        # sum a1 + a2 of two Gaussians' overlap becomes a1 + a2 + 2 (2 v) a1 a2 per axis
        twice = 2 * variance
        x_precision = target_x + b * (1 + 2 * twice * target_x)              # (N, K)
        y_precision = target_y + b * (1 + 2 * twice * target_y)
        overlaps = target_weight * np.pi / np.sqrt(x_precision * y_precision) * np.exp(
            -target_x * b * p * p / x_precision)
        overlap = overlaps.sum(0)
        d_overlap_p = np.sum(overlaps * (-2 * target_x * b * p / x_precision), axis=0)
        d_overlap_b = np.sum(overlaps * (-0.5 * (1 + 2 * twice * target_x) / x_precision
                                         - 0.5 * (1 + 2 * twice * target_y) / y_precision
                                         - (target_x * p / x_precision) ** 2), axis=0)
        b_sum = b[:, None] + b[None, :] + 2 * twice * b_product
        gram = np.pi / b_sum * np.exp(-b_product * separation ** 2 / b_sum)
        pair_x = target_x + target_x.T + 2 * twice * target_x * target_x.T
        pair_y = target_y + target_y.T + 2 * twice * target_y * target_y.T
        target_norm = np.sum(target_weight * target_weight.T * np.pi / np.sqrt(pair_x * pair_y))
        d_log_gram_p = -2 * b_product * separation / b_sum
        d_log_gram_b = -(1 + 2 * twice * b[None, :]) / b_sum - separation ** 2 * b[None, :] ** 2 / b_sum ** 2
        terms.append((weight / target_norm, overlap, gram, d_overlap_p, d_overlap_b, d_log_gram_p, d_log_gram_b))
    overlap_u = sum(scale * (membership @ overlap) for scale, overlap, *_ in terms)
    gram_u = sum(scale * (membership @ gram @ membership.T) for scale, _, gram, *_ in terms)
    gram_u = gram_u + 1e-12 * np.eye(unique) * sum(scale * np.trace(gram) for scale, _, gram, *_ in terms) / lobe_count
    cholesky = np.linalg.cholesky(gram_u)
    mu_u, _ = _optimize().nnls(cholesky.T, np.linalg.solve(cholesky, overlap_u))
    mu = mu_u[group]
    total_weight = sum(weight for _, weight in weighting)
    error = total_weight - 2 * mu_u @ overlap_u + mu_u @ gram_u @ mu_u
    # derivatives of sum_v w_v (|T|^2 - 2 mu.I + mu' J mu) / |T|^2 with respect to each lobe's p and b
    d_p = d_b = 0
    for scale, _, gram, d_overlap_p, d_overlap_b, d_log_gram_p, d_log_gram_b in terms:
        d_p = d_p + scale * (-2 * mu * d_overlap_p + 2 * mu * ((gram * d_log_gram_p) @ mu))
        d_b = d_b + scale * (-2 * mu * d_overlap_b + 2 * mu * ((gram * d_log_gram_b) @ mu))
    gradient = np.concatenate([(membership @ (sign * d_p))[:pairs], membership @ (b * d_b)])
    return max(error, 0) / total_weight, gradient / total_weight, p, b, mu


def _fit_row(target, lobe_count, start, weighting, centres=None):
    pairs, unique, _, _ = _row_layout(lobe_count, centres)
    bounds = [(0.0, 4.0)] * pairs + [(-8.0, 14.0)] * unique
    # bounded truncated Newton: scipy's L-BFGS-B calls multi-threaded BLAS on tiny arrays and
    # runs 10x slower than TNC on a busy machine for these <= 8 parameters
    result = _optimize().minimize(lambda x: _plane_fit(x, target, lobe_count, weighting, centres)[:2], start, jac=True,
                                  method="TNC", bounds=bounds, options={"maxfun": 2000})
    return result.x, np.sqrt(result.fun)


def _fit_table(targets, lobe_count, weighting, centres=None):
    """(R, K, 3) rows (offset, sharpness * width^2, amplitude / D(n)) fitted to ``targets`` (one a row, in
    order of increasing ratio): the first from several starts, then continued (warm-started) row by row so
    neighbouring rows interpolate smoothly, and back down, each row keeping the better of its two fits (going
    up, a row can stay in a basin that one nearer isotropy has left)."""
    pairs, unique, _, _ = _row_layout(lobe_count, centres)
    best = None
    # a symmetric pair at offset 0, or two lobes alike, is a saddle the optimizer cannot leave: start spread out
    for spread, sharpness in itertools.product((0.5, 1.0, 1.5), (1 / ANISOTROPY_RATIO_MIN ** 2, lobe_count ** 2)):
        offsets = spread * np.linspace(1, 0, pairs + 1)[:-1] if pairs else np.array([])
        log_sharpness = np.full(unique, np.log(sharpness))
        log_sharpness[pairs:] += np.log(4.0) * np.arange(unique - pairs)       # centre lobes 4x apart
        start = np.concatenate([offsets, log_sharpness])
        candidate = _fit_row(targets[0], lobe_count, start, weighting, centres)
        if best is None or candidate[1] < best[1]:
            best = candidate
    fits = [best]
    for target in targets[1:]:
        fits.append(_fit_row(target, lobe_count, fits[-1][0], weighting, centres))
    for index in range(len(targets) - 2, -1, -1):
        fits[index] = min(fits[index], _fit_row(targets[index], lobe_count, fits[index + 1][0], weighting, centres),
                          key=lambda fit: fit[1])
    table = np.empty((len(targets), lobe_count, 3))
    for index, ((params, _), target) in enumerate(zip(fits, targets)):
        _, _, p, b, amplitude = _plane_fit(params, target, lobe_count, weighting, centres)
        # exp(-b |x - p|^2) = exp(-(lambda/2) |x - p|^2): sharpness = 2 b
        table[index] = np.stack([p, 2 * b, amplitude], axis=-1)
    return table


def _order_pairs(table):
    """Reorder each row's pairs in place so that interpolation, which pairs lobe k of a row with lobe k of its
    neighbours, pairs like with like: each row's pairs as its neighbours' nearest in (offset, log sharpness),
    the previous row's and, across a 2-D table (A, R, K, 3), the previous block's same row.  The fits need
    not keep the pairs' order: rows near r = 1 come from the sweep back down."""
    pairs = table.shape[-2] // 2
    if pairs < 2:
        return table

    def key(entries):
        return np.stack([np.abs(entries[:2 * pairs:2, 0]), np.log(np.maximum(entries[:2 * pairs:2, 1], 1e-12))], -1)

    for block, row in itertools.product(range(table.shape[0]), range(table.shape[1])):
        neighbours = [key(table[block, row - 1])] if row else []
        neighbours += [key(table[block - 1, row])] if block else []
        if not neighbours:
            continue
        current = key(table[block, row])
        order = list(min(itertools.permutations(range(pairs)),
                         key=lambda order: sum(np.sum((current[list(order)] - n) ** 2) for n in neighbours)))
        table[block, row, :2 * pairs] = table[block, row, :2 * pairs].reshape(pairs, 2, 3)[order].reshape(-1, 3)
    return table


@functools.lru_cache(maxsize=None)
def anisotropy_table(lobe_count, weighting=PLANE_L2):
    """(ratios (R,), table (R, K, 3)) for K = lobe_count lobes of T = exp(-(x^2 + y^2/r^2)); table[..., :] =
    (offset along the long axis / width, sharpness * width^2, amplitude / D(n)), the rows fitted to
    ``weighting``'s error (_fit_table)."""
    if not 1 <= lobe_count <= MAX_LOBES:
        raise ValueError(f"lobe_count must be in 1..{MAX_LOBES}")
    ratios = np.geomspace(ANISOTROPY_RATIO_MIN, 1.0, ANISOTROPY_RATIO_COUNT)
    table = _order_pairs(_fit_table([gaussian_target(ratio) for ratio in ratios], lobe_count, weighting)[None])[0]
    table.setflags(write=False)
    return ratios, table


def anisotropy_table_array(lobe_count, weighting=PLANE_L2, dtype=np.float32):
    """The table as one contiguous array (R, K, 4) for GPU upload:
    (log ratio, offset, sharpness * width^2, amplitude / D(n)) per row and lobe."""
    ratios, table = anisotropy_table(lobe_count, weighting)
    return _with_log_ratio(ratios, table, dtype)


def _with_log_ratio(ratios, table, dtype):
    log_ratio = np.broadcast_to(np.log(ratios)[:, None, None], table.shape[:-1] + (1,))
    packed = np.concatenate([log_ratio, table], axis=-1)
    return np.ascontiguousarray(packed.reshape(-1, *packed.shape[-2:]), dtype)


def _interpolation(value, nodes):
    """(low index, fraction) of linear interpolation in log value between log-spaced nodes, clamped."""
    position = np.interp(np.log(value), np.log(nodes), np.arange(len(nodes)))
    low = np.clip(np.floor(position).astype(int), 0, len(nodes) - 2)
    return low, (position - low)[..., None, None]


def _normalized_frame(width_x, width_y, ratio_min):
    """(long_is_x, long width, short / long ratio clamped to [ratio_min, 1])."""
    long_is_x = width_x >= width_y
    long_width = np.maximum(np.where(long_is_x, width_x, width_y), 1e-12)
    ratio = np.clip(np.where(long_is_x, width_y, width_x) / long_width, ratio_min, 1.0)
    return long_is_x, long_width, ratio


def _lobes_of_entry(entry, long_is_x, long_width, peak, dtype):
    """Table entries (..., K, 3) scaled back from slopes / the long width: axis = normalize(offset * width along
    the long axis, 0 across, 1), sharpness = s / width^2, amplitude = a D(n)."""
    slope = entry[..., 0] * long_width[..., None]
    inverse_length = 1 / np.sqrt(1 + slope * slope)
    tilt = slope * inverse_length
    axis = np.zeros(slope.shape + (3,), dtype)
    long_x = np.broadcast_to(long_is_x[..., None], slope.shape)
    axis[..., 0] = np.where(long_x, tilt, 0)
    axis[..., 1] = np.where(long_x, 0, tilt)
    axis[..., 2] = inverse_length
    return axis, entry[..., 1] / (long_width * long_width)[..., None], entry[..., 2] * peak[..., None]


def anisotropic_lobes(width_x, width_y, peak, lobe_count, mapping_kind=None, weighting=PLANE_L2):
    """K SG lobes of an anisotropic NDF with small-angle Gaussian widths (width_x, width_y)
    (slopes) and peak value D(n), from the normalized table; arrays broadcast.

    mapping_kind (a key of ISOTROPIC_MAPPINGS: "WARD_ISO" for Ward, "BLINN_PHONG"
    for Ashikhmin-Shirley) corrects the small-angle scaling for broad lobes: every
    lobe's sharpness is multiplied by S(w)/2 and amplitude by A(w), the isotropic L2
    mapping at the geometric-mean width w = sqrt(width_x width_y).  Exact for the
    isotropic case; measured on Ward (0.5, 0.5) 0.195 -> 0.066 and (0.8, 0.4)
    0.28 -> 0.15 relative L2 (4 lobes), never worse on the cases tried.

    Returns axis (..., K, 3), sharpness (..., K), amplitude (..., K).
    """
    width_x, width_y, peak = np.broadcast_arrays(np.asarray(width_x), np.asarray(width_y), np.asarray(peak))
    dtype = np.result_type(width_x, width_y, peak, np.float32)
    ratios, table = anisotropy_table(lobe_count, weighting)
    long_is_x, long_width, ratio = _normalized_frame(width_x, width_y, ratios[0])
    low, fraction = _interpolation(ratio, ratios)
    entry = (1 - fraction) * table[low] + fraction * table[low + 1]
    axis, sharpness, amplitude = _lobes_of_entry(entry, long_is_x, long_width, peak, dtype)
    if mapping_kind is not None:
        scaled_sharpness, relative_amplitude = isotropic_mapping(
            mapping_kind, np.sqrt(width_x.astype(np.float64) * width_y.astype(np.float64)))
        sharpness = sharpness * (0.5 * scaled_sharpness)[..., None]
        amplitude = amplitude * relative_amplitude[..., None]
    return axis, sharpness.astype(dtype), amplitude.astype(dtype)


# ----------------------------------------------------------------------------- anisotropic GGX's table

# The anisotropic GGX table's alphas (the geometric mean sqrt(alpha_x alpha_y)): every other alpha of
# ggx_two_lobe_table from 0.025, below which its lobes change by under 0.3%; and its ratios, twice as dense
# as Ward's table: at 25 the lobes between two rows were up to 1.26x as far from GGX (relative L2 of D) as the
# rows' own, at 49 1.07x (tests/core/test_ndf_fit.py).
GGX_ANISOTROPY_ALPHAS = np.geomspace(10 ** -1.6, 1.0, 9)
GGX_ANISOTROPY_RATIO_COUNT = 49


def ggx_composed_target(ratio, alpha):
    """GGX's two isotropic lobes at alpha (ggx_two_lobes, fitted on the sphere) stretched to ratio r, as the
    Gaussian mixture _plane_fit takes: sum_c a_c exp(-(s_c / 2)(x^2 + y^2/r^2)) with x, y the slopes / alpha_x
    (the long axis), s_c = sharpness_c alpha^2 and a_c = amplitude_c / D(n).  Isotropic (r = 1), a row that
    holds these two lobes is GGX's sphere fit at any alpha; the plain small-angle GGX 1/(1 + x^2 + y^2/r^2)^2
    would lose that for broad lobes (alpha = 0.6: relative L2 of D 0.02 -> 0.36)."""
    entry = _ggx_two_lobe_entry(np.float64(alpha))
    half_sharpness = 0.5 * entry[:, 0]
    return entry[:, 1], half_sharpness, half_sharpness / (ratio * ratio)


@functools.lru_cache(maxsize=None)
def ggx_anisotropy_table(lobe_count, weighting=LIGHT_WEIGHTED):
    """(alphas (A,), ratios (R,), table (A, R, K, 3)): anisotropic GGX's K lobes fitted jointly to
    ggx_composed_target at each alpha and ratio (_fit_table), table[..., :] = (offset along the long axis /
    alpha_x, sharpness * alpha_x^2, amplitude / D(n)).  About 3-8 s a lobe count (2-8), cached on disk by
    the renderer."""
    if not 2 <= lobe_count <= MAX_LOBES:
        raise ValueError(f"lobe_count must be in 2..{MAX_LOBES}")
    ratios = np.geomspace(ANISOTROPY_RATIO_MIN, 1.0, GGX_ANISOTROPY_RATIO_COUNT)
    # two lobes: both at the centre, where a pair could not hold GGX's two isotropic lobes
    centres = 2 if lobe_count == 2 else lobe_count % 2
    table = _order_pairs(np.stack([_fit_table([ggx_composed_target(ratio, alpha) for ratio in ratios], lobe_count,
                                              weighting, centres) for alpha in GGX_ANISOTROPY_ALPHAS]))
    table.setflags(write=False)
    return GGX_ANISOTROPY_ALPHAS, ratios, table


def ggx_anisotropy_table_array(lobe_count, weighting=LIGHT_WEIGHTED, dtype=np.float32):
    """The table as one contiguous array (A R, K, 4) for GPU upload, alpha's blocks of R rows one after the
    other: (log ratio, offset, sharpness * alpha_x^2, amplitude / D(n))."""
    _, ratios, table = ggx_anisotropy_table(lobe_count, weighting)
    return _with_log_ratio(ratios, table, dtype)


def ggx_anisotropic_lobes(alpha_x, alpha_y, lobe_count, weighting=LIGHT_WEIGHTED):
    """SG lobes of anisotropic GGX (alphas along x and y; arrays broadcast) from ggx_anisotropy_table,
    interpolated bilinearly in log ratio and log sqrt(alpha_x alpha_y).  One lobe: the Gaussian table's, scaled
    by GGX's one-lobe mapping.

    Before it, GGX's two isotropic lobes were each stretched and made of half the count from Ward's table, one
    fitted without the other; fitted together, at (0.17, 0.048) the relative L2 of D falls 0.345 -> 0.265 at 4
    lobes and 0.15 -> 0.10 at 8, and the lobes alone under an environment 0.21 -> 0.15 and 0.12 -> 0.10
    (tests/core/test_environment_specular.py, test_models.py); isotropic rows are the two-lobe fit as before.
    Returns axis (..., K, 3), sharpness (..., K), amplitude (..., K)."""
    alpha_x, alpha_y = np.broadcast_arrays(np.asarray(alpha_x), np.asarray(alpha_y))
    dtype = np.result_type(alpha_x, alpha_y, np.float32)
    alpha_x, alpha_y = np.maximum(alpha_x, 1e-6), np.maximum(alpha_y, 1e-6)     # D(n) stays finite, as in GLSL
    peak = 1 / (np.pi * alpha_x * alpha_y)
    if lobe_count <= 1:
        return anisotropic_lobes(alpha_x, alpha_y, peak, 1, "GGX")
    alphas, ratios, table = ggx_anisotropy_table(lobe_count, weighting)
    long_is_x, long_width, ratio = _normalized_frame(alpha_x, alpha_y, ratios[0])
    ratio_low, ratio_fraction = _interpolation(ratio, ratios)
    alpha_low, alpha_fraction = _interpolation(np.clip(np.sqrt(alpha_x * alpha_y), alphas[0], 1.0), alphas)
    entry = sum(weight * table[alpha_low + da, ratio_low + dr]
                for da, alpha_weight in ((0, 1 - alpha_fraction), (1, alpha_fraction))
                for dr, weight in ((0, alpha_weight * (1 - ratio_fraction)), (1, alpha_weight * ratio_fraction)))
    axis, sharpness, amplitude = _lobes_of_entry(entry, long_is_x, long_width, peak, dtype)
    return axis, sharpness.astype(dtype), amplitude.astype(dtype)


# ----------------------------------------------------------------------------- error measures

def ndf_l2_error(model, lobes, nodes_per_segment=24, phi_count=192):
    """Relative L2 over the hemisphere of the SG mixture ``lobes`` = (axis (K,3), sharpness (K,),
    amplitude (K,)) against the model's exact D (uniform-parameter models)."""
    directions, weights = hemisphere_quadrature(model.ndf_widths(), nodes_per_segment, phi_count)
    axis, sharpness, amplitude = (np.asarray(a, np.float64) for a in lobes)
    cosine = directions @ axis.T
    approximation = np.sum(amplitude * np.exp(sharpness * np.minimum(cosine - 1, 0)), axis=-1)
    return float(relative_l2(model.ndf(directions), approximation, weights))


def brdf_relative_rmse(model, lobes, count=200_000, seed=0):
    """Relative RMSE over (o, i) in hemisphere x hemisphere of the cosine-weighted specular
    BRDF with D replaced by the SG mixture: sqrt(int (M (D* - D) n.i)^2 / int (M D n.i)^2).

    Monte Carlo with a defensive mixture: wi half from the model's sampler, half uniform,
    o uniform on the hemisphere; the same samples in numerator and denominator.
    """
    rng = np.random.default_rng(seed)
    wo = rng.normal(size=(count, 3))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo[:, 2] = np.abs(wo[:, 2])
    uniform = rng.normal(size=(count, 3))
    uniform /= np.linalg.norm(uniform, axis=-1, keepdims=True)
    uniform[:, 2] = np.abs(uniform[:, 2])
    sampled, _ = model.sample(wo, rng.random((count, 2)))
    wi = np.where((rng.random(count) < 0.5)[:, None], sampled, uniform)
    density = 0.5 * model.pdf(wo, wi) + 0.5 * np.where(wi[:, 2] > 0, 1 / (2 * np.pi), 0)
    h = wo + wi
    h /= np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-30)
    axis, sharpness, amplitude = (np.asarray(a, np.float64) for a in lobes)
    approximation = np.sum(amplitude * np.exp(sharpness * np.minimum(h @ axis.T - 1, 0)), axis=-1)
    weight = model.m_factor(wo, wi) * np.maximum(wi[:, 2], 0)
    exact = weight * model.ndf(h)
    fitted = weight * np.where(h[:, 2] > 0, approximation, 0)
    safe = np.where(density > 0, density, 1)
    numerator = np.sum(np.where(density > 0, (fitted - exact) ** 2 / safe, 0))
    denominator = np.sum(np.where(density > 0, exact ** 2 / safe, 0))
    return float(np.sqrt(numerator / max(denominator, 1e-300)))

