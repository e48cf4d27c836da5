"""Numpy mirror of shaders/techniques/common/fitted_texels.glsl and sg_models.glsl's fitted_m_factor: a stored
lobe fit (blender.lobe_fit, export.FittedLobes) read at each pixel's texel, its shadowing S and its
M_o(i) = F_eta(i.h) S(o) S(i) / (pi (i.n)(o.n)).  Shared by the fitted-lobes technique's slice (sg_shading), a
bi-scale material whose small-scale BRDF is the fit (biscale_shading) and the SH technique's tables of the fit
(spherical_harmonics, sh_shading)."""
import numpy as np

from ...measured.microfacet_fit import decompress_shadowing
from ...measured.svbrdf_table import interpolate_shadowing
from ...reflectance import brdf
from ...spherical import sg

FLOAT = np.float32
FITTED_MODEL = "FITTED"        # the variant's model with a stored fit (MODEL_FITTED in the GLSL)


def fitted_texel_values(fitted, uv):
    """fitted_texels.glsl's fitted_select_texel + fetches: the nearest texel of the UV (floor(uv * size),
    clamped) in an export.FittedLobes; returns the shade() params of model FITTED and (kd (N, 3), eta (N,))."""
    layers = np.asarray(fitted.layers, FLOAT)                       # (L, H, W, 4), row 0 at t = 0
    texels = texel_indices(fitted, uv)
    return _texel_values(fitted, layers.reshape(layers.shape[0], -1, 4)[:, texels])


def texel_indices(fitted, uv):
    """Row-major index y W + x of the UV's nearest texel (fitted_select_texel), (N,)."""
    height, width = fitted.layers.shape[1:3]
    uv = np.asarray(uv, FLOAT)
    x = np.clip(np.floor(uv[:, 0] * FLOAT(width)).astype(np.int64), 0, width - 1)
    y = np.clip(np.floor(uv[:, 1] * FLOAT(height)).astype(np.int64), 0, height - 1)
    return y * width + x


def every_texel(fitted):
    """fitted_texel_values of every texel of an export.FittedLobes, row-major from row 0 (t = 0): texel
    y W + x."""
    layers = np.asarray(fitted.layers, FLOAT)
    return _texel_values(fitted, layers.reshape(layers.shape[0], -1, 4))


def _texel_values(fitted, texel):
    """The shade() params and kd of texels' layers (L, N, 4)."""
    count = fitted.lobe_count
    lobes = np.stack([texel[1 + 2 * k] for k in range(count)], axis=1)        # (N, K, 4)
    colour = np.stack([texel[2 + 2 * k, :, :3] for k in range(count)], axis=1)
    coefficients = np.concatenate([texel[1 + 2 * count + j] for j in range(fitted.shadowing_layers)],
                                  axis=1)[:, :fitted.components]
    table = np.asarray(fitted.table, np.float64)[..., 0]
    shadowing = decompress_shadowing(table[1], table[2:2 + fitted.components], coefficients.astype(np.float64))
    params = {"axis": sg.normalize(lobes[..., :3]), "sharpness": lobes[..., 3], "colour": colour,
              "eta": texel[0, :, 3], "shadowing": shadowing, "shadowing_theta": table[0]}
    return params, texel[0, :, :3]


def fitted_shadowing(params, direction):
    """S of each pixel's texel at local directions (N, M, 3) -> (N, M) (fitted_shadowing_of)."""
    w = sg.normalize(np.asarray(direction, FLOAT)).astype(np.float64)
    theta = np.arctan2(np.hypot(w[..., 0], w[..., 1]), np.maximum(w[..., 2], 0))
    return interpolate_shadowing(params["shadowing"], params["shadowing_theta"], theta)


def fitted_m_factor(params, wo, wi):
    """M_o(i) of each pixel's texel at local directions (K', N, 3), the pixel index second (fitted_m_factor with
    S(o) from wo)."""
    wo = sg.normalize(np.asarray(wo, FLOAT)).astype(np.float64)
    wi = sg.normalize(np.asarray(wi, FLOAT)).astype(np.float64)
    h = sg.normalize(wo + wi)
    fresnel = brdf.fresnel_dielectric(np.sum(wi * h, axis=-1), np.asarray(params["eta"], np.float64)[None])
    shadowing_o = fitted_shadowing(params, np.moveaxis(wo, 0, 1)).T                            # (K', N)
    shadowing_i = fitted_shadowing(params, np.moveaxis(wi, 0, 1)).T
    above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
    with np.errstate(all="ignore"):
        value = fresnel * shadowing_o * shadowing_i / (
            np.pi * np.maximum(wi[..., 2], brdf.COSINE_EPSILON) * np.maximum(wo[..., 2], brdf.COSINE_EPSILON))
    return np.where(above, value, 0.0)
