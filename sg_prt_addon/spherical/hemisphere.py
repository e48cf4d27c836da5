"""Integral of a spherical Gaussian over a hemisphere at any angle: wang2009's fh.

Definition (wang2009 eq. 25-31, section 5.3).  For an SG with axis p and
sharpness lambda, and a hemisphere H(m) = {i : i.m >= 0} whose boundary great
circle lies at signed angular distance theta_d from p (positive: p inside H),
i.e. m.p = sin(theta_d),

    fh(theta_d, lambda) = integral over H(m) of exp(lambda (i.p - 1)) di.

Anchors: fh(pi/2) = (2 pi / lambda)(1 - e^-lambda) (hemisphere centred on the
axis, ``sg.axis_hemisphere_integral``); fh(0) = half the sphere integral;
fh(-pi/2) = sphere integral - fh(pi/2); fh(t) + fh(-t) = sphere integral.
Our copy of the paper garbles eq. 27-30; the definition above is the one its
text and eq. 31 imply.  An SSDF reconstructs visibility as one hemisphere, so
|theta_d| > pi/2 saturates: theta_d is clamped to [-pi/2, pi/2] everywhere here.

Normalized form (eq. 46): fh_hat = fh / fh(pi/2), in [e^-lambda, 1].
It is convenient to write fh_hat = e^-lambda + (1 - e^-lambda) (1 + g) / 2,
where g(theta_d) is odd in theta_d with g(+-pi/2) = +-1 (this follows from
fh(t) + fh(-t) = sphere integral).  g -> sin(theta_d) as lambda -> 0 and
g -> erf(sqrt(lambda/2) theta_d) as lambda -> infinity.

Fast form (ours, fitted with scipy; docs/ACCURACY.md has its measured error):

    x = sin(theta_d) = p.m
    g = erf(k x (1 - (1 - x^2)/9)) / erf(k)
    k^2 = (81/128) lambda + C0 + (C1 lambda + C2) / (lambda^2 + C3 lambda + C4)

with erf itself replaced by erf(y) ~ sign(y) sqrt(1 - exp(-y^2 (4/pi + a y^2) / (1 + a y^2)))
(GLSL has no erf).  81/128 makes k (8/9) = sqrt(lambda/2), the exact sharp-lobe
limit; the cubic warp of x and the rational term absorb the moderate-lambda
shape.  Max abs error of fh_hat about 0.0015 over lambda in [0.1, 1e5].
``derive_fast_constants()`` re-runs the fit (its minimax lands on nearby
constants with the same 0.0014 error; the ones below are rounded to 4 digits).

Exact values: ``fh_exact`` integrates over rings around m, where the SG's ring
average is a Bessel function (smooth integrand, scipy quad, relative 1e-11).

eq. 31 comes in two forms: ``visibility_product`` as printed (amplitude times
fh / fh(pi/2)) and ``visibility_product_integral_preserving``, whose lobe
integrates over the sphere to mu fh exactly as the text intends (the printed one
over-counts by 1 + e^-lambda).  Either is exact only when applied to the lobe
that is integrated last (the product of all SG factors).
"""
import numpy as np

from . import sg

# erf approximation constant (fitted, minimax absolute error 1.05e-4 on [0, inf)).
ERF_APPROX_A = 0.1478
# Cubic warp of x = sin(theta_d): x (1 + FH_SHAPE_B (1 - x^2)).
FH_SHAPE_B = -1.0 / 9.0
# k^2 = FH_K2_SLOPE lambda + C0 + (C1 lambda + C2) / (lambda^2 + C3 lambda + C4); min over lambda >= 0 is 0.3586.
FH_K2_SLOPE = 81.0 / 128.0
FH_K2_C0 = -0.3975
FH_K2_C1 = -1.893
FH_K2_C2 = 3.341
FH_K2_C3 = 0.3843
FH_K2_C4 = 4.419
# Sharpness beyond which the fast form is a step to rounding; clamp to keep lambda^2 finite in float32.
_MAX_SHARPNESS = 1e8


HALF_PI = 0.5 * np.pi


