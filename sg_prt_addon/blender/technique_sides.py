"""The techniques' Blender sides: each technique's settings, panel rows, stored data and fallbacks, found through
the registry (techniques.base.Technique.blender_side), so that nothing here or elsewhere in blender/ names a
technique.

A side is a module of the technique's package (``techniques/<package>/blender``) with, all optional:

- ``SETTINGS``: {attribute: PropertyGroup class}, registered at ``material.sgprt.<attribute>`` while one of the
  techniques naming the side is registered (techniques sharing a side share its groups);
- ``LEGACY``: {attribute: {property: name}}: values files kept flat on ``material.sgprt`` under the old name,
  moved into the group when a file is loaded;
- ``CLASSES``: operators and panels of its own (a panel's parent: ``SGPRT_PT_material``);
- ``draw(layout, material, name)``: its rows in the material panel, under the technique's choice;
- ``read(material, params)``: its settings into the export.MaterialParams (every side's, whatever the choice:
  a fallback technique reads its own);
- ``resolve(material, params, name) -> (technique name, warnings)``: what renders the material when it picks
  the technique `name`: that technique with the stored data it reads put in params, or another one (the
  default, a technique of the same side) with the reasons;
- ``settings_given(material)``: the material holds data of the side's (stored factors): its SG-PRT settings were
  given (properties.settings_given);
- ``lobe_fit_use(material, name)``: a line for the Lobe Fit panel saying how the technique uses the material's
  stored lobe fit ("" to say nothing), or None when it renders the model instead;
- ``take_lobe_fit(material, name)``: after a fit is stored, make the technique read it (False: it cannot, and
  the technique that renders fits is picked).
"""
import importlib
import sys

import bpy

from .. import techniques

_groups = {}        # attribute -> [PropertyGroup class, names of the registered techniques using it]
_classes = {}       # class -> names of the registered techniques using it
_owner = None       # the PropertyGroup class the groups hang from (properties.SGPRT_PG_material)


def side_of(technique):
    """The module of a technique's Blender side, or None."""
    if not technique.blender_side:
        return None
    package = sys.modules[type(technique).__module__].__package__      # a package's __init__: the package
    return importlib.import_module(technique.blender_side, package)


def _sides():
    """The Blender sides of the registered techniques, each once, in registration order."""
    found = []
    for technique in techniques.registered():
        side = side_of(technique)
        if side is not None and side not in found:
            found.append(side)
    return found


def _side_of_name(name):
    return side_of(techniques.get(name)) if name in techniques.names() else None


def _attach(technique):
    side = side_of(technique)
    if side is None:
        return
    for attribute, group in getattr(side, "SETTINGS", {}).items():
        entry = _groups.setdefault(attribute, [group, set()])
        if not entry[1]:
            bpy.utils.register_class(group)
            setattr(_owner, attribute, bpy.props.PointerProperty(type=group))
        entry[1].add(technique.name)
    for cls in getattr(side, "CLASSES", ()):
        users = _classes.setdefault(cls, set())
        if not users:
            bpy.utils.register_class(cls)
        users.add(technique.name)


def _detach(technique):
    side = side_of(technique)
    if side is None:
        return
    for cls in reversed(getattr(side, "CLASSES", ())):
        users = _classes.get(cls, set())
        users.discard(technique.name)
        if not users and cls in _classes:
            del _classes[cls]
            bpy.utils.unregister_class(cls)
    for attribute in getattr(side, "SETTINGS", {}):
        entry = _groups.get(attribute)
        if entry is None:
            continue
        entry[1].discard(technique.name)
        if not entry[1]:
            delattr(_owner, attribute)
            bpy.utils.unregister_class(entry[0])
            del _groups[attribute]


def register(owner):
    """Register the registered techniques' sides on the material settings class `owner`, and every technique's
    registered later (techniques.watch); files loaded from now on have their old flat settings moved."""
    global _owner
    _owner = owner
    for technique in techniques.registered():
        _attach(technique)
    techniques.watch(_attach, _detach)
    if _move_legacy not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_move_legacy)
    _move_legacy()


def unregister():
    if _move_legacy in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_move_legacy)
    techniques.unwatch(_attach)
    for technique in reversed(techniques.registered()):
        _detach(technique)


@bpy.app.handlers.persistent
def _move_legacy(*_args):
    """Settings files kept flat on material.sgprt under their old names, moved into their sides' groups."""
    materials = getattr(bpy.data, "materials", ())
    for side in _sides():
        for attribute, renames in getattr(side, "LEGACY", {}).items():
            for material in materials:
                settings = getattr(material, "sgprt", None)
                if settings is None or attribute not in _groups:
                    continue
                stored = settings.keys()
                for prop, old in renames.items():
                    if old in stored:
                        group = getattr(settings, attribute)
                        if not group.is_property_set(prop):
                            group[prop] = settings[old]
                        del settings[old]


def draw(layout, material):
    """The chosen technique's rows in the material panel."""
    name = techniques.of_settings(material.sgprt)
    side = _side_of_name(name)
    if side is not None and hasattr(side, "draw"):
        side.draw(layout, material, name)


def read(material, params):
    for side in _sides():
        if hasattr(side, "read"):
            side.read(material, params)


def resolve(material, params):
    """(the technique that renders the material, warnings): its choice when it can render it, else a fallback."""
    name = techniques.of_settings(material.sgprt)
    if name not in techniques.names():
        return techniques.DEFAULT, [f"material '{material.name}': technique {name!r} is not available in this "
                                    f"version (registered: {', '.join(techniques.names())}): rendered with "
                                    f"{techniques.DEFAULT}"]
    side = _side_of_name(name)
    if side is None or not hasattr(side, "resolve"):
        return name, []
    return side.resolve(material, params, name)


def settings_given(material):
    return any(side.settings_given(material) for side in _sides() if hasattr(side, "settings_given"))


def lobe_fit_use(material):
    """How the material's technique uses its stored lobe fit (a line for the Lobe Fit panel), or None."""
    name = techniques.of_settings(material.sgprt)
    side = _side_of_name(name)
    return side.lobe_fit_use(material, name) if side is not None and hasattr(side, "lobe_fit_use") else None


def take_lobe_fit(material):
    """After a lobe fit is stored: the material's technique reads it when it can, else the technique that
    renders fits is picked."""
    name = techniques.of_settings(material.sgprt)
    side = _side_of_name(name)
    if side is not None and hasattr(side, "take_lobe_fit") and side.take_lobe_fit(material, name):
        return
    fitted = techniques.rendering_stored("lobe_fit")
    if fitted is not None:
        material.sgprt.technique = fitted.name
