"""Material settings of the SG-PRT engine: `material.sgprt`.

Every model parameter can be driven by an image over the active UV map: the
shaded value is the property times the texture sample (RGB for colours, the
red channel for scalars), like a factor next to a texture in Blender's nodes.
"""
import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

from .. import techniques
from ..lighting import shadow_maps
from ..lighting.lights import AREA_PATCHES_PER_SIDE
from ..reflectance import models, ndf_fit
from . import technique_sides

FRESNEL_MODES = (("NONE", "None", "The specular colour at every angle (Blender's Glossy BSDF)"),
                 ("SCHLICK", "Schlick", "The specular colour at normal incidence, white at grazing angles "
                                        "(Blender's Principled BSDF: metals and dielectrics)"))
SOURCES = (("NODE_TREE", "Node Tree", "Render the material's shader nodes (Principled, Diffuse, Glossy, Emission, "
                                      "Mix and Add, image textures, normal maps; blender/node_reader.py)"),
           ("SETTINGS", "SG-PRT Settings", "Render the settings below, whatever the node tree holds"))
# What a material's look is made of in its SG-PRT settings: one of them set (or a stored fit or factors) means
# the settings were given, so a material without an explicit Source renders them (files older than Source)
APPEARANCE_PROPERTIES = ("model", "diffuse_color", "specular_color", "roughness", "ior", "exponent", "alpha_x",
                         "alpha_y", "nu", "nv", "lobe_count", "normal_strength", "fresnel",
                         "multiscatter", "layered_diffuse", "emission_color", "emission_strength")

# Parameters that may be driven by an image texture: `<name>_texture`.
TEXTURED_PARAMETERS = ("diffuse_color", "specular_color", "roughness", "ior", "exponent",
                       "alpha_x", "alpha_y", "nu", "nv")


# The registered techniques as enum items; Blender keeps no copy of the strings of a dynamic enum, so the
# list a callback returns must outlive the call
_technique_items = []


def technique_items(self, context):
    _technique_items[:] = techniques.enum_items()
    return _technique_items


def settings_given(settings):
    """Whether a material's SG-PRT appearance settings were ever set (an image, a stored lobe fit or factors
    count; image pointers are tested by value: reading one marks it set)."""
    images = tuple(name + "_texture" for name in TEXTURED_PARAMETERS) + ("normal_map",)
    return (any(settings.is_property_set(name) for name in APPEARANCE_PROPERTIES)
            or any(getattr(settings, name) is not None for name in images)
            or settings.lobe_fit.format_version > 0 or technique_sides.settings_given(settings.id_data))


def has_node_tree(material):
    """A material whose shader nodes Blender renders (Blender 5 always uses them; use_nodes before)."""
    import bpy

    tree = material.node_tree
    return tree is not None and (bpy.app.version >= (5, 0, 0) or material.use_nodes)


def resolved_source(settings):
    """NODE_TREE or SETTINGS: the choice stored, else the node tree for a material that has one and was never
    given SG-PRT settings."""
    stored = settings.get("source_choice")
    if stored is not None:
        return SOURCES[int(stored)][0] if 0 <= int(stored) < len(SOURCES) else "SETTINGS"
    material = settings.id_data
    return "NODE_TREE" if has_node_tree(material) and not settings_given(settings) else "SETTINGS"


def _get_source(self):
    return [item[0] for item in SOURCES].index(resolved_source(self))


def _set_source(self, value):
    self["source_choice"] = int(value)
    self.id_data.update_tag()


def _tag_changed(self, context):
    """Edits from Python do not tag the datablock (a material, a scene) for the depsgraph (the UI does): tag
    it, so view_update sees every change, whoever made it."""
    self.id_data.update_tag()


def _texture(name):
    return PointerProperty(
        type=bpy.types.Image, update=_tag_changed, name=f"{name.replace('_', ' ').title()} Texture",
        description=f"Image over the active UV map multiplying {name.replace('_', ' ')} "
                    "(RGB for colours, red channel for scalars)")


