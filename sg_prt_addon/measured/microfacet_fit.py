"""Fitting measured BRDFs to the general microfacet model and SG lobes (wang2009 section 4.2).

Pipeline (every step takes arrays, writes nothing, and accepts ``progress(fraction)``
which may return True to cancel; a cancelled step returns None):

1. ``factorize``: from samples rho(o, i) of B texels at N shared direction pairs,
   recover per texel the Lambert albedo kd, a tabulated isotropic NDF D(theta_h) and
   an isotropic shadowing S(theta) with (eq. 13)

       rho(o, i) = kd / pi + ks F(o, i) S(o) S(i) D(h) / (pi (i.n)(o.n)).

   The grey (channel-mean) data are fitted by alternation (Ngan 2005 / Wang 2008 style):
   with S fixed, (kd, D) is a linear least-squares problem (D piecewise linear on a
   theta_h grid); with kd fixed, log((rho - kd/pi) / F-and-cosines) = log D(h) +
   log S(o) + log S(i) is linear in (log D, log S), solved jointly (weighted by the
   squared specular part so it approximates the linear error); a few damped Gauss-Newton
   steps on S then polish the linear-domain objective, which the log optimum misses
   where the data leave the model class.  Weights: the caller's quadrature weight times
   ((i.n)^2 + (o.n)^2)/2 (the cosine-weighted BRDF is what renders and what
   relative_rmse measures), masked by validity.  Second-difference penalties keep D and
   S smooth where samples are scarce or inconsistent (S near grazing).  Scale: S = 1 on
   average below 60 degrees, D normalized (integral of D cos = 1), ks takes the rest;
   kd and ks per channel by a final 2-parameter least squares.  eta: a fixed value (the
   paper uses 1.33) or candidates from which each texel keeps the best residual (eta
   is weakly identifiable: S and ks absorb most of its effect).
2. ``compress_shadowing``: PCA of S across texels (the paper: 90D to 8D).
3. ``fit_ndf_lobes``: SG mixtures of the tabulated D: 1-2 lobes around z+ by
   Levenberg-Marquardt (ndf_fit.fit_isotropic_batch, lobes sorted by increasing
   sharpness) or K free-axis lobes (fit_free_axes_batch: the same model as
   ndf_fit.fit_anisotropic, Levenberg-Marquardt over many texels at once; the paper uses
   L-BFGS-B per texel, which ran 4-15x slower here).
4. ``fit_lobes``: steps 2-3 on a factorization or an SvbrdfTable, returning a ``LobeFit``
   whose ``evaluate`` is the fitted model; ``fit_merl``: steps 1-3 for a MERL BRDF;
   ``relative_rmse``: the 4D error against any BRDF.
"""
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sparse

from ..reflectance import ndf_fit
from ..reflectance.brdf import fresnel_dielectric
from . import merl
from .svbrdf_table import (
    SvbrdfTable,
    default_ndf_theta,
    default_shadowing_theta,
    evaluate_microfacet,
    interpolate_ndf,
    interpolate_shadowing,
)

HALF_PI = 0.5 * np.pi
PAPER_ETA = 1.33
DEFAULT_ETA_CANDIDATES = (1.2, 1.33, 1.5, 1.7, 2.0)
POLISH_SMOOTHNESS_RATIO = 0.1  # linear-domain S penalty relative to the log-domain one


# ----------------------------------------------------------------------------- sample sets

def _theta(w):
    return np.arctan2(np.hypot(w[..., 0], w[..., 1]), w[..., 2])


def half_difference_samples(theta_h_count=64, theta_d_count=32, phi_d_count=32, phi_h_count=1, offset=0.5):
    """Direction pairs (wo, wi) (N, 3) on a product grid in half/difference angles with
    4D quadrature weights (N,) (dw_o dw_i = 4 cos(theta_d) dw_h dw_d), so sum(weights * f)
    approximates the integral over both hemispheres.  theta_h = (pi/2) u^2 with u midpoint
    nodes (dense near the specular peak, like MERL); offset in (0, 1) shifts every node
    within its cell (a second, independent grid for error measurement).  Pairs with a
    direction below the horizon are dropped."""
    u = (np.arange(theta_h_count) + offset) / theta_h_count
    theta_h = HALF_PI * u * u
    d_theta_h = np.pi * u / theta_h_count
    theta_d = (np.arange(theta_d_count) + offset) / theta_d_count * HALF_PI
    phi_d = (np.arange(phi_d_count) + offset) / phi_d_count * 2 * np.pi
    phi_h = (np.arange(phi_h_count) + offset) / phi_h_count * 2 * np.pi
    grids = np.meshgrid(theta_h, theta_d, phi_d, phi_h, indexing="ij")
    wo, wi = merl.directions_from_half_difference(grids[0], grids[1], grids[2], grids[3])
    cell = ((np.sin(theta_h) * d_theta_h)[:, None, None, None]
            * (np.sin(theta_d) * np.cos(theta_d) * HALF_PI / theta_d_count)[None, :, None, None]
            * (2 * np.pi / phi_d_count) * (2 * np.pi / phi_h_count))
    weights = np.broadcast_to(4 * cell, wo.shape[:-1])
    wo, wi, weights = wo.reshape(-1, 3), wi.reshape(-1, 3), weights.reshape(-1)
    above = (wo[:, 2] > 0) & (wi[:, 2] > 0)
    return wo[above], wi[above], weights[above]


def merl_samples(brdf, theta_h_step=1, theta_d_step=2, phi_d_step=4):
    """(wo, wi (N, 3), rho (1, N, 3), valid (1, N), weights (N,)) at the bin centres of a
    MerlBrdf (every step-th bin), with 4D quadrature weights of the bins (phi_d covers
    [0, pi): the other half is the same data with o and i swapped)."""
    (theta_h, theta_d, phi_d), (ih, jd, kp) = merl.bin_centre_angles(theta_h_step, theta_d_step, phi_d_step)
    wo, wi = merl.directions_from_half_difference(theta_h, theta_d, phi_d)
    # bin widths: theta_h = (pi/2) u^2, u step 1/90 per bin
    u = (ih + 0.5) / merl.THETA_H_BINS
    weights = (4 * np.cos(theta_d) * np.sin(theta_d) * np.sin(theta_h) * np.pi * u / merl.THETA_H_BINS * theta_h_step
               * HALF_PI / merl.THETA_D_BINS * theta_d_step * np.pi / merl.PHI_D_BINS * phi_d_step * 2 * 2 * np.pi)
    above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
    rho = brdf.rho[ih, jd, kp][above]
    valid = brdf.valid[ih, jd, kp][above]
    return wo[above], wi[above], rho[None], valid[None], weights[above]


