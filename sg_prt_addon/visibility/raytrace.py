"""Ray casting against a triangle mesh: the one module that imports embreex.

Keeping Embree behind this module lets it move to a subprocess on platforms
where its bundled Embree/TBB clashes with Blender's own.

embreex traces one ray at a time in C with the GIL released, so two Python
threads over ray chunks use both cores.  Its rays start at tnear = 0: callers
must move ray origins off the surface (``offset_origins``), or a ray leaving a
triangle can hit that same triangle.
"""
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

# embreex's "no limit" tfar; distances of missed rays are reported as inf.
_EMBREE_FAR = np.float32(1e37)
_CHUNK_RAYS = 1 << 16
# Coordinates a bake traces: a vertex beyond them, NaN or Inf is bad input, and its triangles are not traced
# (one such vertex would make the scene's size, and so every ray's origin offset, NaN or huge).
COORDINATE_LIMIT = 1e10


def traceable(vertices):
    """(V,) bool: which vertices (V, 3) are finite and within COORDINATE_LIMIT."""
    vertices = np.asarray(vertices, np.float64).reshape(-1, 3)
    with np.errstate(invalid="ignore"):
        return np.all(np.abs(vertices) <= COORDINATE_LIMIT, axis=1)


class RayHits(NamedTuple):
    """First hits of a batch of rays.  Missed rays: hit False, distance inf,
    triangle -1, u = v = 0.  The hit point is (1-u-v) p0 + u p1 + v p2."""
    hit: np.ndarray        # (N,) bool
    distance: np.ndarray   # (N,) float64, along the (not necessarily unit) direction
    triangle: np.ndarray   # (N,) int64
    u: np.ndarray          # (N,) float64 barycentric weight of the triangle's 2nd vertex
    v: np.ndarray          # (N,) float64 barycentric weight of the triangle's 3rd vertex


def offset_origins(points, normals, scale, directions=None):
    """Move points by ``scale`` along their normals so rays leaving them do not hit their own triangle.

    With ``directions`` given, each normal is first flipped to the side the ray
    leaves to (a shadow ray below the geometric normal starts below the surface).
    ``scale`` is a distance: use ``RayTracer.offset`` for one relative to the scene size.
    """
    normals = np.asarray(normals, dtype=np.float64)
    if directions is not None:
        backwards = np.einsum("...i,...i->...", normals, np.asarray(directions, dtype=np.float64)) < 0
        normals = np.where(backwards[..., None], -normals, normals)
    return np.asarray(points, dtype=np.float64) + scale * normals


