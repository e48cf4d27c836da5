"""Exact rotation of SH coefficient vectors (kautz2002's appendix).

Rotating a function by R, g(s) = f(R^T s), maps its coefficients by a block-diagonal matrix M(R): band l
to band l only, a (2l + 1)^2 block, and M is itself orthogonal.  Three ways to get or apply it here:

- ``band_matrices``: the blocks by Ivanic and Ruedenberg's recurrence (J. Phys. Chem. 1996, with the 1998
  correction): band l from band l - 1 and band 1 (R itself, reordered), a few multiply-adds an entry.
- ``rotate_zyz``: the paper's second method, what the GLSL does per pixel: R = Rz(alpha) Ry(beta)
  Rz(gamma) and Ry(beta) = Rx(-90) Rz(beta) Rx(90); a z rotation turns each (m, -m) pair by m times its
  angle (cos/sin pairs), the two fixed x rotations are constant sparse blocks (``x90_blocks``).
- ``projected_band_matrices``: the definition, M_ij = integral of Y_i(s) Y_j(R^T s) ds by a quadrature
  exact for the product: the reference the two fast ones are tested against.

``flop_counts`` counts each method's multiplies and adds for one rotation of one colour.
"""
import math
from functools import lru_cache

import numpy as np

from . import basis, projection

# Band 1 in the order m = -1, 0, 1 holds (-y, z, -x) / sqrt(4 pi / 3) (Condon-Shortley): the matrix of
# band 1 is R's rows and columns permuted to (y, z, x), with the signs the phase gives cancelling in pairs
_BAND1_AXES = (1, 2, 0)
_BAND1_SIGNS = np.array([-1.0, 1.0, -1.0])


def band1_matrix(rotation):
    """The 3 x 3 block of band 1 for a rotation matrix (3, 3)."""
    r = np.asarray(rotation, np.float64)
    block = r[np.ix_(_BAND1_AXES, _BAND1_AXES)]
    return block * np.outer(_BAND1_SIGNS, _BAND1_SIGNS)


def _recurrence_coefficients(band, m, n):
    """Ivanic-Ruedenberg's u, v, w for entry (m, n) of band l."""
    d = 1.0 if m == 0 else 0.0
    denominator = (band + n) * (band - n) if abs(n) < band else 2 * band * (2 * band - 1)
    u = math.sqrt((band + m) * (band - m) / denominator)
    v = 0.5 * math.sqrt((1 + d) * (band + abs(m) - 1) * (band + abs(m)) / denominator) * (1 - 2 * d)
    w = -0.5 * math.sqrt(max((band - abs(m) - 1) * (band - abs(m)), 0) / denominator) * (1 - d)
    return u, v, w


def _p(i, band, a, b, r1, previous):
    """Ivanic-Ruedenberg's P: r1 indexed [-1..1] by +1, previous (band - 1's block) by + band - 1."""
    lp = band - 1
    if b == band:
        return r1[i + 1, 2] * previous[a + lp, 2 * lp] - r1[i + 1, 0] * previous[a + lp, 0]
    if b == -band:
        return r1[i + 1, 2] * previous[a + lp, 0] + r1[i + 1, 0] * previous[a + lp, 2 * lp]
    return r1[i + 1, 1] * previous[a + lp, b + lp]


def _entry(band, m, n, r1, previous):
    u, v, w = _recurrence_coefficients(band, m, n)
    value = 0.0
    if u:
        value += u * _p(0, band, m, n, r1, previous)
    if v:
        if m == 0:
            term = _p(1, band, 1, n, r1, previous) + _p(-1, band, -1, n, r1, previous)
        elif m > 0:
            term = (_p(1, band, m - 1, n, r1, previous) * math.sqrt(1 + (m == 1))
                    - _p(-1, band, -m + 1, n, r1, previous) * (1 - (m == 1)))
        else:
            term = (_p(1, band, m + 1, n, r1, previous) * (1 - (m == -1))
                    + _p(-1, band, -m - 1, n, r1, previous) * math.sqrt(1 + (m == -1)))
        value += v * term
    if w:
        if m > 0:
            term = _p(1, band, m + 1, n, r1, previous) + _p(-1, band, -m - 1, n, r1, previous)
        else:
            term = _p(1, band, m - 1, n, r1, previous) - _p(-1, band, -m + 1, n, r1, previous)
        value += w * term
    return value


