"""Homomorphic factorization of a BRDF into positive factors over 2D maps (mccool2001).

The paper's three-factor form (eq. 8-9) f(o, i) ~ p(o) q(h) p(i), h = norm(o + i), and a two-factor form
f ~ p(o) q(h).  In log space (eq. 5, 10) each BRDF sample gives one linear equation in the texels of the
log-factors: the bilinear weights of its projections (eq. 11-14; two projections landing on one texel
add).  The Laplacian of every factor texture, weighted by `smoothness` (eq. 17, the masks of Fig. 3: the
grid graph's Laplacian), constrains texels no sample reaches and fills gaps.  The sparse system is solved
in the least-squares sense (scipy's LSMR with Jacobi column scaling; the paper used QMR) coarse to fine:
each level's solution, upsampled, starts the next (the paper's multiresolution start).  Minimising the log residual minimises
relative error (3.1.2).

Maps: parabolic (the paper's, 4.1): a local direction d with d_z >= 0 at
u = (d_x / (1 + d_z) + 1) / 2, v likewise, the hemisphere filling the disk inscribed in the unit square.
Texel k of a side of R texels has its centre at (k + 1/2) / R, as the GPU samples it, so bilinear
interpolation of the stored log-texels at (u, v), then exp, is exactly what was fitted: the engine stores
the log-factors in float textures and exponentiates after the fetch (the paper interpolated the factors
themselves, which did not match its fit).  The hemi-octahedral map (MAPPINGS) fills the whole square and
wins on coarse maps (16^2), but its creases, the square's diagonals, meet at the pole where q's peak lies:
at the technique's 64^2 the parabolic map is as good or better for every model measured (docs/ACCURACY.md).

Samples: f (an analytic model, a MERL file, or one texel of an SVBRDF table) is sampled on a Fibonacci lattice of each hemisphere (uniform in solid angle, the paper's even
distribution, 4.3), every view with every light; NaN, Inf and negative values are masked and counted
(measured data has them).  Zero is fine: the log takes f + eps A (eq. 6, eps = 1e-5, A the mean sample).
alpha (eq. 20's correction) scales the product so the energy it reflects over the samples, sum f (n.i),
equals the data's: the log fit is biased low (3.1.1).
"""
import time
from dataclasses import dataclass, field

import numpy as np

from ..spherical.lattice import hemisphere_points
from . import merl

EPSILON = 1e-5                  # eq. 6's bias, as the paper fixes it
FORMS = {
    # factor texture of each projection, in order: view o, half vector h, light i, o.h (= i.h)
    "pqp": ("p", "q", "p", None),     # eq. 9: p(o) q(h) p(i), reciprocal, two textures
    "pq": ("p", "q", None, None),     # p(o) q(h): the light direction only through the cosine the renderer adds
    # eq. 9 times the 1D factor r(o.h) the paper proposes for Fresnel (its section 5): reciprocal
    "pqpr": ("p", "q", "p", "r"),
}
FORM_LABELS = {"pqp": "p(o) q(h) p(i)", "pq": "p(o) q(h)", "pqpr": "p(o) q(h) p(i) r(o.h)"}
ONE_DIMENSIONAL = {"r"}         # factors of o.h: a (1, R) map over u = o.h
DEFAULT_FORM = "pqp"
DEFAULT_MAPPING = "parabolic"


def _sparse():
    """scipy.sparse with its linalg, imported when a factorization runs: rendering never factors, and the
    import costs every process (a batch job is one a frame) about 0.1 s."""
    import scipy.sparse
    import scipy.sparse.linalg
    return scipy.sparse


@dataclass
class Factorization:
    """log_factors: name ("p", "q", "r") -> (R, R, C) float32 log-texels ((1, R, C) for r), row = v,
    column = u (the texture's layout, row 0 at v = 0); alpha (C,): eq. 20's correction; form: a key of FORMS; scale (C,): A of eq. 6
    (the log-factors hold log(f / A), split over the factors); counts: the masked samples."""
    form: str
    resolution: int
    log_factors: dict
    alpha: np.ndarray
    scale: np.ndarray
    counts: dict = field(default_factory=dict)
    sample_count: int = 0
    seconds: float = 0.0
    mapping: str = DEFAULT_MAPPING      # a key of MAPPINGS: the 2D maps' parameterization

    def evaluate(self, wo, wi):
        """The factored BRDF (..., C) at local directions (..., 3); zero where either is below the horizon."""
        wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
        log_value = np.zeros(np.broadcast_shapes(wo.shape, wi.shape)[:-1] + (len(self.alpha),))
        for name, uv in zip(FORMS[self.form], map_coordinates(wo, wi, self.mapping)):
            if name is not None:
                log_value = log_value + sample_map(self.log_factors[name], uv)
        value = self.alpha * self.scale * np.exp(log_value)
        above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
        return np.where(above[..., None], value, 0.0)


