"""Projection onto the real SH basis: functions by exact quadrature, equirect images, zonal functions (caps,
the clamped cosine) rotated to any axis, and the windows that trade ringing for blur.

Quadrature: Gauss-Legendre nodes in z = cos(theta) times equally spaced phi integrates every polynomial of
degree < 2 n_z in z and < n_phi in phi exactly, so a band-limited function (or a product of two) is
projected to float precision; discontinuous functions (caps, visibility) converge only as the grid refines.
"""
import math

import numpy as np

from ..lighting import equirect
from . import basis


def sphere_quadrature(z_count, phi_count=None):
    """(directions (K, 3), weights (K,)) of the Gauss-Legendre x uniform-phi rule; the weights sum to 4 pi."""
    phi_count = 2 * z_count if phi_count is None else phi_count
    z, weight_z = np.polynomial.legendre.leggauss(z_count)
    phi = (np.arange(phi_count) + 0.5) * (2 * np.pi / phi_count)
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    directions = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
    weights = np.broadcast_to(weight_z[:, None] * (2 * np.pi / phi_count), (z_count, phi_count))
    return directions.reshape(-1, 3), weights.reshape(-1).copy()


def exact_quadrature(order):
    """A rule that projects any product of two order-``order`` expansions exactly (degree 2 (order - 1))."""
    return sphere_quadrature(order + 1, 2 * order + 1)


def project_samples(directions, values, weights, order):
    """c_i = sum_k w_k f(d_k) Y_i(d_k): (N^2,) or (N^2, C) for values (K,) or (K, C)."""
    y = basis.evaluate(directions, order)
    v = np.asarray(values, np.float64)
    weighted = v * (np.asarray(weights)[:, None] if v.ndim > 1 else np.asarray(weights))
    return y.T @ weighted


def project_function(function, order, z_count=None):
    """Projection of function(directions (K, 3)) -> (K,) or (K, C), by the Gauss-Legendre rule (exact for
    band-limited functions of degree < 2 z_count; default: 4 x the order, plenty for smooth ones)."""
    directions, weights = sphere_quadrature(z_count or 4 * order)
    return project_samples(directions, function(directions), weights, order)


def project_equirect(image, order, window=None):
    """Coefficients (N^2, C) of an equirect environment (H, W, C), row 0 at the top (lighting/equirect.py):
    each texel's radiance at its centre times its exact solid angle; ``window``: None, "hanning" or "lanczos"."""
    image = np.asarray(image, np.float64)
    height, width = image.shape[:2]
    directions = equirect.texel_directions(height, width).reshape(-1, 3)
    weights = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    coefficients = project_samples(directions, image.reshape(height * width, -1), weights, order)
    return apply_window(coefficients, window_factors(window, order))


# ----------------------------------------------------------------------------- windows

WINDOWS = ("hanning", "lanczos")


def window_factors(name, order):
    """sigma_l (order,) of a window over bands 0 .. order - 1: None or "none" -> ones; "hanning":
    (1 + cos(pi l / order)) / 2; "lanczos": sinc(l / order).  Both leave band 0 (the mean) alone."""
    bands = np.arange(order, dtype=np.float64)
    if name is None or name == "none":
        return np.ones(order)
    if name == "hanning":
        return 0.5 * (1.0 + np.cos(np.pi * bands / order))
    if name == "lanczos":
        return np.sinc(bands / order)
    raise ValueError(f"unknown window {name!r}: one of {WINDOWS}")


def apply_window(coefficients, factors):
    """Every coefficient of band l times factors[l]."""
    c = np.asarray(coefficients, np.float64)
    bands, _ = basis.band_of(c.shape[0])
    scale = np.asarray(factors)[bands]
    return c * (scale[:, None] if c.ndim > 1 else scale)


# ----------------------------------------------------------------------------- zonal functions

def rotate_zonal(zonal, axis):
    """The coefficients (N^2,) of the zonal function with coefficients zonal[l] (the (l, 0) ones, about +z)
    turned to ``axis``: c_lm = sqrt(4 pi / (2l + 1)) z_l Y_lm(axis)."""
    zonal = np.asarray(zonal, np.float64)
    order = len(zonal)
    bands, _ = basis.band_of(basis.coefficient_count(order))
    axis = np.asarray(axis, np.float64)
    axis = axis / np.linalg.norm(axis, axis=-1, keepdims=True)
    scale = np.sqrt(4 * np.pi / (2 * bands + 1)) * zonal[bands]
    return basis.evaluate(axis, order) * scale


def legendre_polynomials(x, order):
    """P_l(x) for l = 0 .. order (order + 1 arrays, one past the order: cap_zonal needs P_{l+1})."""
    x = np.asarray(x, np.float64)
    values = [np.ones_like(x), x.copy()]
    for band in range(1, order):
        values.append(((2 * band + 1) * x * values[band] - band * values[band - 1]) / (band + 1))
    return values[:order + 1]


