"""The clamped cosine max(0, n.i) and its integral against spherical Gaussians.

wang2009 eq. 39-40 computes diffuse light as the inner product of the lighting
SG with a single-lobe SG fit of the clamped cosine, C*(i; n) = G(i; n, 2.133, 1.170).
That lobe carries 8.2% more energy than the cosine (its sphere integral is
3.40 against pi) and is 17% too bright for sharp lights around the normal.

``sg_clamped_cosine_integral`` replaces it by a closed form of

    I(c, lambda) = integral over the sphere of exp(lambda (i.p - 1)) max(0, n.i) di,
    c = n.p = cos(alpha).

Derivation (ours).  With U = 2 pi / lambda, the two poles are exact:

    I_up  = I(+1) = U (1 - (1 - e^-lambda) / lambda)
    I_low = I(-1) = U e^-lambda ((1 - e^-lambda) / lambda - e^-lambda),

and max(0, x) - max(0, -x) = x gives I(c) - I(-c) = c (I_up - I_low) exactly.
Write I = I_low + (I_up - I_low) s(c).  Under the normalized SG, X = n.i has
mean c L (L = coth(lambda) - 1/lambda, the Langevin function) and variance

    var(c) = c^2 V + across(c) L / lambda,   V = 1/lambda^2 - 1/sinh(lambda)^2 = var(cos theta),

with across = 1 - c^2 for moments matched exactly.  Modelling X as a Gaussian,
E[max(0, X)] = mu Phi(mu / sigma) + sigma phi(mu / sigma) = R(mu, sigma), and
s(c) = (R(c L, sigma(c)) - R(-L, sigma(-1))) / L, which meets both poles and
the odd identity above for any even sigma(c).  Two fitted corrections:
across(c) = (1 - beta)(1 - c^2) + beta (1 + sin(alpha)) / 2 (beta -> 1 for sharp
lobes makes the Gaussian tail exp(-lambda (1 - sin alpha)) exact below the
horizon) and a variance scale f(lambda); both are rational in lambda, fitted
minimax to quadrature over lambda in [1e-3, 1e4] and all c (constants below).
For broad lobes the weight I_up - I_low = O(lambda) makes the shape of s irrelevant.
"""
import functools

import numpy as np

from . import sg
from .hemisphere import erf_approx

# Truncation of the exponential tail e^-t in the ring quadrature: e^-40 = 4e-18.
_TAIL = 40.0
QUADRATURE_NODES = 64


@functools.lru_cache(maxsize=None)
def _clustered_rule(count):
    """Gauss-Legendre nodes mapped to [0, 1] and clustered at both ends by s = (1 - cos(pi u)) / 2, and
    their weights: ring averages have square-root kinks at the ends of each sub-interval, which this
    substitution makes smooth (converged to ~1e-14 at 48 nodes)."""
    nodes, weights = np.polynomial.legendre.leggauss(count)
    u = 0.5 * (nodes + 1.0)
    return 0.5 * (1.0 - np.cos(np.pi * u)), 0.25 * np.pi * weights * np.sin(np.pi * u)


def ring_quadrature(ring_average, sharpness, breakpoints, nodes=QUADRATURE_NODES):
    """(lambda / 2 pi) * integral over the sphere of exp(lambda (i.p - 1)) f(i), as a 1D
    integral over the polar angle theta around p.

    ``ring_average(cos_theta, sin_theta)`` is the mean of f over the ring at polar
    angle theta.  With t = lambda (1 - cos theta) the integral is
    int_0^{2 lambda} e^-t ring_average dt, evaluated in float64 by clustered
    Gauss-Legendre on each sub-interval between ``breakpoints`` (values of t where
    the ring average has a kink), each truncated after e^-40, so lambda up to 1e6
    is as accurate as lambda = 1.  Vectorized: broadcasts over sharpness and breakpoints.
    """
    clustered, clustered_weights = _clustered_rule(nodes)
    sharpness = np.asarray(sharpness, np.float64)
    edges = np.sort(np.stack(np.broadcast_arrays(0.0 * sharpness, *breakpoints, 2.0 * sharpness)), axis=0)
    lam = sharpness[..., None]
    safe = np.where(lam > 0, lam, 1.0)
    total = 0.0
    for start, stop in zip(edges[:-1], edges[1:]):
        length = np.minimum(stop - start, _TAIL)
        offset = length[..., None] * clustered
        t = start[..., None] + offset
        cos_theta = np.clip(1.0 - t / safe, -1.0, 1.0)
        sin_theta = np.sqrt(np.clip(t * (2.0 * lam - t), 0.0, None)) / safe  # no cancellation near the pole
        values = np.exp(-offset) * ring_average(cos_theta, sin_theta)
        total = total + np.exp(-start) * length * np.sum(values * clustered_weights, axis=-1)
    return total

