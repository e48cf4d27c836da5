"""Copy from Node Tree: the node tree's reading (blender/node_reader.py) written into the material's SG-PRT
settings, which then render (Source: SG-PRT Settings), for users who tune the SG-specific controls."""
import bpy

from ..reflectance import principled
from . import node_reader, properties

# MaterialParams fields that are settings of the same name
COPIED_FIELDS = ("model", "diffuse_color", "specular_color", "roughness", "alpha_x", "alpha_y", "nu", "nv",
                 "fresnel", "multiscatter", "normal_strength", "tangent_rotation")


def copy_reading(material):
    """Write the reading into material.sgprt; returns the reading's notes (with the slots whose texture the
    settings cannot hold: one the nodes compute from several images, or an affine function or channel of one
    (the settings hold one image a slot), and the emission's (the settings have no emission texture))."""
    reading = node_reader.read_material(material)
    held = properties.TEXTURED_PARAMETERS + ("normal_map",)
    dropped = sorted(slot for slot, value in reading.textures.items() if not isinstance(value, str) or slot not in held)
    if dropped:
        reading.notes.append(f"textures not copied (the factor alone): {', '.join(dropped)}")
    settings = material.sgprt
    for name in COPIED_FIELDS:
        if name in reading.fields:
            setattr(settings, name, reading.fields[name])
    layered_f0 = reading.fields.get("layered_f0", -1.0)
    settings.layered_diffuse = layered_f0 >= 0
    if layered_f0 > 0:
        settings.ior = principled.ior_of_f0(layered_f0)
    emission = reading.fields.get("emission", (0.0, 0.0, 0.0))
    strength = max(emission)
    settings.emission_strength = strength
    if strength > 0:
        settings.emission_color = tuple(c / strength for c in emission)
    for slot in properties.TEXTURED_PARAMETERS:
        image_name = reading.textures.get(slot)
        image = bpy.data.images.get(image_name) if isinstance(image_name, str) else None
        setattr(settings, slot + "_texture", image)
    image_name = reading.textures.get("normal_map")
    settings.normal_map = bpy.data.images.get(image_name) if image_name else None
    settings.source = "SETTINGS"
    return reading.notes


class SGPRT_OT_copy_from_node_tree(bpy.types.Operator):
    bl_idname = "sgprt.copy_from_node_tree"
    bl_label = "Copy from Node Tree"
    bl_description = ("Fill the SG-PRT settings from the material's shader nodes and render them from now on "
                      "(Source: SG-PRT Settings)")
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        material = getattr(context, "material", None)
        return material is not None and material.node_tree is not None

    def execute(self, context):
        material = context.material
        notes = copy_reading(material)
        message = f"'{material.name}': SG-PRT settings copied from its node tree"
        if notes:
            message += f" ({len(notes)} node(s) read otherwise: see the render's warnings)"
        self.report({"INFO"}, message)
        return {"FINISHED"}


classes = (SGPRT_OT_copy_from_node_tree,)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
