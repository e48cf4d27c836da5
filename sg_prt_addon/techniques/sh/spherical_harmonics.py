"""kautz2002 as a technique: any BRDF under low-frequency light, the BRDF times the cosine projected into SH
per local view (harmonics/brdf_table.py), the lighting as SH, shading as their dot product (eq. 1), the
rotation between frames per pixel on the GPU (shaders/techniques/sh/; techniques/sh/sh_shading.py is the
mirror).

What it reads: the material's model and parameters; an isotropic model's table has its spatially varying
parameter (roughness, exponent, alpha) as an axis, so that parameter's texture applies, as in the paper's
Fig. 4; an anisotropic model's parameters are uniform over the material (their textures are warned and
not applied).  Or (SH BRDF: Lobe Fit, export puts it in params.fitted) the material's stored lobe fit, the
measured BRDF SG_FITTED renders: a table per texel of the fit (harmonics/fitted_table.py, the texel as the
axis, nearest texel as SG_FITTED reads it), kd from the fit, only a normal map of the textures; isotropic
fits only (export refuses free axes and tables over fitted_table.MAX_TABLE_BYTES, rendering them with the
fitted SG lobes).  Lighting: the environment's equirect map projected once per map (SH_ENVIRONMENT_ORDER
bands, truncated to the material's order), or the world colour; point and spot lights as uniform caps,
suns as their SG (both zonal about their direction).  The material's order (2-8) and window (none,
Hanning, Lanczos: ringing against blur, docs/ACCURACY.md) pick the variant.

Shadows: with a transfer bake of the object (blender/transfer_bake.py, visibility/transfer.py) the
environment reaches the surface through the vertex's transfer: the glossy term dots the BRDF product with
T L and the diffuse term is t . L (the paper's section 5 after Sloan 2002), the products of L with the
compressed transfer's terms computed once per lighting per object (visibility.transfer.transferred_radiance)
and weighed by the PCA weights: at the vertices, once per lighting (vertex_transfer_values), the pixels
interpolating the sums, where the varyings hold them (vertex_transfer_rows: order 5 and below); else per
pixel by the interpolated weights (up to 63 terms of N^2 + 1 fetches a pixel: 4-5x the unshadowed frame
at order 5, the vertices' sums about 1x; docs/PERFORMANCE.md).  A light's diffuse term is t . (its SH) and its
glossy term is scaled by the same visible fraction of the light (t . L_light over the unshadowed
clamped-cosine integral); the shading order is at most the transfer's.
"""
import collections
import math
from dataclasses import dataclass

import numpy as np

from ...harmonics import brdf_table, fitted_table, projection
from ...reflectance import models
from ...visibility import per_vertex, transfer
from .. import material_textures, shader_sources, surface_layering
from ..base import SURFACE_TEXTURES, Technique
from ..material_textures import NodeValues
from ..sg import fitted_texels
from . import sh_glsl, sh_shading

NAME = "SH"
GLSL_DIR = "sh"
ORDERS = tuple(range(2, 9))
DEFAULT_ORDER = 5
WINDOWS = ("none",) + projection.WINDOWS
SH_ENVIRONMENT_ORDER = max(ORDERS)
COLOUR_SLOTS = ("diffuse_color", "specular_color", "normal_map", *SURFACE_TEXTURES)
LIBRARY_FILES = ("sg.glsl", "lights.glsl")
# the MaterialData field each axis parameter is in (shaders/engine/scene_data.glsl)
PARAMETER_FIELDS = {"roughness": "material.parameters0.x", "exponent": "material.parameters0.z",
                    "alpha_x": "material.parameters0.w"}
ENVIRONMENT_CACHE_SIZE = 4