# ----------------------------------------------------------------------------- hat bases

def _hat_basis(values, grid, zero_at_horizon=False):
    """Sparse matrices (N, G) of piecewise-linear interpolation on ``grid`` (clamped):
    linear (1 - t, t), squares ((1 - t)^2, t^2) and cross ((1 - t) t at the lower node).
    zero_at_horizon: an extra node at pi/2 held at 0 (the shadowing convention of
    svbrdf_table.shadowing_with_horizon), dropped from the unknowns."""
    if zero_at_horizon and grid[-1] < HALF_PI - 1e-9:
        linear, square, cross = _hat_basis(values, np.append(grid, HALF_PI))
        return linear[:, :-1], square[:, :-1], cross[:, :-1]
    position = np.interp(values, grid, np.arange(len(grid)))
    low = np.minimum(np.floor(position).astype(int), len(grid) - 2)
    t = position - low
    rows = np.arange(len(values))
    shape = (len(values), len(grid))

    def matrix(low_value, high_value):
        return sparse.csr_matrix((np.concatenate([low_value, high_value]),
                                  (np.concatenate([rows, rows]), np.concatenate([low, low + 1]))), shape=shape)

    cross = sparse.csr_matrix(((1 - t) * t, (rows, low)), shape=shape)
    return matrix(1 - t, t), matrix((1 - t) ** 2, t * t), cross


def _second_difference_penalty(count):
    difference = np.diff(np.eye(count), 2, axis=0)
    return difference.T @ difference


def _matrix_scale(values):
    """Per-texel scale of a normal matrix for relative penalties and ridges; 1 for texels without
    data (all weights 0), so their systems stay well posed (solution 0) instead of denormal."""
    return np.where(values > 1e-200, values, 1.0)


def _solve_banded_normal(diagonal, upper, penalty, rhs, extra=None):
    """Solve (tridiag(diagonal, upper) + scale * penalty) x = rhs per row (B, G), where scale
    is each row's mean diagonal (so the penalty is relative).  extra = (corner (B,),
    coupling (B, G), rhs (B,)) adds one more unknown (kd) coupled to every node."""
    batch, count = diagonal.shape
    size = count + (extra is not None)
    matrix = np.zeros((batch, size, size))
    index = np.arange(count)
    matrix[:, index, index] = diagonal
    matrix[:, index[:-1], index[:-1] + 1] = upper[:, :-1]
    matrix[:, index[:-1] + 1, index[:-1]] = upper[:, :-1]
    scale = _matrix_scale(diagonal.mean(axis=1))
    matrix[:, :count, :count] += scale[:, None, None] * penalty
    # a ridge of 1e-9 keeps empty nodes (no samples) solvable
    matrix[:, index, index] += 1e-9 * scale[:, None]
    right = rhs
    if extra is not None:
        corner, coupling, extra_rhs = extra
        matrix[:, count, count] = corner + 1e-12 * scale
        matrix[:, count, :count] = coupling
        matrix[:, :count, count] = coupling
        right = np.concatenate([rhs, extra_rhs[:, None]], axis=1)
    return np.linalg.solve(matrix, right[..., None])[..., 0]


# ----------------------------------------------------------------------------- factorization

@dataclass
class MicrofacetFactorization:
    """Per texel (B,): diffuse kd (B, 3), specular ks (B, 3), eta (B,), NDF (B, T) on ndf_theta
    (integral of D cos = 1), shadowing (B, S) on shadowing_theta (mean 1 below 60 degrees), and the relative
    weighted RMS residual of the grey fit (B,)."""
    diffuse: np.ndarray
    specular: np.ndarray
    eta: np.ndarray
    ndf_theta: np.ndarray
    ndf: np.ndarray
    shadowing_theta: np.ndarray
    shadowing: np.ndarray
    residual: np.ndarray

    def to_table(self, shape):
        """An SvbrdfTable of (H, W) = shape texels."""
        shape = tuple(shape)
        return SvbrdfTable(diffuse=self.diffuse.reshape(shape + (3,)).astype(np.float32),
                           specular=self.specular.reshape(shape + (3,)).astype(np.float32),
                           eta=self.eta.reshape(shape).astype(np.float32),
                           ndf_theta=self.ndf_theta, ndf_phi=np.zeros(1),
                           ndf=self.ndf.reshape(shape + (-1, 1)).astype(np.float32),
                           shadowing_theta=self.shadowing_theta,
                           shadowing=self.shadowing.reshape(shape + (-1,)).astype(np.float32)).validate()


class _Pairs:
    """Per-pair quantities shared by every texel: hat bases, cosines, the joint log-domain design."""

    def __init__(self, wo, wi, weights, ndf_theta, shadowing_theta):
        self.cos_o, self.cos_i = np.maximum(wo[:, 2], 1e-7), np.maximum(wi[:, 2], 1e-7)
        h = wo + wi
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        self.cos_ih = np.abs(np.sum(wi * h, axis=-1))
        self.h_linear, self.h_square, self.h_cross = _hat_basis(_theta(h), ndf_theta)
        self.o_linear = _hat_basis(_theta(wo), shadowing_theta, zero_at_horizon=True)[0]
        self.i_linear = _hat_basis(_theta(wi), shadowing_theta, zero_at_horizon=True)[0]
        # the error metric weights (rho (i.n))^2; symmetrized over the two roles of a pair
        self.weights = weights * 0.5 * (self.cos_o ** 2 + self.cos_i ** 2)
        self.ndf_count, self.shadowing_count = len(ndf_theta), len(shadowing_theta)
        self.shadowing_theta = shadowing_theta
        self.transposed = {name: getattr(self, name).T.tocsr() for name in ("h_linear", "h_square", "h_cross")}
        # log(rho_s / geometry) = log D(h) + log S(o) + log S(i): one row of 6 hat weights per pair
        # over the unknowns (log D nodes, log S nodes); products of the 6 give the normal matrix
        design = sparse.hstack([self.h_linear, self.o_linear + self.i_linear]).tocsr()
        self.design_t = design.T.tocsr()
        self.outer_t = _row_outer(design, design)
        # Gauss-Newton on S: products of the o and i interpolation rows
        self.outer_oo_t = _row_outer(self.o_linear, self.o_linear)
        self.outer_oi_t = _row_outer(self.o_linear, self.i_linear)
        self.outer_ii_t = _row_outer(self.i_linear, self.i_linear)
        self.o_linear_t, self.i_linear_t = self.o_linear.T.tocsr(), self.i_linear.T.tocsr()

    def geometry(self, eta):
        """F / (pi (i.n)(o.n)) (N,)."""
        return fresnel_dielectric(self.cos_ih, eta) / (np.pi * self.cos_o * self.cos_i)


