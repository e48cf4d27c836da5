"""The small-scale geometry of a bi-scale material (iwasaki2012 section 3.1): one tile of a periodic surface,
as triangles, from a height-field image or from a mesh, and what the BVNDF needs of it: area-weighted sample
points with their normals, and rays traced with the tile repeated around it.

Frame: the tile spans [0, size_x] x [0, size_y] in x and y, its mean surface faces z+ (the large-scale normal);
x is the large-scale tangent (a height-field image's columns run along x, its rows along -y: row 0 on top,
as the image shows it).
"""
from dataclasses import dataclass

import numpy as np

from ..visibility import raytrace

# Sample points of the area integrals (eq. 2): iwasaki2012 section 5 samples the tile by area this way.  The
# effective BRDF's error does not move from 2048 to 32768 of them (docs/ACCURACY.md, biscale): the SG forms
# dominate it.
DEFAULT_SAMPLES = 4096
# Cell sides a ray crosses before it counts as escaped (TiledTracer)
MAX_SEGMENTS = 64


@dataclass(frozen=True)
class Microgeometry:
    """One periodic tile: vertices (V, 3), triangles (T, 3) and the tile's size in x and y."""
    vertices: np.ndarray
    triangles: np.ndarray
    size: tuple

    @property
    def footprint(self):
        """Area of the tile's projection on the large-scale plane."""
        return float(self.size[0] * self.size[1])

    def facets(self):
        """(normals (T, 3) unit, areas (T,)) of the triangles; degenerate ones have area 0 and normal z+."""
        p0, p1, p2 = (self.vertices[self.triangles[:, k]] for k in range(3))
        cross = np.cross(p1 - p0, p2 - p0)
        length = np.linalg.norm(cross, axis=1)
        normals = np.where(length[:, None] > 0, cross / np.where(length > 0, length, 1.0)[:, None],
                           np.array([0.0, 0.0, 1.0]))
        return normals, 0.5 * length


def from_height_field(heights, size=1.0, height_scale=1.0):
    """A tile from a periodic height-field image (H, W) (row 0 on top): heights in units of the tile's width
    times height_scale; two triangles a texel, wrapping at the edges so the tile repeats seamlessly."""
    heights = np.asarray(heights, np.float64)
    if heights.ndim == 3:
        heights = heights[..., :3].mean(axis=-1)
    if heights.ndim != 2 or min(heights.shape) < 2:
        raise ValueError(f"a height field is a 2D image of at least 2 x 2 texels, got shape {heights.shape}")
    bad = int(np.count_nonzero(~np.isfinite(heights)))
    if bad:
        raise ValueError(f"the height field has {bad} texel(s) that are not finite numbers (NaN or Inf)")
    rows, columns = heights.shape
    size_x = float(size)
    size_y = size_x * rows / columns
    # vertices on the (rows + 1) x (columns + 1) lattice, the last row and column repeating the first
    wrapped = np.pad(heights, ((0, 1), (0, 1)), mode="wrap")
    r, c = np.meshgrid(np.arange(rows + 1), np.arange(columns + 1), indexing="ij")
    vertices = np.stack([c * (size_x / columns), (rows - r) * (size_y / rows),
                         wrapped * (height_scale * size_x)], axis=-1).reshape(-1, 3)
    index = r[:-1, :-1] * (columns + 1) + c[:-1, :-1]
    right, down = index + 1, index + columns + 1
    # counter-clockwise seen from z+ (rows run along -y)
    triangles = np.concatenate([np.stack([index, down, right], axis=-1).reshape(-1, 3),
                                np.stack([right, down, down + 1], axis=-1).reshape(-1, 3)])
    return Microgeometry(vertices, triangles.astype(np.int64), (size_x, size_y))


def from_mesh(vertices, triangles, size):
    """A tile from a mesh whose x and y extent is one period of size (size_x, size_y), starting at (0, 0)
    (a Blender object's tile: its mesh in object space, moved there by the caller)."""
    vertices = np.asarray(vertices, np.float64).reshape(-1, 3)
    triangles = np.asarray(triangles, np.int64).reshape(-1, 3)
    size = (float(size[0]), float(size[1]))
    if not len(triangles):
        raise ValueError("the small-scale mesh has no faces")
    if not np.all(np.isfinite(vertices)):
        raise ValueError("the small-scale mesh has vertices that are not finite numbers")
    if min(size) <= 0:
        raise ValueError(f"a tile needs a positive size, got {size}")
    if triangles.min() < 0 or triangles.max() >= len(vertices):
        raise ValueError("the small-scale mesh's triangles index vertices it does not have")
    geometry = Microgeometry(vertices, triangles, size)
    normals, areas = geometry.facets()
    if float(np.sum(areas * normals[:, 2])) <= 1e-9 * geometry.footprint:
        raise ValueError("the small-scale mesh does not face z+ (its faces' projected area is not positive): "
                         "a tile is a surface seen from above")
    return geometry


@dataclass(frozen=True)
class SamplePoints:
    """Points spread over the tile by area: positions (N, 3), unit normals (N, 3) and the area each stands for."""
    positions: np.ndarray
    normals: np.ndarray
    area: float


