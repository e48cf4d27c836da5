"""The BVNDF of a tile as SGs (iwasaki2012 section 4): the NDF's lobes fitted once (eq. 6, spherical EM),
their amplitudes re-solved for every pair of directions (eq. 7-8) from the tile's masking and shadowing.

gamma~(n, i, o) = gamma(n, i, o) (n.i)(n.o) / a_v(o) (eq. 5) is, for the tile's sample points s (area dA each),
the sum of deltas at their normals with weights w_s(i, o) = dA V_s(i) V_s(o) max(0, n_s.i) max(0, n_s.o) / a_v(o),
a_v(o) = sum_s dA V_s(o) max(0, n_s.o).  The least-squares amplitudes solve A mu = b with A_jk = <G_j, G_k> and
b_j = sum_s w_s G_j(n_s) (eq. 8's normal equations; iwasaki2012 bins the normals first, the sum is the limit),
kept non-negative.  That fit is not mass-preserving: a cluster of normals sharper than its lobe (a flat facet,
whose lobe's sharpness is capped) gets up to twice its weight.  The default therefore shares each point's
weight among the lobes by the NDF mixture's responsibilities, mu_j = c(eta_j) sum_s w_s r_sj: the integral of
the lobes is that of gamma~ exactly, the amplitudes are non-negative by construction, and where the data has
the lobes' shape the two agree (AMPLITUDE_SOLVES; their errors in docs/ACCURACY.md).

Directions i and o run over the hemisphere map's sample lattice (visibility.hemisphere_map.sample_directions,
R x R each, R = 12 the paper's 144): the tables are indexed [i, o] by lattice index b R + a, and read between
nodes by multilinear interpolation (interpolate, below).  The lattice's outer ring lies on the
horizon, where every cosine is 0: its rays leave at HORIZON_LIFT above it, so the stored values there are
the limits the interpolation needs (a value per unit cos(theta_i), below).
"""
import functools
import hashlib
from dataclasses import dataclass

import numpy as np

from ..spherical import lattice, sg
from ..visibility import hemisphere_map
from . import microgeometry, spherical_em

DEFAULT_RESOLUTION = 12
DEFAULT_LOBES = 16           # iwasaki2012 figures 3-4 use 4 to 8; sharp small-scale BRDFs need more (docs/ACCURACY.md)
HORIZON_LIFT = np.radians(3.0)
_SOLVER_ITERATIONS = 200
AMPLITUDE_SOLVES = ("responsibility", "least_squares")
ALBEDO_POINTS = 2048
NORMAL_BIN = 1e-2             # per normal component, about 0.6 degree: below the lobes' widths (docs/ACCURACY.md)


def lattice_directions(resolution):
    """(R^2, 3) unit directions of the table's nodes, index b R + a; the horizon ring lifted by HORIZON_LIFT."""
    directions = hemisphere_map.sample_directions(resolution).reshape(-1, 3)
    floor = np.sin(HORIZON_LIFT)
    low = directions[:, 2] < floor
    horizontal = np.linalg.norm(directions[:, :2], axis=1, keepdims=True)
    lifted = np.concatenate([directions[:, :2] / np.maximum(horizontal, 1e-12) * np.cos(HORIZON_LIFT),
                             np.full((len(directions), 1), floor)], axis=1)
    return np.where(low[:, None], lifted, directions)