def band_matrices(rotation, order):
    """[block of band l ((2l + 1, 2l + 1)) for l < order] of M(R), by the recurrence (in the recurrence's
    own sign convention, which has no Condon-Shortley phase: the phase is (-1)^m on both sides, applied
    to band 1 going in and to every block coming out)."""
    r1_plain = np.asarray(rotation, np.float64)[np.ix_(_BAND1_AXES, _BAND1_AXES)]
    blocks = [np.ones((1, 1))]
    if order > 1:
        blocks.append(r1_plain)
    for band in range(2, order):
        previous = blocks[-1]
        blocks.append(np.array([[_entry(band, m, n, r1_plain, previous) for n in range(-band, band + 1)]
                                for m in range(-band, band + 1)]))
    signs = [(-1.0) ** np.abs(np.arange(-band, band + 1)) for band in range(order)]
    return [block * np.outer(sign, sign) for block, sign in zip(blocks, signs)]


def block_diagonal(blocks):
    """The (N^2, N^2) matrix of a list of band blocks."""
    size = sum(len(block) for block in blocks)
    matrix = np.zeros((size, size))
    start = 0
    for block in blocks:
        matrix[start:start + len(block), start:start + len(block)] = block
        start += len(block)
    return matrix


def rotation_matrix(rotation, order):
    """M(R) (N^2, N^2): coefficients of f(R^T s) = M(R) @ coefficients of f(s)."""
    return block_diagonal(band_matrices(rotation, order))


def rotate(coefficients, rotation):
    """Coefficients (N^2,) or (N^2, C) of the function rotated by R (3, 3), by the recurrence's matrix."""
    c = np.asarray(coefficients, np.float64)
    return rotation_matrix(rotation, basis.order_of(c.shape[0])) @ c


def projected_band_matrices(rotation, order):
    """The reference: M_ij = integral of Y_i(s) Y_j(R^T s) ds, by a rule exact for the product."""
    directions, weights = projection.exact_quadrature(order)
    here = basis.evaluate(directions, order)
    turned = basis.evaluate(directions @ np.asarray(rotation, np.float64), order)     # rows: R^T s
    matrix = (here * weights[:, None]).T @ turned
    return [matrix[b * b:(b + 1) ** 2, b * b:(b + 1) ** 2] for b in range(order)]


# ----------------------------------------------------------------------------- zyz: the GLSL's method

def axis_rotation(axis, angle):
    """3 x 3 rotation by ``angle`` about coordinate axis 0 (x), 1 (y) or 2 (z), right-handed."""
    c, s = math.cos(angle), math.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    return r


def euler_zyz(rotation, tolerance=1e-9):
    """(alpha, beta, gamma) with R = Rz(alpha) Ry(beta) Rz(gamma); at beta = 0 or pi only alpha + gamma or
    alpha - gamma is defined: gamma = 0 there."""
    r = np.asarray(rotation, np.float64)
    sine_beta = math.hypot(r[0, 2], r[1, 2])
    beta = math.atan2(sine_beta, r[2, 2])
    if sine_beta > tolerance:
        return math.atan2(r[1, 2], r[0, 2]), beta, math.atan2(r[2, 1], -r[2, 0])
    if r[2, 2] > 0:
        return math.atan2(r[1, 0], r[0, 0]), beta, 0.0
    return math.atan2(-r[1, 0], -r[0, 0]), beta, 0.0


def rotate_z(coefficients, angle):
    """Rotation about z: band l's pair (m, -m) turns by m angle (cos/sin of m angle by the angle-sum recurrence)."""
    c = np.array(coefficients, np.float64)
    order = basis.order_of(c.shape[0])
    out = c.copy()
    cosine, sine = math.cos(angle), math.sin(angle)
    cm, sm = 1.0, 0.0
    for m in range(1, order):
        cm, sm = cm * cosine - sm * sine, sm * cosine + cm * sine
        for band in range(m, order):
            plus, minus = basis.index(band, m), basis.index(band, -m)
            out[plus] = cm * c[plus] - sm * c[minus]
            out[minus] = sm * c[plus] + cm * c[minus]
    return out


@lru_cache(maxsize=None)
def x90_blocks(order):
    """Band blocks of M(Rx(+90 degrees)) (exact: the recurrence at a constant rotation; entries below 1e-12
    are zeroed, they are zero in exact arithmetic).  M(Rx(-90)) is their transpose."""
    blocks = band_matrices(axis_rotation(0, math.pi / 2), order)
    return tuple(np.where(np.abs(block) < 1e-12, 0.0, block) for block in blocks)


def _apply_blocks(blocks, coefficients, transpose=False):
    out = np.empty_like(coefficients)
    for band, block in enumerate(blocks):
        rows = slice(band * band, (band + 1) ** 2)
        out[rows] = (block.T if transpose else block) @ coefficients[rows]
    return out