@dataclass(frozen=True)
class SHKey:
    technique: str = NAME
    order: int = DEFAULT_ORDER
    window: str = "none"
    isotropic: bool = True
    parameter: str = "roughness"        # the table's axis (isotropic), None otherwise
    textures: tuple = ()
    node_values: NodeValues = NodeValues()   # what a node tree computes (material_textures.node_values)
    has_lights: bool = False
    gbuffer: bool = False
    transfer_layers: int = 0            # vec4 rows a vertex of the transfer bake (0: none)
    vertex_transfer: int = 0            # vec4 a vertex of the transfer summed at the vertices (0: per pixel)
    layering: tuple = ()            # surface_layering.flags of the material
    fitted_lobes: int = 0           # a stored lobe fit's tables (SH_FITTED): its lobes (0: the model's table)
    fitted_components: int = 0      # and its shadowing's PCA components

    def describe(self):
        table = (f"lobe fit ({self.fitted_lobes} lobes)" if self.fitted_lobes else
                 f"{self.parameter} axis" if self.isotropic else "anisotropic map")
        parts = [f"order {self.order}", f"window {self.window}", table, "lights" if self.has_lights else "no lights"]
        if self.textures:
            parts.append("textures: " + ", ".join(self.textures))
        if self.gbuffer:
            parts.append("G-buffer")
        if self.transfer_layers:
            parts.append(f"transfer ({self.transfer_layers} weight vec4, "
                         + (f"summed at the vertices: {self.vertex_transfer} vec4)" if self.vertex_transfer
                            else "summed per pixel)"))
        if self.layering:
            parts.append("layering: " + ", ".join(self.layering))
        return ", ".join(parts)


def texture_slots(params):
    """The texture slots the technique applies for a material: the colours, the normal map, the surface's
    (base.SURFACE_TEXTURES) and the table axis parameter's texture; with a lobe fit the normal map and the
    surface's (the fit holds the look)."""
    if getattr(params, "fitted", None) is not None:
        return ("normal_map", *SURFACE_TEXTURES)
    axis = brdf_table.PARAMETER_AXES.get(params.model)
    return COLOUR_SLOTS + ((axis[0],) if axis else ())


def table_for(params, order=None, store=None):
    """The table of a material (export.MaterialParams) at its order (or `order`, the variant's: a transfer bake
    of a lower order lowers it): its lobe fit's FittedTable when params.fitted, else its model's BrdfTable
    with its fixed parameters.  store: where a table built in another process may be kept (the engine's
    DrawContext.cached_arrays), or None."""
    order = int(order or params.sh_order)
    if getattr(params, "fitted", None) is not None:
        return fitted_table_for(params.fitted, order, store)
    model = models.BY_NAME[params.model]
    values = {name: float(getattr(params, name)) for name in model.parameters}
    return brdf_table.table_for(params.model, order=order, store=store, **values)


def fitted_table_for(fitted, order, store=None):
    """The harmonics.fitted_table.FittedTable of an export.FittedLobes: its texels as the SG_FITTED mirror reads
    them (fitted_texels.every_texel), so both tabulate the same BRDF; store as table_for's."""
    values, _ = fitted_texels.every_texel(fitted)
    return fitted_table.table_for(values["sharpness"], values["eta"], values["shadowing"], values["shadowing_theta"],
                                  fitted.layers.shape[1:3], order, store=store)


def fitted_refusal(fitted, order):
    """Why the SH technique cannot tabulate an isotropic export.FittedLobes at an order (its table's size), or
    None."""
    height, width = fitted.layers.shape[1:3]
    size = fitted_table.table_bytes(height * width, fitted.lobe_count, order)
    if size > fitted_table.MAX_TABLE_BYTES:
        return (f"its {width}x{height} texels' tables at order {order} would take {size / 2 ** 20:.3g} MB, more "
                f"than {fitted_table.MAX_TABLE_BYTES / 2 ** 20:.3g}: a lower SH order or a smaller fit")
    if width * fitted_table.DEFAULT_VIEWS > fitted_table.MAX_TEXTURE_WIDTH:
        return (f"its {width} texels a row make a table texture wider than "
                f"{fitted_table.MAX_TEXTURE_WIDTH} texels")
    return None


def axis_constants(table):
    """sh_axis of the shader (sh_shading.glsl): the parameter axis' scale, low end, log flag, node count."""
    if table.layout != "theta" or table.parameter is None:
        return [0.0, 1.0, 0.0, 1.0]
    _, spacing, low, high = brdf_table.PARAMETER_AXES[table.model]
    scale = 1.0 / math.log(high / low) if spacing == "log" else 1.0 / (high - low)
    return [scale, low, 1.0 if spacing == "log" else 0.0, float(len(table.parameter_nodes))]