@dataclass(frozen=True)
class BVNDF:
    """axes (J, 3), sharpness (J,) and mixture weights (J,) of the NDF lobes (tile frame); amplitudes (J, K, K)
    mu_j(i, o) per unit cos(theta_i); integral (K, K) the exact integral of gamma~ over n per unit cos(theta_i)
    (the diffuse term's, eq. 9 without its SG approximation), albedo (K,) its cosine-weighted mean over i
    (1 / pi integral of D(i, o) cos(theta_i) di: a constant world's diffuse factor); directions (K, 3) the
    lattice, K = R^2."""
    axes: np.ndarray
    sharpness: np.ndarray
    mixture: np.ndarray
    amplitudes: np.ndarray
    integral: np.ndarray
    albedo: np.ndarray
    directions: np.ndarray
    resolution: int

    @property
    def lobe_count(self):
        return len(self.sharpness)

    @functools.cached_property
    def signature(self):
        """A content hash: what the engine keys its GPU tables by."""
        digest = hashlib.sha1()
        for array in (self.axes, self.sharpness, self.amplitudes, self.integral):
            digest.update(np.ascontiguousarray(array).tobytes())
        return digest.hexdigest()

    # the shading's view of one tile or two (MaskedTiles): lobes [0, first_lobes) are the first tile's
    first_lobes = property(lambda self: self.lobe_count)
    diffuse_tiles = property(lambda self: self.integral[None])
    albedo_tiles = property(lambda self: self.albedo[None])


@dataclass(frozen=True)
class MaskedTiles:
    """Two tiles chosen per pixel by a mask (iwasaki2012 fig. 1c): the first where the mask is 0, the second
    where it is 1, their effective BRDFs blended linearly between (a pixel partly covered by each).  Shading
    reads the two BVNDFs' lobes one after the other, the second's amplitudes and diffuse scaled by the mask."""
    first: BVNDF
    second: BVNDF

    def __post_init__(self):
        if self.first.resolution != self.second.resolution:
            raise ValueError("the two tiles' tables need the same direction lattice")

    lobe_count = property(lambda self: self.first.lobe_count + self.second.lobe_count)
    first_lobes = property(lambda self: self.first.lobe_count)
    resolution = property(lambda self: self.first.resolution)
    directions = property(lambda self: self.first.directions)
    signature = property(lambda self: self.first.signature + self.second.signature)
    axes = property(lambda self: np.concatenate([self.first.axes, self.second.axes]))
    sharpness = property(lambda self: np.concatenate([self.first.sharpness, self.second.sharpness]))
    amplitudes = property(lambda self: np.concatenate([self.first.amplitudes, self.second.amplitudes]))
    diffuse_tiles = property(lambda self: np.stack([self.first.integral, self.second.integral]))
    albedo_tiles = property(lambda self: np.stack([self.first.albedo, self.second.albedo]))


@dataclass(frozen=True)
class TileSamples:
    """What every later step reads of the tile: its sample points, their cosines times visibility towards
    each lattice direction (N, K), and the visible projected area a_v of each direction (K,)."""
    points: microgeometry.SamplePoints
    cosines: np.ndarray
    projected_area: np.ndarray
    directions: np.ndarray

    def weights(self, i_index, o_index):
        """(N,) w_s(i, o) of the pair of lattice nodes (the delta weights of gamma~)."""
        return self.points.area * self.cosines[:, i_index] * self.cosines[:, o_index] / \
            self.projected_area[o_index]


def trace_tile(geometry, resolution=DEFAULT_RESOLUTION, samples=microgeometry.DEFAULT_SAMPLES, seed=0,
               tracer=None):
    """Sample the tile and trace its points' visibility towards every lattice direction."""
    directions = lattice_directions(resolution)
    points = microgeometry.sample_points(geometry, samples, seed)
    own = tracer is None
    tracer = tracer or microgeometry.TiledTracer(geometry)
    cosines = np.maximum(points.normals @ directions.T, 0.0)
    point_index, node_index = np.nonzero(cosines)       # a facet turned away needs no ray: its weight is 0
    try:
        visible = tracer.visible(points.positions[point_index], points.normals[point_index],
                                 directions[node_index])
    finally:
        if own:
            tracer.close()
    cosines[point_index[~visible], node_index[~visible]] = 0.0
    projected = points.area * cosines.sum(axis=0)
    if np.any(projected <= 0):
        raise ValueError("the tile shows nothing towards some directions of the lattice "
                         "(no point faces them unoccluded): is it a surface seen from above?")
    return TileSamples(points, cosines.astype(np.float32), projected, directions)


