"""BRDF product tables of a stored lobe fit (kautz2002 section 3 for the fitted BRDF of wang2009 eq. 13, the
measured BRDF or SVBRDF of measured.microfacet_fit, as blender/lobe_fit.py stores it and the SG_FITTED
technique renders it):

    rho(o, i) = kd / pi + sum_k a_k G(h; z, lambda_k) F_eta(i.h) S(o) S(i) / (pi max(i_z, eps) max(o_z, eps))

per texel, a_k the lobes' RGB amplitudes, S the decompressed shadowing interpolated on its theta nodes
(svbrdf_table.interpolate_shadowing).  The diffuse term is the SH technique's exact clamped cosine; the table
holds the specular part, per texel t, lobe k and view theta_v:

    c_tk(v)_i = integral of Y_i(s) G(h; z, lambda_tk) F_eta_t(s.h) S_t(s) max(s_z, 0) / max(s_z, eps) ds

and the product's coefficients are sum_k a_tk c_tk(v) S_t(v) / (pi max(v_z, eps)).  The colours a_k stay out
(linear: a table a lobe is smaller than one a colour for the 1-2 lobes of these fits, and the shader weighs
each lobe's rotated vector by its colour), and so does the view's own factor S(v) / (pi v_z): the shader has
it exactly from the fit's shadowing, and tabulated, its rise towards grazing views (S falls to 0 only in the
last half degree) spoils the linear interpolation between view nodes (docs/ACCURACY.md, harmonics).

Isotropic fits only: lobes about the normal (Fit Lobes' z+ axes, 1-2 lobes) make each texel's product, in
the frame turned until the view lies in its x-z plane, depend on theta_v alone and even in y, so only the
N (N + 1) / 2 coefficients with m >= 0 are stored (the paper's Fig. 4 with the texel as the parameter axis).
A free-axes fit is anisotropic per texel: a parabolic view map per texel (the paper's anisotropic layout) at
even 16 x 16 views (the paper used 128 x 128), order 5 and 4 lobes is 115 KB a texel, 470 MB for 64 x 64
texels, and its lobes, off the normal, would each need nodes about their own axis (no rule shared by the
texels), so the SH technique refuses it (techniques/sh/blender renders it with the fitted SG lobes instead).

Layout and size: coefficients (T texels, K lobes, V views, M = N (N + 1) / 2) float32, V = 64 theta_v nodes at
(j + 1/2) / V pi / 2; the GPU's copy (texture_layers) pads M to whole vec4s: T K V 4 ceil(M / 4) floats, e.g.
64 x 64 texels, 2 lobes: 34 MB at order 5, 75 MB at order 8.  table_bytes() gives it; MAX_TABLE_BYTES bounds
what the engine builds.

Quadrature, deterministic and shared by every texel of a group (so a view's work is one matrix product, the
texels vectorized): nodes in the half vector's polar coordinates about the normal, where the lobes are
round whatever the view; phi_h at midpoints of [0, pi] (the integrand is even in y, m >= 0: twice the half),
theta_h on Gauss-Legendre panels graded from a quarter of the sharpest lobe's width (doubling, then steps
of PANEL_STEP), each phi line clipped where s reaches the horizon and split where s passes the last
shadowing node (S's ramp to 0); di = 4 (o.h) dh.  Texels are grouped by their lobes' sharpness (powers of
SHARPNESS_GROUP): a group's panels start at its sharpest lobe's width and stop where its broadest lobe has
fallen below e^-TAIL_EXPONENT.  Texels with the same lobes, eta and shadowing share one row.
"""
import collections
import hashlib
import math
import time
from dataclasses import dataclass

import numpy as np

from ..measured.svbrdf_table import shadowing_with_horizon
from ..reflectance.brdf import COSINE_EPSILON
from . import basis

DEFAULT_VIEWS = 64
MAX_TABLE_BYTES = 128 * 2 ** 20     # the GPU copy (texture_layers) the engine builds at most
MAX_TEXTURE_WIDTH = 16384           # texels a row of a texture OpenGL 4.1+ guarantees: W V
PHI_NODES = 32                      # midpoints on [0, pi] (PHI_MIN on panels ending near the normal)
PHI_MIN = 6
PHI_FULL_AT = 0.2                   # rad: panels ending beyond take PHI_NODES, nearer ones fewer in proportion
PANEL_NODES = 6                     # Gauss-Legendre nodes a theta_h panel
PANEL_STEP = 0.25                   # rad: the widest panel
SHARPNESS_GROUP = 8.0               # texels grouped by lambda in [8^g, 8^(g+1))
TAIL_EXPONENT = 20.0                # G below e^-20 of its peak is left out
TEXEL_CHUNK = 2048                  # texel rows a matrix product (memory: chunk x K x nodes float32)
CACHE_SIZE = 4


