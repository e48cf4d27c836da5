"""kautz2002 as a technique: any BRDF under low-frequency light, the BRDF times the cosine projected into SH
per local view (harmonics/brdf_table.py), the lighting as SH, shading as their dot product (eq. 1), the
rotation between frames per pixel on the GPU (shaders/techniques/sh/; techniques/sh_shading.py is the
mirror).

What it reads: the material's model and parameters; an isotropic model's table has its spatially varying
parameter (roughness, exponent, alpha) as an axis, so that parameter's texture applies, as in the paper's
Fig. 4; an anisotropic model's parameters are uniform over the material (their textures are warned and
not applied).  Lighting: the environment's equirect map projected once per map (SH_ENVIRONMENT_ORDER
bands, truncated to the material's order), or the world colour; point and spot lights as uniform caps,
suns as their SG (both zonal about their direction).  The material's order (2-8) and window (none,
Hanning, Lanczos: ringing against blur, docs/ACCURACY.md) pick the variant.
"""
import collections
import math
from dataclasses import dataclass

import numpy as np

from ..harmonics import brdf_table, projection
from ..reflectance import models
from . import sh_glsl, sh_shading, shader_sources
from .base import Technique

NAME = "SH"
GLSL_DIR = "sh"
ORDERS = tuple(range(2, 9))
DEFAULT_ORDER = 5
WINDOWS = ("none",) + projection.WINDOWS
SH_ENVIRONMENT_ORDER = max(ORDERS)
COLOUR_SLOTS = ("diffuse_color", "specular_color", "normal_map")
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
    has_lights: bool = False
    gbuffer: bool = False

    def describe(self):
        parts = [f"order {self.order}", f"window {self.window}",
                 f"{self.parameter} axis" if self.isotropic else "anisotropic map",
                 "lights" if self.has_lights else "no lights"]
        if self.textures:
            parts.append("textures: " + ", ".join(self.textures))
        if self.gbuffer:
            parts.append("G-buffer")
        return ", ".join(parts)


def window_name(params):
    """The material's window as harmonics.projection names it (None: no window)."""
    window = getattr(params, "sh_window", "none")
    return None if window == "none" else window


def texture_slots(params):
    """The texture slots the technique applies for a material: the colours, the normal map, and the table
    axis parameter's texture."""
    axis = brdf_table.PARAMETER_AXES.get(params.model)
    return COLOUR_SLOTS + ((axis[0],) if axis else ())


def table_for(params):
    """The BrdfTable of a material (export.MaterialParams): its model at its order and fixed parameters."""
    model = models.BY_NAME[params.model]
    values = {name: float(getattr(params, name)) for name in model.parameters}
    return brdf_table.table_for(params.model, order=int(params.sh_order), **values)


def axis_constants(table):
    """sh_axis of the shader (sh_shading.glsl): the parameter axis' scale, low end, log flag, node count."""
    if table.layout != "theta":
        return [0.0, 1.0, 0.0, 1.0]
    _, spacing, low, high = brdf_table.PARAMETER_AXES[table.model]
    scale = 1.0 / math.log(high / low) if spacing == "log" else 1.0 / (high - low)
    return [scale, low, 1.0 if spacing == "log" else 0.0, float(len(table.parameter_nodes))]


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
    paper = "kautz2002"

    mirror = staticmethod(sh_shading.shade_fragments)

    def variant_key(self, params, inputs):
        axis = brdf_table.PARAMETER_AXES.get(params.model)
        slots = texture_slots(params)
        textures = tuple(sorted(name for name in params.textures if name in slots))
        order = int(np.clip(int(getattr(params, "sh_order", DEFAULT_ORDER)), min(ORDERS), max(ORDERS)))
        return SHKey(order=order, window=getattr(params, "sh_window", "none"), isotropic=axis is not None,
                     parameter=axis[0] if axis else None, textures=textures, has_lights=inputs.has_lights,
                     gbuffer=inputs.gbuffer)

    def defines(self, key):
        out = {"SH_PARAMETER": PARAMETER_FIELDS[key.parameter] if key.isotropic else "0.0"}
        if key.isotropic:
            out["SH_ISOTROPIC"] = 1
            if key.parameter in key.textures:
                out["SH_PARAMETER_TEXTURE"] = "texture_" + key.parameter
        if key.has_lights:
            out["HAS_LIGHTS"] = 1
        for name in key.textures:
            if name in COLOUR_SLOTS:
                out["HAS_NORMAL_MAP" if name == "normal_map" else "HAS_TEXTURE_" + name.upper()] = 1
        if key.gbuffer:
            out["GBUFFER"] = 1
        return out

    def samplers(self, key):
        return ([("FLOAT_2D_ARRAY", "sh_table"), ("FLOAT_2D", "sh_environment")]
                + [("FLOAT_2D", "texture_" + name) for name in key.textures])

    def create_info_calls(self, key):
        files = [name for name in LIBRARY_FILES if name != "lights.glsl" or key.has_lights]
        sources = [shader_sources.library_source(name) for name in files]
        sources += [shader_sources.technique_source("common", "surface_common.glsl"),
                    sh_glsl.constants_source(key.order, None if key.window == "none" else key.window)]
        sources += [shader_sources.technique_source(GLSL_DIR, name)
                    for name in ("sh_library.glsl", "sh_shading.glsl", "surface.frag.glsl")]
        return shader_sources.surface_calls(self.defines(key), "\n".join(sources), self.samplers(key), key.gbuffer,
                                            push_constants=(("VEC4", "sh_axis"),))

    def bind(self, shader, key, context):
        table = table_for(context.params)
        environment = context.inputs.environment
        shader.uniform_block("scene", context.scene_buffer)
        shader.uniform_block("material", context.material_buffer)
        if key.isotropic:              # an anisotropic map has no parameter axis: the constant is compiled out
            shader.uniform_float("sh_axis", axis_constants(table))
        shader.uniform_sampler("sh_table", context.material_table(f"sh_table_{key.order}",
                                                                  lambda: brdf_table.texture_layers(table)))

        def environment_row():
            coefficients = environment_coefficients(environment)
            row = np.zeros((1, len(coefficients), 4), np.float32)
            row[0, :, :3] = coefficients
            return row

        shader.uniform_sampler("sh_environment", context.table(f"sh_environment_{id(environment)}", environment_row))
        for name in key.textures:
            shader.uniform_sampler("texture_" + name, context.image(name))


TECHNIQUE = SphericalHarmonics()