def projections(wo, wi):
    """The directions each factor is a function of: (o, h, i), h = norm(o + i) (eq. 8)."""
    h = wo + wi
    h = h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-30)
    return wo, h, wi


def map_coordinates(wo, wi, mapping=DEFAULT_MAPPING):
    """(u, v) (..., 2) of each projection of FORMS' order: o, h, i on the 2D map of MAPPINGS[mapping], and
    (o.h, 1/2) of the 1D map."""
    o, h, i = projections(wo, wi)
    coordinates = MAPPINGS[mapping]
    cosine = np.clip(np.sum(o * h, axis=-1), 0.0, 1.0)
    return (coordinates(o), coordinates(h), coordinates(i), np.stack([cosine, np.full_like(cosine, 0.5)], axis=-1))


def parabolic_coordinates(direction):
    """(u, v) (..., 2) in [0, 1]^2 of local directions (..., 3), clamped to the upper hemisphere."""
    d = np.asarray(direction, np.float64)
    d = d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-30)
    z = np.maximum(d[..., 2], 0.0)
    tangential = np.linalg.norm(d[..., :2], axis=-1, keepdims=True)
    # below the horizon: the horizon point of the same azimuth (the disk's rim)
    xy = np.where(d[..., 2:3] >= 0, d[..., :2], d[..., :2] / np.maximum(tangential, 1e-30))
    return 0.5 * (xy / (1.0 + z)[..., None] + 1.0)


def octahedral_coordinates(direction):
    """(u, v) (..., 2) in [0, 1]^2 of local directions (..., 3) on the hemi-octahedral map: d / |d|_1 projected
    onto the plane and turned 45 degrees, so the upper hemisphere fills the whole square (the parabolic disk
    leaves 1 - pi/4 of it unused) and the square's border is the horizon.  Below the horizon: z = 0."""
    d = np.asarray(direction, np.float64)
    d = np.concatenate([d[..., :2], np.maximum(d[..., 2:3], 0.0)], axis=-1)
    p = d[..., :2] / np.maximum(np.sum(np.abs(d), axis=-1, keepdims=True), 1e-30)
    return 0.5 * (np.stack([p[..., 0] + p[..., 1], p[..., 0] - p[..., 1]], axis=-1) + 1.0)


MAPPINGS = {"parabolic": parabolic_coordinates, "octahedral": octahedral_coordinates}