def erf_approx(y):
    """erf(y) in a GLSL-portable form (one exp, one sqrt), max abs error 1.1e-4.

    Form of Winitzki's approximation with our own minimax constant ERF_APPROX_A.
    """
    y = np.asarray(y)
    dtype = sg._float_dtype(y)
    y = y.astype(dtype, copy=False)
    # erf(6) == 1 to float64 rounding; clamping keeps y^4 finite.
    y_abs = np.minimum(np.abs(y), dtype.type(6))
    y2 = y_abs * y_abs
    a = dtype.type(ERF_APPROX_A)
    exponent = y2 * (dtype.type(4 / np.pi) + a * y2) / (1 + a * y2)
    # (0-d float32 arithmetic with Python scalars promotes: cast back)
    return (np.sign(y) * np.sqrt(-np.expm1(-exponent))).astype(dtype, copy=False)


def clamp_theta(theta_d):
    theta_d = np.asarray(theta_d)
    return np.clip(theta_d, -HALF_PI, HALF_PI).astype(sg._float_dtype(theta_d), copy=False)


def fh_k(sharpness):
    """Steepness k(lambda) of the fast form (see module docstring); always >= 0.598."""
    lam = np.minimum(np.maximum(np.asarray(sharpness), 0), _MAX_SHARPNESS)
    rational = (FH_K2_C1 * lam + FH_K2_C2) / (lam * lam + FH_K2_C3 * lam + FH_K2_C4)
    return np.sqrt(FH_K2_SLOPE * lam + FH_K2_C0 + rational)


def fh_normalized_from_sine(sine_theta_d, sharpness):
    """Fast fh_hat given sin(theta_d) = p.m directly (no trig): the form shaders use.

    Returns values in [0, 1] with the dtype of the inputs.
    """
    x = np.asarray(sine_theta_d)
    lam = np.asarray(sharpness)
    dtype = sg._float_dtype(x, lam)
    x = np.clip(x.astype(dtype, copy=False), -1, 1)
    lam = np.maximum(lam.astype(dtype, copy=False), 0)
    k = fh_k(lam).astype(dtype, copy=False)
    warped = x * (1 + dtype.type(FH_SHAPE_B) * (1 - x * x))
    g = erf_approx(k * warped) / erf_approx(k)
    lower = np.exp(-lam)  # fh_hat(-pi/2) = e^-lambda
    value = lower + (1 - lower) * (dtype.type(0.5) + dtype.type(0.5) * g)
    return np.clip(value, 0, 1).astype(dtype, copy=False)


def fh_normalized(theta_d, sharpness):
    """Fast fh_hat(theta_d, lambda) = fh / fh(pi/2) (wang2009 eq. 46), theta_d clamped to +-pi/2."""
    return fh_normalized_from_sine(np.sin(clamp_theta(theta_d)), sharpness)


def fh(theta_d, sharpness):
    """Fast fh(theta_d, lambda) = fh_hat * (2 pi / lambda)(1 - e^-lambda)."""
    normalized = fh_normalized(theta_d, sharpness)
    return normalized * sg.axis_hemisphere_integral(np.asarray(sharpness, normalized.dtype)).astype(normalized.dtype)


def _hemisphere_quadrature(sine_theta_d, sharpness, cosine_weighted):
    """Integral over H(m) of exp(lambda (i.p - 1)) [times i.m if cosine_weighted], by quad.

    Rings around m: with i.m = cos(a) and p.m = sin(t), averaging the SG over
    the ring gives a modified Bessel function, so
        fh = 2 pi int_0^{pi/2} exp(lambda (sin(a + t) - 1)) i0e(lambda cos(t) sin(a)) sin(a) da,
    a smooth integrand (i0e keeps it overflow-free), peaked at a = pi/2 - t
    with width ~ 1/sqrt(lambda); the integration is restricted to where the
    exponent is within 60 of its maximum, whose value is factored out.
    """
    # scipy here and in derive_fast_constants (references and derivations only): every process that renders
    # would otherwise import scipy.integrate and scipy.optimize, about 0.2 s
    from scipy import integrate, special

    x = float(np.clip(sine_theta_d, -1.0, 1.0))
    lam = float(max(sharpness, 0.0))
    t = np.arcsin(x)
    cos_t = np.sqrt(max(0.0, 1.0 - x * x))
    peak = HALF_PI - max(t, 0.0)  # argmax of sin(a + t) on [0, pi/2]
    peak_exponent = lam * (np.sin(peak + t) - 1.0)
    # Half-width where lambda (max - sin(a + t)) reaches 60 (the drop is >= that of a centred peak).
    offset = max(-t, 0.0)
    cos_edge = np.cos(offset) - (60.0 / lam if lam > 0 else np.inf)
    width = np.pi if cos_edge <= -1.0 else np.arccos(cos_edge) - offset
    lo, hi = max(0.0, peak - width), min(HALF_PI, peak + width)

    def integrand(a):
        value = np.exp(lam * (np.sin(a + t) - 1.0) - peak_exponent) * special.i0e(lam * cos_t * np.sin(a)) * np.sin(a)
        return value * np.cos(a) if cosine_weighted else value

    points = [peak] if lo < peak < hi else None
    value, _ = integrate.quad(integrand, lo, hi, points=points, epsabs=0.0, epsrel=1e-11, limit=200)
    return sg.TWO_PI * value * np.exp(peak_exponent)


