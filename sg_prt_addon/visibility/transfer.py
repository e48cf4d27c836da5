"""Precomputed radiance transfer for the SH technique (kautz2002 section 5, after Sloan et al. 2002): per
vertex p, how the object's own geometry shadows distant SH lighting.  Pure numpy + the ray tracer.

- Diffuse transfer vector: t_i(p) = integral of V_p(s) max(n.s, 0) Y_i(s) ds, so the shadowed irradiance
  of lighting L is sum_i t_i L_i (Sloan's diffuse transfer, exact within the order).
- Glossy transfer matrix: T_ij(p) = integral of Y_i(s) V_p(s) Y_j(s) ds (symmetric), so T L is the SH of
  the visible incident radiance V_p L; the SH technique dots it with the BRDF product (the paper's sec. 5:
  the transfer applied to the lighting before the rotation and the lookup).  Shadows only: no
  interreflection bounce.
- V_p(s) is 1 where a ray from p (moved off the surface) along s escapes the scene and s is above the
  vertex's tangent plane, 0 otherwise; the integrals are the open sky's (exact) less the occluded
  directions of a lattice of the vertex's hemisphere, turned into the world frame by SH rotation.

Compression: every vertex's transfer, [t (N^2), the upper triangle of T (N^2 (N^2 + 1) / 2)], is one
vector of D values; PCA (visibility/pca.py) keeps the mean and K terms, K chosen by an error target on
the relative RMS of the vectors, at most visibility.per_vertex.MAX_TERMS so the weights [1, w_0 ..] fill
the per-vertex rows.  The shader reconstructs t(p) and T(p) L from the weights (the per-term products
B_k L are computed once per frame per object).
"""
import time
from dataclasses import dataclass

import numpy as np

from ..harmonics import basis, projection, rotation
from ..spherical import lattice
from . import buried, decode, hemisphere_map, pca
from .per_vertex import MAX_TERMS
from .pipeline import BakeCancelled, topology_hash
from .raytrace import RayTracer

MAX_ORDER = 6          # D = 36 + 666 = 702 values a vertex before compression


@dataclass
class TransferOptions:
    order: int = 5
    directions: int = 1024          # of the whole sphere: half of them, the hemisphere's, are traced a vertex
    terms: int | None = None        # fixed PCA terms; None: the fewest reaching error_target
    error_target: float = 0.02      # relative RMS of the transfer vectors
    max_terms: int = MAX_TERMS
    threads: int = 2
    relative_offset: float = 1e-4


@dataclass
class TransferResult:
    order: int
    coefficients: np.ndarray        # (V, K) float32 PCA weights
    mean: np.ndarray                # (D,) float32
    basis: np.ndarray               # (K, D) float32
    terms: int
    relative_error: float           # relative RMS of the reconstructed transfer vectors
    vertex_count: int
    topology_hash: str
    rays_traced: int
    seconds: float
    relative_error_by_terms: np.ndarray = None
    buried_points: int = 0          # points inside other geometry whose vectors came from their neighbours


def vector_size(order):
    """D: values of one vertex's transfer before compression."""
    count = order * order
    return count + count * (count + 1) // 2


def pack(diffuse, glossy):
    """One vector (..., D) of diffuse (..., N^2) and symmetric glossy (..., N^2, N^2): its upper triangle."""
    count = diffuse.shape[-1]
    upper = np.triu_indices(count)
    return np.concatenate([diffuse, glossy[..., upper[0], upper[1]]], axis=-1)


def unpack(vector, order):
    """(diffuse (..., N^2), glossy (..., N^2, N^2)) of packed transfer vectors (..., D)."""
    vector = np.asarray(vector)
    count = order * order
    upper = np.triu_indices(count)
    glossy = np.zeros(vector.shape[:-1] + (count, count), vector.dtype)
    glossy[..., upper[0], upper[1]] = vector[..., count:]
    glossy[..., upper[1], upper[0]] = vector[..., count:]
    return vector[..., :count], glossy


