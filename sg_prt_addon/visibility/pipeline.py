"""The visibility bake: mesh vertices -> rays -> SSDF -> PCA, from plain arrays (wang2009 section 5.2).

``bake_visibility`` writes nothing anywhere: it returns a ``BakeResult`` (or
raises ``BakeCancelled`` / an error), so a cancelled or failed bake leaves
whatever the caller stored before intact.
"""
import hashlib
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
import threadpoolctl

from . import binary_visibility, buried, hemisphere_map, pca, ssdf
from .per_vertex import MAX_TERMS
from .raytrace import RayTracer


class BakeCancelled(Exception):
    """The progress callback returned True; nothing was produced."""


@dataclass
class BakeOptions:
    resolution: int = 32            # stored SSDF samples per side = coarse rays per side
    refinement: int = 5             # odd supersampling factor of mixed coarse cells (fine grid 160 x 160)
    terms: Optional[int] = None     # PCA terms; None: the fewest reaching error_target
    error_target: float = pca.DEFAULT_ERROR_TARGET  # RMS angular error of the PCA, radians (when terms is None)
    max_terms: int = MAX_TERMS      # wang2009 uses 48; these and the mean fill MAX_ROWS vec4 (pack_coefficients)
    batch_vertices: int = 256       # vertices traced per RayTracer call (amortizes Python overhead)
    threads: int = 2
    relative_offset: float = 1e-4   # ray origin offset along the normal, times the occluders' diagonal


@dataclass
class BakeResult:
    """A finished bake.  SSDF of vertex x at the stored sample [b, a] (``hemisphere_map.sample_directions``)
    ~ mean + coefficients[x] @ basis."""
    coefficients: np.ndarray        # (V, N) float32
    basis: np.ndarray               # (N, R, R) float32, orthonormal over texels
    mean: np.ndarray                # (R, R) float32
    resolution: int
    terms: int
    rms_error: float                # RMS angular error of the PCA over vertices and texels, radians
    rms_error_by_terms: np.ndarray  # (max_terms + 1,) the same for 0..max_terms terms
    vertex_count: int
    topology_hash: str              # of the baked mesh (vertex count + triangles): detects stale bakes
    frame_reference_axis: np.ndarray = field(default_factory=lambda: hemisphere_map.FRAME_REFERENCE_AXIS.copy())
    rays_traced: int = 0
    buried_points: int = 0          # points inside other geometry whose rows came from their neighbours (buried)
    seconds_tracing: float = 0.0    # inside Embree's queries, summed over threads (the rest is SSDF, PCA, numpy)
    seconds: float = 0.0

    def ssdf(self, vertex_index=slice(None)):
        """Decompressed SSDF (..., R, R) float32 of some vertices."""
        flat = self.coefficients[vertex_index] @ self.basis.reshape(self.terms, -1) + self.mean.ravel()
        return flat.reshape(flat.shape[:-1] + self.mean.shape).astype(np.float32)


def topology_hash(vertex_count, triangles):
    """Hex digest of the vertex count and the triangle index list (int64, C order)."""
    digest = hashlib.blake2b(digest_size=16)
    digest.update(np.int64(vertex_count).tobytes())
    digest.update(np.ascontiguousarray(triangles, np.int64).tobytes())
    return digest.hexdigest()


def _report(progress, fraction, message):
    if progress is not None and progress(float(fraction), message):
        raise BakeCancelled(message)


def one_blas_thread():
    """Context: numpy's BLAS (and scipy's) on one thread.  The bake's own threads already fill the cores, and
    the SSDF's products (``ssdf.signed_distance``) are too small for BLAS's threads to pay: on 2 cores they
    took the second core from the other batch's rays, and the whole bake ran 1.3x slower."""
    return threadpoolctl.threadpool_limits(limits=1, user_api="blas")


