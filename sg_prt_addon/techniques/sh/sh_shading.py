"""Numpy mirror of the SH technique's fragment shader (shaders/techniques/sh/): the same steps per pixel, in
float32 where the shader is.  table: a harmonics.brdf_table.BrdfTable, or a harmonics.fitted_table.FittedTable
of the material's lobe fit (SH_FITTED: the product is RGB, (N, N^2, 3)); environment: (>= N^2, 3) SH
coefficients of the world lighting (spherical_harmonics.environment_coefficients)."""
import math

import numpy as np

from ...harmonics import basis, brdf_table, fitted_table, projection, rotation
from ...lighting import lights
from ...measured.svbrdf_table import interpolate_shadowing
from ...reflectance.brdf import COSINE_EPSILON
from ...spherical import sg, texture_fetch
from ..sg import fitted_texels, sg_shading

FLOAT = np.float32


def _table_coefficients(table, o, parameter):
    """The shader's sh_table_lookup: (N, N^2) at local views o (N, 3)."""
    layers = brdf_table.texture_layers(table)
    if table.layout == "theta":
        uv = np.stack([_view_theta(o) * FLOAT(2 / np.pi), table.parameter_coordinate(parameter)], -1).astype(FLOAT)
    else:
        uv = brdf_table.parabolic_coordinates(o).astype(FLOAT)
    count = table.coefficients.shape[-1]
    samples = np.concatenate([texture_fetch.bilinear(layers[k], uv) for k in range(len(layers))], axis=-1)
    return samples[:, :count].astype(FLOAT)


def _view_theta(o):
    """theta_v of local views (N, 3) as the shader takes it (atan; pi / 2 below the horizon)."""
    return np.arctan2(np.maximum(np.linalg.norm(o[:, :2], axis=-1), FLOAT(1e-30)), np.maximum(o[:, 2], 0)).astype(FLOAT)


def _product(table, o, frame, parameter):
    """The shader's sh_product: the BRDF product at local views o (N, 3) in world coordinates, (N, N^2), or
    (N, N^2, 3) from a lobe fit's table, whose `parameter` is then (texel indices (N,), fitted_texels params of
    the pixels' texels)."""
    if table.layout != "fitted":
        return rotation.rotate_zyz_many(_table_coefficients(table, o, parameter), frame).astype(FLOAT)
    texels, values = parameter
    theta = _view_theta(o)
    shadowing = interpolate_shadowing(values["shadowing"], values["shadowing_theta"], theta[:, None].astype(np.float64))
    view_factor = (shadowing[:, 0].astype(FLOAT) / (FLOAT(np.pi) * np.maximum(o[:, 2], FLOAT(COSINE_EPSILON)))).astype(FLOAT)
    lobes = fitted_table.lookup(table, texels, theta)                              # (N, K, N^2)
    c = np.zeros(lobes.shape[:1] + lobes.shape[2:] + (3,), FLOAT)
    for k in range(lobes.shape[1]):
        colour = np.asarray(values["colour"], FLOAT)[:, k] * view_factor[:, None]
        c += colour[:, None, :] * rotation.rotate_zyz_many(lobes[:, k], frame).astype(FLOAT)[..., None]
    return c


def _cap_flux_and_factors(position, light_data, order):
    """(axis (N, P, 3), flux (N, P, 3), g (N, P, order), sine of the angular radius (N, P)) of the point and
    spot lights and area lights' patches as uniform caps."""
    to_light = light_data.point_position[None] - position[:, None]
    distance2 = np.sum(to_light * to_light, axis=-1)
    radius2 = light_data.point_radius[None] ** 2
    effective2 = lights.light_cap_extent(distance2, radius2, light_data.soft_falloff[None]).astype(FLOAT)
    axis = sg.normalize(to_light)
    sin2 = radius2 / effective2
    cos_half = np.sqrt(np.maximum(1 - sin2, 0)).astype(FLOAT)
    g = projection.cap_factors(sin2 / (1 + cos_half), order, FLOAT)
    sine = np.sqrt(sin2).astype(FLOAT)
    emission = sg_shading.point_light_emission(axis, light_data)
    flux = light_data.point_intensity[None] * (2 / (effective2 * (1 + cos_half)) * emission)[..., None]
    return axis.astype(FLOAT), flux.astype(FLOAT), g, sine