def _quadrature_array(sine_theta_d, sharpness, cosine_weighted):
    x, lam = np.broadcast_arrays(np.asarray(sine_theta_d, np.float64), np.asarray(sharpness, np.float64))
    out = np.empty(x.shape)
    for index in np.ndindex(x.shape):
        out[index] = _hemisphere_quadrature(x[index], lam[index], cosine_weighted)
    return out


def fh_exact(theta_d, sharpness):
    """fh(theta_d, lambda) by adaptive quadrature (relative precision ~1e-11), float64.

    Works for lambda in [0, 1e6]; about 1 ms per value.
    """
    return _quadrature_array(np.sin(clamp_theta(np.asarray(theta_d, np.float64))), sharpness, False)


def fh_normalized_exact(theta_d, sharpness):
    """fh_exact / fh(pi/2), with fh(pi/2) in closed form."""
    return fh_exact(theta_d, sharpness) / sg.axis_hemisphere_integral(np.asarray(sharpness, np.float64))


def _sine_to_normal(axis, normal):
    axis = sg.normalize(axis)
    normal = sg.normalize(normal)
    return np.clip(np.sum(axis * normal, axis=-1), -1, 1)


def hemisphere_integral(axis, sharpness, amplitude, normal):
    """Fast integral of G(i; p, lambda, mu) over {i : i.n >= 0}: mu fh(theta_d) with sin(theta_d) = p.n."""
    sine = _sine_to_normal(axis, normal)
    normalized = fh_normalized_from_sine(sine, sharpness)
    dtype = normalized.dtype
    upper = sg.axis_hemisphere_integral(np.maximum(np.asarray(sharpness, dtype), 0))
    return (np.asarray(amplitude) * normalized * upper).astype(dtype, copy=False)


def hemisphere_integral_exact(axis, sharpness, amplitude, normal):
    """Quadrature version of hemisphere_integral (float64)."""
    sine = _sine_to_normal(np.asarray(axis, np.float64), np.asarray(normal, np.float64))
    return np.asarray(amplitude) * _quadrature_array(sine, sharpness, False)


def visibility_product(axis, sharpness, amplitude, theta_d):
    """G (x) V ~ G(i; p, lambda, mu fh(theta_d) / fh(pi/2)) (wang2009 eq. 31), fast fh.

    The product with the SSDF-reconstructed hemispherical visibility keeps the
    axis and sharpness and rescales the amplitude so that the integral matches.
    Returns (axis, sharpness, amplitude).

    Exact (up to fh) only for the lobe that is integrated last, i.e. the
    product of all SG factors (wang2009 eq. 39 forms C* (x) L* first).  Applied
    to one factor before multiplying by a second SG H, the error reaches 100%
    of the integral of G H when H is as sharp as G or sharper (measured in
    benchmarks/accuracy/hemisphere.py); it stays small only for H much broader.
    """
    normalized = fh_normalized(theta_d, sharpness)
    return axis, sharpness, (np.asarray(amplitude) * normalized).astype(normalized.dtype, copy=False)


def visibility_product_integral_preserving(axis, sharpness, amplitude, theta_d):
    """eq. 31 with the normalization its text asks for: the returned lobe's integral over
    the whole sphere equals mu fh(theta_d) (fast fh).

    The printed eq. 31 divides by fh(pi/2) = (2 pi / lambda)(1 - e^-lambda), the
    integral over the lobe's own hemisphere, while the lobe is then integrated
    over the sphere, (2 pi / lambda)(1 - e^-2 lambda): that over-counts by the
    factor 1 + e^-lambda (12% for the eq. 40 cosine lobe, lambda = 2.133; 37% at
    lambda = 1; negligible above lambda ~ 10).  Here amplitude * fh_hat / (1 + e^-lambda).
    """
    normalized = fh_normalized(theta_d, sharpness)
    lam = np.maximum(np.asarray(sharpness, normalized.dtype), 0)
    scale = normalized / (1 + np.exp(-lam))
    return axis, sharpness, (np.asarray(amplitude) * scale).astype(normalized.dtype, copy=False)


