"""The SG techniques' Blender side (blender/technique_sides.py): the view warp every SG technique reads
(material.sgprt.sg), a bi-scale material's small-scale geometry (material.sgprt.biscale) and its panel, and what
renders a material that picks the fitted lobes or the bi-scale technique without the data they read."""
import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty

from .... import techniques
from ....biscale import effective_brdf
from ....blender import export, lobe_fit
from ....blender.panels import MaterialPanel
from ....blender.properties import _tag_changed
from ... import surface_layering
from .. import biscale_shading, sg_biscale, sg_fitted, sg_parametric, sg_shading
from . import biscale_source

# How each NDF lobe is warped to the view slice: spherical.warp's modes, upper case (figures from its docstring).
VIEW_WARPS = (
    ("SPLIT3", "3 Lobes", "Three warped lobes per NDF lobe (default): the most accurate at grazing views "
                          "(mean energy error 0.09 at 75 degrees)"),
    ("SPLIT2", "2 Lobes", "Two warped lobes per NDF lobe: about a fifth faster on anisotropic metals, "
                          "energy error 0.15 at 75 degrees"),
    ("PAPER", "1 Lobe", "The paper's single warped lobe: fastest, loses energy at grazing views "
                        "(0.08 at 75 degrees, 0.2 at 85)"),
)


class SGPRT_PG_sg(bpy.types.PropertyGroup):
    """What every SG technique reads (material.sgprt.sg)."""
    view_warp: EnumProperty(update=_tag_changed, name="View Warp", items=VIEW_WARPS, default="SPLIT3",
                            description="Lobes each NDF lobe becomes in the view slice (wang2009 eq. 17-22 and its "
                                        "split): fewer render faster, more are more accurate at grazing views")


def _is_mesh(self, obj):
    return obj.type == "MESH"


class SGPRT_PG_biscale(bpy.types.PropertyGroup):
    """A bi-scale material's small-scale geometry (technique SG_BISCALE; blender/biscale_source.py): a tileable
    height field or a mesh tile, seen under the material's own model."""
    source: EnumProperty(update=_tag_changed, name="Geometry", default="IMAGE",
                         items=(("IMAGE", "Height Field", "A tileable height image (its mean of RGB) over one tile"),
                                ("OBJECT", "Mesh Tile", "A mesh object's faces, one period of the surface across "
                                                        "its X and Y extent, facing +Z")),
                         description="What the surface is made of at the small scale")
    height_image: PointerProperty(update=_tag_changed, type=bpy.types.Image, name="Height",
                                  description="Tileable height field: heights are its values times Height Scale, "
                                              "in tile widths")
    height_scale: FloatProperty(update=_tag_changed, name="Height Scale", default=0.05, min=0.0,
                                soft_max=0.5, description="Height of an image value of 1, in tile widths")
    small_scale: EnumProperty(update=_tag_changed, name="Small-Scale BRDF", default="MODEL",
                              items=(("MODEL", "Material Model", "The material's own isotropic model, colours and "
                                                                 "textures"),
                                     ("LOBE_FIT", "Lobe Fit", "The material's stored lobe fit (Fit Lobes: a measured "
                                                              "BRDF, isotropic, Axes Auto)")),
                              description="What the small-scale geometry's surface reflects with")
    tile_object: PointerProperty(update=_tag_changed, type=bpy.types.Object, name="Tile", poll=_is_mesh,
                                 description="Mesh whose faces are one tile of the surface (object space)")
    mask: PointerProperty(update=_tag_changed, type=bpy.types.Image, name="Mask",
                          description="Where the second tile replaces the first: its red channel over the UV map "
                                      "(0: the first tile, 1: the second, between: both, blended)")
    second_height_image: PointerProperty(update=_tag_changed, type=bpy.types.Image, name="Second Height",
                                         description="The second tile's tileable height field, used where the "
                                                     "mask is 1")
    second_height_scale: FloatProperty(update=_tag_changed, name="Second Height Scale", default=0.05,
                                       min=0.0, soft_max=0.5,
                                       description="Height of an image value of 1 in the second tile, in tile widths")
    lobes: IntProperty(update=_tag_changed, name="Lobes", default=16, min=1, max=32,
                       description="SG lobes of the tile's normal distribution (more follow sharp small-scale "
                                   "BRDFs better; docs/ACCURACY.md, bi-scale)")
    resolution: IntProperty(update=_tag_changed, name="Directions", default=12, min=4, max=20,
                            description="Lattice of view and light directions per side (12: 144 each, the paper's)")
    samples: IntProperty(update=_tag_changed, name="Samples", default=4096, min=256, max=65536,
                         description="Points on the tile whose shadowing and masking are traced")


