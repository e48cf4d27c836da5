"""Materials: material.sgprt (or its node tree) read into MaterialParams, with the technique that renders it
(its Blender side resolves it: blender/technique_sides.py); a stored lobe fit as FittedLobes."""
from dataclasses import dataclass, field

import numpy as np

from ... import techniques
from ...reflectance import layering, models, principled
from .. import technique_sides
from .messages import finite_texels, warn

SCALAR_PARAMETERS = models.SCALAR_PARAMETERS
COLOUR_PARAMETERS = ("diffuse_color", "specular_color")
TEXTURED_PARAMETERS = COLOUR_PARAMETERS + SCALAR_PARAMETERS


@dataclass
class MaterialParams:
    """material.sgprt as plain values; textures as (name, (H, W, 4) float32 array, row 0 at the bottom)."""
    name: str = ""
    model: str = "GGX"
    diffuse_color: tuple = (0.5, 0.5, 0.5)
    specular_color: tuple = (0.25, 0.25, 0.25)
    roughness: float = 0.3
    ior: float = 1.5
    exponent: float = 100.0
    alpha_x: float = 0.2
    alpha_y: float = 0.05
    nu: float = 100.0
    nv: float = 1000.0
    lobe_count: int = 0             # an anisotropic model's NDF lobes; 0: its default (models.lobes_of)
    warp_mode: str = "split3"      # spherical.warp mode (its DEFAULT_MODE) of the view slice (material.sgprt.sg.view_warp)
    sh_order: int = 5              # the SH technique's order and window (material.sgprt.sh: harmonics.projection's
                                   # names, or "none")
    sh_window: str = "none"
    # the glossy layer (reflectance.layering): Schlick Fresnel on the specular colour, Multiscatter GGX's gain,
    # the F0 of a dielectric layer over the diffuse (below 0: none); emitted radiance (Combined only)
    fresnel: str = "NONE"
    multiscatter: bool = False
    layered_f0: float = -1.0
    emission: tuple = (0.0, 0.0, 0.0)
    # the surface's coverage (a node tree's transparency: reflectance/coverage.py) and the holdout's share of
    # the drawn surface (its alpha is 1 - holdout)
    alpha: float = 1.0
    holdout: float = 0.0
    source: str = "SETTINGS"       # what the look was read from: material.sgprt.source (NODE_TREE, SETTINGS)
    # texture coordinates from the UV map: u' = a u + b v + c, v' = d u + e v + f (a node tree's Mapping node)
    uv_transform: tuple = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    decoded_slots: tuple = ()      # data slots whose sRGB images are decoded to linear (node trees: as Blender)
    normal_strength: float = 1.0
    tangent_source: str = "UV_MAP"
    tangent_axis: tuple = (1.0, 0.0, 0.0)
    tangent_rotation: float = 0.0
    # parameter name or "normal_map" -> image name, or (node trees) a reflectance.texture_expression.Expression of
    # images, computed per pixel (techniques/material_textures.py)
    textures: dict = field(default_factory=dict)
    technique: str = techniques.DEFAULT    # the registered technique that renders it (techniques/)
    fitted: object = None          # FittedLobes with the fitted-lobes technique and a VALID stored fit
    factorization: object = None   # the factored technique's FactoredTables of its VALID stored factors
    biscale: object = None         # biscale.bvndf.BVNDF of the material's small-scale tile (bi-scale technique)
    # datablocks the look is computed from besides its texture images, ("IMAGE" | "OBJECT" | "MESH", name): the
    # scene state exports the material again when one changes (a bi-scale tile's height image or mesh)
    reads: tuple = ()
    # a technique's own settings without a field above, name -> hashable value (its Blender side's read() sets them)
    options: dict = field(default_factory=dict)

    def values_key(self):
        """Everything but textures, hashable: the material UBO is rebuilt when this changes."""
        def hashable(name, value):
            if name == "options":
                return tuple(sorted(value.items()))
            return value.signature if name in ("fitted", "factorization", "biscale") and value is not None else value

        return tuple((k, hashable(k, v)) for k, v in self.__dict__.items() if k != "textures")