class SGPRT_PG_lobe_fit_image(bpy.types.PropertyGroup):
    """One packed FLOAT image of a fitted material (layout: blender/lobe_fit.py)."""
    role: StringProperty(name="Role", description="What the image holds: base, lobe_K_axis, lobe_K_amplitude, "
                                                  "shadowing_K, shadowing_table, error")
    image: PointerProperty(type=bpy.types.Image, name="Image")


class SGPRT_PG_lobe_fit(bpy.types.PropertyGroup):
    """A measured BRDF fitted to SG lobes by sgprt.fit_lobes: metadata and its images."""
    format_version: IntProperty(name="Format Version", default=0, description="0: no fit stored")
    source_file: StringProperty(name="Source File", description="File name the fit was made from")
    source_path: StringProperty(name="Source Path", description="Full path the fit was made from")
    source_kind: StringProperty(name="Source Kind", description="MERL or SVBRDF_TABLE")
    lobe_count: IntProperty(name="Lobes", default=0, min=0)
    free_axes: BoolProperty(name="Free Axes", default=False, description="Lobe axes fitted freely (else z+)")
    shadowing_components: IntProperty(name="Shadowing Components", default=0, min=0)
    shadowing_samples: IntProperty(name="Shadowing Samples", default=0, min=0)
    width: IntProperty(name="Width", default=0, min=0)
    height: IntProperty(name="Height", default=0, min=0)
    fit_error: FloatProperty(name="Fit Error", default=0.0, description="Mean relative RMSE of the fitted BRDF")
    fit_error_max: FloatProperty(name="Max Fit Error", default=0.0)
    ndf_error: FloatProperty(name="NDF Error", default=0.0, description="Mean relative L2 error of the SG fit of D")
    date: StringProperty(name="Date", description="When the fit was stored (ISO 8601 UTC)")
    seconds: FloatProperty(name="Seconds", default=0.0)
    images: CollectionProperty(type=SGPRT_PG_lobe_fit_image, name="Images")