class SGPRT_PT_material_biscale(MaterialPanel, bpy.types.Panel):
    bl_label = "Small-Scale Geometry"
    bl_parent_id = "SGPRT_PT_material"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and techniques.of_settings(context.material.sgprt) == sg_biscale.NAME

    def draw(self, context):
        settings = context.material.sgprt.biscale
        layout = self.layout
        layout.use_property_split = True
        layout.prop(settings, "source")
        if settings.source == "IMAGE":
            layout.template_ID(settings, "height_image", open="image.open")
            layout.prop(settings, "height_scale")
        else:
            layout.prop(settings, "tile_object")
        layout.template_ID(settings, "mask", open="image.open")
        if settings.mask is not None:
            layout.template_ID(settings, "second_height_image", open="image.open")
            layout.prop(settings, "second_height_scale")
        for name in ("lobes", "resolution", "samples"):
            layout.prop(settings, name)
        status = biscale_source.last_status(context.material)
        if status:
            layout.label(text=status, icon="INFO")
        layout.prop(settings, "small_scale")
        if settings.small_scale == "LOBE_FIT":
            layout.label(text="The lobe fit below (Measured BRDF): isotropic, Axes Auto", icon="MATERIAL")
        else:
            layout.label(text="The model above (isotropic)", icon="MATERIAL")


SETTINGS = {"sg": SGPRT_PG_sg, "biscale": SGPRT_PG_biscale}
LEGACY = {"sg": {"view_warp": "view_warp"}}
CLASSES = (SGPRT_PT_material_biscale,)


def draw(layout, material, name):
    layout.prop(material.sgprt.sg, "view_warp")


def read(material, params):
    params.warp_mode = material.sgprt.sg.view_warp.lower()       # VIEW_WARPS: spherical.warp's mode names


def resolve(material, params, name):
    if name == sg_fitted.NAME:
        return _resolve_fitted(material, params)
    if name == sg_biscale.NAME:
        return _resolve_biscale(material, params)
    return name, []


def _resolve_fitted(material, params):
    params.fitted = export.export_fitted_lobes(material)
    if params.fitted is None:
        state, message = lobe_fit.fit_status(material)
        return sg_parametric.NAME, [f"material '{material.name}': no usable lobe fit ({message or state.lower()}): "
                                    "rendered with its model"]
    return sg_fitted.NAME, []


def _resolve_biscale(material, params):
    """The bi-scale technique with the material's tile (params.biscale) and small-scale BRDF (its model, or its
    stored lobe fit in params.fitted), or a single-scale technique with the reason."""
    settings = material.sgprt.biscale
    label = sg_biscale.TECHNIQUE.label
    warnings = []
    if settings.small_scale == "LOBE_FIT":
        params.fitted, reason = isotropic_lobe_fit(material)
        if params.fitted is None:
            return techniques.DEFAULT, [f"material '{material.name}': {label}: no usable small-scale lobe fit "
                                        f"({reason}): rendered as a single scale with its model"]
    elif params.model not in biscale_shading.SMALL_SCALE_MODELS:
        return techniques.DEFAULT, [f"material '{material.name}': {label} needs an isotropic small-scale model "
                                    f"({', '.join(biscale_shading.SMALL_SCALE_MODELS)}), not {params.model}: "
                                    "rendered as a single scale"]
    params.reads = biscale_source.reads(material)
    params.biscale, reason = biscale_source.tables(material)
    if params.biscale is None:
        fallback = techniques.DEFAULT if params.fitted is None else sg_fitted.NAME
        return fallback, [f"material '{material.name}': no usable small-scale geometry ({reason}): rendered as a "
                          f"single scale{' with its lobe fit' if params.fitted is not None else ''}"]
    if biscale_source.masked(settings):
        params.textures[sg_shading.BISCALE_MASK] = settings.mask.name
    elif settings.mask is not None:
        warnings.append(f"material '{material.name}': its bi-scale mask has no second height image: the mask is not "
                        "applied")
    layers = surface_layering.flags(params)
    if layers and params.fitted is None:
        warnings.append(f"material '{material.name}': {label} does not apply {', '.join(layers)}")
    ignored = sorted(slot for slot in params.textures if slot not in sg_biscale.texture_slots(params))
    if ignored:
        warnings.append(f"material '{material.name}': {label} does not apply the textures on {', '.join(ignored)}"
                        f"{' (the lobe fit holds the small-scale look)' if params.fitted is not None else ''}")
    return sg_biscale.NAME, warnings


def isotropic_lobe_fit(material):
    """(FittedLobes, None) of the material's stored fit when its lobes lie about the normal (a small-scale BRDF
    must be isotropic), else (None, the reason)."""
    fitted = export.export_fitted_lobes(material)
    if fitted is None:
        state, message = lobe_fit.fit_status(material)
        return None, message or state.lower()
    reason = lobe_tilt(fitted)
    if reason is not None:
        return None, reason + " for an isotropic small-scale BRDF"
    return fitted, None


def lobe_tilt(fitted):
    """Why a FittedLobes is not isotropic (its lobes leave the normal: a free-axes fit), or None."""
    tilt, degrees = effective_brdf.axis_tilt(fitted.layers[1:1 + 2 * fitted.lobe_count:2, ..., :3])
    if tilt > effective_brdf.AXIS_TOLERANCE:
        return f"its lobes leave the normal by up to {degrees:.1f} degrees: fit with Axes Auto"
    return None


def lobe_fit_use(material, name):
    if name == sg_fitted.NAME:
        return ""
    if name == sg_biscale.NAME and material.sgprt.biscale.small_scale == "LOBE_FIT":
        return "The small-scale BRDF of the bi-scale material"
    return None


def take_lobe_fit(material, name):
    if name == sg_biscale.NAME:
        material.sgprt.biscale.small_scale = "LOBE_FIT"      # a bi-scale material's fit is its small-scale BRDF
        return True
    return False
