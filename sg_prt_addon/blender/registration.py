"""Register and unregister everything the add-on adds to Blender, in dependency order."""
import bpy

from . import lobe_fit, panels, properties, visibility_bake


def _engine_classes():
    try:
        from ..engine import classes
    except ImportError as error:  # a broken install must say what is missing, not register half an add-on
        raise RuntimeError(f"SG-PRT: the render engine package failed to import: {error}") from error
    return classes


_registered_engine_classes = []


def register():
    engine_classes = _engine_classes()
    properties.register()
    panels.register()
    visibility_bake.register()
    lobe_fit.register()           # after panels: its panel's parent is SGPRT_PT_material
    for cls in engine_classes:
        bpy.utils.register_class(cls)
        _registered_engine_classes.append(cls)


def unregister():
    while _registered_engine_classes:
        bpy.utils.unregister_class(_registered_engine_classes.pop())
    lobe_fit.unregister()
    visibility_bake.unregister()
    panels.unregister()
    properties.unregister()