def bilinear_weights(uv, width, height=None):
    """(texel indices (..., 4), weights (..., 4)) of GPU bilinear filtering with clamp-to-edge at uv
    (..., 2) in a height x width map (height: width), texels numbered row * width + column (eq. 11-13 with
    texel centres at (k + 1/2) / size)."""
    height = width if height is None else height
    x = np.asarray(uv[..., 0]) * width - 0.5
    y = np.asarray(uv[..., 1]) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = x - x0, y - y0
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    xa, xb = np.clip(x0, 0, width - 1), np.clip(x0 + 1, 0, width - 1)
    ya, yb = np.clip(y0, 0, height - 1), np.clip(y0 + 1, 0, height - 1)
    index = np.stack([ya * width + xa, ya * width + xb, yb * width + xa, yb * width + xb], -1)
    weight = np.stack([(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy], -1)
    return index, weight


def sample_map(log_map, uv):
    """Bilinear samples (..., C) of an (H, W, C) map at uv (..., 2), as bilinear_weights weighs them."""
    height, width = log_map.shape[:2]
    index, weight = bilinear_weights(uv, width, height)
    flat = np.asarray(log_map, np.float64).reshape(height * width, -1)
    return np.einsum("...k,...kc->...c", weight, flat[index])


def grid_laplacian(width, height=None):
    """The Laplacian of a height x width texel grid: degree minus neighbours (Fig. 3's masks)."""
    height = width if height is None else height
    n = width * height
    index = np.arange(n).reshape(height, width)
    rows, cols = [], []
    for a, b in ((index[:, :-1], index[:, 1:]), (index[:-1, :], index[1:, :])):
        rows += [a.ravel(), b.ravel()]
        cols += [b.ravel(), a.ravel()]
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    adjacency = _sparse().csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    return _sparse().diags(np.asarray(adjacency.sum(axis=1)).ravel()) - adjacency


def sample_brdf(brdf, view_count=256, light_count=256):
    """(wo (K, 3), wi (K, 3), f (K, C)) of a BRDF callable brdf(wo, wi) -> (..., C) or (...,) over every pair
    of view_count x light_count hemisphere points."""
    views, lights = hemisphere_points(view_count), hemisphere_points(light_count)
    wo = np.repeat(views, light_count, axis=0)
    wi = np.tile(lights, (view_count, 1))
    values = np.asarray(brdf(wo, wi), np.float64)
    return wo, wi, values.reshape(len(wo), -1)


def map_shape(name, resolution):
    """(height, width) of a factor's map."""
    return (1, resolution) if name in ONE_DIMENSIONAL else (resolution, resolution)


def sample_merl(source, count=256):
    """(wo, wi, values (K, 3)) of a merl.MerlBrdf on count x count hemisphere pairs, by its nearest bin; the
    file's invalid bins are NaN (masked and counted by factorize), not zero."""
    def evaluate(wo, wi):
        theta_h, theta_d, phi_d, _above = merl.bin_indices(wo, wi)
        return np.where(source.valid[theta_h, theta_d, phi_d][..., None], source.rho[theta_h, theta_d, phi_d], np.nan)

    return sample_brdf(evaluate, count, count)


def sample_table_texel(table, texel, count=256):
    """(wo, wi, values (K, 3)) of one texel (row-major index) of a svbrdf_table.SvbrdfTable on count x count
    hemisphere pairs: a spatially varying table's BRDF at one point, factorized as one BRDF."""
    def evaluate(wo, wi):
        return table.evaluate(wo, wi, texels=[int(texel)])[0]

    return sample_brdf(evaluate, count, count)


def _system(form, wo, wi, resolution, mapping):
    """The data rows (K, texels of every factor), the factor names in column order and their offsets."""
    names = sorted({name for name in FORMS[form] if name is not None})
    offsets = np.cumsum([0] + [int(np.prod(map_shape(name, resolution))) for name in names])
    rows, cols, vals = [], [], []
    sample = np.arange(len(wo))
    for name, uv in zip(FORMS[form], map_coordinates(wo, wi, mapping)):
        if name is None:
            continue
        height, width = map_shape(name, resolution)
        index, weight = bilinear_weights(uv, width, height)
        rows.append(np.repeat(sample, 4))
        cols.append((index + offsets[names.index(name)]).ravel())
        vals.append(weight.ravel())
    matrix = _sparse().csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                     shape=(len(wo), offsets[-1]))      # duplicates add (eq. 14)
    return matrix, names, offsets


def _upsample(log_map, shape):
    """A coarser level's (h, w, C) log-texels at the finer level's texel centres (bilinear)."""
    u, v = np.meshgrid((np.arange(shape[1]) + 0.5) / shape[1], (np.arange(shape[0]) + 0.5) / shape[0])
    return sample_map(log_map, np.stack([u, v], -1))