def disc_coverage(signed_distance, radius):
    """Visible share of a disc of angular ``radius`` whose centre lies ``signed_distance`` (+ visible) from a
    straight boundary: the disc's area beyond a chord (a small disc's, as on a plane)."""
    x = np.clip(np.asarray(signed_distance, np.float64) / np.maximum(radius, 1e-30), -1.0, 1.0)
    return np.clip(0.5 + (np.arcsin(x) + x * np.sqrt(1.0 - x * x)) / np.pi, 0.0, 1.0)


def derive_fast_constants(n_sharpness=43, seed_constants=None):
    """Re-derive ERF_APPROX_A and the FH_K2_* constants with scipy (about 10 s); returns a dict
    with the constants and the max abs error of fh_hat on the fitting grid.

    Grid: lambda log-spaced in [0.1, 1e5]; x = sin(theta_d) on (0, 1) plus a band of
    6 / sqrt(lambda) (g is odd, so x >= 0 suffices).  Steps: (1) minimax a of the erf
    form on [0, 6]; (2) per lambda, the k minimizing the max error with the -1/9 warp;
    (3) least squares of the rational k^2 to those; (4) Nelder-Mead minimax of all of
    fh_hat's error over the grid, starting from (3).
    """
    from scipy import optimize, special

    y = np.linspace(0, 6, 20001)

    def erf_error(a):
        y2 = y * y
        return np.max(np.abs(np.sqrt(-np.expm1(-y2 * (4 / np.pi + a * y2) / (1 + a * y2))) - special.erf(y)))

    erf_a = optimize.minimize_scalar(erf_error, bounds=(0.1, 0.2), method="bounded", options=dict(xatol=1e-10)).x

    lams = np.geomspace(0.1, 1e5, n_sharpness)
    xs, targets, lam_of = [], [], []
    for lam in lams:
        x = np.unique(np.concatenate([np.linspace(0, 1, 81)[1:-1], np.linspace(0, min(1, 6 / np.sqrt(lam)), 41)[1:-1]]))
        xs.append(x)
        targets.append(fh_normalized_exact(np.arcsin(x), lam))
        lam_of.append(np.full(x.shape, lam))
    x_all, target_all, lam_all = map(np.concatenate, (xs, targets, lam_of))

    def model(x, lam, k):
        g = special.erf(k * x * (1 + FH_SHAPE_B * (1 - x * x))) / special.erf(k)
        lower = np.exp(-lam)
        return lower + (1 - lower) * (0.5 + 0.5 * g)

    best_k = []
    for x, target, lam in zip(xs, targets, lams):
        fit = optimize.minimize_scalar(lambda log_k: np.max(np.abs(model(x, lam, np.exp(log_k)) - target)),
                                       bounds=(-8, 8), method="bounded", options=dict(xatol=1e-9))
        best_k.append(np.exp(fit.x))
    best_k = np.array(best_k)

    def k_squared(params, lam):
        c0, c1, c2, c3, c4 = params
        return FH_K2_SLOPE * lam + c0 + (c1 * lam + c2) / (lam * lam + c3 * lam + c4)

    moderate = lams < 200
    start = seed_constants if seed_constants is not None else [-0.47, 0.0, 0.4, 1.0, 1.0]
    least_squares = optimize.least_squares(
        lambda p: (k_squared(p, lams[moderate]) - best_k[moderate] ** 2) / np.sqrt(best_k[moderate] ** 2 + 0.3), start)

    def grid_error(params):
        k2 = k_squared(params, lam_all)
        if np.any(k2 <= 0):
            return np.inf
        return np.max(np.abs(model(x_all, lam_all, np.sqrt(k2)) - target_all))

    minimax = optimize.minimize(grid_error, least_squares.x, method="Nelder-Mead",
                                options=dict(maxiter=40000, xatol=1e-9, fatol=1e-11, adaptive=True))
    c0, c1, c2, c3, c4 = minimax.x
    return dict(ERF_APPROX_A=erf_a, FH_K2_C0=c0, FH_K2_C1=c1, FH_K2_C2=c2, FH_K2_C3=c3, FH_K2_C4=c4,
                max_error=minimax.fun)
