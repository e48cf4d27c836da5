"""What the surface techniques share of reflectance.layering: the variant flags of a material, the shader's
defines, its table and binding, the material block's layer roughness, and the numpy mirror of
shaders/techniques/common/surface_layering.glsl.  A technique adds the key's `layering` flags to its variant
key, layering_defines to its defines, SAMPLER to its samplers (with layering), calls bind, and its main()
calls surface_layering() after the shading normal; its mirror calls sg_shading.surface_layers at the same
point."""
import numpy as np

from ..reflectance import layering, models
from . import shader_sources

SAMPLER = ("FLOAT_2D", "layering_table")
FILE = "surface_layering.glsl"


def flags(params):
    """The layering a material asks for, as a sorted tuple of "diffuse", "fresnel", "multiscatter" (() none)."""
    out = []
    if getattr(params, "layered_f0", layering.NO_LAYER) >= 0:
        out.append("diffuse")
    if getattr(params, "fresnel", "NONE") == "SCHLICK":
        out.append("fresnel")
    if getattr(params, "multiscatter", False):
        out.append("multiscatter")
    return tuple(out)


def layer_roughness(params):
    """The GGX roughness the layer's tables are read at (MaterialData options.z): the model's equivalent (0
    without layering, or for a material rendered by its stored fit, model FITTED)."""
    model = models.BY_NAME.get(params.model)
    if model is None or not flags(params):
        return 0.0
    return layering.equivalent_roughness(params.model, {name: getattr(params, name) for name in model.parameters})


def textured_roughness(model, textures):
    """Whether the roughness texture also scales the layer's roughness: where the technique applies it to a
    model with a roughness (GGX, Cook-Torrance)."""
    entry = models.BY_NAME.get(model)            # None: a stored fit (model FITTED)
    return entry is not None and "roughness" in entry.parameters and "roughness" in textures


def layering_defines(layering_flags, roughness_textured):
    if not layering_flags:
        return {}
    out = {"LAYERING": 1, "LAYERING_TABLE_SIZE": layering.TABLE_SIZE,
           "LAYERING_SCHLICK_AVERAGE": shader_sources.float_literal(layering.SCHLICK_AVERAGE_WEIGHT)}
    if "fresnel" in layering_flags:
        out["LAYERING_FRESNEL"] = 1
    if "multiscatter" in layering_flags:
        out["LAYERING_MULTISCATTER"] = 1
    if roughness_textured:
        out["LAYERING_TEXTURED_ROUGHNESS"] = 1
    return out


def source():
    return shader_sources.technique_source("common", FILE)


def table_texture():
    return np.ascontiguousarray(layering.layering_table(), np.float32)


def bind(shader, context):
    shader.uniform_sampler("layering_table", context.table("layering", table_texture))