# wang2009 eq. 40: single SG fit of max(0, n.i).
CLAMPED_COSINE_SHARPNESS = 2.133
CLAMPED_COSINE_AMPLITUDE = 1.170

SQRT_TWO = np.sqrt(2.0)
INV_SQRT_TWO_PI = 1.0 / np.sqrt(2.0 * np.pi)


_float_dtype = sg._float_dtype  # same dtype rule as the SG algebra (Python scalars do not promote arrays)


def clamped_cosine_lobe():
    """(sharpness, amplitude) of wang2009 eq. 40's single-lobe fit of max(0, n.i); its axis is n."""
    return CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE


def clamped_cosine_lobe_evaluate(direction, normal):
    """C*(i; n) = G(i; n, 2.133, 1.170) of wang2009 eq. 40."""
    return sg.evaluate(direction, normal, CLAMPED_COSINE_SHARPNESS, CLAMPED_COSINE_AMPLITUDE)


def _cosine(axis, normal):
    """n.p for (unnormalized) axis and normal; degenerate vectors fall back to z+."""
    return np.clip(np.sum(sg.normalize(axis) * sg.normalize(normal), axis=-1), -1.0, 1.0)


def _pole_integrals(sharpness):
    """(I_up, I_low) / (2 pi / lambda): the normal on the lobe axis, and opposite to it."""
    lam = sharpness
    small = lam < 0.25  # below, 1 - (1 - e^-l)/l loses float32 digits: Taylor series (truncation < 1e-11)
    safe = np.where(small, 1, lam)
    x = np.where(small, lam, 0)  # series argument, kept small so no branch can overflow
    # 1 - (1 - e^-l)/l = sum (-1)^(k+1) l^k / (k+1)!,  (1 - e^-l)/l - e^-l = sum (-1)^(k+1) k l^k / (k+1)!
    upper = np.where(small, 0.5 * x * (1 - x * (1 / 3 - x * (1 / 12 - x * (1 / 60 - x * (1 / 360 - x * (1 / 2520 - x * (1 / 20160 - x / 181440))))))),
                     1 - sg.one_minus_exp_over_x(safe))
    lower_moment = np.where(small, 0.5 * x * (1 - x * (2 / 3 - x * (1 / 4 - x * (1 / 15 - x * (1 / 72 - x * (1 / 420 - x * (1 / 2880 - x / 22680))))))),
                            sg.one_minus_exp_over_x(safe) - np.exp(-safe))
    return upper, np.exp(-lam) * lower_moment


def _langevin_moments(sharpness):
    """(L, V): mean and variance of cos(theta) under the normalized SG (von Mises-Fisher):
    L = coth(lambda) - 1/lambda, V = 1/lambda^2 - 1/sinh(lambda)^2, with series where they cancel."""
    lam = sharpness
    small = lam < 0.2
    safe = np.where(small, 1, lam)
    decay = np.exp(-2 * safe)
    one_minus_decay = -np.expm1(-2 * safe)
    series_lam = np.where(small, lam, 0)  # series argument, kept small so no branch can overflow
    square = series_lam * series_lam
    mean = np.where(small, series_lam * (1 / 3 - square / 45 + 2 * square ** 2 / 945 - square ** 3 / 4725),
                    (1 + decay) / one_minus_decay - 1 / safe)
    variance = np.where(small, 1 / 3 - square / 15 + 2 * square ** 2 / 189 - square ** 3 / 675 + 2 * square ** 4 / 10395,
                        (1 / safe) ** 2 - 4 * decay / (one_minus_decay * one_minus_decay))  # (1/l)^2: no overflow
    return mean, np.maximum(variance, 0)


