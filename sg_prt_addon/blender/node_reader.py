"""A material's shader nodes read as the engine's parameters (material.sgprt.source = Node Tree).

From the active Material Output's Surface, the shader tree is walked into weighted closures: Principled,
Diffuse and Glossy BSDFs, Emission, through Mix Shader (a constant factor, or a texture's mean) and Add
Shader.  Their inputs are read as a constant times at most one image (the engine's factor x texture): an
unlinked socket, RGB, Value, constant Math, an Image Texture over the UV map (Color output), a Normal Map
in tangent space.  What cannot be read as Blender renders it takes the nearest reading (a socket's default
value, a texture's mean) and is named in one warning per material.  reflectance/principled.py maps the
BSDFs' values to the model, colours and layering; this module is the bpy side.
"""
from dataclasses import dataclass, field

import numpy as np

from ..reflectance import principled

MATH_OPERATIONS = {"ADD": np.add, "SUBTRACT": np.subtract, "MULTIPLY": np.multiply,
                   "DIVIDE": lambda a, b: a / b if b != 0 else 0.0, "POWER": np.power, "MINIMUM": min,
                   "MAXIMUM": max}
PASS_THROUGH = ("REROUTE",)


@dataclass
class Input:
    """A socket's reading: value (float or RGB tuple) times the image `image` (a bpy Image) when set."""
    value: object
    image: object = None


@dataclass
class Reading:
    """What read_material found: MaterialParams fields, textures (slot -> image name), the data slots whose
    images Blender decodes from sRGB (decoded_slots), and the notes on what was read otherwise."""
    fields: dict = field(default_factory=dict)
    textures: dict = field(default_factory=dict)
    decoded_slots: tuple = ()
    notes: list = field(default_factory=list)


@dataclass
class _Closure:
    kind: str            # "principled", "diffuse", "glossy", "emission"
    weight: float
    node: object
    inputs: dict


def follow(socket):
    """The output socket feeding an input (through reroutes), or None."""
    if not socket.is_linked or not socket.links:
        return None
    link = socket.links[0]
    if getattr(link, "is_muted", False) or not getattr(link, "is_valid", True):
        return None
    out = link.from_socket
    while out.node.type in PASS_THROUGH:
        inputs = out.node.inputs
        if not inputs or not inputs[0].is_linked:
            return None
        out = inputs[0].links[0].from_socket
    return out


def _default(socket):
    value = getattr(socket, "default_value", 0.0)
    try:
        return tuple(float(v) for v in value)[:3]
    except TypeError:
        return float(value)


def _as_colour(value):
    return value if isinstance(value, tuple) else (float(value),) * 3


def _as_scalar(value):
    # Blender's implicit colour -> float: the luminance (Rec. 709 weights)
    return float(np.dot(value[:3], (0.2126, 0.7152, 0.0722))) if isinstance(value, tuple) else float(value)


