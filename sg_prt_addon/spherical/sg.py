"""Spherical Gaussian algebra (wang2009 section 3), in numerically stable forms.

An SG is G(v; p, lambda, mu) = mu * exp(lambda * (v.p - 1)).  Lobes are passed
as separate broadcastable arrays: ``axis`` (..., 3) unit vectors, ``sharpness``
(...) and ``amplitude`` (...) (or (..., C) for colour, broadcast by the caller).

Every function keeps the floating dtype of its inputs (float32 stays float32)
and is safe for sharpness in [0, 1e6], opposite or equal axes, and zero
amplitudes: the forms below never evaluate exp of a large positive number and
never subtract two nearly equal large numbers.
"""
import math

import numpy as np

FOUR_PI = 4.0 * np.pi
TWO_PI = 2.0 * np.pi


def _float_dtype(*arrays):
    """Floating dtype of the inputs; 0-d inputs (Python scalars) only decide when all inputs are 0-d."""
    arrays = [np.asarray(a) for a in arrays]
    shaped = [a.dtype for a in arrays if a.ndim > 0]
    return np.result_type(*(shaped or [a.dtype for a in arrays]), np.float32)


def one_minus_exp_over_x(x):
    """(1 - exp(-x)) / x for x >= 0, exact to rounding near 0 (limit 1)."""
    x = np.asarray(x)
    dtype = _float_dtype(x)
    safe = np.where(x > 0, x, 1)
    # np.where on 0-d inputs promotes to float64: restore the input's precision.
    return np.where(x > 1e-12, -np.expm1(-safe) / safe, 1 - 0.5 * x).astype(dtype, copy=False)


def normalize(v, fallback=(0.0, 0.0, 1.0)):
    """Unit vectors along the last axis; zero or non-finite vectors give ``fallback``."""
    v = np.asarray(v)
    dtype = _float_dtype(v)
    v = v.astype(dtype, copy=False)
    length = np.sqrt(np.sum(v * v, axis=-1, keepdims=True))
    ok = np.isfinite(length) & (length > np.finfo(dtype).tiny * 1e4)
    out = v / np.where(ok, length, 1)
    return np.where(ok, out, np.asarray(fallback, dtype))


def evaluate(direction, axis, sharpness, amplitude=1.0):
    """G(v; p, lambda, mu) = mu exp(lambda (v.p - 1)) (wang2009 eq. 2), evaluated as
    mu exp(-lambda/2 |v - p|^2): equal for unit vectors, without cancellation of
    v.p - 1 near the axis."""
    dtype = _float_dtype(direction, axis, sharpness, amplitude)
    d = np.asarray(direction, dtype) - np.asarray(axis, dtype)
    value = np.asarray(amplitude) * np.exp(-0.5 * np.asarray(sharpness, dtype) * np.sum(d * d, axis=-1))
    return value.astype(dtype, copy=False)


def product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2):
    """Vector product G1 (x) G2 = G(v; p_m, lambda_m, mu_m) (wang2009 eq. 5).

    lambda_m = |l1 p1 + l2 p2|; the log amplitude lambda_m - l1 - l2 is formed as
    -l1 l2 |p1 - p2|^2 / (lambda_m + l1 + l2), which never cancels.  When the
    sum vanishes (opposite axes, equal sharpness) the product is constant and
    the axis is arbitrary: axis1 is returned.
    """
    axis1, axis2 = np.asarray(axis1), np.asarray(axis2)
    l1, l2 = np.asarray(sharpness1), np.asarray(sharpness2)
    summed = l1[..., None] * axis1 + l2[..., None] * axis2
    sharpness = np.sqrt(np.sum(summed * summed, axis=-1))
    diff = axis1 - axis2
    denominator = sharpness + l1 + l2
    log_amplitude = -l1 * l2 * np.sum(diff * diff, axis=-1) / np.where(denominator > 0, denominator, 1)
    amplitude = np.asarray(amplitude1) * np.asarray(amplitude2) * np.exp(log_amplitude)
    dtype = _float_dtype(summed)
    nonzero = sharpness > np.finfo(dtype).tiny * 1e4
    axis = np.where(nonzero[..., None], summed / np.where(nonzero, sharpness, 1)[..., None], axis1)
    # np.where on 0-d inputs promotes to float64: restore the inputs' precision.
    return axis.astype(dtype, copy=False), sharpness.astype(dtype, copy=False), amplitude.astype(dtype, copy=False)