def _padded_rows(matrix):
    """(columns (N, R), values (N, R)) of a CSR matrix with at most R entries a row (-1 pads)."""
    matrix = matrix.tocsr()
    matrix.sum_duplicates()
    per_row = np.diff(matrix.indptr)
    width = max(int(per_row.max()), 1)
    row_of = np.repeat(np.arange(matrix.shape[0]), per_row)
    position = np.arange(len(matrix.indices)) - np.repeat(matrix.indptr[:-1], per_row)
    columns = np.full((matrix.shape[0], width), -1)
    values = np.zeros((matrix.shape[0], width))
    columns[row_of, position] = matrix.indices
    values[row_of, position] = matrix.data
    return columns, values


def _row_outer(a, b):
    """Sparse (Ga * Gb, N): column n holds the outer product of row n of a (N, Ga) and of b
    (N, Gb), so that outer.T-products with per-pair weights (B, N) give sum_n w a_n b_n^T."""
    columns_a, values_a = _padded_rows(a)
    columns_b, values_b = _padded_rows(b)
    size_b = b.shape[1]
    flat = columns_a[:, :, None] * size_b + columns_b[:, None, :]
    values = values_a[:, :, None] * values_b[:, None, :]
    keep = (columns_a[:, :, None] >= 0) & (columns_b[:, None, :] >= 0)
    rows = np.broadcast_to(np.arange(a.shape[0])[:, None, None], keep.shape)[keep]
    outer = sparse.csr_matrix((values[keep], (flat[keep], rows)), shape=(a.shape[1] * size_b, a.shape[0]))
    outer.sum_duplicates()
    return outer


def _right(matrix_t, values):
    """values (B, N) @ matrix (N, G) -> (B, G) with a sparse matrix (given transposed, CSR)."""
    return (matrix_t @ values.T).T


def _at_pairs(matrix, nodes):
    """Node values (B, G) interpolated at the pairs: matrix (N, G) @ nodes.T -> (B, N)."""
    return (matrix @ nodes.T).T


def _linear_step(pairs, grey, weights, geometry, shadowing, ndf_penalty):
    """(kd/pi (B,), D (B, T)) minimizing sum w (grey - kd/pi - geometry S(o) S(i) D(h))^2 for fixed S."""
    transposed = pairs.transposed
    q = geometry * _at_pairs(pairs.o_linear, shadowing) * _at_pairs(pairs.i_linear, shadowing)
    wq = weights * q
    solution = _solve_banded_normal(
        _right(transposed["h_square"], wq * q), _right(transposed["h_cross"], wq * q), ndf_penalty,
        _right(transposed["h_linear"], wq * grey),
        extra=(weights.sum(axis=1), _right(transposed["h_linear"], wq), np.sum(weights * grey, axis=1)))
    return np.maximum(solution[:, -1], 0), np.maximum(solution[:, :-1], 0), q


def _log_step(pairs, grey, weights, geometry, diffuse, penalty):
    """(log D, log S) jointly, for fixed kd: linear least squares on
    log((grey - kd/pi) / geometry) = log D(h) + log S(o) + log S(i), weighted by
    w (grey - kd/pi)^2 so that it approximates the linear-domain error.  Pairs where the
    specular part is not positive carry no weight."""
    specular = grey - diffuse[:, None]
    positive = specular > 1e-6 * np.max(np.abs(grey), axis=1, keepdims=True)
    target = np.log(np.where(positive, specular, 1) / geometry)
    log_weights = np.where(positive, weights * specular * specular, 0)
    size = pairs.ndf_count + pairs.shadowing_count
    matrix = _right(pairs.outer_t, log_weights).reshape(-1, size, size)
    scale = _matrix_scale(np.einsum("bii->b", matrix) / size)
    matrix += scale[:, None, None] * penalty
    # gauge (log S + a, log D - 2a) and empty nodes: a weak pull of log S towards 0, ridge on all
    index = np.arange(size)
    matrix[:, index, index] += 1e-9 * scale[:, None]
    matrix[:, index[pairs.ndf_count:], index[pairs.ndf_count:]] += 1e-6 * scale[:, None]
    rhs = _right(pairs.design_t, log_weights * target)
    solution = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    return solution[:, :pairs.ndf_count], solution[:, pairs.ndf_count:]


def _objective(pairs, grey, weights, geometry, diffuse, ndf, shadowing):
    model = diffuse[:, None] + geometry * _at_pairs(pairs.h_linear, ndf) * (
        _at_pairs(pairs.o_linear, shadowing) * _at_pairs(pairs.i_linear, shadowing))
    return np.sum(weights * (grey - model) ** 2, axis=1)


def _shadowing_gauss_newton(pairs, grey, weights, geometry, diffuse, ndf, shadowing, penalty, damping=1e-3):
    """One damped Gauss-Newton step on S of the linear-domain objective (kd, D fixed), with the
    full symmetric Jacobian e (S(i) phi(o) + S(o) phi(i)); texels whose objective would grow
    keep their S."""
    e = geometry * _at_pairs(pairs.h_linear, ndf)
    s_o, s_i = _at_pairs(pairs.o_linear, shadowing), _at_pairs(pairs.i_linear, shadowing)
    residual = grey - diffuse[:, None] - e * s_o * s_i
    size = shadowing.shape[1]
    we2 = weights * e * e
    cross = _right(pairs.outer_oi_t, we2 * s_i * s_o).reshape(-1, size, size)
    matrix = (_right(pairs.outer_oo_t, we2 * s_i * s_i).reshape(-1, size, size)
              + _right(pairs.outer_ii_t, we2 * s_o * s_o).reshape(-1, size, size)
              + cross + np.swapaxes(cross, 1, 2))
    weighted_residual = weights * residual * e
    rhs = _right(pairs.o_linear_t, weighted_residual * s_i) + _right(pairs.i_linear_t, weighted_residual * s_o)
    diagonal = np.einsum("bii->bi", matrix)
    scale = _matrix_scale(diagonal.mean(axis=1))
    # relative to the largest diagonal entry: grazing nodes carry most of the weight, and data
    # outside the model class (retro-reflection, non-Lambert diffuse) make them oscillate
    regularization = _matrix_scale(diagonal.max(axis=1))[:, None, None] * penalty
    matrix += regularization
    index = np.arange(size)
    matrix[:, index, index] += damping * scale[:, None]
    rhs -= np.einsum("bij,bj->bi", regularization, shadowing)
    step = np.linalg.solve(matrix, rhs[..., None])[..., 0]
    candidate = np.clip(shadowing + step, 0, None)
    before = _objective(pairs, grey, weights, geometry, diffuse, ndf, shadowing)
    after = _objective(pairs, grey, weights, geometry, diffuse, ndf, candidate)
    return np.where((after < before)[:, None], candidate, shadowing)