class RayTracer:
    """Occlusion and first-hit queries against one static triangle mesh.

    vertices (V, 3) float, triangles (T, 3) int.  Queries take (N, 3) origins
    and directions (any float dtype; traced in float32) and run on ``threads``
    threads over chunks of ``chunk_rays`` rays, which also bounds memory.
    """

    def __init__(self, vertices, triangles, threads=2, chunk_rays=_CHUNK_RAYS, relative_offset=1e-4):
        self.vertices = np.ascontiguousarray(vertices, dtype=np.float32).reshape(-1, 3)
        self.triangles = np.ascontiguousarray(triangles, dtype=np.int32).reshape(-1, 3)
        if len(self.triangles) and (self.triangles.min() < 0 or self.triangles.max() >= len(self.vertices)):
            raise ValueError("triangle indices out of range")
        good = traceable(self.vertices)
        if not good.all():
            # a triangle of a bad vertex becomes a point (no area: never hit), so hits keep the callers' indices
            bad = ~good[self.triangles].all(axis=1)
            self.triangles = self.triangles.copy()
            self.triangles[bad] = self.triangles[bad, :1]
            self.vertices = np.where(good[:, None], self.vertices, np.float32(0.0))
        used = self.vertices[good]
        extent = np.ptp(used, axis=0) if len(used) else np.zeros(3)
        self.scene_size = float(max(np.linalg.norm(extent), 1e-6))
        # Origin offset: well above float32 rounding of scene coordinates
        # (~1e-7 of their magnitude), well below any feature we care about.
        self.offset = relative_offset * self.scene_size
        self.threads = max(1, int(threads))
        self.chunk_rays = max(1, int(chunk_rays))
        self._scene = rtcore_scene.EmbreeScene()
        self._empty = len(self.triangles) == 0
        if not self._empty:
            TriangleMesh(self._scene, self.vertices, self.triangles)
            # The first run() commits the scene: do it here, on one thread.
            self._scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32), query="OCCLUDED")
        self._pool = ThreadPoolExecutor(self.threads) if self.threads > 1 else None
        self.rays_traced = 0   # running count of rays queried, for throughput figures
        self.seconds_tracing = 0.0      # summed over threads: the time inside Embree's occlusion queries
        self._count_lock = threading.Lock()     # queries may come from several threads at once

    def close(self):
        if getattr(self, "_pool", None) is not None:
            self._pool.shutdown(wait=False)
            self._pool = None

    def __del__(self):
        self.close()

    def _prepare(self, origins, directions, max_distance):
        origins = np.ascontiguousarray(np.reshape(origins, (-1, 3)), dtype=np.float32)
        directions = np.ascontiguousarray(np.reshape(directions, (-1, 3)), dtype=np.float32)
        if origins.shape != directions.shape:
            raise ValueError(f"origins {origins.shape} and directions {directions.shape} differ")
        if max_distance is None:
            far = np.full(len(origins), _EMBREE_FAR, np.float32)
        else:
            far = np.broadcast_to(np.asarray(max_distance, np.float32), (len(origins),))
            far = np.ascontiguousarray(np.clip(np.nan_to_num(far, nan=0.0, posinf=_EMBREE_FAR), 0, _EMBREE_FAR))
        return origins, directions, far

    def _count(self, rays, seconds=0.0):
        with self._count_lock:
            self.rays_traced += rays
            self.seconds_tracing += seconds

    def _map_chunks(self, work, count):
        starts = range(0, count, self.chunk_rays)
        slices = [slice(s, min(s + self.chunk_rays, count)) for s in starts]
        if self._pool is None or len(slices) == 1:
            return [work(s) for s in slices]
        return list(self._pool.map(work, slices))

    def occluded(self, origins, directions, max_distance=None):
        """(N,) bool: True where something lies along the ray within (0, max_distance].

        max_distance is in units of the direction's length (scalar or (N,));
        None means unbounded.
        """
        origins, directions, far = self._prepare(origins, directions, max_distance)
        self._count(len(origins))
        result = np.zeros(len(origins), bool)
        if self._empty or len(origins) == 0:
            return result

        def work(part):
            # tfar is copied per chunk: embreex may write into the array it is given.
            started = time.perf_counter()
            ids = self._scene.run(origins[part], directions[part], dists=far[part].copy(), query="OCCLUDED")
            self._count(0, time.perf_counter() - started)
            result[part] = ids != -1

        self._map_chunks(work, len(origins))
        return result

    def intersect(self, origins, directions, max_distance=None):
        """First hit of each ray: a RayHits of (N,) arrays."""
        origins, directions, far = self._prepare(origins, directions, max_distance)
        count = len(origins)
        self._count(count)
        distance = np.full(count, np.inf)
        triangle = np.full(count, -1, np.int64)
        u = np.zeros(count)
        v = np.zeros(count)
        if not self._empty and count:
            def work(part):
                out = self._scene.run(origins[part], directions[part], dists=far[part].copy(), output=1)
                hit = out["primID"] >= 0
                triangle[part] = np.where(hit, out["primID"], -1)
                distance[part] = np.where(hit, out["tfar"], np.inf)
                u[part] = np.where(hit, out["u"], 0.0)
                v[part] = np.where(hit, out["v"], 0.0)

            self._map_chunks(work, count)
        return RayHits(triangle >= 0, distance, triangle, u, v)

    def hit_points(self, hits):
        """World positions (N, 3) float64 of hits from their barycentrics (more accurate than o + t d);
        missed rays give 0."""
        corners = self.vertices[self.triangles[np.maximum(hits.triangle, 0)]].astype(np.float64)
        w = np.stack([1.0 - hits.u - hits.v, hits.u, hits.v], axis=-1)
        return np.where(hits.hit[:, None], np.einsum("nk,nkc->nc", w, corners), 0.0)

    def geometric_normals(self, triangle_index):
        """Unit geometric normals (N, 3) float64 of triangles (winding order: right-handed)."""
        corners = self.vertices[self.triangles[np.maximum(triangle_index, 0)]].astype(np.float64)
        n = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        length = np.linalg.norm(n, axis=-1, keepdims=True)
        return np.where(length > 0, n / np.where(length > 0, length, 1), np.array([0.0, 0.0, 1.0]))
