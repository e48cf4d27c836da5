"""iwasaki2012's bi-scale materials rendered by wang2009's SG shading: the effective BRDF of a small-scale tile
(its BVNDF's lobes and tables, biscale.bvndf, from export.MaterialParams.biscale) with the material's own
isotropic model as the small-scale BRDF, or its stored lobe fit (MaterialParams.fitted: a measured small-scale
BRDF, iwasaki2012 fig. 8) (shaders/techniques/biscale/biscale.glsl; mirror biscale_shading.py)."""
from .. import material_textures
from ..base import SURFACE_TEXTURES
from ..sg import sg_fitted, sg_parametric
from ..sg.sg_lobes import SGLobes, VariantKey, scene_fields, warp_mode_of
from ..sg.sg_parametric import material_terms
from . import biscale_shading

NAME = "SG_BISCALE"
# the small-scale parameters a texture may scale per pixel, and the colours and normal map
TEXTURES = ("diffuse_color", "specular_color", "roughness", "ior", "exponent", "alpha_x", "normal_map",
            *SURFACE_TEXTURES, biscale_shading.MASK_SLOT)
FITTED_TEXTURES = ("normal_map", *SURFACE_TEXTURES, biscale_shading.MASK_SLOT)   # a fit holds its colours and lobes


def texture_slots(params):
    return FITTED_TEXTURES if getattr(params, "fitted", None) is not None else TEXTURES


class SGBiScale(SGLobes):
    name = NAME
    label = "Bi-Scale SG Lobes (Iwasaki 2012)"
    description = ("The effective BRDF of a small-scale height field or mesh tile under the material's model, as "
                   "SG lobes: all-frequency light and SSDF shadows (Iwasaki et al. 2012, Wang et al. 2009)")
    number = 4
    paper = "iwasaki2012"
    mirror = staticmethod(biscale_shading.shade_fragments)

    def variant_key(self, params, inputs):
        tables = getattr(params, "biscale", None)
        if tables is None:
            raise ValueError(f"material '{params.name}' has no small-scale geometry for {self.label}")
        fitted = getattr(params, "fitted", None)
        if fitted is None and params.model not in biscale_shading.SMALL_SCALE_MODELS:
            raise ValueError(f"material '{params.name}': a bi-scale material's model must be isotropic "
                             f"({', '.join(biscale_shading.SMALL_SCALE_MODELS)}), not {params.model}")
        if fitted is None:
            model, components = params.model, 0
            has_diffuse, has_specular = material_terms(params, glossy_layer=False)
        else:           # the fit's colours are in its layers (sg_fitted's key: both terms)
            model, components = sg_fitted.MODEL, int(fitted.components)
            has_diffuse, has_specular = True, True
        textures = tuple(sorted(name for name in params.textures if name in texture_slots(params)))
        small = biscale_shading.small_lobe_count(params.model, fitted)
        return VariantKey(self.name, model, int(tables.lobe_count) * small, textures=textures,
                          node_values=material_textures.node_values(params, textures, inputs),
                          has_diffuse=has_diffuse, has_specular=has_specular, warp_mode=warp_mode_of(params),
                          shadowing_components=components, biscale_resolution=int(tables.resolution),
                          biscale_first_lobes=int(tables.first_lobes), biscale_small_lobes=small,
                          **scene_fields(inputs, has_diffuse, has_specular))

    @staticmethod
    def _fitted(key):
        return key.model == sg_fitted.MODEL

    def model_defines(self, key):
        # the key's lobe count is the effective lobes': the BVNDF's times the small-scale BRDF's
        small = key.biscale_small_lobes
        defines = {"BISCALE": 1, "BISCALE_RESOLUTION": key.biscale_resolution, "BISCALE_SMALL_LOBES": small,
                   "BISCALE_FIRST_LOBES": key.biscale_first_lobes,
                   "BISCALE_LOBE_LAYERS": biscale_shading.lobe_layers(key.ndf_lobes // small)}
        if self._fitted(key):       # the fit's own lobes are the small-scale ones, not the effective lobes
            defines |= sg_fitted.TECHNIQUE.model_defines(key) | {"FITTED_LOBES": small}
        return defines

    def library_files(self, key):
        """The hemisphere map (the tables' lattice) besides what the SG shading takes."""
        files = super().library_files(key)
        return files if "hemisphere_map.glsl" in files else files + ["hemisphere_map.glsl"]

    @staticmethod
    def _reads_ggx_table(key):
        """GGX's two small-scale lobes come from its table, read with the specular term only."""
        return key.model == "GGX" and key.has_specular

    def lobe_source(self, key):
        """biscale.glsl: the effective lobes, their M and the tile's diffuse factor."""
        return ("biscale", "biscale.glsl")

    def technique_files(self, key):
        """GGX's two-lobe table reader (the small-scale lobes) besides what the SG shading takes."""
        own = [("sg", "ggx_two_lobes.glsl")] if self._reads_ggx_table(key) else []
        return own + [entry for entry in super().technique_files(key) if entry not in own]

    def model_samplers(self, key):
        samplers = [("FLOAT_2D", "biscale_lobes"), ("FLOAT_2D_ARRAY", "biscale_tables")]
        if self._fitted(key):
            samplers += sg_fitted.TECHNIQUE.model_samplers(key)
        return samplers + ([("FLOAT_2D", "ggx_table")] if self._reads_ggx_table(key) else [])

    def bind_model(self, shader, key, context):
        tables = context.params.biscale
        shader.uniform_sampler("biscale_lobes", context.material_table(
            ("biscale_lobes", tables.signature), lambda: biscale_shading.lobe_texture(tables)))
        shader.uniform_sampler("biscale_tables", context.material_table(
            ("biscale_tables", tables.signature), lambda: biscale_shading.table_texture(tables)))
        if self._fitted(key):
            sg_fitted.TECHNIQUE.bind_model(shader, key, context)
        if self._reads_ggx_table(key):
            shader.uniform_sampler("ggx_table", context.table("ggx_two_lobes", sg_parametric.ggx_table))


TECHNIQUE = SGBiScale()
