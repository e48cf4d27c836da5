"""BRDF product tables (kautz2002 section 3): c_i(v, q) = integral of Y_i(s) f(s, v) max(s_z, 0) ds, the
SH projection of the BRDF times the cosine for every local view v and parameter value q, so that shading
under a lighting expansion L is the dot product sum_i L_i c_i(v) (eq. 1).

Layouts.  An isotropic model's product, with the local frame turned about the normal until the view lies
in its x-z plane (phi_v = 0), depends on theta_v only: the table is (parameter nodes P, theta_v nodes V,
N^2), theta_v at (k + 1/2) / V * pi / 2, and its coefficients with m < 0 vanish (the product is even in y).
The spatially varying parameter (roughness, exponent) is the other axis, as in the paper's Fig. 4.  An
anisotropic model keeps its tangent frame: views on a parabolic map (the paper's), (1, R^2, N^2), its
parameters fixed per material.

Quadrature per table entry: multiple importance sampling with the balance heuristic over two deterministic
lattices, the model's own importance sampling (brdf.sample, the lobe) and cosine-weighted directions (the
tails and broad lobes): sum over both sets of f cos Y / (n_b p_b + n_c p_c).  Deterministic, so a table is
the same on every run and cached by its inputs.
"""
import collections
import time
from dataclasses import dataclass

import numpy as np

from ..reflectance import brdf, models
from ..spherical import texture_fetch
from . import basis

# model -> (parameter, nodes' spacing, low, high) of the parameter axis of isotropic models
PARAMETER_AXES = {
    "GGX": ("roughness", "linear", 0.02, 1.0),
    "COOK_TORRANCE": ("roughness", "linear", 0.02, 1.0),
    "BLINN_PHONG": ("exponent", "log", 1.0, 10000.0),
    "WARD_ISO": ("alpha_x", "linear", 0.02, 1.0),
    "BECKMANN": ("roughness", "linear", 0.02, 1.0),
}
DEFAULT_ORDER = 5
DEFAULT_VIEWS = 64              # theta_v nodes (isotropic) or parabolic side (anisotropic: DEFAULT_MAP)
DEFAULT_MAP = 32
DEFAULT_PARAMETER_NODES = 16
DEFAULT_SAMPLES = 1024          # of each lattice per entry
CACHE_SIZE = 8


@dataclass(frozen=True, eq=False)
class BrdfTable:
    """coefficients (P, V, N^2) float32 (layout: the module docstring); parameter_nodes (P,) (isotropic) or
    () (anisotropic); fixed: the model parameters not on an axis, as (name, value) pairs."""
    model: str
    order: int
    layout: str                 # "theta" or "parabolic"
    resolution: int             # V (theta) or R (parabolic, V = R^2)
    parameter: str | None
    parameter_nodes: np.ndarray
    fixed: tuple
    coefficients: np.ndarray
    seconds: float = 0.0

    def parameter_coordinate(self, value):
        """Texture coordinate in [0, 1] of a parameter value along the axis (texel centres at (k + 1/2) / P)."""
        _, spacing, low, high = PARAMETER_AXES[self.model]
        value = np.clip(np.asarray(value, np.float64), low, high)
        t = (np.log(value / low) / np.log(high / low)) if spacing == "log" else (value - low) / (high - low)
        count = len(self.parameter_nodes)
        return (t * (count - 1) + 0.5) / count

    def view_coordinates(self, view):
        """(u, v) texture coordinates of local views (..., 3): theta_v / (pi / 2) (isotropic; v unused) or
        the parabolic map's (anisotropic)."""
        view = np.asarray(view, np.float64)
        if self.layout == "theta":
            theta = np.arctan2(np.maximum(np.linalg.norm(view[..., :2], axis=-1), 1e-30), np.maximum(view[..., 2], 0.0))
            return np.stack([theta / (np.pi / 2), np.zeros_like(theta)], -1)
        return parabolic_coordinates(view)


def parabolic_coordinates(direction):
    """(u, v) of a local direction on the parabolic map (upper hemisphere; below it, the rim)."""
    d = np.asarray(direction, np.float64)
    d = d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-30)
    z = np.maximum(d[..., 2], 0.0)
    tangential = np.maximum(np.linalg.norm(d[..., :2], axis=-1, keepdims=True), 1e-30)
    xy = np.where(d[..., 2:3] >= 0, d[..., :2], d[..., :2] / tangential)
    return 0.5 * (xy / (1.0 + z)[..., None] + 1.0)


def parabolic_directions(resolution):
    """(R, R, 3) local directions at the texel centres of a parabolic map (row = v); outside the disk, the rim."""
    centres = (np.arange(resolution) + 0.5) / resolution
    u, v = np.meshgrid(centres, centres)
    s, t = 2 * u - 1, 2 * v - 1
    r2 = s * s + t * t
    scale = np.where(r2 <= 1, 1.0, 1 / np.sqrt(np.maximum(r2, 1e-30)))
    s, t, r2 = s * scale, t * scale, np.minimum(r2, 1.0)
    z = (1 - r2) / (1 + r2)
    return np.concatenate([np.stack([s, t], -1) * (1 + z)[..., None], z[..., None]], -1)


def theta_directions(count):
    """(V, 3) views in the x-z plane at theta_v = (k + 1/2) / V * pi / 2."""
    theta = (np.arange(count) + 0.5) / count * (np.pi / 2)
    return np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], -1)


def parameter_nodes(model, count=DEFAULT_PARAMETER_NODES):
    _, spacing, low, high = PARAMETER_AXES[model]
    t = np.linspace(0.0, 1.0, count)
    return low * (high / low) ** t if spacing == "log" else low + (high - low) * t