def rotate_zyz(coefficients, rotation):
    """M(R) c applied as Rz(alpha) Rx(-90) Rz(beta) Rx(90) Rz(gamma) (right to left), no matrix built."""
    c = np.array(coefficients, np.float64)
    blocks = x90_blocks(basis.order_of(c.shape[0]))
    alpha, beta, gamma = euler_zyz(rotation)
    c = rotate_z(c, gamma)
    c = _apply_blocks(blocks, c)
    c = rotate_z(c, beta)
    c = _apply_blocks(blocks, c, transpose=True)
    return rotate_z(c, alpha)


def euler_zyz_many(rotations, tolerance=1e-6):
    """euler_zyz of many rotations (P, 3, 3) at once: (alpha, beta, gamma) each (P,), the same branches."""
    r = np.asarray(rotations)
    sine_beta = np.hypot(r[:, 0, 2], r[:, 1, 2])
    beta = np.arctan2(sine_beta, r[:, 2, 2])
    regular = sine_beta > tolerance
    up = r[:, 2, 2] > 0
    alpha = np.where(regular, np.arctan2(r[:, 1, 2], r[:, 0, 2]),
                     np.where(up, np.arctan2(r[:, 1, 0], r[:, 0, 0]), np.arctan2(-r[:, 1, 0], -r[:, 0, 0])))
    gamma = np.where(regular, np.arctan2(r[:, 2, 1], -r[:, 2, 0]), 0.0)
    return alpha, beta, gamma


def rotate_z_many(coefficients, angles):
    """rotate_z of coefficients (P, N^2, ...) by angles (P,), in the coefficients' precision."""
    c = np.asarray(coefficients)
    order = basis.order_of(c.shape[1])
    out = c.copy()
    trailing = (slice(None),) + (None,) * (c.ndim - 2)
    for m in range(1, order):
        cm, sm = np.cos(m * angles).astype(c.dtype)[trailing], np.sin(m * angles).astype(c.dtype)[trailing]
        for band in range(m, order):
            plus, minus = basis.index(band, m), basis.index(band, -m)
            out[:, plus] = cm * c[:, plus] - sm * c[:, minus]
            out[:, minus] = sm * c[:, plus] + cm * c[:, minus]
    return out


def _apply_blocks_many(blocks, c, transpose=False):
    out = np.empty_like(c)
    for band, block in enumerate(blocks):
        rows = slice(band * band, (band + 1) ** 2)
        matrix = (block.T if transpose else block).astype(c.dtype)
        out[:, rows] = np.einsum("ij,pj...->pi...", matrix, c[:, rows])
    return out


def rotate_zyz_many(coefficients, rotations):
    """rotate_zyz of coefficients (P, N^2, ...) by rotations (P, 3, 3), vectorized over P (the shader's
    steps; float32 in, float32 arithmetic)."""
    c = np.asarray(coefficients)
    blocks = x90_blocks(basis.order_of(c.shape[1]))
    alpha, beta, gamma = euler_zyz_many(np.asarray(rotations, np.float64))
    c = rotate_z_many(c, gamma)
    c = _apply_blocks_many(blocks, c)
    c = rotate_z_many(c, beta)
    c = _apply_blocks_many(blocks, c, transpose=True)
    return rotate_z_many(c, alpha)


# ----------------------------------------------------------------------------- cost

def flop_counts(order):
    """Multiplies and adds of one rotation of one coefficient vector (one colour), per method:
    "matrix": applying M(R)'s blocks (sum of (2l + 1)^2 multiply-adds);
    "recurrence": building the blocks by Ivanic-Ruedenberg (beyond band 1), then applying them;
    "zyz": three z rotations (4 multiplies + 2 adds a pair, plus the cos/sin recurrence) and two x90
    products (a multiply-add per non-zero entry); the Euler angles' atan2 and the sin/cos of three angles
    are counted as 1 each."""
    pairs = sum(band for band in range(order))
    matrix = sum((2 * band + 1) ** 2 for band in range(order))
    build = 0
    for band in range(2, order):
        for m in range(-band, band + 1):
            for n in range(-band, band + 1):
                u, v, w = _recurrence_coefficients(band, m, n)
                p_cost = 3 if abs(n) == band else 1          # P: two products and a sum, or one product
                terms = (1 if u else 0) + (2 if v and (m == 0 or abs(m) > 1) else (1 if v else 0)) \
                    + (2 if w else 0)
                build += terms * (p_cost + 1) + ((1 if u else 0) + (1 if v else 0) + (1 if w else 0))
    z_rotation = 6 * pairs + 6 * (order - 1)
    x90 = sum(int(np.count_nonzero(block)) for block in x90_blocks(order)) * 2
    zyz = 3 * z_rotation + 2 * x90 + 3 + 6
    return {"matrix": 2 * matrix, "recurrence": build + 2 * matrix, "zyz": zyz,
            "x90_nonzero": sum(int(np.count_nonzero(block)) for block in x90_blocks(order))}
