"""PCA compression of per-vertex SSDFs (wang2009 eq. 24), in bounded memory.

V_d,x(i) ~ mean(i) + sum_j w_x,j B_j(i).  The D x D covariance (D = R^2 texels)
is accumulated in float64 (from float32 chunk products) chunk by chunk (8 MB at 32 x 32, 134 MB at 64 x 64),
never a V x D float64 matrix; only the leading eigenpairs are computed
(scipy eigh with subset_by_index above 48 x 48 texels).  The residual of n terms follows from the
trace: RMS angular error(n) = sqrt((trace C - sum of the n largest
eigenvalues) / D), the RMS over all vertices and texels, in radians.
"""
from typing import NamedTuple

import numpy as np

CHUNK_ROWS = 4096
# Full eigendecomposition (LAPACK syevd, faster here than the subset driver) up to 48 x 48 texels.
FULL_EIGH_MAX_DIMS = 2304
# The bake's default RMS angular error target, radians.  0.01, after 0.02 and 0.015: against Cycles the
# sharp glossy scenes' error falls with the terms it keeps (docs/ACCURACY.md's truth suite: ggx010_hdri
# 0.107 at 0.015 rad, 47 terms, 0.095 at 0.01, 63); a subdivided Suzanne takes every term (MAX_TERMS).
DEFAULT_ERROR_TARGET = 0.01


class PcaModel(NamedTuple):
    mean: np.ndarray            # (D,) float64
    basis: np.ndarray           # (N, D) float64, orthonormal rows, leading first
    eigenvalues: np.ndarray     # (max_terms,) float64, descending
    rms_error_by_terms: np.ndarray  # (max_terms + 1,) RMS radians with 0..max_terms terms
    total_variance: float       # trace of the covariance (per texel sum)

    @property
    def terms(self):
        return self.basis.shape[0]

    @property
    def rms_error(self):
        return float(self.rms_error_by_terms[self.terms])


def _chunks(count):
    return (slice(start, min(start + CHUNK_ROWS, count)) for start in range(0, count, CHUNK_ROWS))


def fit(samples, terms=None, error_target=DEFAULT_ERROR_TARGET, max_terms=48):
    """PCA of ``samples`` (V, D) (any float dtype, e.g. float16) -> PcaModel.

    terms: fixed number of terms; None chooses the fewest terms whose RMS error
    is <= error_target (radians), at most max_terms.
    """
    count, dims = samples.shape
    max_terms = int(min(max_terms if terms is None else max(terms, 1), dims, max(count, 1)))
    mean = np.zeros(dims)
    for part in _chunks(count):
        mean += samples[part].astype(np.float64).sum(axis=0)
    mean /= max(count, 1)
    covariance = np.zeros((dims, dims))
    mean32 = mean.astype(np.float32)
    for part in _chunks(count):
        # float32 products (2x faster BLAS), summed in float64 across chunks: relative error ~1e-6
        centred = samples[part].astype(np.float32) - mean32
        covariance += centred.T @ centred
    covariance /= max(count, 1)
    total = float(np.trace(covariance))
    if dims <= FULL_EIGH_MAX_DIMS:
        values, vectors = np.linalg.eigh(covariance)
        values, vectors = values[dims - max_terms:], vectors[:, dims - max_terms:]
    else:
        # imported here: only a bake needs it, and an import at the top costs every process
        from scipy import linalg
        values, vectors = linalg.eigh(covariance, subset_by_index=[dims - max_terms, dims - 1])
    values = np.maximum(values[::-1], 0.0)
    vectors = vectors[:, ::-1].T
    # Deterministic signs: the largest component of each basis vector is positive.
    signs = np.sign(vectors[np.arange(len(vectors)), np.argmax(np.abs(vectors), axis=1)])
    vectors *= np.where(signs == 0, 1.0, signs)[:, None]
    residual = np.maximum(total - np.concatenate([[0.0], np.cumsum(values)]), 0.0)
    rms = np.sqrt(residual / dims)
    if terms is None:
        below = np.nonzero(rms <= error_target)[0]
        terms = int(below[0]) if len(below) else max_terms
    terms = int(min(terms, max_terms))
    return PcaModel(mean, vectors[:terms], values, rms, total)


def project(model, samples):
    """PCA coefficients (V, N) float32 of samples (V, D)."""
    out = np.empty((samples.shape[0], model.terms), np.float32)
    mean32 = model.mean.astype(np.float32)
    basis32 = model.basis.T.astype(np.float32)
    for part in _chunks(samples.shape[0]):
        out[part] = (samples[part].astype(np.float32) - mean32) @ basis32
    return out


def reconstruct(model, coefficients):
    """(V, D) float64 from coefficients (V, N)."""
    return model.mean + np.asarray(coefficients, np.float64) @ model.basis