class SocketReader:
    """Reads sockets as Inputs and shader trees as closures, collecting notes (material: the one read, whose
    meshes' UV maps an Image Texture's UV Map node is checked against; None for a world)."""

    def __init__(self, material=None):
        self.material = material
        self.notes = []

    def note(self, node, what):
        text = f"'{node.name}' ({node.bl_label}): {what}"
        if text not in self.notes:
            self.notes.append(text)

    # ------------------------------------------------------------------ values

    def value(self, socket, colour):
        """Input of a socket: a constant, or a constant times one image."""
        out = follow(socket)
        if out is None:
            value = _default(socket)
            return Input(_as_colour(value) if colour else _as_scalar(value))
        node = out.node
        if node.type in ("RGB", "VALUE"):
            value = _default(out)
            return Input(_as_colour(value) if colour else _as_scalar(value))
        if node.type == "TEX_IMAGE":
            return self.image_input(node, out, colour, socket)
        if node.type == "MATH" and node.operation in MATH_OPERATIONS:
            return self.math(node, colour, socket)
        self.note(node, f"not read: {socket.name} uses its value {_rounded(_default(socket))}")
        value = _default(socket)
        return Input(_as_colour(value) if colour else _as_scalar(value))

    def math(self, node, colour, socket):
        a, b = (self.value(node.inputs[k], False) for k in range(2))
        if a.image is not None and b.image is not None or node.operation != "MULTIPLY" and (a.image or b.image):
            self.note(node, f"{node.operation.lower()} of a texture: {socket.name} uses its value")
            value = _default(socket)
            return Input(_as_colour(value) if colour else _as_scalar(value))
        result = float(MATH_OPERATIONS[node.operation](a.value, b.value))
        if node.use_clamp:
            result = float(np.clip(result, 0.0, 1.0))
        return Input(_as_colour(result) if colour else result, a.image or b.image)

    def image_input(self, node, out, colour, socket):
        image = node.image
        if image is None:
            self.note(node, f"no image: {socket.name} uses its value")
            value = _default(socket)
            return Input(_as_colour(value) if colour else _as_scalar(value))
        if out.name != "Color":
            self.note(node, f"its {out.name} output is read as its Color")
        vector = follow(node.inputs["Vector"])
        if vector is not None:
            source = vector.node
            if source.type == "UVMAP" and source.uv_map and self._other_uv_map(source.uv_map):
                self.note(source, f"UV map '{source.uv_map}': each mesh's active UV map is used")
            elif source.type not in ("UVMAP", "TEX_COORD") or (source.type == "TEX_COORD" and vector.name != "UV"):
                self.note(source, "texture coordinates other than the UV map: the active UV map is used")
        if node.projection != "FLAT":
            self.note(node, f"{node.projection.lower()} projection: read flat over the UV map")
        return Input((1.0, 1.0, 1.0) if colour else 1.0, image)

    def _other_uv_map(self, name):
        """Whether a mesh with this material has an active UV map other than `name` (export reads the active)."""
        import bpy

        if self.material is None:
            return False
        for mesh in bpy.data.meshes:
            if self.material.name in mesh.materials and mesh.uv_layers.active is not None \
                    and mesh.uv_layers.active.name != name:
                return True
        return False

    # ------------------------------------------------------------------ shaders

    def closures(self, socket, weight):
        out = follow(socket)
        if out is None or weight <= 0.0:
            return []
        node = out.node
        kind = {"BSDF_PRINCIPLED": "principled", "BSDF_DIFFUSE": "diffuse", "BSDF_GLOSSY": "glossy",
                "BSDF_ANISOTROPIC": "glossy", "EMISSION": "emission"}.get(node.type)
        if kind is not None:
            return [_Closure(kind, weight, node, {})]
        if node.type == "ADD_SHADER":
            return self.closures(node.inputs[0], weight) + self.closures(node.inputs[1], weight)
        if node.type == "MIX_SHADER":
            factor = self.value(node.inputs["Fac"], False)
            fac = float(np.clip(factor.value, 0.0, 1.0))
            if factor.image is not None:
                mean = _image_mean(factor.image)
                self.note(node, f"a texture factor: its mean {mean:.3g} is used")
                fac = float(np.clip(fac * mean, 0.0, 1.0))
            return self.closures(node.inputs[1], weight * (1.0 - fac)) + self.closures(node.inputs[2], weight * fac)
        self.note(node, "shader not supported: rendered as nothing")
        return []


def _rounded(value):
    return tuple(round(v, 4) for v in value) if isinstance(value, tuple) else round(value, 4)


def _image_mean(image):
    """The mean of an image's first channel as stored (1 for an image without pixels)."""
    if image.size[0] == 0 or image.size[1] == 0 or image.channels == 0:
        return 1.0
    pixels = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(pixels)
    return float(np.nanmean(pixels[::image.channels]))


def output_node(tree):
    """The material's active output node (the one every engine renders), or None."""
    node = None
    if hasattr(tree, "get_output_node"):
        node = tree.get_output_node("ALL")
    if node is None:
        node = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    return node