def lobe_gram(axes, sharpness):
    """A_jk = integral of G_j G_k (unit amplitudes), eq. 8's matrix."""
    return sg.inner_product(axes[:, None], sharpness[:, None], 1.0, axes[None], sharpness[None], 1.0)


def solve_nonnegative(gram, right, iterations=_SOLVER_ITERATIONS):
    """min |A mu - b| with mu >= 0 for many right-hand sides (J, M) at once: the unconstrained solution
    clipped, then projected gradient steps (A is J x J, small; the same for every column)."""
    mu = np.maximum(np.linalg.lstsq(gram, right, rcond=1e-10)[0], 0.0)
    step = 1.0 / max(float(np.linalg.eigvalsh(gram).max()), 1e-30)
    for _ in range(iterations):
        mu = np.maximum(mu - step * (gram @ mu - right), 0.0)
    return mu


def binned_normals(normals, areas, step=NORMAL_BIN):
    """The triangles' normals merged where they agree within `step` (per component), their areas summed:
    (normals (M, 3), areas (M,)), M at most the distinct directions, not the triangles (iwasaki2012 bins the
    NDF on a cube map first; a height field of 256^2 texels has 131k triangles, far fewer distinct normals
    at the lobes' widths)."""
    cells = int(np.ceil(2.0 / step)) + 1          # per component, over [-1, 1]
    keys = np.round((np.asarray(normals, np.float64) + 1.0) / step).astype(np.int64)
    unique, inverse = np.unique((keys[:, 0] * cells + keys[:, 1]) * cells + keys[:, 2], return_inverse=True)
    inverse = inverse.reshape(-1)
    summed = np.zeros((len(unique), 3))
    np.add.at(summed, inverse, normals * areas[:, None])
    return sg.normalize(summed), np.bincount(inverse, areas, minlength=len(unique))


def fit_ndf(geometry, lobes=DEFAULT_LOBES):
    """The NDF's lobes: spherical EM over the triangles' normals weighted by their areas (eq. 6), binned."""
    normals, areas = geometry.facets()
    return spherical_em.fit(*binned_normals(normals, areas), lobes)


def compute(geometry, lobes=DEFAULT_LOBES, resolution=DEFAULT_RESOLUTION, samples=microgeometry.DEFAULT_SAMPLES,
            seed=0, tile=None, solve="responsibility"):
    """The tile's BVNDF as SGs.  tile: a TileSamples of the same geometry and resolution (trace_tile), reused;
    solve: one of AMPLITUDE_SOLVES."""
    tile = tile or trace_tile(geometry, resolution, samples, seed)
    axes, sharpness, mixture = fit_ndf(geometry, lobes)
    return from_samples(tile, axes, sharpness, mixture, resolution, solve)


def _lobe_weighted_sums(tile, weights):
    """sum_s w_s(i, o) weights[s, j] for every pair of nodes: (J, K, K), per unit cos(theta_i)."""
    cosines = tile.cosines                         # float32: sums of a few thousand terms, 1e-6 relative
    weights = np.asarray(weights, np.float32)
    # per unit cos(theta_i): the lattice's lifted horizon ring keeps a finite, continuous value
    scale = tile.points.area / (tile.projected_area[None, :] * tile.directions[:, 2][:, None])     # (K_i, K_o)
    sums = np.stack([(cosines * weights[:, j:j + 1]).T @ cosines for j in range(weights.shape[1])])
    return sums.astype(np.float64) * scale[None]