def _normalize_shadowing(shadowing, shadowing_theta):
    """S scaled to mean 1 over theta < 60 degrees (unshadowed there for any plausible roughness);
    the max is a poor gauge: one noisy grazing node would rescale everything."""
    near_normal = shadowing_theta < np.radians(60)
    return shadowing / np.maximum(shadowing[:, near_normal].mean(axis=1), 1e-12)[:, None]


def _factorize_chunk(pairs, grey, weights, eta, iterations, smoothness, shadowing_smoothness, polish_iterations):
    """Factorize grey (B, N) with per-pair weights (B, N): alternate the linear (kd, D) step and
    the joint log-domain (D, S) step, then polish S.  Returns D (B, T), S (B, S), the specular
    shape geometry S S D at the pairs (B, N) and the relative residual (B,)."""
    geometry = pairs.geometry(eta)
    ndf_penalty = smoothness * _second_difference_penalty(pairs.ndf_count)
    log_penalty = np.zeros((pairs.ndf_count + pairs.shadowing_count,) * 2)
    log_penalty[:pairs.ndf_count, :pairs.ndf_count] = smoothness * _second_difference_penalty(pairs.ndf_count)
    log_penalty[pairs.ndf_count:, pairs.ndf_count:] = (shadowing_smoothness
                                                         * _second_difference_penalty(pairs.shadowing_count))
    shadowing = np.ones((len(grey), pairs.shadowing_count))
    diffuse, ndf, q = _linear_step(pairs, grey, weights, geometry, shadowing, ndf_penalty)
    for _ in range(iterations):
        _, log_shadowing = _log_step(pairs, grey, weights, geometry, diffuse, log_penalty)
        shadowing = _normalize_shadowing(np.exp(log_shadowing), pairs.shadowing_theta)
        diffuse, ndf, q = _linear_step(pairs, grey, weights, geometry, shadowing, ndf_penalty)
    # the log-domain optimum is not the linear one where the data leave the model class:
    # polish S by Gauss-Newton on the linear objective
    linear_penalty = shadowing_smoothness * POLISH_SMOOTHNESS_RATIO * _second_difference_penalty(pairs.shadowing_count)
    for _ in range(polish_iterations):
        shadowing = _shadowing_gauss_newton(pairs, grey, weights, geometry, diffuse, ndf, shadowing, linear_penalty)
        shadowing = _normalize_shadowing(shadowing, pairs.shadowing_theta)
        diffuse, ndf, q = _linear_step(pairs, grey, weights, geometry, shadowing, ndf_penalty)
    shape = q * _at_pairs(pairs.h_linear, ndf)
    residual = np.sqrt(np.sum(weights * (diffuse[:, None] + shape - grey) ** 2, axis=1)
                       / np.maximum(np.sum(weights * grey ** 2, axis=1), 1e-300))
    return ndf, shadowing, shape, residual


def _ndf_normalization(ndf, ndf_theta):
    """Integral of D cos over the hemisphere (2 pi int D cos sin dtheta), piecewise-linear D."""
    theta, weights = _ndf_quadrature(ndf_theta)
    values = _interpolate_rows(ndf, ndf_theta, theta)
    return values @ (weights * np.cos(theta))


