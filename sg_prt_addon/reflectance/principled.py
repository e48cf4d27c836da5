"""Blender's shader nodes in the engine's terms: the Principled, Diffuse and Glossy BSDFs mapped to a model,
colours and reflectance.layering's settings (pure: plain numbers in, a dict of export.MaterialParams fields
out; blender/node_reader.py reads the nodes).

What Cycles does (intern/cycles/kernel/svm/closure.h, read for Blender 4.2-5.x): alpha = roughness^2; the
Principled BSDF with Anisotropic a > 0: aspect = sqrt(1 - 0.9 a), alpha_x = alpha / aspect along the tangent,
alpha_y = alpha aspect, the tangent turned by Anisotropic Rotation x 2 pi; the Glossy BSDF maps its Anisotropy
its own way (glossy_anisotropic_alphas: a > 0 widens the lobe across the tangent, a < 0 along it); the metal
(weight Metallic) has Schlick-like Fresnel from F0 = the base colour (F82 tint, white tint: Schlick); what
remains is a dielectric of F0 = ((ior - 1)/(ior + 1))^2 x 2 Specular IOR Level, tinted by Specular Tint, over
the diffuse base (weighted by 1 - Transmission), which loses the dielectric's directional albedo.  Both glossy
lobes share one GGX, so their Fresnel terms add to one Schlick term with F0 = Metallic base + (1 - Metallic)
F0_dielectric tint (Schlick is linear in F0).
"""
import numpy as np

from .texture_expression import Expression

# Glossy BSDF distributions -> (model, multiscatter)
GLOSSY_DISTRIBUTIONS = {"GGX": ("GGX", False), "MULTI_GGX": ("GGX", True), "BECKMANN": ("BECKMANN", False),
                        "ASHIKHMIN_SHIRLEY": ("ASHIKHMIN_SHIRLEY", False), "SHARP": ("GGX", False)}
MIN_ROUGHNESS = 0.001       # material.sgprt.roughness's lower end: a mirror renders as the sharpest lobe


def dielectric_f0(ior, specular_ior_level=0.5):
    """F0 of Cycles' dielectric layer: ((ior - 1)/(ior + 1))^2 times 2 x Specular IOR Level, in [0, 1]."""
    ior = max(float(ior), 1e-5)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    return float(np.clip(f0 * 2.0 * max(float(specular_ior_level), 0.0), 0.0, 1.0))


def ior_of_f0(f0):
    """The IOR whose normal-incidence reflectance is f0 (the inverse of dielectric_f0 at level 0.5)."""
    root = np.sqrt(np.clip(float(f0), 0.0, 0.999999))
    return float((1.0 + root) / (1.0 - root))


def anisotropic_alphas(roughness, anisotropic):
    """(alpha_x, alpha_y) of Cycles' anisotropic GGX."""
    alpha = float(np.clip(roughness, 0.0, 1.0)) ** 2
    aspect = np.sqrt(1.0 - 0.9 * float(np.clip(anisotropic, 0.0, 1.0)))
    return alpha / aspect, alpha * aspect


def glossy_anisotropic_alphas(roughness, anisotropy):
    """(alpha_x, alpha_y) of Cycles' Glossy BSDF (and the Anisotropic BSDF before it): Anisotropy clamped to
    [-0.99, 0.99]; a >= 0: alpha_x = alpha (1 - a), alpha_y = alpha / (1 - a) (highlights stretched across the
    tangent, as Blender's manual says); a < 0: alpha_x = alpha / (1 + a), alpha_y = alpha (1 + a); isotropic at
    |a| <= 1e-4, as Cycles makes it."""
    alpha = float(np.clip(roughness, 0.0, 1.0)) ** 2
    anisotropy = float(np.clip(anisotropy, -0.99, 0.99))
    if abs(anisotropy) <= 1e-4:
        return alpha, alpha
    if anisotropy < 0.0:
        return alpha / (1.0 + anisotropy), alpha * (1.0 + anisotropy)
    return alpha * (1.0 - anisotropy), alpha / (1.0 - anisotropy)


def _plain(value):
    """A constant Expression as its number (scalar: the red channel) or colour; anything else as it is."""
    if not isinstance(value, Expression) or value.as_constant() is None:
        return value
    constant = value.as_constant()
    return constant[0] if len(set(constant)) == 1 else constant


def _rgb(value):
    """(3,) float64 of a colour given as 3 or 4 components or one number."""
    values = np.asarray(value, np.float64)
    return np.broadcast_to(values[:3] if values.ndim else values, (3,))


def _colour(value):
    """A colour field: an RGB tuple, or the Expression of a textured one."""
    return value if isinstance(value, Expression) else tuple(float(c) for c in _rgb(value))


def _ashikhmin_shirley_exponent(alpha):
    """Cycles' Ashikhmin-Shirley exponent of an alpha: 2 / alpha^2 - 2."""
    alpha = max(float(alpha), 1e-3)
    return float(np.clip(2.0 / (alpha * alpha) - 2.0, 1.0, 1e5))