def _light_sets(position, light_data, order):
    sets = []
    if len(light_data.point_radius):
        sets.append(_cap_flux_and_factors(position, light_data, order))
    if len(light_data.sun_sharpness):
        count = len(light_data.sun_sharpness)
        flux = light_data.sun_amplitude * sg.sphere_integral(light_data.sun_sharpness, FLOAT(1))[:, None]
        g = projection.sg_factors(light_data.sun_sharpness, order, FLOAT)
        # the cap the SG stands for (lights.glsl light_cap_energy_lobe: sharpness ln(10) / sin^2)
        sine = np.sqrt(np.minimum(FLOAT(np.log(10)) / np.maximum(light_data.sun_sharpness, FLOAT(1e-6)), 1))
        sets.append((np.broadcast_to(light_data.sun_axis[None], (len(position), count, 3)),
                     np.broadcast_to(flux[None], (len(position), count, 3)).astype(FLOAT),
                     np.broadcast_to(g[None], (len(position), count, order)),
                     np.broadcast_to(sine[None].astype(FLOAT), (len(position), count))))
    return sets


def _zonal_sum(weights, t):
    """sh_zonal_sum: sum_l weights[..., l] (2l + 1) / (4 pi) P_l(t)."""
    order = weights.shape[-1]
    p = projection.legendre_polynomials(t.astype(FLOAT), max(order - 1, 1))
    bands = np.arange(order)
    return np.sum(weights * ((2 * bands + 1) / FLOAT(4 * np.pi)).astype(FLOAT)
                  * np.stack(p[:order], -1).astype(FLOAT), axis=-1)


def transfer_sums(rows, products, terms, count):
    """(T L (N, count, 3), t . L (N, 3), t (N, count)) float32 of rows (N, 4 L) [1, w_0, ...] of the transfer's
    weights: sum_k w_k of products (4 L, count + 1, >= 3) spherical_harmonics.transfer_radiance_texture (row k:
    T_k L, then t_k . L) and of terms (4 L, D) visibility.transfer.basis_terms.  The shader's per-pixel loop
    of the interpolated weights, or (VERTEX_TRANSFER) at the vertices before the interpolation: by linearity
    the same."""
    rows, products, terms = (np.asarray(a, FLOAT) for a in (rows, products, terms))
    # one matrix product (einsum's loop took 20x as long: 0.16 s for 8,000 vertices and 48 terms)
    lit = (rows @ np.ascontiguousarray(products[:, :count + 1, :3]).reshape(len(products), -1)).reshape(
        len(rows), count + 1, 3)
    return lit[:, :count], lit[:, count], rows @ terms[:, :count]