def read_material(material):
    """Reading of a bpy Material's node tree."""
    reader = SocketReader(material)
    reading = Reading(notes=reader.notes)
    tree = material.node_tree
    output = output_node(tree) if tree is not None else None
    if output is None:
        reader.notes.append("no Material Output node: renders black")
        reading.fields.update(diffuse_color=(0.0, 0.0, 0.0), specular_color=(0.0, 0.0, 0.0))
        return reading
    closures = reader.closures(output.inputs["Surface"], 1.0)
    _combine(reader, closures, reading)
    return reading


def _combine(reader, closures, reading):
    """The closures' weighted sum as one parameter set: diffuse colours add, the heaviest glossy lobe gives the
    model (others are named), emissions add."""
    fields = reading.fields
    fields.update(diffuse_color=(0.0, 0.0, 0.0), specular_color=(0.0, 0.0, 0.0), emission=(0.0, 0.0, 0.0))
    diffuse_total = np.zeros(3)
    diffuse_image = None
    specular = None
    emission = np.zeros(3)
    for closure in closures:
        values, images = _closure_values(reader, closure)
        weight = closure.weight
        if "normal_map" in images and "normal_map" not in reading.textures:
            reading.textures["normal_map"] = images.pop("normal_map")
            fields["normal_strength"] = values.pop("normal_strength")
        if "diffuse_color" in values and closure.kind != "glossy":
            colour = np.asarray(values["diffuse_color"]) * weight
            if images.get("diffuse_color") is not None:
                if diffuse_image is not None and diffuse_image is not images["diffuse_color"]:
                    reader.note(closure.node, "a second textured diffuse colour: its texture is not applied")
                else:
                    diffuse_image = images["diffuse_color"]
            diffuse_total += colour
        if "specular_color" in values:
            if specular is None or weight > specular[0]:
                if specular is not None:
                    reader.note(specular[1].node, "a second glossy lobe: not rendered")
                specular = (weight, closure, values, images)
            else:
                reader.note(closure.node, "a second glossy lobe: not rendered")
        emission += np.asarray(values.get("emission", (0.0, 0.0, 0.0))) * weight
    fields["diffuse_color"] = tuple(float(c) for c in diffuse_total)
    if diffuse_image is not None:
        reading.textures["diffuse_color"] = diffuse_image
    if specular is not None:
        weight, closure, values, images = specular
        fields.update({k: v for k, v in values.items() if k not in ("diffuse_color", "emission", "normal_strength")})
        fields["specular_color"] = tuple(float(c) * weight for c in values["specular_color"])
        for slot, image in images.items():
            if slot not in ("diffuse_color", "normal_map"):
                reading.textures[slot] = image
    else:
        fields["layered_f0"] = -1.0
    fields["emission"] = tuple(float(c) for c in emission)
    reading.decoded_slots = tuple(sorted(slot for slot, image in reading.textures.items()
                                         if slot not in ("diffuse_color", "specular_color", "normal_map")
                                         and _is_srgb(image)))
    reading.textures = {slot: image.name for slot, image in reading.textures.items()}


def _is_srgb(image):
    return not image.is_float and image.colorspace_settings.name == "sRGB"


def _normal_input(reader, node, values, images):
    """A Normal input fed by a Normal Map node (tangent space) over an image: the normal map and strength."""
    out = follow(node.inputs["Normal"])
    if out is None:
        return
    source = out.node
    if source.type != "NORMAL_MAP":
        reader.note(source, "not read as a normal: the mesh normal is used")
        return
    if source.space != "TANGENT":
        reader.note(source, f"{source.space.lower()} space: the mesh normal is used")
        return
    colour = reader.value(source.inputs["Color"], True)
    if colour.image is None:
        reader.note(source, "no image: the mesh normal is used")
        return
    strength = reader.value(source.inputs["Strength"], False)
    images["normal_map"] = colour.image
    values["normal_strength"] = float(strength.value)