def bake_ssdf(vertices, normals, tracer, options, progress=None, tangents=None):
    """Uncompressed SSDFs (V, R * R) float16 of vertices (rays only; no PCA).

    float16 halves memory (41 MB for 20k vertices at 32 x 32); its rounding is
    <= 4.9e-4 rad for |values| <= pi, far below a texel (0.05 rad).
    """
    vertices = np.asarray(vertices, np.float64).reshape(-1, 3)
    frames = hemisphere_map.local_frame(normals, tangents)
    origins = vertices + tracer.offset * frames[:, 2]
    count = len(vertices)
    resolution = options.resolution
    out = np.empty((count, resolution * resolution), np.float16)

    def bake_batch(part):
        fine, _ = binary_visibility.adaptive_visibility(tracer, origins[part], frames[part], resolution,
                                                        options.refinement)
        out[part] = ssdf.ssdf_from_fine(fine, resolution).reshape(fine.shape[0], -1)

    # Each worker bakes whole batches (coarse rays, refinement, distances): the numpy steps of one batch run
    # while another's rays are traced (embreex and numpy release the GIL), where one batch at a time left the
    # cores idle between its steps.  Batches write disjoint rows, in any order; progress follows the first ones.
    parts = [slice(start, min(start + options.batch_vertices, count))
             for start in range(0, count, options.batch_vertices)]
    with one_blas_thread():
        pool = ThreadPoolExecutor(max(1, options.threads))
        try:
            futures = [pool.submit(bake_batch, part) for part in parts]
            for part, future in zip(parts, futures):
                future.result()
                _report(progress, 0.9 * part.stop / max(count, 1), f"visibility {part.stop}/{count} vertices")
        finally:
            pool.shutdown(wait=True, cancel_futures=True)      # a cancel or an error: no batch keeps running
    return out


def bake_visibility(vertices, triangles, normals, occluder_vertices, occluder_triangles,
                    options: Optional[BakeOptions] = None,
                    progress: Optional[Callable[[float, str], Optional[bool]]] = None,
                    tangents=None, point_triangles=None) -> BakeResult:
    """Bake PCA-compressed SSDF visibility at every vertex of a mesh.

    vertices (V, 3), normals (V, 3) (per vertex, world space); triangles (T, 3)
    of the baked mesh (only hashed); occluder_vertices / occluder_triangles: all
    scene triangles that cast shadows, the baked mesh included.  tangents:
    optional (V, 3) x axes of the local frames (default ``hemisphere_map.local_frame``:
    the shader must build the same frame).  point_triangles: optional (T, 3) triangles over the baked
    points (the mesh's triangles where the points are its vertices): with them, points buried inside
    other geometry take their rows from their neighbours (``visibility.buried``).
    progress(fraction, message) is called after each batch of vertices; returning True raises
    BakeCancelled.
    """
    options = options or BakeOptions()
    if options.refinement % 2 != 1 or options.resolution < 2:
        raise ValueError("resolution must be >= 2 and refinement odd")
    started = time.perf_counter()
    vertices = np.asarray(vertices, np.float64).reshape(-1, 3)
    normals = np.asarray(normals, np.float64).reshape(-1, 3)
    if normals.shape != vertices.shape:
        raise ValueError(f"normals {normals.shape} do not match vertices {vertices.shape}")
    _report(progress, 0.0, "building the ray tracer")
    # one thread a tracer call: bake_ssdf runs options.threads batches at once
    tracer = RayTracer(occluder_vertices, occluder_triangles, threads=1, chunk_rays=1 << 15,
                       relative_offset=options.relative_offset)
    try:
        samples = bake_ssdf(vertices, normals, tracer, options, progress, tangents)
        buried_points = 0 if point_triangles is None else buried.fill_buried_points(
            samples, tracer, vertices, normals, point_triangles, open_share=(samples > 0).mean(axis=1),
            threads=options.threads)
        rays, seconds_tracing = tracer.rays_traced, tracer.seconds_tracing
    finally:
        tracer.close()
    _report(progress, 0.9, "PCA")
    model = pca.fit(samples, options.terms, options.error_target, options.max_terms)
    coefficients = pca.project(model, samples)
    resolution = options.resolution
    result = BakeResult(
        coefficients=coefficients,
        basis=model.basis.reshape(-1, resolution, resolution).astype(np.float32),
        mean=model.mean.reshape(resolution, resolution).astype(np.float32),
        resolution=resolution, terms=model.terms, rms_error=model.rms_error,
        rms_error_by_terms=model.rms_error_by_terms, vertex_count=len(vertices),
        topology_hash=topology_hash(len(vertices), triangles), rays_traced=rays, buried_points=buried_points,
        seconds_tracing=seconds_tracing, seconds=time.perf_counter() - started)
    if progress is not None:
        progress(1.0, "done")  # finished: a late cancel request no longer discards the result
    return result
