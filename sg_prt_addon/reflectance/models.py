"""The BRDF models a material can pick, in one table: the enum of material.sgprt.model, the parameters
the panel shows and the export and the mirror read, and which models are anisotropic (several SG lobes
from the anisotropy table, a tangent frame).  brdf.py holds their exact forms (brdf.model_from_name), the
GLSL their lobes (MODEL_<name>, shaders/lib/brdf.glsl and techniques/sg/anisotropic_lobes.glsl)."""
from dataclasses import dataclass


@dataclass(frozen=True)
class Model:
    name: str               # the identifier: material.sgprt.model, MODEL_<name> in the shader
    label: str
    description: str
    parameters: tuple       # the material fields it reads besides the colours, in panel order
    anisotropic: bool = False
    default_lobes: int = 1  # NDF lobes where the material's Lobes is 0 (Auto): an anisotropic model's (lobes_of)

    @property
    def panel_parameters(self):
        """What the material panel shows: the parameters, and the lobe count of an anisotropic fit."""
        return self.parameters + (("lobe_count",) if self.anisotropic else ())


MODELS = (
    Model("GGX", "GGX", "Microfacet GGX matching Blender's Glossy BSDF (alpha = roughness^2, height-correlated "
                        "Smith shadowing, no Fresnel)", ("roughness",)),
    Model("COOK_TORRANCE", "Cook-Torrance", "Cook-Torrance with the Gaussian NDF of wang2009 eq. 10-12 and "
                                            "dielectric Fresnel", ("roughness", "ior")),
    Model("BLINN_PHONG", "Blinn-Phong", "Blinn-Phong specular lobe", ("exponent",)),
    Model("WARD_ISO", "Ward Isotropic", "Isotropic Ward", ("alpha_x",)),
    # Lobes by default (Auto): the anisotropy table's models 4, anisotropic GGX's own table 6.  Against Cycles (the
    # truth suite's tori, docs/ACCURACY.md): anisotropic GGX (alpha 0.17 x 0.048) relative RMSE 0.132 / 0.107 /
    # 0.105 at 4 / 6 / 8 lobes for 1 / 1.21 / 1.46x the render() time, 6 the knee; Ashikhmin-Shirley (nu 50, nv 800)
    # 0.0502 at 4 and 0.0500 at 6, which cost 1.32x the frame (Ward, the same table, is not scored against Cycles)
    Model("WARD_ANISO", "Ward Anisotropic", "Anisotropic Ward, fitted with several SG lobes", ("alpha_x", "alpha_y"),
          anisotropic=True, default_lobes=4),
    Model("ASHIKHMIN_SHIRLEY", "Ashikhmin-Shirley", "Anisotropic Ashikhmin-Shirley, fitted with several SG lobes",
          ("nu", "nv"), anisotropic=True, default_lobes=4),
    # appended: a .blend stores the enum by position
    Model("GGX_ANISO", "GGX Anisotropic", "Anisotropic GGX as Blender's Principled BSDF with Anisotropic > 0 "
                                          "(alpha x along the tangent, alpha y across it), fitted with several SG "
                                          "lobes", ("alpha_x", "alpha_y"), anisotropic=True, default_lobes=6),
    Model("BECKMANN", "Beckmann", "Microfacet Beckmann matching Blender's Glossy BSDF of that distribution "
                                  "(alpha = roughness^2, height-correlated Smith shadowing, no Fresnel)", ("roughness",)),
)
BY_NAME = {model.name: model for model in MODELS}
NAMES = tuple(BY_NAME)
ANISOTROPIC = tuple(model.name for model in MODELS if model.anisotropic)
# Every parameter some model reads (the material's scalar fields)
SCALAR_PARAMETERS = ("roughness", "ior", "exponent", "alpha_x", "alpha_y", "nu", "nv")


def lobes_of(model, lobe_count):
    """NDF lobes of a material of `model` (a name) whose Lobes is `lobe_count`: one for an isotropic model; for an
    anisotropic one its Lobes, or where that is 0 (Auto) the model's default_lobes."""
    entry = BY_NAME.get(model)
    if entry is None or not entry.anisotropic:
        return 1
    return int(lobe_count) if int(lobe_count) >= 1 else entry.default_lobes


def enum_items():
    """(identifier, label, description) of every model, for the material's EnumProperty."""
    return [(model.name, model.label, model.description) for model in MODELS]