def _closure_values(reader, closure):
    """(MaterialParams fields, slot -> bpy Image) of one closure."""
    node, kind = closure.node, closure.kind
    images = {}

    def read(name, colour, slot=None):
        item = reader.value(node.inputs[name], colour)
        if item.image is not None:
            if slot is None:
                reader.note(node, f"a texture on {name}: its value {_rounded(item.value)} is used")
            else:
                images[slot] = item.image
        return item

    if kind == "emission":
        colour = read("Color", True)
        strength = read("Strength", False)
        return {"emission": tuple(c * strength.value for c in colour.value)}, {}
    if kind == "diffuse":
        colour = read("Color", True, "diffuse_color")
        if reader.value(node.inputs["Roughness"], False).value > 0:
            reader.note(node, "Oren-Nayar roughness: rendered as Lambert")
        values = {"diffuse_color": colour.value}
        _normal_input(reader, node, values, images)
        return values, images
    if kind == "glossy":
        colour = read("Color", True, "specular_color")
        roughness = read("Roughness", False, "roughness")
        anisotropy = read("Anisotropy", False) if "Anisotropy" in node.inputs else Input(0.0)
        rotation = read("Rotation", False) if "Rotation" in node.inputs else Input(0.0)
        values = principled.glossy(colour.value, roughness.value, node.distribution, anisotropy.value, rotation.value)
        _texture_on_width(reader, node, values, images)
        _normal_input(reader, node, values, images)
        return values, images
    return _principled_values(reader, node, read, images)


def _principled_values(reader, node, read, images):
    base = read("Base Color", True, "diffuse_color")
    metallic = read("Metallic", False)
    roughness = read("Roughness", False, "roughness")
    inputs = node.inputs
    optional = {name: read(name, False).value for name in ("Specular IOR Level", "Anisotropic", "Anisotropic Rotation",
                                                           "Transmission Weight", "Emission Strength", "Alpha",
                                                           "Coat Weight", "Sheen Weight", "Subsurface Weight")
                if name in inputs}
    tint = read("Specular Tint", True).value if "Specular Tint" in inputs else (1.0, 1.0, 1.0)
    emission = read("Emission Color", True).value if "Emission Color" in inputs else (0.0, 0.0, 0.0)
    values = principled.principled(
        base.value, metallic.value, roughness.value, read("IOR", False).value, optional.get("Specular IOR Level", 0.5),
        tint, optional.get("Anisotropic", 0.0), optional.get("Anisotropic Rotation", 0.0),
        optional.get("Transmission Weight", 0.0), emission, optional.get("Emission Strength", 0.0),
        multiscatter=node.distribution == "MULTI_GGX")
    if base.image is not None and metallic.value > 0.0:
        if metallic.value >= 1.0:
            images["specular_color"] = base.image
        else:
            reader.note(node, "a textured Base Color under Metallic between 0 and 1: the metal's colour is the "
                              "Base Color's factor alone")
    for name, what in (("Transmission Weight", "transmission"), ("Coat Weight", "the coat"),
                       ("Sheen Weight", "sheen"), ("Subsurface Weight", "subsurface scattering")):
        if optional.get(name, 0.0) > 0.0:
            reader.note(node, f"{what} ({name} {optional[name]:.3g}) is not rendered")
    if optional.get("Alpha", 1.0) < 1.0:
        reader.note(node, f"Alpha {optional['Alpha']:.3g}: rendered opaque")
    _texture_on_width(reader, node, values, images)
    _normal_input(reader, node, values, images)
    return values, images


def _texture_on_width(reader, node, values, images):
    """A roughness texture drives the GGX roughness itself; the other models' widths are not linear in it."""
    if "roughness" in images and values["model"] != "GGX":
        reader.note(node, f"a texture on Roughness with the {values['model']} model: its value is used")
        del images["roughness"]