def open_sky(order):
    """(t, T) of an unoccluded vertex in its own frame (z along the normal), exactly: the clamped cosine's
    zonal coefficients, and the hemisphere's Gram matrix by a Gauss-Legendre x azimuth rule exact for it."""
    z_count = order + 2
    t, w = np.polynomial.legendre.leggauss(z_count)
    z, wz = 0.5 * (t + 1.0), 0.5 * w
    phi = (np.arange(2 * order + 2) + 0.5) * (2 * np.pi / (2 * order + 2))
    r = np.sqrt(1.0 - z * z)
    directions = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
    weights = np.broadcast_to(wz[:, None] * (2 * np.pi / len(phi)), directions.shape[:2]).reshape(-1)
    y = basis.evaluate(directions.reshape(-1, 3), order)
    diffuse = projection.rotate_zonal(projection.clamped_cosine_zonal(order), [0.0, 0.0, 1.0])
    return diffuse, (y * weights[:, None]).T @ y


def transfer_vectors(vertices, normals, tracer, order, directions, progress=None, batch=256):
    """(V, D) float32 packed transfer of every vertex (world space vertices and normals (V, 3)).

    The integrals are taken in each vertex's own frame (hemisphere_map.local_frame: z along the normal): the
    open sky's exactly (open_sky), less the occluded directions of a Fibonacci lattice of ``directions`` // 2
    points of the hemisphere, so the tangent plane's cut costs nothing (a whole-sphere lattice straddles
    it: 1.35e-2 of the largest entry unoccluded at 1024 directions, docs/ACCURACY.md); then turned into the
    world frame: t by M(R), T by M(R) T M(R)^T (harmonics.rotation, R local -> world)."""
    vertices = np.asarray(vertices, np.float64)
    frames = hemisphere_map.local_frame(np.asarray(normals, np.float64))           # rows: world -> local
    local = lattice.hemisphere_points(max(int(directions) // 2, 1))
    weight = 2.0 * np.pi / len(local)
    y = basis.evaluate(local, order)                                                # (S, N^2)
    sky_diffuse, sky_glossy = open_sky(order)
    count = order * order
    upper = np.triu_indices(count)
    products = y[:, upper[0]] * y[:, upper[1]]                                      # (S, N^2 (N^2 + 1) / 2)
    cosine = local[:, 2]
    out = np.empty((len(vertices), vector_size(order)), np.float32)
    for start in range(0, len(vertices), batch):
        stop = min(start + batch, len(vertices))
        world = np.einsum("sj,bjk->bsk", local, frames[start:stop])                 # (B, S, 3)
        origins = vertices[start:stop, None, :] + tracer.offset * frames[start:stop, None, 2, :]
        visible = ~tracer.occluded(np.broadcast_to(origins, world.shape).reshape(-1, 3),
                                   world.reshape(-1, 3)).reshape(world.shape[:2])
        occluded = ~visible
        # the open sky exactly, less what the lattice finds occluded (a control variate: an unoccluded
        # vertex is exact, only the occluders' outlines carry the lattice's error)
        diffuse = sky_diffuse - (occluded * (cosine * weight)) @ y                  # (B, N^2), local frame
        glossy = np.zeros((stop - start, count, count))
        glossy[:, upper[0], upper[1]] = sky_glossy[upper] - (occluded * weight) @ products
        glossy[:, upper[1], upper[0]] = glossy[:, upper[0], upper[1]]
        to_world = np.swapaxes(frames[start:stop], 1, 2)                             # columns t, b, n
        diffuse = rotation.rotate_zyz_many(diffuse, to_world)
        glossy = rotation.rotate_zyz_many(glossy, to_world)                          # M T
        glossy = rotation.rotate_zyz_many(np.swapaxes(glossy, 1, 2), to_world)       # M (M T)^T = M T M^T
        out[start:stop] = pack(diffuse, glossy)
        if progress is not None and progress(stop / len(vertices), f"transfer {stop}/{len(vertices)} vertices"):
            raise BakeCancelled("cancelled")
    return out


def bake_transfer(vertices, triangles, normals, occluder_vertices, occluder_triangles, options=None,
                  progress=None, point_triangles=None):
    """Bake and compress the transfer of one mesh's vertices (world space; occluders: every scene triangle
    that casts shadows, the mesh included).  progress(fraction, message) -> True cancels (BakeCancelled).
    point_triangles: as pipeline.bake_visibility's (buried points take their neighbours' vectors)."""
    options = options or TransferOptions()
    if not 2 <= options.order <= MAX_ORDER:
        raise ValueError(f"transfer order {options.order}: 2 to {MAX_ORDER}")
    started = time.perf_counter()
    vertices = np.asarray(vertices, np.float64).reshape(-1, 3)
    normals = np.asarray(normals, np.float64).reshape(-1, 3)
    tracer = RayTracer(occluder_vertices, occluder_triangles, threads=options.threads, chunk_rays=1 << 15,
                       relative_offset=options.relative_offset)
    try:
        def scaled(fraction, message):
            return progress is not None and progress(0.9 * fraction, message)
        samples = transfer_vectors(vertices, normals, tracer, options.order, options.directions, scaled)
        # the glossy matrix's first entry is the visible solid angle over 4 pi (band 0: the same in any frame)
        open_share = samples[:, options.order ** 2] / open_sky(options.order)[1][0, 0]
        buried_points = 0 if point_triangles is None else buried.fill_buried_points(
            samples, tracer, vertices, normals, point_triangles, open_share=open_share, threads=options.threads)
        rays = tracer.rays_traced
    finally:
        tracer.close()
    if progress is not None and progress(0.9, "PCA"):
        raise BakeCancelled("cancelled")
    model, errors = compress(samples, options.terms, options.error_target, options.max_terms)
    result = TransferResult(options.order, pca.project(model, samples), model.mean.astype(np.float32),
                            model.basis.astype(np.float32), model.terms, float(errors[model.terms]),
                            len(vertices), topology_hash(len(vertices), triangles), rays,
                            time.perf_counter() - started, errors, buried_points)
    if progress is not None:
        progress(1.0, "done")
    return result


def compress(samples, terms=None, error_target=0.02, max_terms=MAX_TERMS):
    """(pca.PcaModel, relative RMS error by terms (max_terms + 1,)): the relative error is the RMS of the
    residual over the RMS of the vectors themselves (not their spread about the mean)."""
    model = pca.fit(samples, terms=max_terms, max_terms=max_terms)
    scale = np.sqrt(np.mean(np.sum(np.asarray(samples, np.float64) ** 2, axis=1)) / samples.shape[1])
    errors = model.rms_error_by_terms / max(scale, 1e-30)
    if terms is None:
        below = np.nonzero(errors <= error_target)[0]
        terms = int(below[0]) if len(below) else max_terms
    terms = int(min(terms, model.terms))
    return pca.PcaModel(model.mean, model.basis[:terms], model.eigenvalues, model.rms_error_by_terms,
                        model.total_variance), errors


def reconstruct(result):
    """(V, D) float32 transfer vectors of a TransferResult (mean + weights x basis)."""
    return (result.mean[None] + result.coefficients @ result.basis).astype(np.float32)


def basis_texture(mean, basis_vectors):
    """(L, 1, D, 4) float32 texture array of [mean, B_0, ...] four to a layer (the rows' layout)."""
    return decode.pack_basis_texture(np.asarray(mean)[None, :], np.asarray(basis_vectors)[:, None, :])


def basis_terms(basis_texture_array):
    """(4 L, D) float32 [mean, B_0, ..., zero padding] of a basis_texture (L, 1, D, 4)."""
    texture = np.asarray(basis_texture_array)
    return np.ascontiguousarray(texture[:, 0].transpose(0, 2, 1).reshape(-1, texture.shape[2]))


def order_of(size):
    """The transfer order N of vectors of D = vector_size(N) values (ValueError otherwise)."""
    for order in range(1, MAX_ORDER + 1):
        if vector_size(order) == size:
            return order
    raise ValueError(f"{size} values a vertex: no transfer order")


def transferred_radiance(terms, lighting, transfer_order, order):
    """(K, N^2 + 1, C) float32 of every term k of terms (K, D) ([mean, B_0, ...]) at shading order N <=
    transfer_order: columns i < N^2 are (T_k L)_i, the glossy transfer of the lighting L (>= N^2, C),
    column N^2 is t_k . L, the diffuse transfer's irradiance: what the shader weighs by the vertex's
    [1, w_0, ...] per frame.  The leading N^2 block of an order's transfer is the lower order's (the same
    integrals)."""
    count = order * order
    lighting = np.asarray(lighting, np.float64)[:count]
    diffuse, glossy = unpack(np.asarray(terms, np.float64), transfer_order)
    out = np.empty((len(diffuse), count + 1, lighting.shape[1]), np.float32)
    out[:, :count] = np.einsum("kij,jc->kic", glossy[:, :count, :count], lighting)
    out[:, count] = diffuse[:, :count] @ lighting
    return out
