"""Fresnel, multiple scattering and the diffuse under a glossy layer, as colour factors at the pixel's view.

Blender's glossy lobes differ from the engine's GGX (brdf.GGX, no Fresnel) in three ways:

- Fresnel inside the integral: Schlick's F(o.h) = F0 + (1 - F0)(1 - o.h)^5 on the Principled BSDF (metals with
  F0 = the base colour; dielectrics from the IOR, whose curve Schlick follows to a few per cent);
- Multiscatter GGX (the Principled BSDF's default): the lobe times 1 + F_ms (1 - E) / E, with
  F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)) (Cycles' energy preservation, DESIGN.md "Blender's
  Principled BSDF");
- the diffuse base under the dielectric layer loses what that layer reflects at this view: kd (1 - A(o)).

The techniques shade the engine's GGX, so Fresnel leaves the integral: it is replaced by its average over
the lobe at this view, F_E(o) = (F0 (E - E_w) + E_w) / E, with E(o) the GGX albedo and E_w(o) the albedo
weighted by (1 - o.h)^5.  Exact in the white furnace; under a light the error is the spread of F(o.h) over
the lobe (docs/ACCURACY.md, layering).  F_E replaces the specular colour (F0), a factor the diffuse colour;
shaders/techniques/common/surface_layering.glsl computes the same, and `factors` is its mirror.

Table: (TABLE_SIZE, TABLE_SIZE, 4) float32 over (roughness rows, cos theta_o columns) at texel centres, as
ggx_albedo's: E, E_w, E_avg(roughness) (the cosine-weighted mean of E over views), 0.
"""
import functools

import numpy as np

from . import ggx_albedo

TABLE_SIZE = ggx_albedo.TABLE_SIZE
# Schlick's F averaged over the hemisphere with cos weighting: F0 + (1 - F0) * 2 int (1 - mu)^5 mu dmu
SCHLICK_AVERAGE_WEIGHT = 1.0 / 21.0
# Below this the diffuse is not layered (MaterialParams.layered_f0)
NO_LAYER = -1.0
FLOAT = np.float32
AVERAGE_NODES = 16


@functools.lru_cache(maxsize=1)
def layering_table():
    grid = ggx_albedo.texel_centres()
    albedo = ggx_albedo.albedo_table()
    weighted = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], schlick_weight=True)
    # E_avg = 2 int E(mu) mu dmu, by Gauss-Legendre in mu (E is smooth in mu: 16 nodes hold it to 7e-5 of 64)
    x, w = np.polynomial.legendre.leggauss(AVERAGE_NODES)
    mu = 0.5 * (x + 1.0)
    view_albedo = ggx_albedo.directional_albedo(mu[None, :], grid[:, None])
    average = np.sum(view_albedo * (mu * w)[None, :], axis=1)             # 2 * (1/2) sum: the interval's 1/2
    table = np.zeros((TABLE_SIZE, TABLE_SIZE, 4), np.float32)
    table[..., 0], table[..., 1], table[..., 2] = albedo, weighted, average[:, None]
    table.setflags(write=False)
    return table


def equivalent_roughness(model, params):
    """The GGX roughness whose albedo tables stand for `model`'s lobe (Cycles' sqrt(sqrt(alpha_x alpha_y))):
    a Beckmann-like width alpha reads as roughness sqrt(alpha); exponents n as alpha = sqrt(2 / (n + 2))."""
    def from_exponent(n):
        return np.sqrt(2.0 / (float(n) + 2.0))
    alpha = {
        "GGX": lambda: float(params["roughness"]) ** 2,
        "COOK_TORRANCE": lambda: float(params["roughness"]),
        "BLINN_PHONG": lambda: from_exponent(params["exponent"]),
        "WARD_ISO": lambda: float(params["alpha_x"]),
        "BECKMANN": lambda: float(params["roughness"]) ** 2,
        "WARD_ANISO": lambda: np.sqrt(float(params["alpha_x"]) * float(params["alpha_y"])),
        "GGX_ANISO": lambda: np.sqrt(float(params["alpha_x"]) * float(params["alpha_y"])),
        "ASHIKHMIN_SHIRLEY": lambda: np.sqrt(from_exponent(params["nu"]) * from_exponent(params["nv"])),
    }[model]()
    return float(np.sqrt(np.clip(alpha, 0.0, 1.0)))


def table_values(cos_o, roughness):
    """(E, E_w, E_avg) (N,) float32 by the GPU's bilinear fetch of layering_table at (cos_o, roughness)."""
    from ..spherical.texture_fetch import bilinear

    s, t = ggx_albedo.table_coordinates(cos_o, roughness)
    values = bilinear(layering_table(), np.stack(np.broadcast_arrays(s, t), axis=-1))
    return values[..., 0], values[..., 1], values[..., 2]


def _specular_colour(f0, albedo, weighted, average, fresnel, multiscatter):
    """Per channel: the colour on the engine's GGX lobe: Schlick's average over the lobe from f0 (or f0 itself,
    a constant colour), times the multiscatter gain (or 1)."""
    one = FLOAT(1.0)
    albedo = np.maximum(albedo, FLOAT(1e-4))
    if fresnel:
        single = (f0 * (albedo - weighted) + weighted) / albedo
        fresnel_average = f0 + (one - f0) * FLOAT(SCHLICK_AVERAGE_WEIGHT)
    else:
        single = f0
        fresnel_average = f0
    if not multiscatter:
        return single
    fresnel_average = np.minimum(fresnel_average, one)
    multiple = fresnel_average * average / np.maximum(one - fresnel_average * (one - average), FLOAT(1e-4))
    return single * (one + multiple * (one - albedo) / albedo)


def factors(f0, layered_f0, cos_o, roughness, fresnel, multiscatter):
    """(specular colour (N, 3), diffuse factor (N,)) float32 at views cos_o (N,) and roughness (N,): the colour
    that replaces the specular colour on the engine's GGX lobe, and what multiplies the diffuse colour.

    f0 (N, 3): the specular colour at normal incidence; layered_f0 (N,) or scalar: the dielectric layer's F0
    over the diffuse (below 0: the diffuse is not layered, factor 1); fresnel: Schlick on (else a constant
    colour); multiscatter: Multiscatter GGX's gain."""
    cos_o = np.clip(np.asarray(cos_o, FLOAT), FLOAT(0.0), FLOAT(1.0))
    roughness = np.clip(np.asarray(roughness, FLOAT), FLOAT(0.0), FLOAT(1.0))
    albedo, weighted, average = table_values(cos_o, roughness)
    f0 = np.asarray(f0, FLOAT)
    specular = _specular_colour(f0, albedo[:, None], weighted[:, None], average[:, None], fresnel, multiscatter)
    layered_f0 = np.broadcast_to(np.asarray(layered_f0, FLOAT), cos_o.shape)
    layer = _specular_colour(np.maximum(layered_f0, FLOAT(0.0)), albedo, weighted, average, True, multiscatter)
    reflected = np.clip(layer * albedo, FLOAT(0.0), FLOAT(1.0))
    diffuse = np.where(layered_f0 < FLOAT(0.0), FLOAT(1.0), FLOAT(1.0) - reflected)
    return specular.astype(FLOAT), diffuse.astype(FLOAT)


def schlick(f0, cos_theta):
    """Schlick's Fresnel F0 + (1 - F0)(1 - cos)^5 (float64)."""
    f0 = np.asarray(f0, np.float64)
    return f0 + (1.0 - f0) * (1.0 - np.clip(cos_theta, 0.0, 1.0)) ** 5