def from_samples(tile, axes, sharpness, mixture, resolution, solve="responsibility"):
    """Amplitudes and integrals of gamma~ over the traced tile for given NDF lobes."""
    if solve not in AMPLITUDE_SOLVES:
        raise ValueError(f"unknown amplitude solve {solve!r}: {AMPLITUDE_SOLVES}")
    lobes = len(sharpness)
    normals = tile.points.normals[:, None, :]
    nodes = len(tile.directions)
    if solve == "least_squares":
        right = _lobe_weighted_sums(tile, sg.evaluate(normals, axes[None], sharpness[None], 1.0))
        amplitudes = solve_nonnegative(lobe_gram(axes, sharpness), right.reshape(lobes, -1))
    else:
        density = sg.evaluate(normals, axes[None], sharpness[None], 1.0) * \
            (mixture * spherical_em.normalization(sharpness))[None]
        responsibility = density / np.maximum(density.sum(axis=1, keepdims=True), 1e-300)
        sums = _lobe_weighted_sums(tile, responsibility)
        amplitudes = sums.reshape(lobes, -1) / sg.sphere_integral(sharpness)[:, None]
    # the responsibilities share each point's weight whole among the lobes: their sums add up to gamma~'s
    integral = (sums.sum(axis=0) if solve == "responsibility" else
                _lobe_weighted_sums(tile, np.ones((len(tile.points.normals), 1)))[0]).astype(np.float32)
    return BVNDF(axes, sharpness, mixture, amplitudes.reshape(len(sharpness), nodes, nodes).astype(np.float32),
                 integral, diffuse_albedo(integral, resolution), tile.directions, int(resolution))


def diffuse_albedo(integral, resolution, points=ALBEDO_POINTS):
    """(K,) 1 / pi integral of D(i, o) cos(theta_i) over i for each lattice o, on an equal-area point set."""
    incoming = lattice.hemisphere_points(points)
    outgoing = lattice_directions(resolution)
    values = interpolate(np.asarray(integral)[None], incoming[:, None, :], outgoing[None], resolution)[0]
    return (2.0 / points * np.sum(values * incoming[:, 2:3], axis=0)).astype(np.float32)


def lattice_coordinates(directions, resolution):
    """Continuous lattice coordinates (..., 2) in [0, R - 1] (a, b) of directions (clamped to the hemisphere)."""
    directions = np.asarray(directions, np.float64)
    clamped = np.concatenate([directions[..., :2], np.maximum(directions[..., 2:], 0.0)], axis=-1)
    square = hemisphere_map.hemisphere_to_square(sg.normalize(clamped))
    return np.clip((square + 1.0) * (0.5 * (resolution - 1)), 0.0, resolution - 1)


def interpolate(tables, wi, wo, resolution):
    """Multilinear reading of tables (M, K, K) [i node, o node] at directions wi, wo (..., 3): (M, ...)."""
    tables = np.asarray(tables)
    shape = np.broadcast_shapes(np.shape(wi)[:-1], np.shape(wo)[:-1])
    ci = np.broadcast_to(lattice_coordinates(wi, resolution), shape + (2,)).reshape(-1, 2)
    co = np.broadcast_to(lattice_coordinates(wo, resolution), shape + (2,)).reshape(-1, 2)
    top = resolution - 2

    def corners(c):
        low = np.minimum(np.floor(c).astype(np.int64), top)
        return low, c - low

    (ia, ib), (fa_i, fb_i) = zip(*(corners(ci[:, k]) for k in range(2)))
    (oa, ob), (fa_o, fb_o) = zip(*(corners(co[:, k]) for k in range(2)))
    result = np.zeros((tables.shape[0], len(ci)))
    for di in (0, 1):
        for dj in (0, 1):
            i_node = (ib + dj) * resolution + ia + di
            w_i = (fa_i if di else 1 - fa_i) * (fb_i if dj else 1 - fb_i)
            for do in (0, 1):
                for dk in (0, 1):
                    o_node = (ob + dk) * resolution + oa + do
                    w_o = (fa_o if do else 1 - fa_o) * (fb_o if dk else 1 - fb_o)
                    result += tables[:, i_node, o_node] * (w_i * w_o)
    return result.reshape((tables.shape[0],) + shape)
