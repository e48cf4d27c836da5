"""Ground truth for the bi-scale maths (sg_prt_addon.biscale): the effective BRDF of eq. 1 by brute force.

Rays fall on the periodic tile along -o from points spread uniformly over it (uniform in projected area
along o, so the first hits sample the visible surface weighted by n.o / a_v(o)); each hit is shaded with the
exact small-scale BRDF in its facet's frame and shadowed towards i by the tile: the mean over the rays is
f(i, o) = integral over the visible area of f_s V(i) (n.i)(n.o) dA / a_v(o), eq. 1 with nothing binned,
fitted or convolved.  Its noise is the rays' standard error, returned with it.
"""
import numpy as np

from sg_prt_addon.biscale import effective_brdf, microgeometry
from sg_prt_addon.reflectance import brdf


class AnalyticSmallScale:
    """A validation.brdf_generators.AnalyticMaterial (the BRDF a measured file was generated from) as a small-scale
    BRDF of the ground truth: what a bi-scale material with a lobe fit to that file should look like."""

    def __init__(self, analytic):
        self.analytic = analytic
        self.typical_roughness = float(np.max(analytic.roughness))

    def evaluate_on_facets(self, normals, wi, wo):
        local_i, local_o = effective_brdf.facet_directions(normals, wi, wo)
        return self.analytic.evaluate(local_o, local_i)


def effective_brdf_traced(geometry, small, wi, wo, rays=20000, seed=1, tracer=None):
    """(rho (P, 3), standard error (P, 3)): the effective BRDF without the large-scale cosine (f / cos(theta_i))
    at pairs of unit directions wi, wo (P, 3) in the tile frame, by ray tracing the tile; small: a small-scale
    BRDF (biscale.effective_brdf's, or AnalyticSmallScale)."""
    wi = np.atleast_2d(np.asarray(wi, np.float64))
    wo = np.atleast_2d(np.asarray(wo, np.float64))
    normals, _ = geometry.facets()
    own = tracer is None
    tracer = tracer or microgeometry.TiledTracer(geometry)
    rng = np.random.default_rng(seed)
    start = np.column_stack([rng.random(rays) * geometry.size[0], rng.random(rays) * geometry.size[1],
                             np.full(rays, tracer.top + 1e-3 * max(geometry.size))])
    values, errors = [], []
    try:
        for i, o in zip(wi, wo):
            hit, positions, triangle = tracer.first_hit(start, np.broadcast_to(-o, start.shape))
            facet = normals[np.maximum(triangle, 0)]
            lit = hit & (facet @ i > 0) & (facet @ o > 0)
            shade = np.zeros((rays, 3))
            if np.any(lit):
                visible = tracer.visible(positions[lit], facet[lit], np.broadcast_to(i, (int(lit.sum()), 3)))
                f = small.evaluate_on_facets(facet[lit], i, o) * (facet[lit] @ i)[:, None]
                shade[lit] = f * visible[:, None]
            cos_i = max(i[2], 1e-6)
            values.append(shade.mean(axis=0) / cos_i)
            errors.append(shade.std(axis=0) / np.sqrt(rays) / cos_i)
    finally:
        if own:
            tracer.close()
    return np.array(values), np.array(errors)


def effective_brdf_of_samples(tile, small, i_index, o_index):
    """rho (3,) at a pair of lattice nodes from the BVNDF's own samples with the exact small-scale BRDF: eq. 1
    as the tables discretize it, before any SG (bvndf.TileSamples)."""
    weights = tile.weights(i_index, o_index).astype(np.float64)
    keep = weights > 0
    i, o = tile.directions[i_index], tile.directions[o_index]
    f = small.evaluate_on_facets(tile.points.normals[keep], i, o)
    return (weights[keep] @ f) / i[2]


def relative_rms(estimate, reference, wi):
    """Relative RMS of the effective BRDF with its cosine (f = rho cos(theta_i)): the grazing pairs, where rho
    is large and the light it meets small, weigh what they deliver."""
    cosine = np.asarray(wi)[..., 2:3]
    difference = (np.asarray(estimate) - np.asarray(reference)) * cosine
    return float(np.sqrt(np.sum(difference ** 2) / max(np.sum((np.asarray(reference) * cosine) ** 2), 1e-300)))


def direction_pairs(count, seed=0, max_zenith=np.radians(80.0)):
    """(wi, wo) (count, 3) each: random pairs over the hemisphere up to max_zenith, half of them near the
    mirror configuration (where a glossy effective BRDF peaks)."""
    rng = np.random.default_rng(seed)

    def directions(n):
        cos = rng.uniform(np.cos(max_zenith), 1.0, n)
        phi = rng.uniform(0, 2 * np.pi, n)
        sin = np.sqrt(1 - cos * cos)
        return np.column_stack([sin * np.cos(phi), sin * np.sin(phi), cos])

    wo = directions(count)
    wi = directions(count)
    mirror = count // 2
    jitter = rng.normal(scale=0.08, size=(mirror, 3))
    reflected = np.column_stack([-wo[:mirror, :2], wo[:mirror, 2:]]) + jitter
    reflected[:, 2] = np.maximum(reflected[:, 2], np.cos(max_zenith))
    wi[:mirror] = reflected / np.linalg.norm(reflected, axis=1, keepdims=True)
    return wi, wo