# Fitted constants of the Gaussian model (see module docstring; fit: scipy Nelder-Mead,
# minimax of |error| / I_up on lambda in [1e-3, 1e4] x c in [-1, 1]):
# variance scale f = 1 + (F1 lambda + F0) / (lambda^2 + F3 lambda + F2)  (denominator > 0)
VARIANCE_F1 = 0.35459
VARIANCE_F0 = -0.96364
VARIANCE_F3 = -2.42236
VARIANCE_F2 = 4.64645
# tail blend beta = lambda^P / (lambda^P + B)
TAIL_POWER = 2.94198
TAIL_OFFSET = 43.2488
# the fitted terms are at their limits (beta = 1, f = 1 + 4e-7) beyond this sharpness;
# clamping their argument keeps lambda^2 and lambda^P finite in float32
_FIT_SHARPNESS_LIMIT = 1e6


def _gaussian_positive_mean(mean, variance):
    """E[max(0, X)] for X ~ N(mean, variance) = mu Phi(mu / sigma) + sigma phi(mu / sigma)."""
    sigma = np.sqrt(variance)
    ratio = mean / np.maximum(sigma, np.finfo(sigma.dtype).tiny)
    ratio = np.clip(ratio, -1e4, 1e4)
    return mean * 0.5 * (1 + erf_approx(ratio / SQRT_TWO)) + sigma * INV_SQRT_TWO_PI * np.exp(-0.5 * ratio * ratio)


def sg_clamped_cosine_integral(axis, sharpness, amplitude, normal):
    """Integral over the sphere of G(i; p, lambda, mu) max(0, n.i), closed form (module docstring).

    Replaces wang2009 eq. 39-40's single-lobe route; error <= 0.1% of I_up measured
    (benchmarks/accuracy/clamped_cosine.py).  GLSL-portable: exp, sqrt, pow and
    erf_approx only.  Keeps the input dtype; axis and normal need not be unit.
    """
    dtype = _float_dtype(axis, sharpness, amplitude, normal)
    cosine = _cosine(np.asarray(axis, dtype), np.asarray(normal, dtype))
    sharpness = np.asarray(sharpness, dtype)
    return (np.asarray(amplitude, dtype) * clamped_cosine_from_cosine(cosine, sharpness)).astype(dtype, copy=False)


def clamped_cosine_from_cosine(cosine, sharpness):
    """I(c, lambda) with unit amplitude, c = n.p in [-1, 1] (fast closed form, keeps the dtype)."""
    return clamped_cosine_from_terms(cosine, sharpness, sharpness_terms(sharpness, _float_dtype(cosine, sharpness)))


SHARPNESS_TERMS = ("upper", "lower", "mean", "variance", "scale", "beta", "tangential", "at_bottom")


def sharpness_terms(sharpness, dtype=None):
    """(..., 8) the parts of clamped_cosine_from_cosine that depend on lambda alone (SHARPNESS_TERMS):
    computed once a lobe when many normals see the same lobe (an environment's SG mixture)."""
    dtype = np.dtype(dtype or _float_dtype(sharpness))
    lam = np.maximum(np.asarray(sharpness, dtype), 0)
    fit_lam = np.minimum(lam, _FIT_SHARPNESS_LIMIT)
    upper, lower = _pole_integrals(lam)
    mean_cos, var_cos = _langevin_moments(lam)
    scale = 1 + (VARIANCE_F1 * fit_lam + VARIANCE_F0) / (fit_lam * fit_lam + VARIANCE_F3 * fit_lam + VARIANCE_F2)
    lam_power = fit_lam ** dtype.type(TAIL_POWER)
    beta = lam_power / (lam_power + dtype.type(TAIL_OFFSET))
    tangential = mean_cos / np.maximum(lam, np.finfo(dtype).tiny)  # E[sin^2 theta] / 2 = L / lambda
    tangential = np.where(lam > 0, tangential, dtype.type(1 / 3))
    at_bottom = _gaussian_positive_mean(-mean_cos, scale * (var_cos + 0.5 * beta * tangential))
    terms = np.broadcast_arrays(upper, lower, mean_cos, var_cos, scale, beta, tangential, at_bottom)
    return np.stack(terms, axis=-1).astype(dtype, copy=False)


