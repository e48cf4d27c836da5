"""An object's modifier stack as a final render evaluates it, for bakes of objects whose modifiers change the
topology (their rows live on a companion mesh: blender/per_vertex_store.py).

- fingerprint(obj): each modifier's name, type and the settings a render evaluates (its RNA properties but the
  viewport's and the interface's, its Geometry Nodes inputs, its node group by content), JSON-ready, stored with
  the bake; changes(baked, current) says what differs, in words;
- viewport_differences(obj): where the viewport evaluates the stack otherwise than a render does;
- as_rendered(scene): for a while, the viewport's depsgraph evaluating the render's settings (Python cannot make a
  render depsgraph): each modifier's Realtime set as its Render, Subdivision Surface and Multiresolution at their
  render levels, Simplify's render subdivision; all restored after.  What else differs between the two
  evaluations (a Geometry Nodes "Is Viewport" node...) gives other faces, which the render's check of the
  record's faces catches (unshadowed, with the reason).
"""
import contextlib
import hashlib
import json

import bpy

# RNA properties that change only the viewport's evaluation or the interface, not what a render evaluates
NOT_RENDERED = {"rna_type", "name", "type", "show_viewport", "show_in_editmode", "show_on_cage", "show_expanded",
                "is_active", "is_override_data", "execution_time", "persistent_uid"}
# the viewport's own subdivision levels, by modifier type (the render reads render_levels)
VIEWPORT_LEVELS = {"SUBSURF": ("levels",), "MULTIRES": ("levels", "sculpt_levels")}
# a node's place and looks in the editor
NODE_LAYOUT = {"rna_type", "name", "location", "location_absolute", "width", "height", "dimensions", "select",
               "hide", "label", "color", "use_custom_color", "color_tag", "parent", "warning_propagation"}


def _dump(value):
    # compared as JSON text: NaN equals NaN, tuples equal lists
    return json.dumps(value, sort_keys=True)


def _id_value(datablock, memo):
    """A datablock a setting points at: its name, and a node tree's content too (an edited group re-evaluates)."""
    if isinstance(datablock, bpy.types.NodeTree):
        if datablock.name not in memo:
            memo[datablock.name] = None                 # being digested (Blender refuses recursive groups)
            memo[datablock.name] = _node_tree_digest(datablock, memo)
        return {"id": datablock.name, "content": memo[datablock.name]}
    return {"id": datablock.name}


def _plain(value, memo):
    """A setting's value as JSON-ready data (ID properties, arrays, vectors, datablocks)."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, bpy.types.ID):
        return _id_value(value, memo)
    if hasattr(value, "to_dict"):                       # an ID property group
        return {str(key): _plain(item, memo) for key, item in value.to_dict().items()}
    if hasattr(value, "to_list"):                       # an ID property array
        return [_plain(item, memo) for item in value.to_list()]
    if isinstance(value, dict):
        return {str(key): _plain(item, memo) for key, item in value.items()}
    if isinstance(value, (set, frozenset)):             # an enum flag
        return sorted(value)
    try:
        return [_plain(item, memo) for item in value]   # RNA arrays, vectors, matrices (by rows)
    except TypeError:
        return type(value).__name__


def _settings(struct, skipped, memo):
    """{identifier: value} of a struct's RNA properties a render evaluates: simple values and datablocks; not
    collections, nor pointers to other structs, nor `skipped`, nor the interface's show_* / open_* (but
    show_render)."""
    values = {}
    for prop in struct.bl_rna.properties:
        name = prop.identifier
        if (name in skipped or prop.type == "COLLECTION" or name.startswith("open_")
                or (name.startswith("show_") and name != "show_render")):
            continue
        try:
            value = getattr(struct, name)
        except (AttributeError, RuntimeError, TypeError):
            continue
        if prop.type == "POINTER" and value is not None and not isinstance(value, bpy.types.ID):
            continue
        values[name] = _plain(value, memo)
    return values


def _node_tree_digest(tree, memo):
    """A digest of what a node tree computes: its nodes' settings and inputs' values, and its links."""
    nodes = [[node.bl_idname, node.name, _settings(node, NODE_LAYOUT, memo),
              [[socket.identifier, _plain(getattr(socket, "default_value", None), memo)] for socket in node.inputs]]
             for node in sorted(tree.nodes, key=lambda node: node.name)]
    links = sorted([link.from_node.name, link.from_socket.identifier, link.to_node.name, link.to_socket.identifier,
                    bool(link.is_muted)] for link in tree.links)
    return hashlib.blake2b(_dump([nodes, links]).encode(), digest_size=8).hexdigest()


def _node_inputs(modifier, memo):
    """A Geometry Nodes modifier's inputs by identifier: RNA structs (value, type, attribute name) under
    ``properties.inputs`` from Blender 5.2, the modifier's ID properties before."""
    interface = getattr(modifier, "properties", None)
    if interface is not None:
        inputs = interface.inputs
        return {prop.identifier: _settings(getattr(inputs, prop.identifier), {"rna_type", "name"}, memo)
                for prop in inputs.bl_rna.properties if prop.identifier not in ("rna_type", "name")}
    return {key: _plain(modifier[key], memo) for key in modifier.keys()}