def shade(position, normal, tangent, view_origin, is_perspective, diffuse_color, specular_color, parameter,
          light_data, environment, table, window="none", transfer=None):
    """Diffuse and specular radiance (N, 3) float32 of pixels; transfer: None or the HAS_TRANSFER variant's
    inputs at the pixels, transfer_sums' (T L (N, N^2, 3), t . L (N, 3), t (N, >= N^2))."""
    order = table.order
    count = order * order
    position = np.asarray(position, FLOAT)
    n, t, b = sg_shading.shading_frame(normal, tangent)
    view = sg_shading.view_directions(position, view_origin, is_perspective)
    if table.layout in ("theta", "fitted"):            # isotropic: the view in the frame's x-z plane
        along = view - n * np.sum(n * view, axis=-1, keepdims=True)
        turn = np.sum(along * along, axis=-1, keepdims=True) > FLOAT(1e-12)
        t = np.where(turn, sg.normalize(along), t)
        b = np.where(turn, np.cross(n, t), b).astype(FLOAT)
    frame = np.stack([t, b, n], axis=-1)                                  # local -> world, columns t, b, n
    o = np.einsum("nji,nj->ni", frame, view)
    c = _product(table, o, frame, parameter)                              # the product in world coordinates
    c = c if c.ndim == 3 else c[..., None]                                # (N, N^2, colours 1 or 3)
    window_factors = projection.window_factors(window, order).astype(FLOAT)
    cosine = (projection.clamped_cosine_zonal(order)
              / [basis.normalization(band, 0) for band in range(order)]).astype(FLOAT)
    bands, _ = basis.band_of(count)
    if transfer is None:
        light = projection.apply_window(np.asarray(environment, FLOAT)[:count, :3], window_factors).astype(FLOAT)
        radiance = np.einsum("nic,ic->nc", c, light)
        irradiance = (basis.evaluate(n, order).astype(FLOAT) * cosine[bands]) @ light
    else:
        lit, irradiance, diffuse_transfer = (np.asarray(a, FLOAT) for a in transfer)
        radiance = np.einsum("nic,nic->nc", c, lit[:, :count])
        diffuse_transfer = diffuse_transfer[:, :count]                             # (N, N^2): t(p)
    for axis, flux, g, sine in _light_sets(position, light_data, order):
        weight = window_factors * g                                       # (N, P, order)
        y = basis.evaluate(axis, order).astype(FLOAT)                     # (N, P, N^2)
        glossy = np.sum((weight[..., bands] * y)[..., None] * c[:, None], axis=-2)     # (N, P, colours)
        elevation = np.sum(n[:, None] * axis, axis=-1)
        unshadowed = _zonal_sum(weight * cosine, elevation)
        above = (elevation > -sine).astype(FLOAT)          # a light wholly below the horizon lights nothing
        if transfer is not None:
            shadowed = np.sum(weight[..., bands] * diffuse_transfer[:, None, :] * y, axis=-1)
            visible = np.where(unshadowed > FLOAT(1e-12),
                               np.clip(shadowed / np.where(unshadowed > 0, unshadowed, FLOAT(1)), 0, 1), FLOAT(0))
            glossy, unshadowed = glossy * visible[..., None], shadowed
        glossy, unshadowed = glossy * above[..., None], unshadowed * above
        radiance = radiance + np.sum(flux * glossy, axis=1)
        irradiance = irradiance + np.sum(flux * unshadowed[..., None], axis=1)
    diffuse = np.asarray(diffuse_color, FLOAT) * FLOAT(1 / math.pi) * np.maximum(irradiance, 0)
    specular = np.asarray(specular_color, FLOAT) * np.maximum(radiance, 0)
    return diffuse.astype(FLOAT), specular.astype(FLOAT)


def shade_fragments(material, textures, table, environment, position, normal, tangent, uv, view_origin,
                    is_perspective, light_data, transfer=None):
    """Mirror of the technique's main(): per-fragment inputs as the G-buffer holds them, the material's
    BrdfTable, the environment's coefficients and (HAS_TRANSFER) the transfer inputs of shade()."""
    count = len(position)
    if table.layout == "fitted":             # SH_FITTED: kd and the lobes' colours from the fit's texel
        values, kd = fitted_texels.fitted_texel_values(material.fitted, uv)
        shading_normal, shading_tangent = sg_shading.surface_geometry(material, textures, normal, tangent, uv)
        return shade(position, shading_normal, shading_tangent, view_origin, is_perspective, kd,
                     np.ones((count, 3), FLOAT), (fitted_texels.texel_indices(material.fitted, uv), values),
                     light_data, environment, table, material.sh_window, transfer)
    diffuse_color, specular_color = sg_shading.surface_colours(material, textures, uv, count)
    parameter = np.full(count, FLOAT(getattr(material, table.parameter)) if table.parameter else 0, FLOAT)
    if table.parameter in textures:
        parameter = parameter * sg_shading.sample_material_texture(textures[table.parameter], uv)[:, 0]
    shading_normal, shading_tangent = sg_shading.surface_geometry(material, textures, normal, tangent, uv)
    roughness_texture = textures["roughness"] if table.parameter == "roughness" and "roughness" in textures else None
    diffuse_color, specular_color = sg_shading.surface_layers(material, roughness_texture, uv, diffuse_color,
                                                              specular_color, shading_normal, position, view_origin,
                                                              is_perspective)
    return shade(position, shading_normal, shading_tangent, view_origin, is_perspective, diffuse_color,
                 specular_color, parameter, light_data, environment, table, material.sh_window, transfer)