class SGPRT_PG_material(bpy.types.PropertyGroup):
    source: EnumProperty(name="Source", items=SOURCES, get=_get_source, set=_set_source,
                         description="What the material's look is read from: its shader nodes, or the SG-PRT "
                                     "settings (default: the node tree, unless the material has SG-PRT settings)")
    # default 0: the number of techniques.DEFAULT; a file without the setting: techniques.of_settings
    technique: EnumProperty(update=_tag_changed, name="Technique", items=technique_items, default=0,
                            description="The rendering method of this material (techniques/: the reference each "
                                        "implements is in its description)")
    model: EnumProperty(update=_tag_changed, name="Model", items=models.enum_items(), default="GGX",
                        description="Specular reflectance model, rendered with spherical Gaussian NDF lobes")
    diffuse_color: FloatVectorProperty(update=_tag_changed, name="Diffuse", subtype="COLOR", size=3, default=(0.5, 0.5, 0.5),
                                       min=0.0, soft_max=1.0, description="Lambertian albedo kd")
    specular_color: FloatVectorProperty(update=_tag_changed, name="Specular", subtype="COLOR", size=3, default=(0.25, 0.25, 0.25),
                                        min=0.0, soft_max=1.0, description="Specular colour ks")
    roughness: FloatProperty(update=_tag_changed, name="Roughness", default=0.3, min=0.001, max=1.0,
                             description="Cook-Torrance m; for GGX Blender's roughness (alpha = roughness^2)")
    ior: FloatProperty(update=_tag_changed, name="IOR", default=1.5, min=1.0, max=4.0,
                       description="Relative index of refraction of the Cook-Torrance Fresnel term")
    exponent: FloatProperty(update=_tag_changed, name="Exponent", default=100.0, min=1.0, max=1e5,
                            description="Blinn-Phong specular exponent")
    alpha_x: FloatProperty(update=_tag_changed, name="Alpha X", default=0.2, min=0.001, max=1.0,
                           description="Ward roughness along the tangent (the isotropic model uses this only)")
    alpha_y: FloatProperty(update=_tag_changed, name="Alpha Y", default=0.05, min=0.001, max=1.0,
                           description="Ward roughness along the bitangent")
    nu: FloatProperty(update=_tag_changed, name="Nu", default=100.0, min=1.0, max=1e5,
                      description="Ashikhmin-Shirley exponent along the tangent")
    nv: FloatProperty(update=_tag_changed, name="Nv", default=1000.0, min=1.0, max=1e5,
                      description="Ashikhmin-Shirley exponent along the bitangent")
    lobe_count: IntProperty(update=_tag_changed, name="Lobes", default=0, min=0, max=ndf_fit.MAX_LOBES,
                            description="Spherical Gaussian lobes fitted to an anisotropic NDF; 0 (Auto): the "
                                        "model's own count, 6 for anisotropic GGX, 4 for Ward and Ashikhmin-Shirley")

    diffuse_color_texture: _texture("diffuse_color")
    specular_color_texture: _texture("specular_color")
    roughness_texture: _texture("roughness")
    ior_texture: _texture("ior")
    exponent_texture: _texture("exponent")
    alpha_x_texture: _texture("alpha_x")
    alpha_y_texture: _texture("alpha_y")
    nu_texture: _texture("nu")
    nv_texture: _texture("nv")

    fresnel: EnumProperty(update=_tag_changed, name="Fresnel", items=FRESNEL_MODES, default="NONE",
                          description="How the specular colour changes with angle (reflectance/layering.py)")
    multiscatter: BoolProperty(update=_tag_changed, name="Multiscatter", default=False,
                               description="Add the energy of light scattered between microfacets, as Blender's "
                                           "Multiscatter GGX does (brighter and more saturated rough metals)")
    layered_diffuse: BoolProperty(update=_tag_changed, name="Layered Diffuse", default=False,
                                  description="The diffuse lies under a dielectric coat of the IOR and loses what "
                                              "the coat reflects at each view (Blender's Principled BSDF)")
    emission_color: FloatVectorProperty(update=_tag_changed, name="Emission", subtype="COLOR", size=3,
                                        default=(1.0, 1.0, 1.0), min=0.0, soft_max=1.0,
                                        description="Colour of the light the surface emits")
    emission_strength: FloatProperty(update=_tag_changed, name="Emission Strength", default=0.0, min=0.0,
                                     soft_max=10.0, description="Emitted radiance, times the colour (it lights "
                                                                "nothing else)")
    normal_map: PointerProperty(update=_tag_changed, type=bpy.types.Image, name="Normal Map",
                                description="Tangent-space normal map (OpenGL convention, +Y up)")
    normal_strength: FloatProperty(update=_tag_changed, name="Strength", default=1.0, min=0.0, max=10.0,
                                   description="Blend from the mesh normal (0) to the mapped normal (1) and beyond")
    tangent_source: EnumProperty(update=_tag_changed, 
        name="Tangent", default="UV_MAP",
        items=(("UV_MAP", "UV Map", "Tangents from the active UV map"),
               ("OBJECT_AXIS", "Object Axis", "A fixed object-space direction projected onto the surface")),
        description="Where the anisotropy direction comes from")
    tangent_axis: FloatVectorProperty(update=_tag_changed, name="Axis", size=3, default=(1.0, 0.0, 0.0), subtype="XYZ",
                                      description="Object-space tangent direction when the source is Object Axis")
    tangent_rotation: FloatProperty(update=_tag_changed, name="Rotation", default=0.0, subtype="ANGLE",
                                    description="Rotation of the tangent about the normal")
    show_textures: BoolProperty(update=_tag_changed, name="Show Textures", default=True,
                                description="Show the texture slot next to each parameter")
    lobe_fit: PointerProperty(type=SGPRT_PG_lobe_fit, name="Lobe Fit",
                              description="SG lobes fitted to a measured BRDF (sgprt.fit_lobes)")


# Render Samples' defaults, from the truth suite's scenes and the example scenes (docs/ACCURACY.md and
# PERFORMANCE.md "Edges Only"): 16 samples at the edges leave 0.3-13% of one sample's error against 16 samples of
# every pixel, a threshold of 0.2 sampling 3-24% of the pixels, for 1.7-3.7x a one-sample render
DEFAULT_RENDER_SAMPLES = 16
DEFAULT_EDGE_THRESHOLD = 0.2


