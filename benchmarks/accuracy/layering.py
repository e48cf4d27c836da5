"""Accuracy of reflectance.layering: the glossy layer of Blender's BSDFs (Schlick Fresnel, Multiscatter GGX, the
layered diffuse) as colour factors at the view on the engine's GGX lobe.

References: brdf.GGX with Schlick's F(o.h) inside the integral on a 200k-direction hemisphere lattice; the
albedo quadrature (ggx_albedo.directional_albedo) at 4x the table's nodes.
"""
import numpy as np

from sg_prt_addon.reflectance import brdf, ggx_albedo, layering
from sg_prt_addon.spherical import lattice

VIEWS = (0.25, 0.6, 0.95)
ROUGHNESS = (0.3, 0.5, 0.8)
F0 = (0.04, 0.5, 0.95)


def _lobe(directions, cos_o, roughness):
    wo = np.broadcast_to(np.array([np.sqrt(1 - cos_o ** 2), 0.0, cos_o]), directions.shape)
    values = brdf.GGX(roughness=roughness).specular(wo, directions) * directions[:, 2]
    return values, np.sum(wo * brdf.half_vector(wo, directions), axis=-1)


def _fresnel_rows():
    directions = lattice.hemisphere_points(200_000)
    weight = 2 * np.pi / len(directions)
    rows = []
    for f0 in F0:
        albedo_errors, shape_errors = [], []
        for cos_o in VIEWS:
            for roughness in ROUGHNESS:
                values, o_dot_h = _lobe(directions, cos_o, roughness)
                inside = values * layering.schlick(f0, o_dot_h)
                exact = np.sum(inside) * weight
                colour, _ = layering.factors(np.full((1, 3), f0), layering.NO_LAYER, np.array([cos_o]),
                                             np.array([roughness]), True, False)
                albedo = np.sum(values) * weight
                albedo_errors.append(abs(colour[0, 0] * albedo - exact) / exact)
                shape = inside - colour[0, 0] * values
                shape_errors.append(np.linalg.norm(shape) / np.linalg.norm(inside))
        rows.append(dict(name=f"Schlick averaged over the lobe, F0 {f0}: the albedo",
                         reference="Schlick inside the integral, 200k-direction lattice",
                         metric="relative error of int F rho cos (max / mean over 9 views x roughness)",
                         max_error=float(max(albedo_errors)), mean_error=float(np.mean(albedo_errors)),
                         note="views cos 0.25-0.95, roughness 0.3-0.8; the table's fetch and the lattice"))
        rows.append(dict(name=f"Schlick averaged over the lobe, F0 {f0}: the lobe's shape",
                         reference="Schlick inside the integral, 200k-direction lattice",
                         metric="relative L2 of F rho cos over light directions (max / mean)",
                         max_error=float(max(shape_errors)), mean_error=float(np.mean(shape_errors)),
                         note="what a small light sees; worst at grazing views of a dielectric"))
    return rows


def _table_rows():
    table = layering.layering_table()
    grid = ggx_albedo.texel_centres()
    fine = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], nodes_u=256, nodes_phi=128)
    fine_w = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], nodes_u=256, nodes_phi=128,
                                           schlick_weight=True)
    rows = []
    for label, values, reference in (("E", table[..., 0], fine), ("E_w (Schlick-weighted)", table[..., 1], fine_w)):
        error = np.abs(values - reference)
        rows.append(dict(name=f"layering table {label}", reference="directional_albedo at 256 x 128 nodes",
                         metric="absolute error (max / mean over the 32 x 32 texels)", max_error=float(error.max()),
                         mean_error=float(error.mean()), note="largest at cos 0 of the sharpest rows"))
    cos_o = np.linspace(0.02, 1.0, 50).astype(np.float32)
    worst = 0.0
    for roughness in (0.05, 0.3, 0.6, 1.0):
        albedo = layering.table_values(cos_o, np.full_like(cos_o, roughness))[0]
        colour, _ = layering.factors(np.ones((50, 3)), layering.NO_LAYER, cos_o, np.full_like(cos_o, roughness),
                                     True, True)
        worst = max(worst, float(np.abs(colour[:, 0] * albedo - 1.0).max()))
    rows.append(dict(name="Multiscatter GGX, white: the furnace", reference="1 (every view keeps its energy)",
                     metric="|E x gain - 1| (max over views and roughness 0.05-1)", max_error=worst,
                     mean_error=worst, note="Cycles' 1 + F_ms (1 - E) / E with F = 1"))
    return rows


def measure():
    return _fresnel_rows() + _table_rows()