def sphere_integral(sharpness, amplitude=1.0):
    """Integral of G over the sphere: 4 pi mu (1 - exp(-2 lambda)) / (2 lambda)."""
    dtype = _float_dtype(sharpness, amplitude)  # Python scalars times 0-d float32 promote to float64
    sharpness = np.asarray(sharpness, dtype)
    return (FOUR_PI * np.asarray(amplitude) * one_minus_exp_over_x(2 * sharpness)).astype(dtype, copy=False)


def axis_hemisphere_integral(sharpness, amplitude=1.0):
    """Integral of G over the hemisphere centred on its own axis: 2 pi mu (1 - e^-lambda) / lambda.

    This is fh(pi/2, lambda) of wang2009 eq. 31; do not confuse it with the
    full-sphere integral above.
    """
    dtype = _float_dtype(sharpness, amplitude)
    sharpness = np.asarray(sharpness, dtype)
    return (TWO_PI * np.asarray(amplitude) * one_minus_exp_over_x(sharpness)).astype(dtype, copy=False)


def inner_product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2):
    """Integral over the sphere of G1 G2 (wang2009 eq. 4) in overflow-free form.

    4 pi mu1 mu2 sinh(d)/d exp(-(l1 + l2)) is rewritten as
    sphere_integral of the product lobe: (1 - e^-2d)/(2d) * 4 pi * mu_m.
    """
    _, sharpness, amplitude = product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2)
    return sphere_integral(sharpness, amplitude)


def rotate(axis, rotation):
    """Rotate lobe axes by a 3x3 matrix (or a stack of them); sharpness and amplitude are
    unchanged since an SG is symmetric about its axis (wang2009 section 3)."""
    return np.einsum("...ij,...j->...i", np.asarray(rotation), np.asarray(axis))


def support_area(sharpness, epsilon=0.1):
    """fa(lambda) of wang2009 eq. 3: solid angle where G(v; z, lambda, 1) >= epsilon.

    The region is the cap cos(theta) >= 1 + ln(epsilon) / lambda, so this is exact for
    lambda >= -ln(epsilon) / 2 (below, the cap would exceed the sphere); for
    lambda > -ln(epsilon) the cap lies within a hemisphere.  The paper uses epsilon = 0.1."""
    # math.log: a Python float keeps float32 input float32 under NumPy 2's promotion (a NumPy float64 would not)
    return -TWO_PI * math.log(epsilon) / np.asarray(sharpness)


def sharpness_from_area(area, epsilon=0.1):
    """Inverse of support_area."""
    return -TWO_PI * math.log(epsilon) / np.asarray(area)


def mixture_evaluate(direction, axes, sharpnesses, amplitudes):
    """Sum of lobes (last axis of sharpnesses indexes lobes) evaluated at direction (..., 3)."""
    direction = np.asarray(direction)[..., None, :]
    return np.sum(evaluate(direction, axes, sharpnesses, amplitudes), axis=-1)


def convolution_lobe(sharpness1, amplitude1, sharpness2, amplitude2):
    """iwasaki2012 eq. 14: the convolution of two SGs, as a function of the angle between their axes, taken
    as one SG in that angle: (sharpness l1 l2 / (l1 + l2), amplitude 2 pi mu1 mu2 / (l1 + l2)).  Exact at
    coincident axes up to e^-2(l1 + l2); inner_product is the exact convolution."""
    l1, l2 = np.asarray(sharpness1), np.asarray(sharpness2)
    total = np.maximum(l1 + l2, np.finfo(_float_dtype(l1, l2)).tiny)
    return l1 * l2 / total, TWO_PI * np.asarray(amplitude1) * np.asarray(amplitude2) / total


def axis_cosine_integral(sharpness):
    """Integral of G(h; n, lambda, 1) (h.n) over the hemisphere around its own axis n:
    2 pi (1 - (1 - e^-lambda) / lambda) / lambda, the projected mass of an NDF lobe (1 for a normalized NDF)."""
    sharpness = np.asarray(sharpness)
    dtype = _float_dtype(sharpness)
    safe = np.where(sharpness > 1e-3, sharpness, 1.0)
    value = np.where(sharpness > 1e-3, (1.0 - one_minus_exp_over_x(safe)) / safe, 0.5 - sharpness / 6.0)
    return (TWO_PI * value).astype(dtype, copy=False)