def factorize(wo, wi, rho, weights=None, valid=None, eta=PAPER_ETA, ndf_theta=None, shadowing_theta=None,
              iterations=4, polish_iterations=2, smoothness=1e-4, shadowing_smoothness=0.1, chunk=256, progress=None):
    """Recover (kd, ks, eta, D, S) per texel from samples (see module doc).

    wo, wi (N, 3) shared direction pairs above the horizon; rho (B, N, 3) (or (N, 3));
    weights (N,) quadrature weights (default 1); valid (B, N) or (N,) bool (default all);
    eta a float, or a sequence of candidates (each texel keeps the one whose screening fit has
    the smallest residual).
    Returns a MicrofacetFactorization, or None if ``progress`` returned True.
    """
    wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
    rho = np.asarray(rho, np.float64)
    if rho.ndim == 2:
        rho = rho[None]
    batch, count = rho.shape[:2]
    weights = np.ones(count) if weights is None else np.asarray(weights, np.float64)
    valid = np.ones((batch, count), bool) if valid is None else np.broadcast_to(valid, (batch, count))
    valid = valid & np.all(np.isfinite(rho), axis=-1)
    rho = np.where(valid[..., None], rho, 0.0)
    ndf_theta = default_ndf_theta() if ndf_theta is None else np.asarray(ndf_theta, np.float64)
    shadowing_theta = default_shadowing_theta() if shadowing_theta is None else np.asarray(shadowing_theta)
    candidates = np.atleast_1d(np.asarray(eta, np.float64))
    pairs = _Pairs(wo, wi, weights, ndf_theta, shadowing_theta)
    out = {"ndf": np.empty((batch, len(ndf_theta))), "shadowing": np.empty((batch, len(shadowing_theta))),
           "eta": np.empty(batch), "residual": np.full(batch, np.inf),
           "diffuse": np.empty((batch, 3)), "specular": np.empty((batch, 3))}
    # several eta: a cheap screening pass (one log-domain step, no polish) picks each texel's
    # eta, then one full fit per chosen value (measured: same choice and error as full fits of
    # every candidate, at about a third of the cost for 5 candidates)
    screening = len(candidates) > 1
    steps = (2 * len(candidates) if screening else 1) * ((batch + chunk - 1) // chunk)
    done = 0
    for start in range(0, batch, chunk):
        part = np.arange(start, min(start + chunk, batch))
        texel_rho = rho[part]
        texel_weights = pairs.weights * valid[part]
        grey = texel_rho.mean(axis=-1)
        choice = np.zeros(len(part), int)
        if screening:
            screen = np.empty((len(part), len(candidates)))
            for index, candidate in enumerate(candidates):
                if progress is not None and progress(done / steps):
                    return None
                done += 1
                screen[:, index] = _factorize_chunk(pairs, grey, texel_weights, candidate, 1, smoothness,
                                                    shadowing_smoothness, 0)[3]
            choice = np.argmin(screen, axis=1)
        for index, candidate in enumerate(candidates):
            chosen = np.nonzero(choice == index)[0]
            if progress is not None and progress(done / steps):
                return None
            done += 1
            if len(chosen) == 0:
                continue
            ndf, shadowing, shape, residual = _factorize_chunk(pairs, grey[chosen], texel_weights[chosen], candidate,
                                                               iterations, smoothness, shadowing_smoothness,
                                                               polish_iterations)
            rows = part[chosen]
            # per channel: rho_c = kd_c / pi + ks_c * shape, a 2x2 weighted least squares
            w = texel_weights[chosen]
            sw, sg, sgg = w.sum(1), (w * shape).sum(1), (w * shape * shape).sum(1)
            y = texel_rho[chosen]
            sy, sgy = np.einsum("bn,bnc->bc", w, y), np.einsum("bn,bnc->bc", w * shape, y)
            determinant = np.maximum(sw * sgg - sg * sg, 1e-300)[:, None]
            ks = np.maximum((sw[:, None] * sgy - sg[:, None] * sy) / determinant, 0)
            kd_over_pi = np.maximum((sy - ks * sg[:, None]) / np.maximum(sw, 1e-300)[:, None], 0)
            normalization = np.maximum(_ndf_normalization(ndf, ndf_theta), 1e-300)
            out["ndf"][rows] = ndf / normalization[:, None]
            out["specular"][rows] = ks * normalization[:, None]
            out["diffuse"][rows] = kd_over_pi * np.pi
            out["shadowing"][rows] = shadowing
            out["eta"][rows] = candidate
            out["residual"][rows] = residual
    if progress is not None and progress(1.0):
        return None
    return MicrofacetFactorization(ndf_theta=ndf_theta, shadowing_theta=shadowing_theta, **out)


# ----------------------------------------------------------------------------- shadowing PCA

def compress_shadowing(shadowing, components=8):
    """PCA of S across texels: (mean (S,), basis (C, S), coefficients (B, C)), C <= min(components, B).
    The paper packs S into 90D vectors and keeps 8 components."""
    shadowing = np.asarray(shadowing, np.float64)
    mean = shadowing.mean(axis=0)
    centred = shadowing - mean
    count = min(components, len(shadowing), shadowing.shape[1])
    _, _, vt = np.linalg.svd(centred, full_matrices=False)
    basis = vt[:count]
    return mean, basis, centred @ basis.T


def decompress_shadowing(mean, basis, coefficients):
    """S (B, S) from its PCA form, clipped at 0 (S may exceed 1: it is normalized to mean 1
    below 60 degrees and can absorb effects the separable model lacks, e.g. correlated masking)."""
    return np.maximum(mean + np.asarray(coefficients) @ basis, 0)


# ----------------------------------------------------------------------------- SG fits of D

def _ndf_quadrature(ndf_theta, points_per_segment=4):
    """Gauss-Legendre nodes between consecutive table nodes and weights 2 pi sin(theta) dtheta."""
    x, w = np.polynomial.legendre.leggauss(points_per_segment)
    lo, hi = ndf_theta[:-1, None], ndf_theta[1:, None]
    theta = (0.5 * (hi - lo) * x + 0.5 * (hi + lo)).ravel()
    weights = (0.5 * (hi - lo) * w).ravel() * np.sin(theta) * 2 * np.pi
    return theta, weights


def _interpolate_rows(values, grid, theta):
    """Piecewise-linear rows (B, T) on grid evaluated at theta (M,) -> (B, M)."""
    position = np.interp(theta, grid, np.arange(len(grid)))
    low = np.minimum(np.floor(position).astype(int), len(grid) - 2)
    t = position - low
    return (1 - t) * values[:, low] + t * values[:, low + 1]


def fit_ndf_lobes(ndf_theta, ndf, lobe_count, ndf_phi=None, free_axes=None, phi_count=None, progress=None,
                  chunk=1024, max_iterations=50, method="lm"):
    """SG mixtures of tabulated NDFs ndf (B, T) (isotropic) or (B, T, P) on (ndf_theta, ndf_phi).

    free_axes False (default for isotropic tables and K <= 2): K lobes around z+ by batched
    Levenberg-Marquardt (ndf_fit.fit_isotropic_batch); True: K free-axis lobes by batched
    Levenberg-Marquardt (fit_free_axes_batch) on a hemisphere quadrature with phi_count
    azimuths (default 12 for isotropic tables, where more did not lower the error, else 32),
    at most max_iterations steps.  method "L-BFGS-B" or "TNC" runs the paper's per-texel
    quasi-Newton fit instead (ndf_fit.fit_anisotropic, same start and quadrature; slower).  Returns (axis (B, K, 3),
    sharpness (B, K), amplitude (B, K), relative L2 of D (B,)), lobes sorted by increasing
    sharpness, or None if cancelled.
    """
    ndf_theta = np.asarray(ndf_theta, np.float64)
    ndf = np.asarray(ndf, np.float64)
    table = ndf if ndf.ndim == 3 else ndf[..., None]
    ndf_phi = np.zeros(1) if ndf_phi is None else np.asarray(ndf_phi, np.float64)
    if free_axes is None:
        free_axes = table.shape[2] > 1 or lobe_count > 2
    batch = len(table)
    empty = ~(np.max(table.reshape(batch, -1), axis=1) > 0)  # black or unmeasured texels (also NaN)
    if empty.any():
        # no specular lobe: zero amplitude, unit sharpness, z+ axis, error 0
        axis = np.zeros((batch, lobe_count, 3))
        axis[..., 2] = 1
        sharpness, amplitude, error = np.ones((batch, lobe_count)), np.zeros((batch, lobe_count)), np.zeros(batch)
        if not empty.all():
            fitted = fit_ndf_lobes(ndf_theta, table[~empty], lobe_count, ndf_phi, free_axes, phi_count, progress,
                                   chunk, max_iterations, method)
            if fitted is None:
                return None
            axis[~empty], sharpness[~empty], amplitude[~empty], error[~empty] = fitted
        return axis, sharpness, amplitude, error
    theta, weights = _ndf_quadrature(ndf_theta)
    axis = np.zeros((batch, lobe_count, 3))
    if not free_axes:
        if table.shape[2] != 1 or lobe_count > 2:
            raise ValueError("lobes around z+ need an isotropic table and 1-2 lobes; use free_axes=True")
        sharpness = np.empty((batch, lobe_count))
        amplitude = np.empty((batch, lobe_count))
        error = np.empty(batch)
        values = _interpolate_rows(table[..., 0], ndf_theta, theta)
        for start in range(0, batch, chunk):
            if progress is not None and progress(start / batch):
                return None
            part = slice(start, start + chunk)
            sharpness[part], amplitude[part], error[part] = ndf_fit.fit_isotropic_batch(
                values[part], theta, weights, lobe_count)
        axis[..., 2] = 1
    else:
        phi_count = phi_count or (12 if table.shape[2] == 1 else 32)
        # a coarser theta quadrature for the free-axis fit: every fourth node, weights x4
        directions_theta, directions_weight = theta[::4], weights[::4] * 4 / phi_count
        phi = (np.arange(phi_count) + 0.5) * (2 * np.pi / phi_count)
        t, p = np.meshgrid(directions_theta, phi, indexing="ij")
        directions = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
        solid_angle = np.repeat(directions_weight, phi_count)
        # start: the z+ 2-lobe fit of the azimuthal mean plus faint tilted lobes (growing lobes one
        # at a time from a single lobe stalls in the symmetric optimum)
        mean_rows = _interpolate_rows(table.mean(axis=2), ndf_theta, theta)
        sharpness = np.empty((batch, lobe_count))
        amplitude = np.empty((batch, lobe_count))
        error = np.empty(batch)
        small_chunk = max(1, chunk // 16)  # the Jacobian is (chunk, M, 5 K)
        for start in range(0, batch, small_chunk):
            if progress is not None and progress(start / batch):
                return None
            part = slice(start, start + small_chunk)
            values = interpolate_ndf(table[part], ndf_theta, ndf_phi, directions)
            if table.shape[2] == 1:
                start_sharpness, start_amplitude, _ = ndf_fit.fit_isotropic_batch(
                    mean_rows[part], theta, weights, min(lobe_count, 2))
                initial = _tilted_start(start_sharpness, start_amplitude, lobe_count)
            else:
                initial = _moment_start(values, directions, solid_angle, table[part, 0].mean(axis=1), lobe_count)
            if method == "lm":
                axis[part], sharpness[part], amplitude[part], error[part] = fit_free_axes_batch(
                    values, directions, solid_angle, initial, max_iterations)
                continue
            for offset, texel in enumerate(range(start, min(start + small_chunk, batch))):
                axis[texel], sharpness[texel], amplitude[texel], error[texel] = ndf_fit.fit_anisotropic(
                    values[offset], directions, solid_angle, lobe_count,
                    initial=tuple(a[offset] for a in initial), max_iterations=max_iterations, method=method)
    if progress is not None and progress(1.0):
        return None
    return axis, sharpness, amplitude, error


def _tilted_start(sharpness, amplitude, lobe_count):
    """Initial K free-axis lobes (B, K, ...) from z+ lobes (sharpness, amplitude (B, J), J <= 2):
    the J lobes on z+ and K - J faint lobes tilted by half the broad lobe's width on a ring,
    at the geometric-mean sharpness."""
    batch, given = sharpness.shape
    extra = lobe_count - given
    tilt = np.minimum(0.5 / np.sqrt(np.maximum(sharpness[:, :1], 1e-6)), 0.5)  # (B, 1), radians
    phi = 2 * np.pi * np.arange(extra) / max(extra, 1)
    axis = np.zeros((batch, lobe_count, 3))
    axis[:, :given, 2] = 1
    axis[:, given:] = np.stack([np.sin(tilt) * np.cos(phi), np.sin(tilt) * np.sin(phi),
                                np.broadcast_to(np.cos(tilt), (batch, extra))], axis=-1)
    middle = np.exp(np.mean(np.log(np.maximum(sharpness, 1e-6)), axis=1, keepdims=True))
    all_sharpness = np.concatenate([sharpness, np.broadcast_to(middle, (batch, extra))], axis=1)
    all_amplitude = np.concatenate([amplitude, np.broadcast_to(1e-2 * amplitude.max(1, keepdims=True),
                                                               (batch, extra))], axis=1)
    return axis, all_sharpness, all_amplitude


def _moment_start(values, directions, weights, peak, lobe_count):
    """Initial K lobes of anisotropic NDFs values (B, M): Gaussian widths and orientation from
    the second moments of the slopes (x, y) = (h_x, h_y) / h_z under D (n.h), then
    ndf_fit.anisotropic_lobes (the normalized anisotropy table) rotated to that orientation."""
    cos_theta = np.maximum(directions[:, 2], 1e-3)
    slope_x, slope_y = directions[:, 0] / cos_theta, directions[:, 1] / cos_theta
    mass = np.maximum(values, 0) * weights * cos_theta
    total = np.maximum(mass.sum(axis=1), 1e-300)
    xx, yy, xy = ((mass * a * b).sum(axis=1) / total for a, b in
                  ((slope_x, slope_x), (slope_y, slope_y), (slope_x, slope_y)))
    angle = 0.5 * np.arctan2(2 * xy, xx - yy)  # principal direction of the slope covariance
    spread = np.sqrt(0.25 * (xx - yy) ** 2 + xy * xy)
    # exp(-x^2/w^2) has variance w^2/2
    long_width = np.clip(np.sqrt(2 * (0.5 * (xx + yy) + spread)), 1e-3, 1.5)
    short_width = np.clip(np.sqrt(2 * np.maximum(0.5 * (xx + yy) - spread, 0)), 1e-3, 1.5)
    axis, sharpness, amplitude = ndf_fit.anisotropic_lobes(long_width, short_width, peak, lobe_count)
    cos_a, sin_a = np.cos(angle)[:, None], np.sin(angle)[:, None]
    rotated = np.stack([cos_a * axis[..., 0] - sin_a * axis[..., 1], sin_a * axis[..., 0] + cos_a * axis[..., 1],
                        axis[..., 2]], axis=-1)
    amplitude = np.maximum(np.asarray(amplitude, np.float64), 1e-6 * peak[:, None])
    return rotated, np.asarray(sharpness, np.float64), amplitude


def _free_axes_residual(params, directions, root_weights, target, scale):
    """Weighted relative residual (B, M) and the lobes' parts for the Jacobian."""
    raw = params[..., :3]
    length = np.maximum(np.linalg.norm(raw, axis=-1), 1e-12)
    axis = raw / length[..., None]
    sharpness = np.exp(np.clip(params[..., 3], -10, 16))
    cosine = np.einsum("bkj,mj->bkm", axis, directions)
    lobes = np.exp(np.clip(params[..., 4], -60, 60))[..., None] * np.exp(
        sharpness[..., None] * np.minimum(cosine - 1, 0))
    residual = root_weights * (lobes.sum(1) - target) / scale
    return residual, axis, length, sharpness, cosine, lobes


def fit_free_axes_batch(values, directions, weights, initial, max_iterations=150):
    """K free-axis SG lobes fitted to B NDFs at once by Levenberg-Marquardt with per-texel
    damping (the batched counterpart of ndf_fit.fit_anisotropic, which runs one texel per
    scipy call).  values (B, M) at directions (M, 3) with solid-angle weights (M,); initial
    (axis (B, K, 3), sharpness (B, K), amplitude (B, K)).  Parameters: raw axis (normalized
    in the model), log sharpness, log amplitude.  Returns (axis (B, K, 3), sharpness (B, K),
    amplitude (B, K), relative L2 (B,)), lobes sorted by increasing sharpness."""
    target = np.asarray(values, np.float64)
    root_weights = np.sqrt(np.asarray(weights, np.float64))
    scale = np.maximum(np.sqrt(np.sum(root_weights ** 2 * target ** 2, axis=1)), 1e-300)[:, None]
    axis, sharpness, amplitude = (np.asarray(a, np.float64) for a in initial)
    params = np.concatenate([axis, np.log(np.maximum(sharpness, 1e-4))[..., None],
                             np.log(np.maximum(amplitude, 1e-30))[..., None]], axis=-1)  # (B, K, 5)
    batch, lobe_count = params.shape[:2]
    residual = _free_axes_residual(params, directions, root_weights, target, scale)[0]
    cost = np.sum(residual ** 2, axis=1)
    damping = np.full(batch, 1e-3)
    active = np.ones(batch, bool)
    for _ in range(max_iterations):
        if not active.any():
            break
        rows = np.nonzero(active)[0]
        p = params[rows]
        r, axis, length, sharp, cosine, lobes = _free_axes_residual(p, directions, root_weights, target[rows],
                                                                    scale[rows])
        factor = (root_weights / scale[rows])[:, None, :] * lobes  # (b, K, M)
        # Jacobian (b, M, K * 5) filled in place: d/d raw axis = factor lambda (d - c axis) / |raw|,
        # d/d log lambda = factor lambda (c - 1), d/d log mu = factor
        jacobian = np.empty((len(rows), directions.shape[0], lobe_count, 5))
        sharp_factor = factor * sharp[..., None]
        scaled = sharp_factor / length[..., None]
        for component in range(3):
            jacobian[..., component] = np.swapaxes(
                scaled * (directions[:, component] - cosine * axis[:, :, component, None]), 1, 2)
        jacobian[..., 3] = np.swapaxes(sharp_factor * (cosine - 1), 1, 2)
        jacobian[..., 4] = np.swapaxes(factor, 1, 2)
        jacobian = jacobian.reshape(len(rows), -1, lobe_count * 5)
        normal = np.swapaxes(jacobian, 1, 2) @ jacobian
        gradient = (np.swapaxes(jacobian, 1, 2) @ r[..., None])[..., 0]
        diagonal = np.einsum("bpp->bp", normal)
        improved = np.zeros(len(rows), bool)
        new_params = p.copy()
        new_cost = cost[rows].copy()
        for _attempt in range(4):
            trial = ~improved
            if not trial.any():
                break
            system = normal[trial] + (damping[rows[trial]][:, None] * np.maximum(diagonal[trial], 1e-12))[..., None] \
                * np.eye(lobe_count * 5)
            step = np.linalg.solve(system, -gradient[trial][..., None])[..., 0].reshape(-1, lobe_count, 5)
            candidate = p[trial] + step
            candidate[..., 3] = np.clip(candidate[..., 3], -10, 16)
            candidate[..., 4] = np.clip(candidate[..., 4], -60, 60)
            # keep |raw axis| near 1: the scale of the raw axis is a free direction of the model
            candidate[..., :3] /= np.maximum(np.linalg.norm(candidate[..., :3], axis=-1, keepdims=True), 1e-12)
            trial_cost = np.sum(_free_axes_residual(candidate, directions, root_weights, target[rows[trial]],
                                                    scale[rows[trial]])[0] ** 2, axis=1)
            better = trial_cost < cost[rows[trial]]
            index = np.nonzero(trial)[0]
            new_params[index[better]] = candidate[better]
            new_cost[index[better]] = trial_cost[better]
            improved[index[better]] = True
            damping[rows[index[better]]] *= 0.3
            damping[rows[index[~better]]] *= 10
        relative_gain = (cost[rows] - new_cost) / np.maximum(cost[rows], 1e-300)
        params[rows], cost[rows] = new_params, new_cost
        # a failed step only raised the damping: retry until it is hopeless
        active[rows] = np.where(improved, relative_gain > 1e-6, damping[rows] < 1e8)
    raw = params[..., :3]
    axis = raw / np.maximum(np.linalg.norm(raw, axis=-1, keepdims=True), 1e-12)
    sharpness, amplitude = np.exp(params[..., 3]), np.exp(params[..., 4])
    order = np.argsort(sharpness, axis=1)
    take = lambda a: np.take_along_axis(a, order, axis=1)  # noqa: E731
    return (np.take_along_axis(axis, order[..., None], axis=1), take(sharpness), take(amplitude), np.sqrt(cost))


# ----------------------------------------------------------------------------- the fitted model

@dataclass
class LobeFit:
    """The fitted representation per texel (B,): diffuse kd (B, 3), eta (B,), SG lobes
    axis (B, K, 3), sharpness (B, K), amplitude (B, K, 3) (RGB: ks times the lobe
    amplitude, as the paper stores it), shadowing PCA (mean (S,), basis (C, S),
    coefficients (B, C)) on shadowing_theta, the relative L2 of each texel's D fit and
    the factorization residual."""
    diffuse: np.ndarray
    eta: np.ndarray
    axis: np.ndarray
    sharpness: np.ndarray
    amplitude: np.ndarray
    shadowing_theta: np.ndarray
    shadowing_mean: np.ndarray
    shadowing_basis: np.ndarray
    shadowing_coefficients: np.ndarray
    ndf_error: np.ndarray
    factorization_residual: np.ndarray

    @property
    def shadowing(self):
        return decompress_shadowing(self.shadowing_mean, self.shadowing_basis, self.shadowing_coefficients)

    def evaluate(self, wo, wi, texels=None):
        """The fitted rho(o, i) (B, N, 3) for direction pairs (N, 3)."""
        texels = np.arange(len(self.diffuse)) if texels is None else np.asarray(texels)
        wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
        h = wo + wi
        h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
        axis = self.axis[texels]  # (B, K, 3)
        cosine = np.einsum("nj,bkj->bnk", h, axis)
        lobes = np.exp(self.sharpness[texels][:, None, :] * np.minimum(cosine - 1, 0))  # (B, N, K)
        rgb_ndf = np.einsum("bnk,bkc->bnc", lobes, self.amplitude[texels])
        rgb_ndf = np.where(h[:, 2:3] > 0, rgb_ndf, 0.0)
        shadowing = self.shadowing[texels]
        s_o = interpolate_shadowing(shadowing, self.shadowing_theta, _theta(wo))
        s_i = interpolate_shadowing(shadowing, self.shadowing_theta, _theta(wi))
        # eq. 13 with the colour in the lobes: evaluate per channel with ks = 1
        out = np.empty(rgb_ndf.shape)
        for channel in range(3):
            out[..., channel] = evaluate_microfacet(
                wo, wi, self.diffuse[texels], np.ones((len(texels), 3)), self.eta[texels],
                rgb_ndf[..., channel], s_o, s_i)[..., channel]
        return out


def fit_lobes(factorization, lobe_count, shadowing_components=8, free_axes=None, progress=None, **lobe_options):
    """SG lobes + PCA shadowing from a MicrofacetFactorization or an SvbrdfTable (isotropic or
    anisotropic NDF); lobe_options (phi_count, max_iterations, method) go to fit_ndf_lobes.
    Texels are flattened (B = H * W).  Returns a LobeFit, or None if cancelled."""
    if isinstance(factorization, SvbrdfTable):
        table = factorization
        factorization = MicrofacetFactorization(
            diffuse=table.flat("diffuse").astype(np.float64), specular=table.flat("specular").astype(np.float64),
            eta=table.flat("eta").astype(np.float64), ndf_theta=table.ndf_theta,
            ndf=table.flat("ndf").astype(np.float64)[..., 0] if table.isotropic else table.flat("ndf"),
            shadowing_theta=table.shadowing_theta, shadowing=table.flat("shadowing").astype(np.float64),
            residual=np.zeros(table.texel_count))
        ndf_phi = table.ndf_phi
    else:
        ndf_phi = None
    lobes = fit_ndf_lobes(factorization.ndf_theta, factorization.ndf, lobe_count, ndf_phi=ndf_phi,
                          free_axes=free_axes, progress=progress, **lobe_options)
    if lobes is None:
        return None
    axis, sharpness, amplitude, error = lobes
    mean, basis, coefficients = compress_shadowing(factorization.shadowing, shadowing_components)
    return LobeFit(diffuse=factorization.diffuse, eta=factorization.eta, axis=axis, sharpness=sharpness,
                   amplitude=amplitude[..., None] * factorization.specular[:, None, :],
                   shadowing_theta=factorization.shadowing_theta, shadowing_mean=mean, shadowing_basis=basis,
                   shadowing_coefficients=coefficients, ndf_error=error,
                   factorization_residual=factorization.residual)


def _scaled_progress(progress, low, high):
    if progress is None:
        return None
    return lambda fraction: progress(low + (high - low) * fraction)


def fit_merl(brdf, lobe_count, eta=DEFAULT_ETA_CANDIDATES, free_axes=None, progress=None):
    """A MerlBrdf (merl.read_merl) to a 1-texel LobeFit: factorize its bin-centre samples
    (invalid bins ignored), then fit ``lobe_count`` SG lobes.  progress(fraction) may return
    True to cancel (then None is returned); about 3 s on this machine."""
    wo, wi, rho, valid, weights = merl_samples(brdf)
    factorization = factorize(wo, wi, rho, weights, valid, eta=eta, progress=_scaled_progress(progress, 0, 0.9))
    if factorization is None:
        return None
    return fit_lobes(factorization, lobe_count, free_axes=free_axes, progress=_scaled_progress(progress, 0.9, 1))


# ----------------------------------------------------------------------------- 4D error

def relative_rmse(reference, fitted, samples=None, texel_chunk=16, cosines="i"):
    """Relative RMSE of the cosine-weighted BRDF rho(o, i) (i.n) over both hemispheres, per
    texel: sqrt(int |f - r|^2 (i.n)^2 / int |r|^2 (i.n)^2), summed over RGB.
    cosines="io" weights by (i.n)(o.n) instead: the (i.n) form is dominated by near-grazing
    specular pairs for glossy materials (rho (i.n) stays large as (o.n) -> 0), where
    tabulated data are least reliable; the symmetric form measures the bulk.

    reference, fitted: callables (wo (N, 3), wi (N, 3), texels (b,)) -> (b, N, 3), called on
    texel chunks; samples (wo, wi, weights) default to an offset half/difference grid
    (half_difference_samples(offset=0.3), independent of the fitting grids).  Returns (B,)
    for B = the number of texels, taken from ``texels`` of ``reference`` (attribute
    ``texel_count``, default 1)."""
    if samples is None:
        samples = half_difference_samples(64, 32, 32, 2, offset=0.3)
    wo, wi, weights = samples
    weight = weights * (wi[:, 2] ** 2 if cosines == "i" else (wi[:, 2] * wo[:, 2]) ** 2)
    count = getattr(reference, "texel_count", 1)
    errors = np.empty(count)
    for start in range(0, count, texel_chunk):
        texels = np.arange(start, min(start + texel_chunk, count))
        r = reference(wo, wi, texels)
        f = fitted(wo, wi, texels)
        errors[texels] = np.sqrt(np.einsum("n,bnc->b", weight, (f - r) ** 2)
                                 / np.maximum(np.einsum("n,bnc->b", weight, r * r), 1e-300))
    return errors