def factorize(wo, wi, values, form=DEFAULT_FORM, resolution=32, smoothness=0.02, levels=3, iterations=400,
              epsilon=EPSILON, mapping=DEFAULT_MAPPING):
    """Factorization of samples values (K, C) at local directions wo, wi (K, 3) (see the module docstring).

    smoothness: lambda of eq. 17, relative to the data rows' scale (it multiplies sqrt(K / texels), so the
    same value smooths alike at any sample count); levels: resolutions resolution / 2^k solved first;
    epsilon: eq. 6's bias (0 only for data without zeros); mapping: the 2D maps' parameterization (MAPPINGS)."""
    start = time.perf_counter()
    values = np.asarray(values, np.float64).reshape(len(wo), -1)
    finite = np.isfinite(values)
    counts = {"nan": int(np.isnan(values).sum()), "inf": int(np.isinf(values).sum()),
              "negative": int((finite & (values < 0)).sum())}
    good = np.all(finite & (values >= 0), axis=1) & (wo[:, 2] > 0) & (wi[:, 2] > 0)
    wo, wi, values = np.asarray(wo, np.float64)[good], np.asarray(wi, np.float64)[good], values[good]
    if len(values) == 0:
        raise ValueError("no valid BRDF sample to factorize")
    channels = values.shape[1]
    scale = np.maximum(values.mean(axis=0), 1e-30)                                  # A of eq. 6
    target = np.log((values + epsilon * scale) / scale)                             # (K, C)
    factor_count = sum(name is not None for name in FORMS[form])
    log_maps = None
    for level in reversed(range(max(int(levels), 1))):
        size = max(resolution >> level, 2)
        matrix, names, offsets = _system(form, wo, wi, size, mapping)
        shapes = [map_shape(name, size) for name in names]
        weight = smoothness * np.sqrt(len(wo) / (size * size))
        laplacians = [grid_laplacian(shape[1], shape[0]) * weight for shape in shapes]
        system = _sparse().vstack([matrix, _sparse().block_diag(laplacians)]).tocsr()
        if log_maps is None:        # the paper's averaged-projection start: log f / factors, everywhere
            guess = np.tile(target.mean(axis=0) / factor_count, (offsets[-1], 1))
        else:
            guess = np.concatenate([_upsample(log_maps[name], shape).reshape(-1, channels)
                                    for name, shape in zip(names, shapes)])
        right = np.concatenate([target, np.zeros((system.shape[0] - len(target), channels))])
        # Jacobi column scaling: a texel's column norm grows with the samples landing on it (many on q's
        # centre, few on p's rim); equalised, LSMR converges in far fewer iterations
        column_norm = np.sqrt(np.asarray(system.multiply(system).sum(axis=0)).ravel())
        column_scale = 1.0 / np.maximum(column_norm, 1e-12)
        scaled = system @ _sparse().diags(column_scale)
        solution = np.empty_like(guess)
        for c in range(channels):
            residual = right[:, c] - system @ guess[:, c]
            step = _sparse().linalg.lsmr(scaled, residual, atol=1e-10, btol=1e-10, maxiter=iterations)[0]
            solution[:, c] = guess[:, c] + column_scale * step
        log_maps = {name: solution[offsets[k]:offsets[k + 1]].reshape(shapes[k] + (channels,))
                    for k, name in enumerate(names)}
    # the gauge: p + c, q - (uses of p) c gives the same product; centre log p on the samples' mean
    uses = sum(name == "p" for name in FORMS[form])
    shift = log_maps["p"].mean(axis=(0, 1))
    log_maps["p"], log_maps["q"] = log_maps["p"] - shift, log_maps["q"] + uses * shift
    if "r" in log_maps:             # and r's mean into q
        shift = log_maps["r"].mean(axis=(0, 1))
        log_maps["r"], log_maps["q"] = log_maps["r"] - shift, log_maps["q"] + shift
    result = Factorization(form, resolution, {k: v.astype(np.float32) for k, v in log_maps.items()},
                           np.ones(channels), scale, counts, int(len(values)), mapping=mapping)
    # eq. 20's alpha: the reflected energy of the samples, sum f (n.i), kept (3.1.1: the log fit is biased
    # low); matching the plain mean instead lets a sharp peak the maps cannot resolve scale every tail up
    # (Ashikhmin-Shirley 50 x 800: alpha 3.3 against 1.75, the brushed torus 27% too bright)
    approximation = result.evaluate(wo, wi)
    cosine = wi[:, 2:3]
    result.alpha = (values * cosine).sum(axis=0) / np.maximum((approximation * cosine).sum(axis=0), 1e-30)
    result.seconds = time.perf_counter() - start
    return result


def relative_rms(factorization, brdf, view_count=128, light_count=128, cosine_weighted=True):
    """sqrt(sum (approx - f)^2 / sum f^2) over every pair of a second, coarser hemisphere lattice (not the
    fit's samples), each term weighted by cos(i) when cosine_weighted (what a light delivers)."""
    wo, wi, values = sample_brdf(brdf, view_count, light_count)
    approximation = factorization.evaluate(wo, wi).reshape(values.shape)
    weight = wi[:, 2:3] if cosine_weighted else 1.0
    ok = np.all(np.isfinite(values), axis=1)
    error = ((approximation - values) * weight)[ok]
    return float(np.sqrt(np.sum(error ** 2) / max(np.sum((values * weight)[ok] ** 2), 1e-300)))
