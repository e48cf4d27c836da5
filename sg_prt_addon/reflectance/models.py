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
    Model("WARD_ANISO", "Ward Anisotropic", "Anisotropic Ward, fitted with several SG lobes", ("alpha_x", "alpha_y"),
          anisotropic=True),
    Model("ASHIKHMIN_SHIRLEY", "Ashikhmin-Shirley", "Anisotropic Ashikhmin-Shirley, fitted with several SG lobes",
          ("nu", "nv"), anisotropic=True),
    # appended: a .blend stores the enum by position
    Model("GGX_ANISO", "GGX Anisotropic", "Anisotropic GGX as Blender's Principled BSDF with Anisotropic > 0 "
                                          "(alpha x along the tangent, alpha y across it), fitted with several SG "
                                          "lobes", ("alpha_x", "alpha_y"), anisotropic=True),
)
BY_NAME = {model.name: model for model in MODELS}
NAMES = tuple(BY_NAME)
ANISOTROPIC = tuple(model.name for model in MODELS if model.anisotropic)
# Every parameter some model reads (the material's scalar fields)
SCALAR_PARAMETERS = ("roughness", "ior", "exponent", "alpha_x", "alpha_y", "nu", "nv")


def enum_items():
    """(identifier, label, description) of every model, for the material's EnumProperty."""
    return [(model.name, model.label, model.description) for model in MODELS]