def clamped_cosine_from_terms(cosine, sharpness, terms):
    """clamped_cosine_from_cosine given the sharpness_terms of its lambda."""
    dtype = _float_dtype(cosine, sharpness, terms)
    c = np.clip(np.asarray(cosine, dtype), -1, 1)
    lam = np.maximum(np.asarray(sharpness, dtype), 0)
    upper, lower, mean_cos, var_cos, scale, beta, tangential, at_bottom = np.moveaxis(np.asarray(terms, dtype), -1, 0)
    sin_alpha = np.sqrt(np.maximum(1 - c * c, 0))
    across = (1 - beta) * (1 - c * c) + beta * 0.5 * (1 + sin_alpha)
    positive = _gaussian_positive_mean(c * mean_cos, scale * (c * c * var_cos + across * tangential))
    fraction = np.clip((positive - at_bottom) / np.maximum(mean_cos, np.finfo(dtype).tiny), 0, 1)
    fraction = np.where(mean_cos > 0, fraction, 0.5 * (1 + c))  # lambda -> 0: s = (1 + c) / 2
    two_pi_over_lambda = sg.TWO_PI / np.where(lam > 0, lam, 1)
    # lambda -> 0: (2 pi / lambda) (lambda / 2) = pi, the cosine's integral
    value = np.where(lam > 0, two_pi_over_lambda * (lower + (upper - lower) * fraction), np.pi)
    return value.astype(dtype, copy=False)


def sg_clamped_cosine_integral_exact(axis, sharpness, amplitude, normal):
    """Same integral by quadrature (float64): ring at polar angle theta around p, where
    n.i = c cos(theta) + sin(alpha) sin(theta) cos(phi) is averaged in closed form over phi."""
    cosine = _cosine(np.asarray(axis, np.float64), np.asarray(normal, np.float64))
    sharpness = np.asarray(sharpness, np.float64)
    return np.asarray(amplitude, np.float64) * clamped_cosine_exact_from_cosine(cosine, sharpness)


def clamped_cosine_exact_from_cosine(cosine, sharpness, nodes=QUADRATURE_NODES):
    """I(c, lambda) with unit amplitude by quadrature, c = n.p (float64, broadcasts); ``nodes`` Gauss
    nodes a sub-interval (ring_quadrature)."""
    cosine, sharpness = np.broadcast_arrays(np.asarray(cosine, np.float64), np.asarray(sharpness, np.float64))
    c = cosine[..., None]
    sin_alpha = np.sqrt(np.maximum(1 - c * c, 0))

    def ring_positive_mean(cos_theta, sin_theta):
        along = c * cos_theta
        across = sin_alpha * sin_theta
        phi0 = np.arccos(np.clip(-along / np.where(across > 0, across, 1.0), -1.0, 1.0))
        partial = (along * phi0 + across * np.sin(phi0)) / np.pi
        return np.where(across > 0, partial, np.maximum(along, 0))

    # the ring of polar angle theta meets the horizon of n from theta = |pi/2 - alpha| to
    # pi - |pi/2 - alpha|, and cos(pi/2 - alpha) = sin(alpha): kinks at lambda (1 -+ sin(alpha))
    edge = sin_alpha[..., 0]
    kinks = [sharpness * (1 - edge), sharpness, sharpness * (1 + edge)]
    integral = ring_quadrature(ring_positive_mean, sharpness, kinks, nodes)
    return np.where(sharpness > 0, sg.TWO_PI * integral / np.where(sharpness > 0, sharpness, 1), np.pi)


# Former private name, still imported by tests/gpu/test_glsl_clamped_cosine.py.
_clamped_cosine_from_cosine = clamped_cosine_from_cosine