TRANSFER_KIND = "transfer"       # the per-vertex kind of a transfer bake (engine/scene_state.py)
VERTEX_TRANSFER = True           # False: the transfer's terms summed per pixel at every order (benchmarks compare)


def transfer_order(data):
    """The order of a transfer bake's PerVertexData (its basis texture holds D = vector_size(order) a term)."""
    return transfer.order_of(data.basis_texture.shape[2])


def transfer_radiance_texture(data, environment, order, window):
    """(4 L, N^2 + 1, 4) float32: row k = term k of the transfer (the mean first) times the environment's
    windowed SH lighting (visibility.transfer.transferred_radiance), for the shader's per-pixel weights."""
    lighting = projection.apply_window(environment_coefficients(environment)[:order * order].astype(np.float64),
                                       projection.window_factors(window, order))
    products = transfer.transferred_radiance(transfer.basis_terms(data.basis_texture), lighting,
                                             transfer_order(data), order)
    out = np.zeros(products.shape[:2] + (4,), np.float32)
    out[..., :3] = products
    return out


def vertex_transfer_rows(order, has_lights):
    """vec4 a vertex of the transfer summed at the vertices: T L (N^2 RGB), t . L (RGB) and, for the lights'
    terms, t (N^2), packed 4 floats a vec4; 0 where they and the surface's own varyings would pass
    shader_sources.max_varyings() (order 6 and above on llvmpipe) or VERTEX_TRANSFER is off."""
    count = order * order
    rows = -(-(3 * (count + 1) + (count if has_lights else 0)) // 4)
    fits = (shader_sources.SURFACE_VARYINGS + rows <= shader_sources.max_varyings()
            and rows <= per_vertex.TEXELS_PER_VERTEX_LIMIT)
    return rows if VERTEX_TRANSFER and fits else 0


def vertex_transfer_values(data, environment, order, window, rows):
    """(V, 4 rows) float32 of a transfer bake's PerVertexData under an environment: each row's
    sh_shading.transfer_sums packed as the shader reads them (T L RGB by coefficient, t . L, then t if the
    rows hold it, zero-padded)."""
    count = order * order
    lit, irradiance, diffuse_transfer = sh_shading.transfer_sums(
        data.rows, transfer_radiance_texture(data, environment, order, window), transfer.basis_terms(
            data.basis_texture), count)
    parts = [lit.reshape(len(lit), -1), irradiance]
    if 4 * rows >= 3 * (count + 1) + count:
        parts.append(diffuse_transfer)
    out = np.zeros((len(lit), 4 * rows), np.float32)
    values = np.concatenate(parts, axis=1)
    out[:, :values.shape[1]] = values
    return out


_environments = collections.OrderedDict()


def environment_coefficients(environment):
    """(SH_ENVIRONMENT_ORDER^2, 3) float32 SH of a lighting.scene_lighting.EnvironmentData: its equirect map
    projected (once per map, cached by identity), or the constant world colour."""
    if not environment.has_texture or environment.radiance is None:
        out = np.zeros((SH_ENVIRONMENT_ORDER ** 2, 3), np.float32)
        out[0] = np.asarray(environment.colour, np.float32)[:3] * math.sqrt(4 * math.pi)
        return out
    entry = _environments.get(id(environment))
    if entry is not None and entry[0] is environment:
        _environments.move_to_end(id(environment))
        return entry[1]
    coefficients = projection.project_equirect(environment.radiance, SH_ENVIRONMENT_ORDER).astype(np.float32)
    _environments[id(environment)] = (environment, coefficients)
    while len(_environments) > ENVIRONMENT_CACHE_SIZE:
        _environments.popitem(last=False)
    return coefficients


class SphericalHarmonics(Technique):
    name = NAME
    label = "Spherical Harmonics (Kautz 2002)"
    description = ("The BRDF times the cosine as SH coefficients per view direction, the lighting as SH, "
                   "shading as their dot product (Kautz et al. 2002): any BRDF under low-frequency light")
    number = 3
    blender_side = ".blender"
    paper = "kautz2002"
    shadow_kind = TRANSFER_KIND

    mirror = staticmethod(sh_shading.shade_fragments)

    def variant_key(self, params, inputs):
        fitted = getattr(params, "fitted", None)
        axis = brdf_table.PARAMETER_AXES.get(params.model) if fitted is None else None
        slots = texture_slots(params)
        textures = tuple(sorted(name for name in params.textures if name in slots))
        order = int(np.clip(int(getattr(params, "sh_order", DEFAULT_ORDER)), min(ORDERS), max(ORDERS)))
        data = inputs.per_vertex_data.get(TRANSFER_KIND)
        if data is not None:
            order = min(order, transfer_order(data))
        fit = dict(fitted_lobes=int(fitted.lobe_count), fitted_components=int(fitted.components),
                   layering=()) if fitted is not None else dict(layering=surface_layering.flags(params))
        return SHKey(order=order, window=getattr(params, "sh_window", "none"),
                     isotropic=axis is not None or fitted is not None, parameter=axis[0] if axis else None,
                     textures=textures, node_values=material_textures.node_values(params, textures, inputs),
                     has_lights=inputs.has_lights, gbuffer=inputs.gbuffer,
                     transfer_layers=data.layers if data is not None else 0,
                     vertex_transfer=vertex_transfer_rows(order, inputs.has_lights) if data is not None else 0, **fit)

    def defines(self, key):
        out = {"SH_PARAMETER": PARAMETER_FIELDS[key.parameter] if key.parameter else "0.0"}
        if key.isotropic:
            out["SH_ISOTROPIC"] = 1
            if key.parameter in key.textures:
                out["SH_PARAMETER_TEXTURE"] = "texture_value_" + key.parameter
        if key.fitted_lobes:
            out.update(SH_FITTED=1, FITTED_LOBES=key.fitted_lobes, FITTED_COMPONENTS=key.fitted_components,
                       FITTED_SHADOWING_LAYERS=-(-key.fitted_components // 4))
        if key.has_lights:
            out["HAS_LIGHTS"] = 1
        for name in key.textures:
            if name in COLOUR_SLOTS:
                out["HAS_NORMAL_MAP" if name == "normal_map" else "HAS_TEXTURE_" + name.upper()] = 1
        if key.gbuffer:
            out["GBUFFER"] = 1
        if key.transfer_layers:
            out.update(HAS_TRANSFER=1, TRANSFER_LAYERS=key.transfer_layers)
        if key.vertex_transfer:
            out["VERTEX_TRANSFER"] = key.vertex_transfer
        out.update(surface_layering.layering_defines(key.layering, key.parameter == "roughness"
                                                     and "roughness" in key.textures))
        return out

    def samplers(self, key):
        samplers = [("FLOAT_2D_ARRAY", "sh_table"), ("FLOAT_2D", "sh_environment")]
        if key.fitted_lobes:           # texelFetch: the UV's nearest texel, as SG_FITTED reads it
            samplers += [("FLOAT_2D_ARRAY", "fitted_layers"), ("FLOAT_2D", "fitted_shadowing")]
        if key.vertex_transfer:
            samplers.append(("FLOAT_2D", "sh_vertex_transfer"))
        elif key.transfer_layers:
            samplers += [("FLOAT_2D", "transfer_coefficients"), ("FLOAT_2D", "sh_transfer_radiance")]
            if key.has_lights:
                samplers.append(("FLOAT_2D_ARRAY", "transfer_basis"))
        samplers += material_textures.samplers(key)
        return samplers + ([surface_layering.SAMPLER] if key.layering else [])

    def per_vertex_inputs(self, key):
        if key.vertex_transfer:
            return (shader_sources.PerVertexInput("sh_vertex_transfer", key.vertex_transfer, "transfer_varying",
                                                  "transfer_rows"),)
        if not key.transfer_layers:
            return ()
        return (shader_sources.PerVertexInput("transfer_coefficients", key.transfer_layers, "transfer_varying",
                                              "transfer_rows"),)

    def create_info_calls(self, key):
        files = [name for name in LIBRARY_FILES if name != "lights.glsl" or key.has_lights]
        sources = [shader_sources.library_source(name) for name in files]
        sources += material_textures.sources(key)
        if key.layering:
            sources.append(surface_layering.source())
        if key.fitted_lobes:
            sources.append(shader_sources.technique_source("common", "fitted_texels.glsl"))
        sources.append(sh_glsl.constants_source(key.order, key.window))
        fetched = self.per_vertex_inputs(key)
        if fetched:
            sources.append(f"vec4 transfer_rows[{fetched[0].rows}];\n"
                           + shader_sources.per_vertex_copy_source(fetched))
        sources += [shader_sources.technique_source(GLSL_DIR, name)
                    for name in ("sh_library.glsl", "sh_shading.glsl", "surface.frag.glsl")]
        return shader_sources.surface_calls(self.defines(key), "\n".join(sources), self.samplers(key), key.gbuffer,
                                            fetched, push_constants=(("VEC4", "sh_axis"),),
                                            node_values=key.node_values,
                                            node_constants=len(material_textures.constant_rows(key)))

    def bind_reads_object(self, key):
        # the transfer bake's rows and radiance table (the mesh's); the environment's row is the scene's
        return key.transfer_layers > 0

    def bind(self, shader, key, context):
        environment = context.inputs.environment
        shader.uniform_block("scene", context.scene_buffer)
        shader.uniform_block("material", context.material_buffer)
        if key.fitted_lobes:           # built once a fit and order (seconds for 64 x 64 texels), then the GPU's copy
            fitted = context.params.fitted
            shader.uniform_sampler("sh_table", context.material_table(
                f"sh_fitted_table_{key.order}",
                lambda: fitted_table.texture_layers(fitted_table_for(fitted, key.order, context.cached_arrays))))
            shader.uniform_sampler("fitted_layers", context.material_table("fitted_layers", lambda: fitted.layers))
            shader.uniform_sampler("fitted_shadowing", context.material_table("fitted_shadowing", lambda: fitted.table))
        else:
            table = table_for(context.params, key.order, context.cached_arrays)    # about 1 s to build
            if key.isotropic:          # an anisotropic map has no parameter axis: the constant is compiled out
                shader.uniform_float("sh_axis", axis_constants(table))
            shader.uniform_sampler("sh_table", context.material_table(f"sh_table_{key.order}",
                                                                      lambda: brdf_table.texture_layers(table)))

        def environment_row():
            coefficients = environment_coefficients(environment)
            row = np.zeros((1, len(coefficients), 4), np.float32)
            row[0, :, :3] = coefficients
            return row

        shader.uniform_sampler("sh_environment", context.environment_table("sh_environment", environment_row))
        if key.vertex_transfer:          # remade when the bake or the lighting changes, not a frame
            buffers = context.per_vertex(TRANSFER_KIND)
            data = buffers.data
            shader.uniform_sampler("sh_vertex_transfer", context.object_table(
                f"sh_vertex_transfer_{key.order}_{key.window}_{key.vertex_transfer}", (data, environment),
                lambda: per_vertex.texture_of(vertex_transfer_values(data, environment, key.order, key.window,
                                                                     key.vertex_transfer), key.vertex_transfer,
                                              buffers.vertices_per_row)))
        elif key.transfer_layers:
            buffers = context.per_vertex(TRANSFER_KIND)
            data = buffers.data
            shader.uniform_sampler("transfer_coefficients", buffers.rows_texture)
            if key.has_lights:
                shader.uniform_sampler("transfer_basis", buffers.basis_texture)
            shader.uniform_sampler("sh_transfer_radiance", context.object_table(
                f"sh_transfer_radiance_{key.order}_{key.window}", (data, environment),
                lambda: transfer_radiance_texture(data, environment, key.order, key.window)))
        material_textures.bind(shader, key, context)
        if key.layering:
            surface_layering.bind(shader, context)


TECHNIQUE = SphericalHarmonics()
