"""The real spherical-harmonic basis (conventions: the package docstring).

Evaluated without trigonometry: for m >= 0, P_l^m(z) / sin^m(theta) by the usual three-term recurrences
in l (stable for the orders here), times Re and Im of (x + i y)^m, which are sin^m(theta) cos(m phi) and
sin^m(theta) sin(m phi).  No division by sin(theta): exact at the poles.
"""
import math

import numpy as np

FOUR_PI = 4.0 * np.pi


def coefficient_count(order):
    """N^2 coefficients of an order-N expansion (bands 0 .. N-1)."""
    return int(order) ** 2


def index(band, m):
    """Position of coefficient (l, m) in a vector: l^2 + l + m."""
    return band * band + band + m


def band_of(count):
    """(l (count,), m (count,)) of every index of an expansion with ``count`` coefficients."""
    bands = np.floor(np.sqrt(np.arange(count))).astype(int)
    return bands, np.arange(count) - bands * bands - bands


def order_of(count):
    """The order N of a vector of N^2 coefficients (ValueError otherwise)."""
    order = int(round(math.sqrt(count)))
    if order * order != count:
        raise ValueError(f"{count} coefficients: not the N^2 of an order-N expansion")
    return order


def normalization(band, m):
    """K_lm = sqrt((2l + 1) / (4 pi) (l - |m|)! / (l + |m|)!)."""
    m = abs(m)
    return math.sqrt((2 * band + 1) / FOUR_PI * math.factorial(band - m) / math.factorial(band + m))


def legendre_over_sine_power(z, order):
    """Q[l][m] = P_l^m(z) / sin^m(theta) for 0 <= m <= l < order (Condon-Shortley phase): dict (l, m) -> array."""
    z = np.asarray(z, np.float64)
    q = {}
    diagonal = np.ones_like(z)                       # Q_0^0
    for m in range(order):
        if m > 0:
            diagonal = -(2 * m - 1) * diagonal       # Q_m^m = (-1)^m (2m - 1)!!
        q[m, m] = diagonal
        if m + 1 < order:
            q[m + 1, m] = z * (2 * m + 1) * diagonal
        for band in range(m + 2, order):
            q[band, m] = ((2 * band - 1) * z * q[band - 1, m] - (band + m - 1) * q[band - 2, m]) / (band - m)
    return q


def evaluate(directions, order):
    """Y (..., N^2) of unit directions (..., 3), order N."""
    d = np.asarray(directions, np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    q = legendre_over_sine_power(z, order)
    out = np.empty(d.shape[:-1] + (coefficient_count(order),))
    cosine_part, sine_part = np.ones_like(x), np.zeros_like(x)          # Re, Im of (x + i y)^m
    for m in range(order):
        if m > 0:
            cosine_part, sine_part = cosine_part * x - sine_part * y, cosine_part * y + sine_part * x
        for band in range(m, order):
            k = normalization(band, m)
            if m == 0:
                out[..., index(band, 0)] = k * q[band, 0]
            else:
                out[..., index(band, m)] = math.sqrt(2.0) * k * q[band, m] * cosine_part
                out[..., index(band, -m)] = math.sqrt(2.0) * k * q[band, m] * sine_part
    return out


def reconstruct(coefficients, directions):
    """The expansion sum_i c_i Y_i at directions (..., 3): coefficients (N^2,) -> (...), (N^2, C) -> (..., C)."""
    c = np.asarray(coefficients, np.float64)
    basis = evaluate(directions, order_of(c.shape[0]))
    return basis @ c