def egg_crate(resolution=64, amplitude=0.05, periods=1):
    """Height field sin(2 pi k x) sin(2 pi k y) (heights in tile widths): bumps and dents in a checkerboard."""
    y, x = np.mgrid[0:resolution, 0:resolution] / resolution
    return amplitude * np.sin(2 * np.pi * periods * x) * np.sin(2 * np.pi * periods * y)


def grooves(resolution=64, amplitude=0.06, periods=2):
    """Parallel rounded grooves along y (heights vary along x only): an anisotropic tile."""
    x = np.arange(resolution) / resolution
    profile = amplitude * np.abs(np.sin(np.pi * periods * x))
    return np.broadcast_to(profile[None, :], (resolution, resolution)).copy()


def random_bumps(resolution=64, amplitude=0.04, cutoff=4, seed=7):
    """A smooth periodic random surface: white noise kept below `cutoff` cycles per tile, scaled to amplitude."""
    rng = np.random.default_rng(seed)
    spectrum = np.fft.fft2(rng.normal(size=(resolution, resolution)))
    frequency = np.fft.fftfreq(resolution) * resolution
    radius = np.hypot(frequency[:, None], frequency[None, :])
    heights = np.real(np.fft.ifft2(spectrum * (radius <= cutoff)))
    return amplitude * heights / np.abs(heights).max()


TILES = {"egg crate": egg_crate, "grooves": grooves, "random bumps": random_bumps}


class TracedEffectiveBRDF:
    """validation.reference's specular-model protocol for a bi-scale material: specular(wo, wi) is an unbiased
    estimate of the whole effective BRDF (diffuse and glossy, RGB, without the large-scale cosine), one ray
    dropped on the tile along -o and one shadow ray towards i per estimate (`rays` of them averaged), so the
    reference renders the ray-traced tile itself, noise included in its error estimate.  Sampling: GGX about the
    large-scale normal at a roughness widened by the tile's slopes (any proposal is unbiased with its own pdf)."""

    def __init__(self, geometry, small, rays=2, seed=11):
        self.geometry, self.small, self.rays = geometry, small, int(rays)
        self.normals, _ = geometry.facets()
        self.tracer = microgeometry.TiledTracer(geometry)
        self.rng = np.random.default_rng(seed)
        normals, areas = self.normals, geometry.facets()[1]
        slope2 = float(np.sum(areas * (1.0 - normals[:, 2] ** 2) / np.maximum(normals[:, 2] ** 2, 1e-6)) /
                       np.sum(areas))
        alpha = small.typical_roughness ** 2
        self.proposal = brdf.GGX(roughness=float((alpha * alpha + slope2 + 0.01) ** 0.25))

    def specular(self, wo, wi):
        wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
        count = len(wo)
        total = np.zeros((count, 3))
        for _ in range(self.rays):
            start = np.column_stack([self.rng.random(count) * self.geometry.size[0],
                                     self.rng.random(count) * self.geometry.size[1],
                                     np.full(count, self.tracer.top + 1e-3 * max(self.geometry.size))])
            hit, positions, triangle = self.tracer.first_hit(start, -wo)
            facet = self.normals[np.maximum(triangle, 0)]
            cos_i = np.sum(facet * wi, axis=1)
            lit = hit & (cos_i > 0) & (np.sum(facet * wo, axis=1) > 0) & (wi[:, 2] > 0) & (wo[:, 2] > 0)
            if not np.any(lit):
                continue
            visible = self.tracer.visible(positions[lit], facet[lit], wi[lit])
            value = self.small.evaluate_on_facets(facet[lit], wi[lit], wo[lit])
            total[lit] += value * (cos_i[lit] * visible / np.maximum(wi[lit, 2], 1e-6))[:, None]
        return total / self.rays

    def sample(self, wo, u):
        return self.proposal.sample(wo, u)

    def pdf(self, wo, wi):
        return self.proposal.pdf(wo, wi)


class BlendedTiles:
    """Two TracedEffectiveBRDFs blended per point by weights (N,) of the second (a bi-scale mask): the
    specular-model protocol for the points a reference texture lookup returns it for."""

    def __init__(self, first, second, weight):
        self.first, self.second, self.weight = first, second, np.asarray(weight, np.float64)

    def specular(self, wo, wi):
        weight = self.weight[:, None]
        return (1.0 - weight) * self.first.specular(wo, wi) + weight * self.second.specular(wo, wi)

    def sample(self, wo, u):
        return self.first.sample(wo, u)

    def pdf(self, wo, wi):
        return self.first.pdf(wo, wi)