def sample_points(geometry, count=DEFAULT_SAMPLES, seed=0):
    """count points by area, stratified (each triangle gets its share, the remainders drawn by area), at
    random barycentric positions; the same seed gives the same points (the tables do not flicker on an edit)."""
    normals, areas = geometry.facets()
    total = float(areas.sum())
    if total <= 0:
        raise ValueError("the small-scale geometry has no area")
    rng = np.random.default_rng(seed)
    expected = areas * (count / total)
    whole = np.floor(expected).astype(np.int64)
    remainder = int(count - whole.sum())
    if remainder > 0:
        fraction = expected - whole
        whole += np.bincount(rng.choice(len(areas), remainder, replace=False, p=fraction / fraction.sum()),
                             minlength=len(areas))
    chosen = np.repeat(np.arange(len(areas)), whole)
    u, v = rng.random(len(chosen)), rng.random(len(chosen))
    flip = u + v > 1
    u, v = np.where(flip, 1 - u, u), np.where(flip, 1 - v, v)
    corners = geometry.vertices[geometry.triangles[chosen]]
    positions = (1 - u - v)[:, None] * corners[:, 0] + u[:, None] * corners[:, 1] + v[:, None] * corners[:, 2]
    return SamplePoints(positions, normals[chosen], total / len(chosen))


class TiledTracer:
    """Rays against the periodic surface, with the tile traced alone: a ray goes from cell side to cell side
    (the tile's x y box) and, where it leaves, comes back in at the opposite side, until it stops, rises above
    the geometry (then nothing can stop it) or has crossed MAX_SEGMENTS sides (then it counts as free: rays
    within a few degrees of the horizon over a steep tile)."""

    def __init__(self, geometry, threads=2):
        self.geometry = geometry
        self._tracer = raytrace.RayTracer(geometry.vertices, geometry.triangles, threads=threads)
        self.offset = 1e-4 * max(geometry.size)
        self.top = float(geometry.vertices[:, 2].max()) if len(geometry.vertices) else 0.0
        self._size = np.asarray(geometry.size, np.float64)

    def wrap(self, points):
        """Points moved by whole periods into the tile."""
        points = np.array(points, np.float64)
        points[..., 0] = np.mod(points[..., 0], self.geometry.size[0])
        points[..., 1] = np.mod(points[..., 1], self.geometry.size[1])
        return points

    def _to_side(self, origins, directions):
        """(ray parameter to the side of the cell the ray leaves by (N,), that side's axis (N,))."""
        distance = np.full((len(origins), 2), np.inf)
        for axis in (0, 1):
            d = directions[:, axis]
            forward, backward = d > 0, d < 0
            distance[forward, axis] = (self._size[axis] - origins[forward, axis]) / d[forward]
            distance[backward, axis] = -origins[backward, axis] / d[backward]
        axis = np.argmin(distance, axis=1)
        return np.maximum(distance[np.arange(len(origins)), axis], 0.0), axis

    def _march(self, origins, directions, query, out):
        """Trace side to side: query(origins, directions, lengths) -> (stopped (M,) bool, value (M, ...)) for
        the rays still going; a stopped ray's value goes to its row of out.  Returns (N,) stopped."""
        origins = self.wrap(origins)
        directions = np.asarray(directions, np.float64)
        going = np.arange(len(origins))
        stopped = np.zeros(len(origins), bool)
        for segment in range(MAX_SEGMENTS):
            if not len(going):
                break
            o, d = (origins, directions) if segment == 0 else (origins[going], directions[going])
            length, axis = self._to_side(o, d)
            done, value = query(o, d, np.minimum(length, 1e30))
            out[going[done]] = value[done]
            stopped[going[done]] = True
            keep = ~done & np.isfinite(length)
            ends = o[keep] + length[keep, None] * d[keep]
            keep[keep] = ends[:, 2] <= self.top          # risen above the geometry: free
            ends = ends[ends[:, 2] <= self.top]
            going, axis, d = going[keep], axis[keep], d[keep]
            rows = np.arange(len(going))
            ends = self.wrap(ends)
            # in again at the opposite side (exactly on it: a wrap would take the far side to 0 again)
            ends[rows, axis] = np.where(d[rows, axis] > 0, 0.0, self._size[axis])
            origins[going] = ends
        return stopped

    def visible(self, positions, normals, directions):
        """(N,) bool: rays from the points (offset along their normals) towards directions meet nothing."""
        directions = np.asarray(directions, np.float64)
        origins = raytrace.offset_origins(self.wrap(positions), normals, self.offset, directions)

        def query(o, d, length):
            blocked = self._tracer.occluded(o, d, length)
            return blocked, blocked

        return ~self._march(origins, directions, query, np.zeros(len(origins), bool))

    def first_hit(self, origins, directions):
        """(hit (N,), positions (N, 3) in the tile, triangle (N,) of the tile) of rays from origins."""
        directions = np.asarray(directions, np.float64)
        tile_triangles = max(len(self.geometry.triangles), 1)

        def query(o, d, length):
            hits = self._tracer.intersect(o, d, length)
            where = o + np.where(hits.hit, hits.distance, 0.0)[:, None] * d
            return hits.hit, np.concatenate([where, (hits.triangle % tile_triangles)[:, None]], axis=1)

        found = np.zeros((len(directions), 4))
        hit = self._march(np.asarray(origins, np.float64), directions, query, found)
        return hit, self.wrap(found[:, :3]), np.where(hit, found[:, 3], -1).astype(np.int64)

    def close(self):
        self._tracer.close()
