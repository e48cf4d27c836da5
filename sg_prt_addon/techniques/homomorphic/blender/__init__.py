"""The factored technique's Blender side (blender/technique_sides.py): its stored factors
(material.sgprt.factorization, factorization.py: the Factor BRDF operator and its panel) and what it renders
without them."""
from .. import factored
from . import factorization

SETTINGS = {"factorization": factorization.SGPRT_PG_factorization}
CLASSES = factorization.classes


def resolve(material, params, name):
    warnings = []
    params.factorization = factorization.stored_tables(material)
    state, message = factorization.factorization_status(material)
    if state == "INVALID":
        warnings.append(f"material '{material.name}': stored BRDF factors unusable ({message}): its model is "
                        "factorized")
    ignored = sorted(slot for slot in params.textures if slot not in factored.TEXTURE_SLOTS)
    if ignored:
        warnings.append(f"material '{material.name}': {factored.TECHNIQUE.label} factorizes the model with uniform "
                        f"parameters: the textures on {', '.join(ignored)} are not applied")
    return name, warnings


def settings_given(material):
    return material.sgprt.factorization.format_version > 0