def fingerprint(obj):
    """[[name, type, {setting: value}]] of an object's modifiers in order (JSON-ready): what a render evaluates.
    A Geometry Nodes modifier's inputs (its ID properties) are the setting "inputs"."""
    memo = {}
    stack = []
    for modifier in obj.modifiers:
        settings = _settings(modifier, NOT_RENDERED.union(VIEWPORT_LEVELS.get(modifier.type, ())), memo)
        if modifier.type == "NODES":
            settings["inputs"] = _node_inputs(modifier, memo)
        stack.append([modifier.name, modifier.type, settings])
    return json.loads(_dump(stack))                     # as it reads back from the record


def _value_text(value):
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, dict) and "id" in value:
        return f"'{value['id']}'"
    return "none" if value is None else str(value)


def _setting_change(name, then, now):
    label = name.replace("_", " ")
    if isinstance(then, dict) and isinstance(now, dict) and "id" in then and then.get("id") == now.get("id"):
        return f"{label} '{now['id']}' edited"
    if all(value is None or isinstance(value, (bool, int, float, str)) or (isinstance(value, dict) and "id" in value)
           for value in (then, now)):
        return f"{label} {_value_text(then)} -> {_value_text(now)}"
    return f"{label} changed"


def changes(baked, current):
    """Phrases saying how the modifier stack `current` (fingerprint) differs from `baked`; [] when the same."""
    if _dump(baked) == _dump(current):
        return []
    then = {name: (kind, settings) for name, kind, settings in baked}
    now = {name: (kind, settings) for name, kind, settings in current}
    phrases = [f"'{name}' removed" for name in then if name not in now]
    phrases += [f"'{name}' added" for name in now if name not in then]
    kept = [name for name in now if name in then]
    if [name for name in then if name in now] != kept:
        phrases.append("reordered")
    for name in kept:
        (kind_then, settings_then), (kind_now, settings_now) = then[name], now[name]
        if kind_then != kind_now:
            phrases.append(f"'{name}' is another kind of modifier")
            continue
        phrases += [f"'{name}' {_setting_change(key, settings_then.get(key), settings_now.get(key))}"
                    for key in sorted(set(settings_then) | set(settings_now))
                    if _dump(settings_then.get(key)) != _dump(settings_now.get(key))]
    return phrases or ["their settings changed"]


def viewport_differences(obj):
    """Phrases naming where the viewport evaluates an object's modifiers otherwise than a render; [] if nowhere."""
    phrases = []
    for modifier in obj.modifiers:
        if modifier.show_viewport != modifier.show_render:
            phrases.append(f"'{modifier.name}' on in {'renders' if modifier.show_render else 'the viewport'} only")
        elif modifier.show_render and modifier.type in VIEWPORT_LEVELS and modifier.levels != modifier.render_levels:
            phrases.append(f"'{modifier.name}' levels {modifier.levels} in the viewport, {modifier.render_levels} "
                           "in renders")
    return phrases


@contextlib.contextmanager
def as_rendered(scene):
    """Inside the block the viewport's depsgraph evaluates the scene's modifiers with the render's settings (module
    docstring); every setting changed is restored after, whatever happens."""
    changed = []                                        # (struct, property, value before)

    def set_as_rendered(struct, name, value):
        before = getattr(struct, name)
        if before == value:
            return
        try:
            setattr(struct, name, value)
        except (AttributeError, TypeError, ValueError, RuntimeError):
            return                                      # linked data: the render's check of the faces decides
        changed.append((struct, name, before))

    try:
        for obj in scene.objects:
            for modifier in obj.modifiers:
                set_as_rendered(modifier, "show_viewport", modifier.show_render)
                if modifier.type in VIEWPORT_LEVELS:
                    set_as_rendered(modifier, "levels", modifier.render_levels)
        if scene.render.use_simplify:
            set_as_rendered(scene.render, "simplify_subdivision", scene.render.simplify_subdivision_render)
        yield
    finally:
        for struct, name, before in reversed(changed):
            setattr(struct, name, before)
