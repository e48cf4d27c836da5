"""I(c, lambda), the clamped-cosine integral of a unit SG (clamped_cosine.py), tabulated for the GPU:
one bilinear texture fetch in place of the closed form's exponentials, power and erf, which the
shading evaluates for every slice lobe and every light (x) slice product of every pixel.

The table is built from the quadrature (clamped_cosine_exact_from_cosine), so its error is the
interpolation's alone: about a third of the closed form's (tests/core/test_clamped_cosine_table.py,
docs/ACCURACY.md).  Layout, one RGBA32F texel a (column, row), linear filtering:

- columns: x = log(lambda) from SHARPNESS_RANGE[0] to [1], texel centres at both ends;
- rows: y(c, lambda) = (c + g(c s)) / (1 + g(s)), s = sqrt(lambda), g(t) = t / (1 + |t|): odd,
  y(+-1) = +-1, and for a sharp lobe half the rows fall in the knee at the horizon, c within a few
  1 / sqrt(lambda) of 0, where I(c) bends from 0 to its straight part;
- R = I(c, lambda) / I(1, lambda), G = I(1, lambda) (1 + lambda / 3) / pi, so I = pi / (1 + lambda / 3) R G.
  Both are smooth along the columns; G = 1 - lambda^2 / 36 + ... for broad lobes, 2/3 for sharp ones, and
  never above 1, so no read exceeds the cosine's own integral pi.

Below the range R -> 1 and G -> 1 (I -> pi, off by O(SHARPNESS_RANGE[0])); above it the knee has
converged to its shape in y and G to 2/3, and pi / (1 + lambda / 3) carries the scale exactly (the
closed form clamps lambda at 1e6 on the GPU; this does not).  On GPUs whose bilinear weights are 8-bit (not llvmpipe's
float32 ones) neighbouring texels differ by at most 0.03, so the weights add at most 1e-4.
"""
import functools

import numpy as np

from . import texture_fetch
from .clamped_cosine import _cosine, clamped_cosine_exact_from_cosine

COLUMNS = 384
ROWS = 192
SHARPNESS_RANGE = (1.0e-4, 1.0e8)
# lambda is read as at least this (its logarithm stays finite); no upper clamp: pi / (1 + lambda / 3) is exact
MIN_SHARPNESS = 1.0e-6
# Gauss nodes a sub-interval of the building quadrature: 3e-6 of I(1, lambda), far below the interpolation
BUILD_NODES = 16
# share of the rows' map given to the knee at the horizon (the module docstring's 0.2)
KNEE_WEIGHT = 0.2


def _g(t):
    return t / (1.0 + np.abs(t))


def row_coordinate(cosine, sharpness):
    """y(c, lambda) in [-1, 1] (the module docstring)."""
    s = np.sqrt(sharpness)
    return (cosine + KNEE_WEIGHT * _g(cosine * s)) / (1.0 + KNEE_WEIGHT * _g(s))


def cosine_of_row(y, sharpness):
    """The inverse of row_coordinate: for y >= 0, s c^2 + (1 + w s - Y s) c - Y = 0 with s = sqrt(lambda),
    w = KNEE_WEIGHT and Y = y (1 + w g(s)), its non-negative root in the form that does not cancel; odd in y."""
    s = np.sqrt(sharpness)
    big_y = np.abs(y) * (1.0 + KNEE_WEIGHT * _g(s))
    linear = 1.0 + KNEE_WEIGHT * s - big_y * s
    c = 2.0 * big_y / (linear + np.sqrt(linear * linear + 4.0 * s * big_y))
    return np.sign(y) * np.minimum(c, 1.0)


def column_coordinate(sharpness):
    """x in [0, 1]: log lambda across SHARPNESS_RANGE, clamped."""
    low, high = np.log(SHARPNESS_RANGE[0]), np.log(SHARPNESS_RANGE[1])
    return np.clip((np.log(sharpness) - low) / (high - low), 0.0, 1.0)


@functools.lru_cache(maxsize=None)
def clamped_cosine_table(columns=COLUMNS, rows=ROWS):
    """(rows, columns, 4) float32, texel (row, column) = (R, G, 0, 0) (the module docstring)."""
    x = np.linspace(0.0, 1.0, columns)
    sharpness = np.exp(np.log(SHARPNESS_RANGE[0]) + x * np.log(SHARPNESS_RANGE[1] / SHARPNESS_RANGE[0]))
    y = np.linspace(-1.0, 1.0, rows)
    cosine = cosine_of_row(y[:, None], sharpness[None, :])
    upper = clamped_cosine_exact_from_cosine(np.ones(columns), sharpness, BUILD_NODES)
    table = np.zeros((rows, columns, 4), np.float32)
    table[..., 0] = clamped_cosine_exact_from_cosine(cosine, sharpness[None, :], BUILD_NODES) / upper
    table[..., 1] = upper * (1.0 + sharpness / 3.0) / np.pi
    table.flags.writeable = False
    return table


def clamped_cosine_from_table(cosine, sharpness, table=None):
    """I(c, lambda) with unit amplitude read from the table as the GPU's bilinear filter reads it
    (GLSL: clamped_cosine_tabulated, step for step); lambda <= 0 (or NaN) is pi, like clamped_cosine_from_cosine."""
    table = clamped_cosine_table() if table is None else table
    rows, columns = table.shape[:2]
    cosine, sharpness = np.broadcast_arrays(np.asarray(cosine, np.float64), np.asarray(sharpness, np.float64))
    broad = ~(sharpness > 0.0)
    lam = np.maximum(np.where(broad, 1.0, sharpness), MIN_SHARPNESS)
    c = np.clip(cosine, -1.0, 1.0)
    size = np.array([columns, rows], np.float64)
    position = np.stack([column_coordinate(lam), 0.5 + 0.5 * row_coordinate(c, lam)], axis=-1)
    texel = texture_fetch.bilinear(table, (position * (size - 1.0) + 0.5) / size)     # texel centres at the ends
    value = np.pi / (1.0 + lam / 3.0) * texel[..., 0] * texel[..., 1]
    return np.where(broad, np.pi, value)


def sg_clamped_cosine_integral_tabulated(axis, sharpness, amplitude, normal, table=None):
    """Integral over the sphere of G(i; p, lambda, mu) max(0, n.i), from the table."""
    return np.asarray(amplitude) * clamped_cosine_from_table(_cosine(axis, normal), np.maximum(sharpness, 0.0), table)