@dataclass(eq=False)
class FittedLobes:
    """A material's stored lobe fit (blender.lobe_fit, format 1) as the engine uploads it.

    layers (L, H, W, 4) float32, Blender row order (row 0 at the bottom, texture t = 0): 0 base
    (kd RGB, eta), 1 + 2k lobe k (axis xyz, sharpness), 2 + 2k lobe k amplitude RGB, then the
    shadowing PCA coefficient layers (4 a layer); table (C + 2, S, 4): row 0 theta_s, row 1 the
    mean, rows 2.. the basis (value in R).  signature: hashable identity of the fit."""
    lobe_count: int
    components: int
    layers: np.ndarray
    table: np.ndarray
    signature: tuple = ()

    @property
    def shadowing_layers(self):
        return -(-self.components // 4)


def export_fitted_lobes(material):
    """FittedLobes of a material's VALID stored fit, else None."""
    from .. import lobe_fit

    if getattr(material, "sgprt", None) is None or lobe_fit.fit_status(material)[0] != "VALID":
        return None
    fit = material.sgprt.lobe_fit
    arrays = lobe_fit.lobe_fit_images(material)
    count, components = int(fit.lobe_count), int(fit.shadowing_components)
    roles = ["base"] + [f"lobe_{k}_{part}" for k in range(count) for part in ("axis", "amplitude")]
    roles += [f"shadowing_{j}" for j in range(-(-components // 4))]
    layers = np.stack([arrays[role][::-1] for role in roles]).astype(np.float32)
    signature = (fit.date, fit.source_path, fit.seconds, count, components, fit.width, fit.height,
                 tuple(item.image.name for item in fit.images if item.image is not None))
    return FittedLobes(count, components, np.ascontiguousarray(layers),
                       np.ascontiguousarray(arrays["shadowing_table"], np.float32), signature)


# --------------------------------------------------------------------------- materials

def default_surface():
    """What Blender renders where an object or a slot has no material: Cycles' default surface, a Diffuse BSDF
    of 0.8 grey."""
    return MaterialParams(diffuse_color=(0.8, 0.8, 0.8), specular_color=(0.0, 0.0, 0.0), layered_f0=layering.NO_LAYER)


def export_material(material):
    """MaterialParams of a bpy Material (None: Blender's default surface; without `sgprt`: the defaults): its
    SG-PRT settings, or its node tree's reading when its Source is the node tree."""
    from .. import properties

    if material is None:
        return default_surface()
    params = MaterialParams()
    params.name = material.name
    settings = getattr(material, "sgprt", None)
    if settings is None:
        return params
    params.model = settings.model
    params.diffuse_color = tuple(settings.diffuse_color)
    params.specular_color = tuple(settings.specular_color)
    for name in SCALAR_PARAMETERS:
        setattr(params, name, float(getattr(settings, name)))
    params.lobe_count = int(settings.lobe_count)
    technique_sides.read(material, params)
    params.normal_strength = float(settings.normal_strength)
    params.tangent_source = settings.tangent_source
    params.tangent_axis = tuple(settings.tangent_axis)
    params.tangent_rotation = float(settings.tangent_rotation)
    params.fresnel = settings.fresnel
    params.multiscatter = bool(settings.multiscatter)
    params.layered_f0 = principled.dielectric_f0(settings.ior) if settings.layered_diffuse else layering.NO_LAYER
    params.emission = tuple(float(c) * float(settings.emission_strength) for c in settings.emission_color)
    for name in TEXTURED_PARAMETERS:
        image = getattr(settings, name + "_texture", None)
        if image is not None:
            params.textures[name] = image.name
    if settings.normal_map is not None:
        params.textures["normal_map"] = settings.normal_map.name
    if properties.resolved_source(settings) == "NODE_TREE":
        _read_node_tree(material, params)
    params.technique, warnings = technique_sides.resolve(material, params)
    for message in warnings:
        warn(message)
    _finite_settings(params)
    return params


# What a node tree's reading replaces of the SG-PRT settings: the look (the technique's own controls, the
# lobe count and the view warp stay the material's)
NODE_TREE_FIELDS = COLOUR_PARAMETERS + SCALAR_PARAMETERS + (
    "model", "fresnel", "multiscatter", "layered_f0", "emission", "alpha", "holdout", "normal_strength",
    "tangent_source", "tangent_axis", "tangent_rotation", "uv_transform")


def _read_node_tree(material, params):
    """The node tree's reading (blender/node_reader.py) in place of the appearance settings (what it does not
    set takes the defaults, not the settings it replaces); its notes in one warning."""
    from .. import node_reader

    reading = node_reader.read_material(material)
    params.source = "NODE_TREE"
    defaults = MaterialParams()
    for name in NODE_TREE_FIELDS:
        setattr(params, name, getattr(defaults, name))
    for name, value in reading.fields.items():
        setattr(params, name, value)
    params.textures = dict(reading.textures)
    params.decoded_slots = reading.decoded_slots
    if reading.notes:
        warn(f"material '{material.name}' (node tree): " + "; ".join(reading.notes))


def _finite_settings(params):
    """Non-finite scalar or colour settings (scripts can store them) -> the defaults, warned."""
    defaults = MaterialParams()
    for name in COLOUR_PARAMETERS + SCALAR_PARAMETERS + ("normal_strength", "tangent_rotation", "tangent_axis",
                                                         "layered_f0", "emission", "alpha", "holdout"):
        value = getattr(params, name)
        if not np.all(np.isfinite(value)):
            setattr(params, name, getattr(defaults, name))
            warn(f"material '{params.name}': {name} {value} not finite, the default {getattr(defaults, name)} used")
    if params.fitted is not None:
        params.fitted.layers = finite_texels(params.fitted.layers, f"material '{params.name}': stored lobe fit")
        params.fitted.table = finite_texels(params.fitted.table, f"material '{params.name}': stored lobe fit table")
