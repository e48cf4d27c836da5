"""Directional albedo of the engine's GGX (brdf.GGX: height-correlated Smith, no Fresnel),
E(o) = integral over i of rho_s(o, i) (n.i), tabulated over (cos theta_o, roughness) for the GPU.

Two SG lobes hold 0.93-0.97 of GGX's projected NDF area at roughness 0.3-0.5 (the rest is its
theta^-4 tail), and the warp loses more at grazing views; E(o) minus the slice lobes' own albedo is
the energy the lobes miss, which the surface shader returns as a broad lobe of environment light
(techniques.sg.sg_shading.environment_tail).

Quadrature in the half vector with GGX's own CDF in u = tan^2 / (alpha^2 + tan^2): D(h) (n.h) dh =
du dphi / (2 pi) exactly, so E = integral of G(o, i) |o.h| / ((n.o)(n.h)) [i above the horizon]
du dphi / (2 pi), a smooth integrand but for the horizon cut (Gauss-Legendre in u, uniform phi).
"""
import functools

import numpy as np

from . import brdf

TABLE_SIZE = 32          # texels per axis: cos theta_o and roughness, each in [0, 1] at texel centres
QUADRATURE_U = 64
QUADRATURE_PHI = 32


def directional_albedo(cos_o, roughness, nodes_u=QUADRATURE_U, nodes_phi=QUADRATURE_PHI, schlick_weight=False):
    """E(o) of brdf.GGX for arrays cos_o, roughness (broadcast) -> float64 array.  schlick_weight: the
    integrand times Schlick's (1 - o.h)^5 (reflectance.layering's second table)."""
    cos_o, roughness = np.broadcast_arrays(np.asarray(cos_o, np.float64), np.asarray(roughness, np.float64))
    shape = cos_o.shape
    cos_o = np.clip(cos_o.ravel(), 1e-4, 1.0)[:, None, None]
    alpha = np.maximum(roughness.ravel() ** 2, 1e-9)[:, None, None]
    x, w = np.polynomial.legendre.leggauss(nodes_u)
    u = 0.5 * (x + 1.0)[None, :, None]
    weight_u = 0.5 * w[None, :, None]
    phi = ((np.arange(nodes_phi) + 0.5) * (2 * np.pi / nodes_phi))[None, None, :]
    tan2 = alpha * alpha * u / (1.0 - u)
    cos_h = 1.0 / np.sqrt(1.0 + tan2)
    sin_h = np.sqrt(np.maximum(1.0 - cos_h * cos_h, 0.0))
    h = np.stack(np.broadcast_arrays(sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h), axis=-1)
    sin_o = np.sqrt(1.0 - cos_o * cos_o)
    o = np.stack(np.broadcast_arrays(sin_o, np.zeros_like(sin_o), cos_o), axis=-1)
    o_dot_h = np.sum(o * h, axis=-1)
    i = 2.0 * o_dot_h[..., None] * h - o
    above = (i[..., 2] > 0) & (o_dot_h > 0)
    lambda_o = brdf.GGX.smith_lambda(np.broadcast_to(o, i.shape), alpha)
    lambda_i = brdf.GGX.smith_lambda(i, alpha)
    integrand = np.where(above, o_dot_h / ((1.0 + lambda_o + lambda_i) * cos_o * cos_h), 0.0)
    if schlick_weight:
        integrand = integrand * (1.0 - np.clip(o_dot_h, 0.0, 1.0)) ** 5
    albedo = np.sum(integrand * weight_u, axis=(1, 2)) / nodes_phi
    return albedo.reshape(shape)


def texel_centres(size=TABLE_SIZE):
    """The table's sample values along either axis: 0 and 1 at the first and last texel centres."""
    return np.linspace(0.0, 1.0, size)


@functools.lru_cache(maxsize=1)
def albedo_table():
    """(TABLE_SIZE, TABLE_SIZE) float32, row r = roughness, column c = cos theta_o, both texel_centres()."""
    grid = texel_centres()
    table = directional_albedo(grid[None, :], grid[:, None]).astype(np.float32)
    table.setflags(write=False)
    return table


def table_coordinates(cos_o, roughness, size=TABLE_SIZE):
    """Texture coordinates (s, t) of the GPU's bilinear fetch that lands on the texel-centre grid."""
    def coordinate(value):
        clipped = np.clip(np.asarray(value, np.float32), 0, 1)
        return (clipped * np.float32(size - 1) + np.float32(0.5)) / np.float32(size)
    return coordinate(cos_o), coordinate(roughness)
