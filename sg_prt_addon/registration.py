"""Register and unregister everything the add-on adds to Blender, in dependency order."""
import bpy

from .blender import lobe_fit, node_copy, panels, properties, technique_sides, transfer_bake, visibility_bake
from .engine.render_engine import SGPRT_RenderEngine

ENGINE_CLASSES = (SGPRT_RenderEngine,)
_registered_engine_classes = []


def register():
    properties.register()
    panels.register()
    visibility_bake.register()
    transfer_bake.register()
    lobe_fit.register()           # after panels: its panel's parent is SGPRT_PT_material
    technique_sides.register(properties.SGPRT_PG_material)     # the techniques' settings, operators and panels
    node_copy.register()
    for cls in ENGINE_CLASSES:
        bpy.utils.register_class(cls)
        _registered_engine_classes.append(cls)


def unregister():
    while _registered_engine_classes:
        bpy.utils.unregister_class(_registered_engine_classes.pop())
    node_copy.unregister()
    technique_sides.unregister()
    lobe_fit.unregister()
    transfer_bake.unregister()
    visibility_bake.unregister()
    panels.unregister()
    properties.unregister()
