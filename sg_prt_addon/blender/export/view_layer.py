"""What renders in a view layer: the objects it shows, and their roles."""
from dataclasses import dataclass

# --------------------------------------------------------------------------- what renders

@dataclass
class RenderRoles:
    """What a render does with a view layer's objects, by (original) name (render_roles)."""
    hidden: set         # disabled in renders: on the object, or on every collection path that holds it
    holdout: set        # in a Holdout collection (through any path), or the object's own Holdout
    indirect: set       # in an Indirect Only collection (through any path): not seen by the camera


def render_roles(view_layer):
    """RenderRoles of a view layer's collections and objects.  A holdout occludes and cuts the film's alpha; an
    indirect-only object is not seen by the camera (this engine renders direct light only: it only shadows,
    through bakes); a hidden one is left out of renders and of bakes (the viewport's depsgraph still lists
    it)."""
    shown, holdout, indirect = set(), set(), set()

    def walk(layer_collection, in_holdout, in_indirect):
        if layer_collection.collection.hide_render:
            return
        in_holdout = in_holdout or layer_collection.holdout
        in_indirect = in_indirect or layer_collection.indirect_only
        names = [obj.name for obj in layer_collection.collection.objects]
        shown.update(names)
        if in_holdout:
            holdout.update(names)
        if in_indirect:
            indirect.update(names)
        for child in layer_collection.children:
            walk(child, in_holdout, in_indirect)

    walk(view_layer.layer_collection, False, False)
    objects = list(view_layer.objects)
    hidden = {obj.name for obj in objects if obj.hide_render or obj.name not in shown}
    holdout.update(obj.name for obj in objects if getattr(obj, "is_holdout", False))
    return RenderRoles(hidden, holdout - hidden, indirect - hidden)