@dataclass(frozen=True, eq=False)
class FittedTable:
    """coefficients (T, K, V, M) float32 (the module docstring), texels laid out (H, W) = shape, row-major."""
    order: int
    shape: tuple
    coefficients: np.ndarray
    seconds: float = 0.0
    layout: str = "fitted"

    @property
    def views(self):
        return self.coefficients.shape[2]

    @property
    def lobes(self):
        return self.coefficients.shape[1]


def positive_m_indices(order):
    """Indices l^2 + l + m of the coefficients with m >= 0, in the stored order (l, then m = 0 .. l)."""
    return np.array([basis.index(band, m) for band in range(order) for m in range(band + 1)])


def view_thetas(views=DEFAULT_VIEWS):
    return (np.arange(views) + 0.5) / views * (np.pi / 2)


def layers_per_lobe(order):
    return -(-len(positive_m_indices(order)) // 4)


def table_bytes(texels, lobes, order, views=DEFAULT_VIEWS):
    """Bytes of the GPU copy of a table (texture_layers: vec4s of float32)."""
    return int(texels) * int(lobes) * int(views) * 16 * layers_per_lobe(order)


def _panel_edges(first, last):
    """theta_h panel edges from 0: [0, first], then doubling widths up to PANEL_STEP, then PANEL_STEP, to last."""
    edges = [0.0, min(first, last)]
    while edges[-1] < last:
        edges.append(min(edges[-1] + min(edges[-1], PANEL_STEP), last))
    return np.array(edges)


def view_nodes(theta_v, sharpest, broadest, last_shadowing_theta):
    """Half vectors h (J, 3) and weights (J,) of the quadrature of one view for lobes of sharpness in
    [broadest, sharpest]: sum_j weight_j g(s_j), s_j = 2 (o.h_j) h_j - o, approximates the integral over
    s_z > 0 of g(s) ds for functions even in y (the weights hold 4 (o.h) and the doubling)."""
    x, w = np.polynomial.legendre.leggauss(PANEL_NODES)
    tail = math.acos(max(1.0 - TAIL_EXPONENT / max(broadest, 1e-9), -1.0))
    edges = _panel_edges(0.25 / math.sqrt(max(sharpest, 1e-9)), min(tail, 0.5 * np.pi))
    parts = []
    # near the normal s circles the mirror direction closely: few azimuths resolve it (PHI_FULL_AT)
    counts = np.clip(np.ceil(PHI_NODES * edges[1:] / PHI_FULL_AT), PHI_MIN, PHI_NODES).astype(int)
    for count in np.unique(counts):
        panels = np.nonzero(counts == count)[0]
        phi = (np.arange(count) + 0.5) * (np.pi / count)
        a, b = math.sin(theta_v) * np.cos(phi), math.cos(theta_v)
        radius, delta = np.hypot(a, b), np.arctan2(b, a)
        # s_z = a sin 2 theta_h + b cos 2 theta_h = radius sin(2 theta_h + delta): the horizon, and s at the
        # last shadowing node (s_z = cos theta_last), on each phi line
        horizon = 0.5 * (np.pi - delta)
        ramp = np.clip(0.5 * (np.pi - np.arcsin(np.minimum(math.cos(last_shadowing_theta) / radius, 1.0))
                              - delta), 0.0, horizon)
        low = np.minimum(edges[None, panels], ramp[:, None])
        high = np.minimum(edges[None, panels + 1], ramp[:, None])
        if panels[-1] == len(edges) - 2:                 # the ramp's own panel, with the last ones
            low = np.concatenate([low, np.minimum(ramp, edges[-1])[:, None]], axis=1)
            high = np.concatenate([high, np.minimum(horizon, edges[-1])[:, None]], axis=1)
        half = 0.5 * (high - low)[..., None]
        theta = half * x + 0.5 * (high + low)[..., None]                               # (P, panels, n)
        weight = half * w * np.sin(theta) * (2 * np.pi / count)      # dh on [0, pi], doubled: the sphere's
        azimuth = np.broadcast_to(phi[:, None, None], theta.shape)
        keep = weight > 0
        parts.append((theta[keep], azimuth[keep], weight[keep]))
    theta, azimuth, weight = (np.concatenate(values) for values in zip(*parts))
    h = np.stack([np.sin(theta) * np.cos(azimuth), np.sin(theta) * np.sin(azimuth), np.cos(theta)], -1)
    o = np.array([math.sin(theta_v), 0.0, math.cos(theta_v)])
    o_h = h @ o
    s_z = 2 * o_h * h[:, 2] - o[2]
    usable = (o_h > 0) & (s_z > 0)
    return h[usable], (4 * o_h * weight)[usable]


def _groups(sharpness):
    """{(low group, high group): texel indices} by the lobes' broadest and sharpest sharpness."""
    g = np.floor(np.log(np.maximum(sharpness, 1e-9)) / math.log(SHARPNESS_GROUP)).astype(int)
    keys = np.stack([g.min(axis=1), g.max(axis=1)], -1)
    groups = collections.defaultdict(list)
    for texel, key in enumerate(map(tuple, keys)):
        groups[key].append(texel)
    return {key: np.array(texels) for key, texels in groups.items()}


def project_texels(sharpness, eta, shadowing, shadowing_theta, order, thetas):
    """c (T, K, V, M) float32 of texels with lobes about the normal at view angles thetas (V,): sharpness (T, K),
    eta (T,), shadowing (T, S) on shadowing_theta (S,) (decompressed, as interpolate_shadowing takes it)."""
    sharpness = np.asarray(sharpness, np.float64)
    eta = np.asarray(eta, np.float64)
    table, grid = shadowing_with_horizon(shadowing, shadowing_theta)
    table = table.astype(np.float32)
    keep = positive_m_indices(order)
    thetas = np.asarray(thetas, np.float64).reshape(-1)
    out = np.zeros(sharpness.shape + (len(thetas), len(keep)), np.float32)
    for (low, high), texels in _groups(sharpness).items():
        broadest, sharpest = SHARPNESS_GROUP ** low, SHARPNESS_GROUP ** (high + 1)
        for v, theta_v in enumerate(thetas):
            h, weight = view_nodes(theta_v, sharpest, broadest, float(shadowing_theta[-1]))
            if not len(h):
                continue
            o = np.array([math.sin(theta_v), 0.0, math.cos(theta_v)])
            o_h = h @ o
            s = 2 * o_h[:, None] * h - o
            s /= np.linalg.norm(s, axis=-1, keepdims=True)
            y = basis.evaluate(s, order)[:, keep].astype(np.float32)                      # (J, M)
            theta_s = np.arctan2(np.hypot(s[:, 0], s[:, 1]), s[:, 2])
            position = np.interp(theta_s, grid, np.arange(len(grid)))
            node = np.minimum(np.floor(position).astype(int), len(grid) - 2)
            fraction = (position - node).astype(np.float32)
            factor = (weight * s[:, 2] / np.maximum(s[:, 2], COSINE_EPSILON)).astype(np.float32)
            cosine_h = (h[:, 2] - 1).astype(np.float32)
            o_h = o_h.astype(np.float32)
            for start in range(0, len(texels), TEXEL_CHUNK):
                part = texels[start:start + TEXEL_CHUNK]
                rows = table[part]
                shadow = rows[:, node] * (1 - fraction) + rows[:, node + 1] * fraction            # (t, J)
                common = _fresnel(o_h, eta[part].astype(np.float32)[:, None]) * shadow * factor
                lobes = np.exp(sharpness[part].astype(np.float32)[:, :, None] * cosine_h) * common[:, None]
                out[part, :, v] = (lobes.reshape(-1, len(h)) @ y).reshape(len(part), -1, len(keep))
    return out


def _fresnel(cosine, eta):
    """brdf.fresnel_dielectric (its formula, F = 1 where g^2 <= 0) of cosines (J,) in (0, 1] and eta (t, 1), as
    (t, J): the same arithmetic without its masking of zero cosines, a third of its time on these arrays."""
    e2 = eta * eta - 1
    g2 = e2 + cosine * cosine
    g = np.sqrt(np.maximum(g2, 0))
    g_plus_c = g + cosine
    g_minus_c = e2 / g_plus_c
    ratio = (cosine * g_plus_c - 1) / (cosine * g_minus_c + 1)
    quotient = g_minus_c / g_plus_c
    f = np.minimum(0.5 * quotient * quotient * (1 + ratio * ratio), 1)
    return np.where(g2 > 0, f, 1).astype(f.dtype) if np.any(eta < 1) else f


def _content_key(*arrays):
    digest = hashlib.blake2b(digest_size=20)
    for array in arrays:
        array = np.ascontiguousarray(array)
        digest.update(str((array.dtype, array.shape)).encode())
        digest.update(array.tobytes())
    return digest.hexdigest()


_cache = collections.OrderedDict()


def table_for(sharpness, eta, shadowing, shadowing_theta, shape, order, views=DEFAULT_VIEWS, store=None):
    """The FittedTable of a fit's texels (project_texels' arrays, T = H W of shape), cached in the process by
    their content; texels with equal rows are projected once.  store: None, or a function (kind, key, build)
    -> build()'s dict of arrays that may keep them elsewhere (the engine's disk cache; key: the content
    digest, shape, order and views), asked on a miss in the process."""
    sharpness = np.asarray(sharpness, np.float64)
    key = (_content_key(sharpness, eta, shadowing, shadowing_theta), tuple(shape), int(order), int(views))
    table = _cache.get(key)
    if table is not None:
        _cache.move_to_end(key)
        return table

    def build():
        start = time.perf_counter()
        rows = np.concatenate([sharpness, np.asarray(eta, np.float64)[:, None], np.asarray(shadowing, np.float64)],
                              1)
        _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        unique = project_texels(sharpness[first], np.asarray(eta)[first], np.asarray(shadowing)[first],
                                shadowing_theta, order, view_thetas(views))
        return {"coefficients": unique[inverse.reshape(-1)], "seconds": np.float64(time.perf_counter() - start)}

    arrays = build() if store is None else store("sh_fitted_table", key, build)
    table = FittedTable(int(order), tuple(shape), arrays["coefficients"], float(arrays["seconds"]))
    _cache[key] = table
    while len(_cache) > CACHE_SIZE:
        _cache.popitem(last=False)
    return table


def texture_layers(table):
    """(K ceil(M / 4), H, W V, 4) float32, as the GPU reads it (texelFetch): layer k ceil(M / 4) + j holds lobe
    k's coefficients 4 j .. 4 j + 3 (of the stored m >= 0 ones); texel (x, y)'s views are columns x V .. x V + V - 1
    of row y."""
    height, width = table.shape
    count, lobes, views, size = table.coefficients.shape
    layers = -(-size // 4)
    padded = np.zeros((count, lobes, views, 4 * layers), np.float32)
    padded[..., :size] = table.coefficients
    grid = padded.reshape(height, width, lobes, views, layers, 4)
    return np.ascontiguousarray(grid.transpose(2, 4, 0, 1, 3, 5).reshape(lobes * layers, height, width * views, 4))


def view_coordinate(theta, views):
    """(node below (N,), fraction (N,)) of view angles (N,) float32 between the table's nodes, clamped to the
    end nodes (the shader's sh_fitted_lookup)."""
    theta = np.asarray(theta, np.float32)
    x = np.clip(theta * np.float32(2 / np.pi) * np.float32(views) - np.float32(0.5), np.float32(0),
                np.float32(views - 1))
    low = np.minimum(x.astype(np.int64), views - 2)
    return low, (x - low.astype(np.float32)).astype(np.float32)


def lookup(table, texels, theta):
    """c (N, K, N^2) float32 at texel indices (N,) and view angles (N,): the stored coefficients linearly
    interpolated between view nodes, m < 0 zero (the shader's sh_fitted_lookup)."""
    low, fraction = view_coordinate(theta, table.views)
    rows = table.coefficients[np.asarray(texels)]                                     # (N, K, V, M)
    index = np.arange(len(rows))
    below, above = rows[index, :, low], rows[index, :, low + 1]
    mixed = below + (above - below) * fraction[:, None, None]
    out = np.zeros(mixed.shape[:2] + (table.order ** 2,), np.float32)
    out[..., positive_m_indices(table.order)] = mixed
    return out