class SGPRT_PG_scene(bpy.types.PropertyGroup):
    """Render settings of the SG-PRT engine: `scene.sgprt`."""
    render_samples: IntProperty(name="Render Samples", default=DEFAULT_RENDER_SAMPLES, min=1, max=64,
                                soft_max=16,
                                description="Samples a pixel of final renders, reconstructed with the Pixel "
                                            "Filter (16 = a 4x4 grid). The viewport draws one")
    pixel_filter_type: EnumProperty(
        name="Pixel Filter", default="BLACKMAN_HARRIS",
        items=[("BOX", "Box", "Every sample within half the Filter Size of the pixel's centre weighs the same", 0),
               ("GAUSSIAN", "Gaussian", "Samples weighted by a Gaussian of standard deviation a quarter of the "
                                        "Filter Size", 1),
               ("BLACKMAN_HARRIS", "Blackman-Harris", "Samples weighted by a Blackman-Harris window reaching "
                                                      "the Filter Size from the pixel's centre (Cycles' default)",
                2)],
        description="The filter final renders reconstruct pixels with, as Cycles' of the same name, over the "
                    "Film's Filter Size (engine/pixel_filter.py)")
    sample_edges_only: BoolProperty(name="Edges Only", default=True,
                                    description="Take the Render Samples only at the pixels where a first frame, "
                                                "shaded at the pixels' centres, differs from a neighbour by more "
                                                "than Edge Threshold (silhouettes, shadow, texture and highlight "
                                                "edges), on the smallest square grid of at least that many; "
                                                "elsewhere that frame.  Off: every pixel, each sample a whole "
                                                "frame")
    edge_threshold: FloatProperty(name="Edge Threshold", default=DEFAULT_EDGE_THRESHOLD, min=0.0,
                                  max=1.0, precision=3,
                                  description="Edges Only: the relative difference between neighbouring pixels "
                                              "that marks an edge (of the brighter one's colour; of alpha). Lower "
                                              "samples more pixels; 0 every pixel that differs at all")
    specular_anti_aliasing: BoolProperty(name="Specular Anti-Aliasing", default=True, update=_tag_changed,
                                         description="Where the surface's normal turns by more than twice "
                                                     "the highlight's width within a pixel, shade that pixel at up to "
                                                     "4 x 4 points of its area instead of its centre: highlights "
                                                     "narrower than a pixel neither flicker nor vanish, at the "
                                                     "cost of shading those pixels again (SG techniques)")
    light_shadows: EnumProperty(
        name="Light Shadows", default="SHADOW_MAPS", update=_tag_changed,
        items=[("SHADOW_MAPS", "Shadow Maps",
                "Point, spot and sun lights cast their shadows from a depth map drawn each frame: sharp edges, "
                "penumbrae from the light's radius or angle (percentage-closer soft shadows), objects without a "
                "visibility bake shadowed too.  Area lights keep the baked visibility", 0),
               ("SSDF", "Baked Visibility",
                "Every light's shadow from the visibility bake (wang2009's SSDF): smooth, its edges wider than "
                "the light's; objects without a bake are unshadowed", 1)],
        description="How lights (not the world) are shadowed")
    shadow_map_size: IntProperty(name="Shadow Map Size", default=shadow_maps.DEFAULT_SIZE, min=64, max=8192,
                                 soft_max=4096, update=_tag_changed,
                                 description="Texels a side of each shadow map (a point or spot light draws six, "
                                             "a sun one); fewer when the lights' maps would pass 256 MB")
    area_light_patches: IntProperty(name="Area Light Patches", default=AREA_PATCHES_PER_SIDE, min=1, max=8,
                                    update=_tag_changed,
                                    description="An area light is cut into about this many patches a side, each "
                                                "a small light with its own shadow: more are exact closer to the "
                                                "light and cost a light each (16 at 4)")


classes = (SGPRT_PG_lobe_fit_image, SGPRT_PG_lobe_fit, SGPRT_PG_material, SGPRT_PG_scene)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Material.sgprt = PointerProperty(type=SGPRT_PG_material, name="SG-PRT",
                                               description="SG-PRT material settings")
    bpy.types.Scene.sgprt = PointerProperty(type=SGPRT_PG_scene, name="SG-PRT", description="SG-PRT render settings")


def unregister():
    del bpy.types.Scene.sgprt
    del bpy.types.Material.sgprt
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