def _lattice(count):
    """(count, 2) points of a 2D Fibonacci lattice in [0, 1)^2 (rank-1, low discrepancy)."""
    k = np.arange(count)
    return np.stack([(k + 0.5) / count, np.mod(k * 0.6180339887498949, 1.0)], -1)


def _cosine_directions(u):
    radius, phi = np.sqrt(u[..., 0]), 2 * np.pi * u[..., 1]
    return np.stack([radius * np.cos(phi), radius * np.sin(phi), np.sqrt(np.maximum(1 - u[..., 0], 0.0))], -1)


def project_product(model, views, order, samples=DEFAULT_SAMPLES):
    """c (V, N^2) of one brdf model object (its specular()) at local views (V, 3), by the MIS quadrature."""
    views = np.asarray(views, np.float64)
    lattice = _lattice(samples)
    cosine_set = _cosine_directions(lattice)                                # (S, 3), pdf cos / pi
    out = np.empty((len(views), basis.coefficient_count(order)))
    for start in range(0, len(views), 32):
        wo = views[start:start + 32, None, :]                               # (B, 1, 3)
        lobe_set, _ = model.sample(np.broadcast_to(wo, (wo.shape[0], samples, 3)), np.broadcast_to(
            lattice, (wo.shape[0], samples, 2)))
        directions = np.concatenate([lobe_set, np.broadcast_to(cosine_set, lobe_set.shape)], axis=1)
        wo_all = np.broadcast_to(wo, directions.shape)
        cosine = np.maximum(directions[..., 2], 0.0)
        density = samples * model.pdf(wo_all, directions) + samples * cosine / np.pi
        f = np.nan_to_num(model.specular(wo_all, directions), nan=0.0, posinf=0.0)
        weight = np.where((cosine > 0) & (density > 0), f * cosine / np.maximum(density, 1e-300), 0.0)
        out[start:start + 32] = np.einsum("bs,bsi->bi", weight, basis.evaluate(directions, order))
    return out


_cache = collections.OrderedDict()


def table_for(model_name, order=DEFAULT_ORDER, resolution=None, parameter_count=DEFAULT_PARAMETER_NODES,
              samples=DEFAULT_SAMPLES, store=None, **params):
    """The BrdfTable of a model (its name in reflectance.models) at the given order, cached in the process by
    every input.  params: the model's parameters (the axis parameter of an isotropic model is ignored).
    store: None, or a function (kind, key, build) -> build()'s dict of arrays that may keep them elsewhere
    (the engine's disk cache; key: every input), asked on a miss in the process."""
    spec = models.BY_NAME[model_name]
    isotropic = model_name in PARAMETER_AXES
    axis = PARAMETER_AXES[model_name][0] if isotropic else None
    fixed = tuple((name, float(params[name])) for name in spec.parameters if name != axis and name in params)
    resolution = int(resolution or (DEFAULT_VIEWS if isotropic else DEFAULT_MAP))
    key = (model_name, order, resolution, parameter_count if isotropic else 1, samples, fixed)
    table = _cache.get(key)
    if table is not None:
        _cache.move_to_end(key)
        return table
    nodes = parameter_nodes(model_name, parameter_count) if isotropic else np.zeros(0)

    def build():
        start = time.perf_counter()
        if isotropic:
            views = theta_directions(resolution)
            coefficients = np.stack([project_product(brdf.model_from_name(model_name, **dict(fixed, **{axis: node})),
                                                     views, order, samples) for node in nodes])
            coefficients[..., basis.band_of(coefficients.shape[-1])[1] < 0] = 0.0   # zero by symmetry: lattice noise
        else:
            views = parabolic_directions(resolution).reshape(-1, 3)
            coefficients = project_product(brdf.model_from_name(model_name, **dict(fixed)), views, order,
                                           samples)[None]
        return {"coefficients": coefficients.astype(np.float32), "seconds": np.float64(time.perf_counter() - start)}

    arrays = build() if store is None else store("sh_brdf_table", key, build)
    table = BrdfTable(model_name, order, "theta" if isotropic else "parabolic", resolution, axis, nodes, fixed,
                      arrays["coefficients"], float(arrays["seconds"]))
    _cache[key] = table
    while len(_cache) > CACHE_SIZE:
        _cache.popitem(last=False)
    return table


def texture_layers(table):
    """The table as a float32 texture array (L, H, W, 4), as the GPU reads it: layer k holds coefficients
    4k .. 4k + 3; rows are the parameter nodes (isotropic) or the parabolic map's v."""
    count, views, size = table.coefficients.shape
    grid = (table.coefficients if table.layout == "theta"
            else table.coefficients[0].reshape(table.resolution, table.resolution, size))
    layers = -(-size // 4)
    padded = np.zeros(grid.shape[:2] + (4 * layers,), np.float32)
    padded[..., :size] = grid
    return np.ascontiguousarray(np.moveaxis(padded.reshape(grid.shape[:2] + (layers, 4)), 2, 0))


def lookup(table, view, parameter=None):
    """c (..., N^2) of local views (..., 3) (isotropic: in the aligned frame, phi_v = 0) by linear
    interpolation along the table's axes with clamp-to-edge, as a GPU's linear filter reads the texture."""
    uv = table.view_coordinates(view)
    coefficients = table.coefficients
    if table.layout == "theta":
        count, views, size = coefficients.shape
        t = table.parameter_coordinate(parameter)
        grid = coefficients.reshape(count, views, size)
        return texture_fetch.bilinear(grid, np.stack([uv[..., 0], np.broadcast_to(t, uv[..., 0].shape)], -1)
                                      .astype(np.float32))
    grid = coefficients[0].reshape(table.resolution, table.resolution, -1)
    return texture_fetch.bilinear(grid, uv.astype(np.float32))
