"""wang2009 with lobes fitted to measured data (blender.lobe_fit, export.FittedLobes): per texel SG
lobes, kd and eta, and the PCA-compressed shadowing, fetched at the UV's nearest texel."""
from .. import material_textures
from ..base import SURFACE_TEXTURES
from .sg_lobes import SGLobes, VariantKey, scene_fields, warp_mode_of

NAME = "SG_FITTED"
MODEL = "FITTED"        # the variant's model: MODEL_FITTED in the GLSL, techniques.sg.sg_shading.FITTED_MODEL in the mirror


class SGFitted(SGLobes):
    name = NAME
    label = "Fitted SG Lobes (Wang 2009)"
    description = ("SG lobes fitted per texel to a measured BRDF or SVBRDF table (Fit Lobes); "
                   "all-frequency light and SSDF shadows (Wang et al. 2009)")
    number = 1
    renders_stored = "lobe_fit"

    def variant_key(self, params, inputs):
        """The stored fit's lobes, shadowing and base; of the material's textures only a normal map and the
        emission apply."""
        fitted = params.fitted
        if fitted is None:
            raise ValueError(f"material '{params.name}' has no usable lobe fit for {self.label}")
        textures = tuple(name for name in (*SURFACE_TEXTURES, "normal_map") if name in params.textures)
        return VariantKey(self.name, MODEL, int(fitted.lobe_count), textures=textures,
                          node_values=material_textures.node_values(params, textures, inputs),
                          shadowing_components=int(fitted.components), warp_mode=warp_mode_of(params),
                          **scene_fields(inputs))

    def model_defines(self, key):
        return {"FITTED_LOBES": key.ndf_lobes, "FITTED_COMPONENTS": key.shadowing_components,
                "FITTED_SHADOWING_LAYERS": -(-key.shadowing_components // 4)}

    def model_samplers(self, key):
        return [("FLOAT_2D_ARRAY", "fitted_layers"),     # texelFetch: the nearest texel
                ("FLOAT_2D", "fitted_shadowing")]

    def bind_model(self, shader, key, context):
        fitted = context.params.fitted
        shader.uniform_sampler("fitted_layers", context.material_table("fitted_layers", lambda: fitted.layers))
        shader.uniform_sampler("fitted_shadowing", context.material_table("fitted_shadowing", lambda: fitted.table))


TECHNIQUE = SGFitted()