def cap_zonal(half_angle, order):
    """z_l of the indicator of a cap of angular radius half_angle about +z (1 inside): K_l0 2 pi times
    the integral of P_l over [cos(half_angle), 1], which is (P_{l-1}(x) - P_{l+1}(x)) / (2l + 1)."""
    x = math.cos(float(half_angle))
    p = legendre_polynomials(x, order)
    zonal = np.empty(order)
    zonal[0] = 1.0 - x
    for band in range(1, order):
        zonal[band] = (p[band - 1] - p[band + 1]) / (2 * band + 1)
    return zonal * 2 * np.pi * np.array([basis.normalization(band, 0) for band in range(order)])


def cap_coefficients(axis, half_angle, radiance, order):
    """A uniform spherical cap (a sphere light seen from outside it, radiance (C,)) as (N^2, C)."""
    shape = rotate_zonal(cap_zonal(half_angle, order), axis)
    return np.outer(shape, np.atleast_1d(np.asarray(radiance, np.float64)))


def profile_zonal(profile, order, node_count=None):
    """z_l = 2 pi K_l0 integral over [-1, 1] of profile(t) P_l(t) dt for a smooth zonal profile(t) of
    t = cos(theta), by Gauss-Legendre (exact for polynomials of degree < 2 node_count)."""
    t, weight = np.polynomial.legendre.leggauss(node_count or 8 * order + 16)
    p = legendre_polynomials(t, order)
    values = profile(t)
    return np.array([2 * np.pi * basis.normalization(band, 0) * np.sum(weight * values * p[band])
                     for band in range(order)])


def clamped_cosine_zonal(order):
    """z_l of max(cos theta, 0): K_l0 A_l with A_l = 2 pi times the integral of t P_l(t) over [0, 1], in
    Ramamoorthi and Hanrahan 2001's closed form (A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4; odd bands above 1
    vanish)."""
    zonal = np.zeros(order)
    for band in range(order):
        k = basis.normalization(band, 0)
        if band == 0:
            value = np.pi
        elif band == 1:
            value = 2 * np.pi / 3
        elif band % 2:
            value = 0.0
        else:
            half = band // 2
            value = (2 * np.pi * (-1) ** (half - 1) / ((band + 2) * (band - 1))
                     * math.factorial(band) / (2 ** band * math.factorial(half) ** 2))
        zonal[band] = k * value
    return zonal


def convolve_zonal(coefficients, zonal):
    """Funk-Hecke: the convolution of an expansion with a zonal kernel (coefficients zonal[l]) scales band l
    by sqrt(4 pi / (2l + 1)) z_l (irradiance from radiance when the kernel is the clamped cosine)."""
    zonal = np.asarray(zonal, np.float64)
    factors = np.sqrt(4 * np.pi / (2 * np.arange(len(zonal)) + 1)) * zonal
    return apply_window(coefficients, factors)


# ----------------------------------------------------------------------------- lights' zonal factors (the GLSL's)

CAP_SERIES_BELOW = 1e-3         # 1 - cos(half angle) below which cap_factors uses its series
SG_UPWARD_FROM = 10.0           # sharpness from which sg_factors recurs upwards


def cap_factors(epsilon, order, dtype=np.float64):
    """g_l (..., order), g_0 = 1, of uniform caps with 1 - cos(half angle) = epsilon (...): a cap of flux
    Phi (its radiance times its solid angle) about an axis a has coefficients Phi g_l Y_lm(a).  The shader's
    arithmetic: (P_{l-1} - P_{l+1}) / ((2l + 1) epsilon), and below CAP_SERIES_BELOW 1 - l (l + 1) epsilon / 4."""
    epsilon = np.asarray(epsilon, dtype)
    x = 1 - epsilon
    bands = np.arange(order)
    series = 1 - bands * (bands + 1) * epsilon[..., None] * dtype(0.25)
    out = np.ones(epsilon.shape + (order,), dtype)
    before, current = np.ones_like(x), x
    for band in range(1, order):
        following = ((2 * band + 1) * x * current - band * before) / dtype(band + 1)
        out[..., band] = (before - following) / (dtype(2 * band + 1) * np.maximum(epsilon, dtype(1e-30)))
        before, current = current, following
    return np.where((epsilon < CAP_SERIES_BELOW)[..., None], series, out).astype(dtype)


def sg_factors(sharpness, order, dtype=np.float64):
    """g_l (..., order) of SGs of sharpness lambda (...): i_l(lambda) / i_0(lambda), as the shader computes
    them (upward recurrence from SG_UPWARD_FROM, Miller's downward ratios below)."""
    lam = np.maximum(np.asarray(sharpness, dtype), dtype(1e-6))
    out = np.ones(lam.shape + (order,), dtype)
    with np.errstate(over="ignore"):
        e = np.exp(-2 * lam)
    if order > 1:
        out[..., 1] = (1 + e) / (1 - e) - 1 / lam
    for band in range(1, order - 1):
        out[..., band + 1] = out[..., band - 1] - (2 * band + 1) / lam * out[..., band]
    ratios = np.zeros(lam.shape + (order,), dtype)
    r = np.zeros_like(lam)
    for band in range(order + 16, 0, -1):
        r = 1 / ((2 * band + 1) / lam + r)
        if band < order:
            ratios[..., band] = r
    downward = np.cumprod(np.where(np.arange(order) == 0, dtype(1), ratios), axis=-1)
    return np.where((lam >= SG_UPWARD_FROM)[..., None], out, downward).astype(dtype)
