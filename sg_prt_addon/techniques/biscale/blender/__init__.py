"""The bi-scale technique's Blender side (blender/technique_sides.py): a material's small-scale geometry
(material.sgprt.biscale) and its panel, the tile's tables (biscale_source), and what renders a material whose tile
or small-scale BRDF cannot."""
import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty

from .... import techniques
from ....blender.panels import MaterialPanel
from ....blender.properties import _tag_changed
from ... import surface_layering
from ...sg import blender as sg_side
from ...sg import sg_fitted
from .. import biscale_shading, sg_biscale
from . import biscale_source


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


SETTINGS = {"sg": sg_side.SGPRT_PG_sg, "biscale": SGPRT_PG_biscale}
LEGACY = sg_side.LEGACY
CLASSES = (SGPRT_PT_material_biscale,)


def draw(layout, material, name):
    sg_side.draw(layout, material, name)


def read(material, params):
    sg_side.read(material, params)


def resolve(material, params, name):
    return _resolve_biscale(material, params)


def _resolve_biscale(material, params):
    """The bi-scale technique with the material's tile (params.biscale) and small-scale BRDF (its model, or its
    stored lobe fit in params.fitted), or a single-scale technique with the reason."""
    settings = material.sgprt.biscale
    label = sg_biscale.TECHNIQUE.label
    warnings = []
    if settings.small_scale == "LOBE_FIT":
        params.fitted, reason = sg_side.isotropic_lobe_fit(material)
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
        params.textures[biscale_shading.MASK_SLOT] = settings.mask.name
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


def lobe_fit_use(material, name):
    if material.sgprt.biscale.small_scale == "LOBE_FIT":
        return "The small-scale BRDF of the bi-scale material"
    return None


def take_lobe_fit(material, name):
    material.sgprt.biscale.small_scale = "LOBE_FIT"      # a bi-scale material's fit is its small-scale BRDF
    return True
