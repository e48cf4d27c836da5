"""Numpy mirror of the factored-BRDF technique's fragment shader (shaders/techniques/factored/): the same
steps, per pixel, in float32 where the shader is.  tables: techniques.homomorphic.factored.FactoredTables."""
import numpy as np

from ...measured import homomorphic
from ...spherical import clamped_cosine, texture_fetch
from ..sg import sg_shading

FLOAT = np.float32


def factored_brdf(log_factors, form, wo, wi):
    """exp of the summed log-factors at local directions (..., 3) -> (..., C), as factored_brdf() of the
    shader reads its maps (GPU bilinear fetch; directions clamped to the hemisphere; no alpha A)."""
    wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
    log_value = 0.0
    for name, uv in zip(homomorphic.FORMS[form], homomorphic.map_coordinates(wo, wi)):
        if name is not None:
            log_value = log_value + texture_fetch.bilinear(np.asarray(log_factors[name], np.float32),
                                                           uv.astype(np.float32))
    return np.exp(log_value)


def shade(position, normal, tangent, view_origin, is_perspective, diffuse_color, specular_color, light_data,
          environment, tables, visibility=None):
    """Diffuse and specular radiance (N, 3) float32 of pixels (as sg_shading.shade takes them); visibility:
    an sg_shading.Visibility (the HAS_VISIBILITY variant's SSDF inputs) or None."""
    position = np.asarray(position, FLOAT)
    n, t, b = sg_shading.shading_frame(normal, tangent)
    view = sg_shading.view_directions(position, view_origin, is_perspective)
    frame = np.stack([t, b, n], axis=-1)
    o = np.einsum("nji,nj->ni", frame, view)
    maps, form = tables.factorization.log_factors, tables.factorization.form
    scale = np.asarray(tables.scale, FLOAT)
    def visible(axis, sharpness):      # every lobe's SSDF visibility, as FACTORED_VISIBILITY
        if visibility is None:
            return FLOAT(1)
        shape = np.shape(sharpness)
        flat_axis = np.broadcast_to(np.asarray(axis, FLOAT), shape + (3,)).reshape(shape[0], -1, 3)
        flat_sharpness = np.broadcast_to(np.asarray(sharpness, FLOAT), shape).reshape(shape[0], -1)
        return sg_shading.lobe_visibility(flat_axis, flat_sharpness, n, visibility).reshape(shape)

    # the broad diffuse lobes' fractions from the vertices (the GPU's per-vertex pass), when given
    diffuse_visible = None if visibility is None or visibility.diffuse is None else np.asarray(visibility.diffuse, FLOAT)
    irradiance = np.zeros(position.shape, FLOAT)
    radiance = np.zeros(position.shape, FLOAT)
    for axis, sharpness, amplitude in sg_shading._light_sets(position, light_data):
        light_visible = 1 if visibility is None else sg_shading.light_cap_visibility(axis, sharpness, visibility)
        energy = amplitude * (clamped_cosine.sg_clamped_cosine_integral(axis, sharpness, FLOAT(1), n[:, None])
                              * light_visible)[..., None]
        irradiance += np.sum(energy, axis=1)
        local = np.einsum("nji,nlj->nli", frame, axis)
        f = scale * factored_brdf(maps, form, np.broadcast_to(o[:, None], local.shape), local)[..., :3]
        radiance += np.sum(energy * f, axis=1).astype(FLOAT)
    albedo = scale * texture_fetch.bilinear(tables.albedo, homomorphic.parabolic_coordinates(o).astype(FLOAT))[:, :3]
    mirror = 2 * np.sum(n * view, axis=-1, keepdims=True) * n - view
    lobe = np.full((len(n), 1), tables.lobe_sharpness, FLOAT)
    mirror_visible = np.asarray(visible(mirror[:, None], lobe), FLOAT).reshape(-1, 1)
    if environment.has_texture:
        count = len(environment.lobe_sharpness)
        env_axis = np.broadcast_to(environment.lobe_axis[None], (len(n), count, 3))
        env_sharpness = np.broadcast_to(environment.lobe_sharpness[None], (len(n), count))
        env_visible = visible(env_axis, env_sharpness) if diffuse_visible is None else diffuse_visible[:, :count]
        irradiance += np.sum(environment.lobe_amplitude[None] * (clamped_cosine.sg_clamped_cosine_integral(
            env_axis, env_sharpness, FLOAT(1), n[:, None]) * env_visible)[..., None], axis=1)
        radiance += albedo * sg_shading.environment_radiance(environment, mirror, lobe[:, 0]) * mirror_visible
    else:
        colour = np.asarray(environment.colour, FLOAT)
        world_visible = visible(n[:, None], np.zeros((len(n), 1), FLOAT)) if diffuse_visible is None \
            else diffuse_visible[:, :1]
        irradiance += np.pi * colour * np.asarray(world_visible, FLOAT).reshape(-1, 1)
        radiance += albedo * colour * mirror_visible
    diffuse = np.asarray(diffuse_color, FLOAT) * FLOAT(1 / np.pi) * irradiance
    return diffuse.astype(FLOAT), (np.asarray(specular_color, FLOAT) * radiance).astype(FLOAT)


def shade_fragments(material, textures, tables, position, normal, tangent, uv, view_origin, is_perspective,
                    light_data, environment, visibility=None):
    """Mirror of the technique's main(): per-fragment inputs as the G-buffer holds them (as
    sg_shading.shade_fragments takes them), and the material's FactoredTables."""
    count = len(position)
    diffuse_color, specular_color = sg_shading.surface_colours(material, textures, uv, count)
    shading_normal, shading_tangent = sg_shading.surface_geometry(material, textures, normal, tangent, uv)
    diffuse_color, specular_color = sg_shading.surface_layers(material, None, uv, diffuse_color, specular_color,
                                                              shading_normal, position, view_origin, is_perspective)
    return shade(position, shading_normal, shading_tangent, view_origin, is_perspective, diffuse_color,
                 specular_color, light_data, environment, tables, visibility)
