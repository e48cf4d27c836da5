"""wang2009 with an analytic BRDF model: the NDF as SG lobes from the model's parameters (property x
texture per pixel), GGX's two-lobe table and albedo tail, the anisotropic models' lobe tables."""
import numpy as np

from ...reflectance import ggx_albedo, models, ndf_fit
from ...spherical import warp
from .. import material_textures, surface_layering
from . import sg_shading
from .sg_lobes import TEXTURE_SLOTS, SGLobes, VariantKey, scene_fields, warp_mode_of

NAME = "SG_PARAMETRIC"
# Material textures that only the specular term reads (left out of a variant without it)
SPECULAR_ONLY_TEXTURES = ("specular_color", "roughness", "ior", "exponent", "alpha_x", "alpha_y", "nu", "nv")


def material_terms(material_params, glossy_layer=True):
    """(has_diffuse, has_specular) of an export.MaterialParams: False when that colour is zero and no
    texture scales it, so the term (colour x irradiance / pi, colour x radiance) is exactly zero and the
    variant leaves its code out.  With the glossy layer's Schlick Fresnel (glossy_layer: the technique applies
    it) a zero specular colour is the F0 of a rim that still reflects at grazing views (Cycles' metals of a black
    base colour), so the specular term stays."""
    def present(colour, slot):      # NaN counts as present: the full variant shows it
        return slot in material_params.textures or any(not float(c) == 0.0 for c in tuple(colour)[:3])

    fresnel = glossy_layer and getattr(material_params, "fresnel", "NONE") == "SCHLICK"
    return (present(material_params.diffuse_color, "diffuse_color"),
            present(material_params.specular_color, "specular_color") or fresnel)


def uses_ggx_table(key):
    return key.model == "GGX" and key.ndf_lobes == 2 and key.has_specular


def uses_ggx_anisotropy_table(key):
    """Anisotropic GGX of two lobes or more: its own table over ratio and alpha (ndf_fit.ggx_anisotropy_table);
    one lobe reads Ward's."""
    return key.model == "GGX_ANISO" and key.ndf_lobes >= 2


def anisotropy_table_weighting(key):
    """The error the variant's anisotropy table was fitted to (ndf_fit.PLANE_L2 or LIGHT_WEIGHTED)."""
    return ndf_fit.LIGHT_WEIGHTED if uses_ggx_anisotropy_table(key) else ndf_fit.PLANE_L2


def anisotropy_table_texture(key):
    """The (rows, K, 4) float32 texture of the variant's anisotropy table: texel (k, row)."""
    build = ndf_fit.ggx_anisotropy_table_array if uses_ggx_anisotropy_table(key) else ndf_fit.anisotropy_table_array
    return build(key.ndf_lobes, anisotropy_table_weighting(key))


def uses_albedo_table(key):
    """The environment tail and energy cap from GGX's albedo: GGX's two lobes, and anisotropic GGX's lobes at
    its equivalent roughness (reflectance.layering.equivalent_roughness)."""
    return uses_ggx_table(key) or (key.model == "GGX_ANISO" and key.has_specular)


def ggx_table():
    """ndf_fit's two-lobe GGX table as an (A, 2, 4) float32 texture: texel (k, row) =
    (log alpha, sharpness * alpha^2, amplitude / D(n), 0)."""
    alphas, table = ndf_fit.ggx_two_lobe_table()
    out = np.zeros((len(alphas), 2, 4), np.float32)
    out[..., 0] = np.log(alphas)[:, None]
    out[..., 1:3] = table
    return out


def ggx_albedo_texture():
    """reflectance.ggx_albedo's table in every channel of a float texture."""
    return np.repeat(ggx_albedo.albedo_table()[..., None], 4, axis=-1)


class SGParametric(SGLobes):
    name = NAME
    label = "SG Lobes (Wang 2009)"
    description = ("The material's BRDF model as spherical Gaussian lobes, warped to the view; all-frequency "
                   "light and SSDF shadows (Wang et al. 2009)")
    number = 0

    def variant_key(self, params, inputs):
        model = params.model
        lobes = models.lobes_of(model, params.lobe_count)
        if model == "GGX":
            lobes = sg_shading.GGX_NDF_LOBES
        has_diffuse, has_specular = material_terms(params)
        textures = tuple(sorted(name for name in params.textures if name in TEXTURE_SLOTS
                                and (has_specular or name not in SPECULAR_ONLY_TEXTURES)))
        return VariantKey(self.name, model, lobes, textures=textures,
                          node_values=material_textures.node_values(params, textures, inputs), has_diffuse=has_diffuse,
                          has_specular=has_specular, warp_mode=warp_mode_of(params) if has_specular else
                          warp.DEFAULT_MODE, layering=surface_layering.flags(params),
                          **scene_fields(inputs, has_diffuse, has_specular))

    def model_defines(self, key):
        defines = {}
        if uses_ggx_anisotropy_table(key):
            log_alphas = np.log(ndf_fit.GGX_ANISOTROPY_ALPHAS)
            defines.update({"GGX_ANISOTROPY_ALPHAS": len(log_alphas),
                            "GGX_ANISOTROPY_LOG_ALPHA_MIN": repr(float(log_alphas[0])),
                            "GGX_ANISOTROPY_LOG_ALPHA_MAX": repr(float(log_alphas[-1]))})
        if uses_albedo_table(key):
            # GGX's energy beyond its two lobes, from its albedo table (reflectance.ggx_albedo)
            defines.update({"ENVIRONMENT_TAIL": 1, "GGX_ALBEDO_SIZE": ggx_albedo.TABLE_SIZE,
                            "TAIL_SHARPNESS_RATIO": f"{sg_shading.TAIL_SHARPNESS_RATIO!r}"})
        return defines

    def model_files(self, key):
        files = ("anisotropic_lobes.glsl",) if key.model in models.ANISOTROPIC else ()
        if uses_ggx_table(key):
            files += ("ggx_two_lobes.glsl",)
        return files

    def model_samplers(self, key):
        samplers = [("FLOAT_2D", "anisotropy_table")] if key.model in models.ANISOTROPIC else []
        if uses_ggx_table(key):
            samplers.append(("FLOAT_2D", "ggx_table"))
        if uses_albedo_table(key):
            samplers.append(("FLOAT_2D", "ggx_albedo_table"))     # ENVIRONMENT_TAIL
        return samplers

    def bind_model(self, shader, key, context):
        if key.model in models.ANISOTROPIC:
            name = ("ggx_anisotropy" if uses_ggx_anisotropy_table(key) else "anisotropy", key.ndf_lobes,
                    anisotropy_table_weighting(key))
            shader.uniform_sampler("anisotropy_table", context.table(name, lambda: anisotropy_table_texture(key)))
        if uses_ggx_table(key):
            shader.uniform_sampler("ggx_table", context.table("ggx_two_lobes", ggx_table))
        if uses_albedo_table(key):
            shader.uniform_sampler("ggx_albedo_table", context.table("ggx_albedo", ggx_albedo_texture))


TECHNIQUE = SGParametric()