def _roughness_fields(roughness, distribution_model, anisotropic_alphas_of=None):
    """The model and its width fields for a roughness; anisotropic_alphas_of(roughness): the node's (alpha_x,
    alpha_y) along the tangent and the bitangent, unequal where it is anisotropic (anisotropic GGX, Ward for
    Beckmann, Ashikhmin-Shirley's two exponents).  A textured roughness (an Expression) is GGX's own: the
    caller gives the others a number."""
    if isinstance(roughness, Expression):
        return {"model": "GGX", "roughness": roughness}
    roughness = float(np.clip(roughness, 0.0, 1.0))
    alphas = None if anisotropic_alphas_of is None else anisotropic_alphas_of(roughness)
    if alphas is not None and alphas[0] != alphas[1]:
        alpha_x, alpha_y = (float(np.clip(alpha, MIN_ROUGHNESS, 1.0)) for alpha in alphas)
        if distribution_model == "ASHIKHMIN_SHIRLEY":
            return {"model": "ASHIKHMIN_SHIRLEY", "nu": _ashikhmin_shirley_exponent(alpha_x),
                    "nv": _ashikhmin_shirley_exponent(alpha_y)}
        if distribution_model == "BECKMANN":      # Ward's NDF is Beckmann's but for a cosine
            return {"model": "WARD_ANISO", "alpha_x": alpha_x, "alpha_y": alpha_y}
        return {"model": "GGX_ANISO", "alpha_x": alpha_x, "alpha_y": alpha_y}
    if distribution_model == "BECKMANN":
        return {"model": "BECKMANN", "roughness": max(roughness, MIN_ROUGHNESS)}
    if distribution_model == "ASHIKHMIN_SHIRLEY":
        exponent = _ashikhmin_shirley_exponent(roughness ** 2)
        return {"model": "ASHIKHMIN_SHIRLEY", "nu": exponent, "nv": exponent}
    return {"model": "GGX", "roughness": max(roughness, MIN_ROUGHNESS)}


def principled(base_color=(0.8, 0.8, 0.8), metallic=0.0, roughness=0.5, ior=1.5, specular_ior_level=0.5,
               specular_tint=(1.0, 1.0, 1.0), anisotropic=0.0, anisotropic_rotation=0.0, transmission=0.0,
               emission_color=(1.0, 1.0, 1.0), emission_strength=0.0, multiscatter=True):
    """MaterialParams fields of a Principled BSDF with these input values (colours linear RGB).  Base Color,
    Metallic, Roughness, Emission Color and Emission Strength may be texture_expression.Expressions (textured):
    the colours then come out as Expressions of the same formulas."""
    base_color, metallic, roughness = (_plain(value) for value in (base_color, metallic, roughness))
    textured_metallic = isinstance(metallic, Expression)
    if isinstance(base_color, Expression):
        base = clamped = base_color
    else:
        base = np.clip(_rgb(base_color), 0.0, None)
        clamped = np.minimum(base, 1.0)
    if not textured_metallic:
        metallic = float(np.clip(metallic, 0.0, 1.0))
    transmission = float(np.clip(transmission, 0.0, 1.0))
    tint = np.clip(_rgb(specular_tint), 0.0, None)
    f0 = dielectric_f0(ior, specular_ior_level)
    specular = metallic * clamped + (1.0 - metallic) * (f0 * tint)
    out = {"diffuse_color": _colour(base * (1.0 - metallic) * (1.0 - transmission)),
           "specular_color": _colour(specular),
           "fresnel": "SCHLICK", "multiscatter": bool(multiscatter),
           "layered_f0": float(f0 * float(np.max(tint))) if textured_metallic or metallic < 1.0 else -1.0,
           "ior": ior_of_f0(f0) if f0 > 0 else 1.0,
           "tangent_rotation": float(anisotropic_rotation) * 2.0 * np.pi,
           "emission": _colour(_plain(Expression.of(_colour(emission_color)) * _plain(emission_strength)))}
    out.update(_roughness_fields(roughness, "GGX", lambda width: anisotropic_alphas(width, float(anisotropic))))
    return out


def glossy(color=(0.8, 0.8, 0.8), roughness=0.5, distribution="GGX", anisotropy=0.0, rotation=0.0):
    """MaterialParams fields of a Glossy BSDF: the colour at every angle (no Fresnel), Multiscatter GGX's gain."""
    model, multiscatter = GLOSSY_DISTRIBUTIONS.get(distribution, ("GGX", False))
    color, roughness = _plain(color), _plain(roughness)
    if distribution == "SHARP":
        roughness = 0.0
    out = {"specular_color": _colour(color),
           "fresnel": "NONE",
           "multiscatter": multiscatter, "tangent_rotation": float(rotation) * 2.0 * np.pi}
    out.update(_roughness_fields(roughness, model, lambda width: glossy_anisotropic_alphas(width, float(anisotropy))))
    return out
