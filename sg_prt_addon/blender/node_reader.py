"""A material's shader nodes read as the engine's parameters (material.sgprt.source = Node Tree).

From the Material Output EEVEE renders, the shader tree (node_graph: groups entered, reroutes and muted nodes
passed) is walked into weighted closures: Principled, Diffuse and Glossy BSDFs, Emission, Transparent BSDF and
Holdout, through Mix Shader (its factor a constant or a texture) and Add Shader; transparency (Principled Alpha
too) becomes the surface's coverage (reflectance/coverage.py).  Their inputs are read as
texture_expression.Expressions: unlinked sockets, RGB and Value, Image Textures, colour attributes, the surface's coordinates, and the nodes
that compute values from them (sums and products in the algebra, the rest reflectance/node_functions.py),
a Normal Map in tangent space.  reflectance/principled.py maps the BSDFs' values to the model, colours and
layering; an expression that is a constant or a factor times one image over the UV map takes the engine's
factor x texture path, any other one is computed per pixel (techniques/material_textures.py).  The emission
is a colour slot like the others.  What cannot be read as Blender renders it takes the nearest reading (a
socket's default value) and is named in one warning per material.
"""
from dataclasses import dataclass, field

import numpy as np

from ..reflectance import coverage, node_functions, principled
from ..reflectance.texture_expression import Expression
from . import curve_nodes, normal_nodes, texture_nodes, uv_maps
from .colour_attributes import default_color_attribute
from .node_graph import enabled_inputs, output_node

IDENTITY_UV_TRANSFORM = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
# Blender's implicit colour -> float conversion (Rec. 709 luminance)
LUMINANCE = (0.2126, 0.7152, 0.0722)
COLOUR_SLOTS = ("diffuse_color", "specular_color", "emission")
# closures that take the place of what is behind, not light of their own (reflectance/coverage.py)
TRANSPARENT, HOLDOUT = "transparent", "holdout"
SEPARATE_NODES = ("SEPARATE_COLOR", "SEPRGB", "SEPXYZ")
COMBINE_NODES = ("COMBINE_COLOR", "COMBRGB", "COMBXYZ")


@dataclass
class Reading:
    """What read_material found: MaterialParams fields, textures (slot -> image name, or an Expression
    computed into a texture), the data slots whose images Blender decodes from sRGB (decoded_slots), and the
    notes on what was read otherwise."""
    fields: dict = field(default_factory=dict)
    textures: dict = field(default_factory=dict)
    decoded_slots: tuple = ()
    notes: list = field(default_factory=list)


@dataclass
class _Closure:
    kind: str            # "principled", "diffuse", "glossy", "emission", TRANSPARENT, HOLDOUT
    weight: object       # float or Expression
    node: object


def follow(socket):
    """The output socket computing an input's value (node_graph: through groups, reroutes and muted nodes), or
    None."""
    return socket.links[0].from_socket if socket.is_linked and socket.links else None


def _default(socket):
    value = getattr(socket, "default_value", 0.0)
    try:
        return tuple(float(v) for v in value)[:3]
    except TypeError:
        return float(value)


def _constant(value, colour):
    """A socket's plain value as an Expression: colours RGB, scalars (a colour read as a scalar: luminance)."""
    if isinstance(value, tuple):
        return Expression.constant(value if colour else float(np.dot(value[:3], LUMINANCE)))
    return Expression.constant(value)


def _weighted_channels(value, weights):
    """sum_k weights[k] x a colour's channel k, on all three channels."""
    return sum((value.channel(k) * weight for k, weight in enumerate(weights)), Expression.constant(0.0))


def _luminance(value):
    """A colour's Rec. 709 luminance on all three channels."""
    return _weighted_channels(value, LUMINANCE)


def _uv_source(socket, meshes):
    """Whether what feeds `socket` is the UV map renders use (unlinked, a UV Map node naming it or none, Texture
    Coordinate's UV) on every mesh of `meshes`."""
    out = follow(socket)
    if out is not None and out.node.type == "UVMAP":
        return uv_maps.coordinates_of(meshes, out.node.uv_map) != "SECOND_UV"
    return out is None or (out.node.type == "TEX_COORD" and out.identifier == "UV")


def _over_the_uv_map(node, meshes):
    """Whether an Image Texture reads the UV map repeating, through at most a Mapping whose values are its own and
    turn about z alone: what the material's uv_transform and the plain texture path carry."""
    if node.extension != "REPEAT":
        return False
    vector = follow(node.inputs["Vector"])
    if vector is None or _uv_source(node.inputs["Vector"], meshes):
        return True
    mapping = vector.node
    if mapping.type != "MAPPING" or mapping.vector_type == "NORMAL" or not _uv_source(mapping.inputs["Vector"],
                                                                                    meshes):
        return False
    if any(name in mapping.inputs and mapping.inputs[name].is_linked for name in ("Location", "Rotation", "Scale")):
        return False
    rotation = mapping.inputs["Rotation"].default_value
    return abs(rotation[0]) <= 1e-9 and abs(rotation[1]) <= 1e-9


def _clamped(value):
    """A value clamped to [0, 1] (a node's Clamp option)."""
    return Expression.function("clamp", ("MINMAX",), (value, 0.0, 1.0))


def _rounded(value):
    return tuple(round(v, 4) for v in value) if isinstance(value, tuple) else round(value, 4)


def scalar_of(expression):
    """A scalar Expression's value when constant (its red channel), else None."""
    value = expression.as_constant()
    return None if value is None else value[0]


class SocketReader:
    """Reads sockets as Expressions and shader trees as closures, collecting notes (material: the one read,
    whose meshes' UV maps an Image Texture's UV Map node is checked against; None for a world)."""

    def __init__(self, material=None):
        self.material = material
        self.notes = []
        self.images = {}            # name -> bpy Image of every image an Expression names
        self.uv_transforms = []     # the UV transform of every Image Texture read (uv_transform_of)

    def note(self, node, what):
        text = f"'{node.name}' ({node.bl_label}): {what}"
        if text not in self.notes:
            self.notes.append(text)

    # ------------------------------------------------------------------ values

    def value(self, socket, colour):
        """The Expression a socket receives: a colour read where a number is wanted (colour False) is its
        luminance, as Blender converts it, but for an image's: its red channel (the grey maps numbers come from
        keep the factor x texture path)."""
        out = follow(socket)
        if out is None:
            return _constant(_default(socket), colour)
        value = self._output_value(out, socket, colour)
        if not colour and out.type == "RGBA" and value.as_constant() is None:
            value = value.channel(0) if out.node.type == "TEX_IMAGE" else _luminance(value)
        return value

    def _output_value(self, out, socket, colour):
        """The Expression of the output socket `out` feeding `socket`."""
        node = out.node
        if node.type in ("RGB", "VALUE"):
            return _constant(_default(out), colour)
        if node.type == "TEX_IMAGE":
            return self.image_value(node, out, socket, colour)
        if node.type in SEPARATE_NODES:
            return self.separate(node, out)
        if node.type in ("VERTEX_COLOR", "ATTRIBUTE"):
            return self.attribute_value(node, out, socket, colour)
        if node.type == "VALTORGB":
            return self.color_ramp(node, out)
        if node.type == "LIGHT_PATH":
            return self.light_path(node, out, socket, colour)
        if node.type in ("TEX_COORD", "NEW_GEOMETRY", "UVMAP"):
            return self.coordinates_value(node, out, socket, colour)
        if node.type in texture_nodes.NODE_TYPES:
            return texture_nodes.value(self, node, out)
        if node.type in curve_nodes.NODE_TYPES:
            return curve_nodes.value(self, node, out)
        if node.type in normal_nodes.NODE_TYPES:
            return normal_nodes.value(self, node, out)
        if node.type in ("FRESNEL", "LAYER_WEIGHT"):
            return self.view_weight(node, out)
        if node.type == "VECT_MATH":
            return self.vector_math(node, out)
        reader = {"MATH": self.math, "INVERT": self.invert, "MIX": self.mix, "MIX_RGB": self.mix, "MAPPING": self.mapping,
                  "CLAMP": self.clamp, "MAP_RANGE": self.map_range, "HUE_SAT": self.hue_saturation_value,
                  "GAMMA": self.gamma, "BRIGHTCONTRAST": self.brightness_contrast, "RGBTOBW": self.luminance,
                  **dict.fromkeys(COMBINE_NODES, self.combine)}.get(node.type)
        if reader is not None:
            result = reader(node, colour)
            if result is not None:
                return result
        else:
            self.note(node, f"not read: {socket.name} uses its value {_rounded(_default(socket))}")
        return _constant(_default(socket), colour)

    def math(self, node, colour):
        """Every operation of the Math node: sums and products in the algebra, the rest node functions."""
        a, b, c = (self.value(socket, False) for socket in list(node.inputs)[:3])
        operation = node.operation
        if operation in ("ADD", "SUBTRACT", "MULTIPLY", "MULTIPLY_ADD"):
            result = {"ADD": lambda: a + b, "SUBTRACT": lambda: a - b, "MULTIPLY": lambda: a * b,
                      "MULTIPLY_ADD": lambda: a * b + c}[operation]()
        elif operation == "DIVIDE" and scalar_of(b) not in (None, 0.0):
            result = a * (1.0 / scalar_of(b))
        elif operation in node_functions.MATH:
            result = Expression.function("math", (operation,), (a, b, c))
        else:
            self.note(node, f"{operation.lower()}: its output is the first input")
            return a
        return _clamped(result) if node.use_clamp else result

    def coordinates_value(self, node, out, socket, colour):
        """Texture Coordinate's Generated, Normal, UV and Object (of the object itself); Geometry's Position,
        Normal and Incoming (world space); a UV Map node's UV (the active map's)."""
        if node.type == "UVMAP":
            name = uv_maps.coordinates_of(self._meshes(), node.uv_map)
            if name is None:
                self.note(node, f"UV map '{node.uv_map}': neither the UV map renders use nor the second one of "
                                "each mesh with this material: each mesh's render UV map is used")
            return Expression.coordinates(name or "UV")
        names = {"Generated": "GENERATED", "Normal": "NORMAL", "UV": "UV", "Object": "OBJECT"} \
            if node.type == "TEX_COORD" else {"Position": "POSITION", "Normal": "WORLD_NORMAL",
                                              "True Normal": "WORLD_NORMAL", "Incoming": "INCOMING"}
        name = names.get(out.identifier)
        if name is None:
            self.note(node, f"its {out.name} output: {socket.name} uses its value {_rounded(_default(socket))}")
            return _constant(_default(socket), colour)
        if name == "OBJECT" and getattr(node, "object", None) is not None:
            self.note(node, f"Object coordinates of '{node.object.name}': the surface's own object is used")
        return Expression.coordinates(name)

    def view_weight(self, node, out):
        """Fresnel and Layer Weight (its Fresnel, Facing) at the view, about their Normal (unlinked: the
        surface's)."""
        normal_socket = node.inputs["Normal"]
        normal = self.value(normal_socket, True) if normal_socket.is_linked else Expression.coordinates("WORLD_NORMAL")
        incoming = Expression.coordinates("INCOMING")
        if node.type == "FRESNEL":
            return Expression.function("fresnel", (), (self.value(node.inputs["IOR"], False), normal, incoming))
        output = "Facing" if out.identifier == "Facing" else "Fresnel"
        return Expression.function("layer_weight", (output,), (self.value(node.inputs["Blend"], False), normal,
                                                              incoming))

    def light_path(self, node, out, socket, colour):
        """Light Path as the engine shades: every pixel a camera ray's first hit (Is Camera Ray 1, the other
        rays' kinds and depths 0); Ray Length is named and its value used."""
        if out.identifier == "Ray Length":
            self.note(node, f"its Ray Length: {socket.name} uses its value {_rounded(_default(socket))}")
            return _constant(_default(socket), colour)
        return Expression.constant(1.0 if out.identifier == "Is Camera Ray" else 0.0)

    def mapping(self, node, colour):
        """The Mapping node on a vector (POINT, TEXTURE, VECTOR, NORMAL)."""
        vector, location, rotation, scale = enabled_inputs(node, "Vector", "Location", "Rotation", "Scale")
        values = [self.value(socket, True) if socket is not None else Expression.constant(0.0)
                  for socket in (vector, location, rotation, scale)]
        return Expression.function("mapping", (node.vector_type,), values)

    def vector_math(self, node, out):
        """The Vector Math node: per-component operations in the algebra and Math's functions, the others across
        the components (node_functions.VECTOR_MATH); its Value output of an operation without one is 0."""
        sockets = list(node.inputs)
        a, b, c = (self.value(socket, True) for socket in sockets[:3])
        scale = self.value(node.inputs["Scale"], False) if "Scale" in node.inputs else Expression.constant(1.0)
        operation = node.operation
        scalar = operation in ("DOT_PRODUCT", "DISTANCE", "LENGTH")
        if (out.identifier == "Value") != scalar:
            return Expression.constant(0.0)
        per_component = {"ADD": lambda: a + b, "SUBTRACT": lambda: a - b, "MULTIPLY": lambda: a * b,
                         "MULTIPLY_ADD": lambda: a * b + c, "SCALE": lambda: a * scale}
        if operation in per_component:
            return per_component[operation]()
        if operation in node_functions.VECTOR_MATH:
            return Expression.function("vector_math", (operation,), (a, b))
        math_operation = {"FRACTION": "FRACT"}.get(operation, operation)
        if math_operation in node_functions.MATH:
            return Expression.function("math", (math_operation,), (a, b, c))
        self.note(node, f"{operation.lower()}: its output is the first input")
        return a

    def clamp(self, node, colour):
        value, low, high = (self.value(node.inputs[name], False) for name in ("Value", "Min", "Max"))
        return Expression.function("clamp", (node.clamp_type,), (value, low, high))

    def map_range(self, node, colour):
        """Map Range of floats (LINEAR, STEPPED, SMOOTHSTEP, SMOOTHERSTEP)."""
        if node.data_type != "FLOAT":
            self.note(node, f"a {node.data_type.lower()} map range: its first input is used")
            return None
        sockets = enabled_inputs(node, "Value", "From Min", "From Max", "To Min", "To Max", "Steps")
        values = [self.value(socket, False) if socket is not None else Expression.constant(4.0) for socket in sockets]
        return Expression.function("map_range", (node.interpolation_type, bool(node.clamp)), values)

    def color_ramp(self, node, out):
        """Color Ramp's Color or Alpha: its stops interpolated per pixel in RGB (LINEAR, EASE, CONSTANT), or its
        table as Cycles makes it (curve_nodes.ramp_table: B-spline, Cardinal, HSV and HSL blending)."""
        ramp = node.color_ramp
        fac = self.value(node.inputs["Fac"], False)
        output = "Alpha" if out.identifier == "Alpha" else "Color"
        if ramp.interpolation not in ("LINEAR", "EASE", "CONSTANT") or (ramp.color_mode != "RGB"
                                                                       and ramp.interpolation != "CONSTANT"):
            return curve_nodes.ramp_value(ramp, output, fac)
        stops = sorted(((float(e.position), tuple(float(v) for v in e.color)) for e in ramp.elements),
                       key=lambda stop: stop[0])
        settings = (ramp.interpolation, tuple(p for p, _ in stops), tuple(c for _, c in stops), output)
        return Expression.function("color_ramp", settings, (fac,))

    def hue_saturation_value(self, node, colour):
        values = [self.value(node.inputs[name], name == "Color") for name in ("Color", "Hue", "Saturation", "Value",
                                                                              "Fac")]
        return Expression.function("hue_saturation_value", (), values)

    def gamma(self, node, colour):
        return Expression.function("gamma", (), (self.value(node.inputs["Color"], True),
                                                 self.value(node.inputs["Gamma"], False)))

    def brightness_contrast(self, node, colour):
        return Expression.function("brightness_contrast", (), (self.value(node.inputs["Color"], True),
                                                               self.value(node.inputs["Bright"], False),
                                                               self.value(node.inputs["Contrast"], False)))

    def luminance(self, node, colour):
        """RGB to BW: Rec. 709 luminance (the default scene-linear space's)."""
        return _luminance(self.value(node.inputs["Color"], True))

    def attribute_value(self, node, out, socket, colour):
        """Color Attribute, or Attribute of the geometry: the mesh's default colour attribute (its Color or
        Vector; Fac: the mean of its channels, as Cycles takes it)."""
        if node.type == "ATTRIBUTE" and node.attribute_type != "GEOMETRY":
            self.note(node, f"{node.attribute_type.lower()} attribute: {socket.name} uses its value "
                            f"{_rounded(_default(socket))}")
            return _constant(_default(socket), colour)
        name = node.layer_name if node.type == "VERTEX_COLOR" else node.attribute_name
        if name and self._other_colour_attribute(name):
            self.note(node, f"attribute '{name}': each mesh's default colour attribute is read")
        value = Expression.attribute(name)
        if out.identifier == "Fac":
            return _weighted_channels(value, (1.0 / 3.0,) * 3)
        if out.identifier == "Alpha":
            self.note(node, "its Alpha output: 1 is used")
            return Expression.constant(1.0)
        return value

    def separate(self, node, out):
        """One output of Separate Color (RGB), Separate RGB or Separate XYZ: that channel of its input."""
        if getattr(node, "mode", "RGB") != "RGB":
            self.note(node, f"{node.mode} mode: its channels are read as red, green and blue")
        channel = [socket.identifier for socket in node.outputs].index(out.identifier)
        return self.value(node.inputs[0], True).channel(min(channel, 2))

    def combine(self, node, colour):
        """Combine Color (RGB), Combine RGB or Combine XYZ: its three inputs as one colour's channels."""
        if getattr(node, "mode", "RGB") != "RGB":
            self.note(node, f"{node.mode} mode: its inputs are read as red, green and blue")
            return None
        return sum((self.value(node.inputs[k], False) * tuple(unit) for k, unit in enumerate(np.eye(3))),
                   Expression.constant(0.0))

    def invert(self, node, colour):
        factor = self.value(node.inputs["Fac"], False)
        value = self.value(node.inputs["Color"], True)
        return factor * (1.0 - value) + (1.0 - factor) * value

    def mix(self, node, colour):
        """Mix (colour, float or vector) and the legacy MixRGB: every blend, the factor clamped where the node
        clamps it, the result where it asks."""
        if node.type == "MIX":
            if node.data_type not in ("RGBA", "FLOAT", "VECTOR"):
                self.note(node, f"a {node.data_type.lower()} mix: its first input is used")
                return None
            suffix = {"RGBA": "Color", "FLOAT": "Float", "VECTOR": "Vector"}[node.data_type]
            per_channel = node.data_type == "VECTOR" and node.factor_mode == "NON_UNIFORM"
            sockets = enabled_inputs(node, "Factor_Vector" if per_channel else "Factor_Float", f"A_{suffix}", f"B_{suffix}")
            blend = node.blend_type if node.data_type == "RGBA" else "MIX"
            clamp_factor, clamp_result = node.clamp_factor, node.data_type == "RGBA" and node.clamp_result
        else:
            per_channel = False
            sockets = enabled_inputs(node, "Fac", "Color1", "Color2")
            blend, clamp_factor, clamp_result = node.blend_type, True, node.use_clamp
        if None in sockets:
            return None
        factor = self.value(sockets[0], per_channel)
        factor = _clamped(factor) if clamp_factor else factor
        a, b = self.value(sockets[1], True), self.value(sockets[2], True)
        blended = {"MIX": lambda: b, "MULTIPLY": lambda: a * b, "ADD": lambda: a + b,
                   "SUBTRACT": lambda: a - b}.get(blend)
        if blend in node_functions.MIX_BLENDS:
            result = Expression.function("mix", (blend,), (factor, a, b))
        else:
            if blended is None:
                self.note(node, f"blend {blend.lower()}: read as mix")
                blended = lambda: b  # noqa: E731
            result = (1.0 - factor) * a + factor * blended()
        return _clamped(result) if clamp_result else result

    def image_value(self, node, out, socket, colour):
        """An Image Texture's Color: over the UV map (through a Mapping of it) and repeating, the engine's factor
        x texture path; at any other coordinates or with another extension, read per pixel there
        (Expression.image_at)."""
        image = node.image
        if image is None:
            self.note(node, f"no image: {socket.name} uses its value")
            return _constant(_default(socket), colour)
        if node.projection != "FLAT":
            self.note(node, f"{node.projection.lower()} projection: read flat")
        self.images[image.name] = image
        if not _over_the_uv_map(node, self._meshes()):
            vector_socket = node.inputs["Vector"]
            vector = self.value(vector_socket, True) if vector_socket.is_linked else Expression.coordinates("UV")
            return Expression.image_at(image.name, node.extension, vector, out.name)
        vector = follow(node.inputs["Vector"])
        transform = IDENTITY_UV_TRANSFORM
        if vector is not None and vector.node.type == "MAPPING":
            transform = self.uv_transform_of(vector.node)
            vector = follow(vector.node.inputs["Vector"])
        self.uv_transforms.append(transform)
        if vector is not None and vector.node.type == "UVMAP":
            self.coordinates_value(vector.node, vector, node.inputs["Vector"], True)     # its note, if any
        if out.name == "Alpha":     # at the material's texture coordinates, as its Color
            return Expression.image_at(image.name, "REPEAT", Expression.coordinates("UV"), "Alpha")
        return Expression.image(image.name)

    def uv_transform_of(self, mapping):
        """A Mapping node on UV coordinates (its values its own, turning about z alone: _over_the_uv_map) as the
        affine (a, b, c, d, e, f): u' = a u + b v + c, v' = d u + e v + f (POINT: R S uv + L; TEXTURE: its
        inverse; VECTOR: R S uv)."""
        inputs = mapping.inputs
        rotation = inputs["Rotation"].default_value
        cos, sin = np.cos(rotation[2]), np.sin(rotation[2])
        scale = inputs["Scale"].default_value
        matrix = np.array([[cos, -sin], [sin, cos]]) @ np.diag([scale[0], scale[1]])
        offset = np.zeros(2)
        if mapping.vector_type in ("POINT", "TEXTURE"):
            offset = np.array(inputs["Location"].default_value[:2], np.float64)
        if mapping.vector_type == "TEXTURE":
            matrix = np.linalg.inv(matrix) if abs(np.linalg.det(matrix)) > 1e-12 else np.eye(2)
            offset = -matrix @ offset
        return (float(matrix[0, 0]), float(matrix[0, 1]), float(offset[0]),
                float(matrix[1, 0]), float(matrix[1, 1]), float(offset[1]))

    def _meshes(self):
        import bpy

        if self.material is None:
            return []
        return [mesh for mesh in bpy.data.meshes if self.material.name in mesh.materials]

    def _other_colour_attribute(self, name):
        """Whether a mesh with this material has a default colour attribute other than `name` (export reads the
        default one)."""
        return any(attribute is not None and attribute.name != name
                   for attribute in map(default_color_attribute, self._meshes()))

    # ------------------------------------------------------------------ shaders

    def closures(self, socket, weight):
        out = follow(socket)
        if out is None or (not isinstance(weight, Expression) and weight <= 0.0):
            return []
        node = out.node
        kind = {"BSDF_PRINCIPLED": "principled", "BSDF_DIFFUSE": "diffuse", "BSDF_GLOSSY": "glossy",
                "BSDF_ANISOTROPIC": "glossy", "EMISSION": "emission"}.get(node.type)
        if node.type == "BSDF_PRINCIPLED" and "Alpha" in node.inputs:
            # Cycles: the BSDF mixed with a Transparent BSDF by its Alpha
            alpha = self.value(node.inputs["Alpha"], False)
            constant = scalar_of(alpha)
            if constant is None or constant < 1.0:
                alpha = max(0.0, constant) if constant is not None else _clamped(alpha)
                return [_Closure("principled", weight * alpha, node), _Closure(TRANSPARENT, weight * (1.0 - alpha), node)]
        if kind is not None:
            return [_Closure(kind, weight, node)]
        if node.type == "BSDF_TRANSPARENT":
            colour = self.value(node.inputs["Color"], True)
            if colour.as_constant() is None or len(set(colour.as_constant())) > 1:
                self.note(node, "a tinted Transparent BSDF: what is behind shows untinted, by its colour's mean")
            return [_Closure(TRANSPARENT, weight * _weighted_channels(colour, (1.0 / 3.0,) * 3), node)]
        if node.type == "HOLDOUT":
            return [_Closure(HOLDOUT, weight, node)]
        if node.type == "ADD_SHADER":
            return self.closures(node.inputs[0], weight) + self.closures(node.inputs[1], weight)
        if node.type == "MIX_SHADER":
            factor = self.value(node.inputs["Fac"], False)
            constant = scalar_of(factor)
            if constant is not None:
                fac = float(np.clip(constant, 0.0, 1.0))
                first, second = weight * (1.0 - fac), weight * fac
            else:
                first, second = weight * (1.0 - factor), weight * factor
            return self.closures(node.inputs[1], first) + self.closures(node.inputs[2], second)
        self.note(node, "shader not supported: rendered as nothing")
        return []


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
    _combine(reader, reader.closures(output.inputs["Surface"], 1.0), reading)
    return reading


def _combine(reader, closures, reading):
    """The closures' weighted sum as one parameter set: diffuse colours add, the heaviest glossy lobe gives the
    model (others are named), emissions add, holdouts add into the holdout slot; the transparent ones set the
    coverage (_drawn)."""
    fields = reading.fields
    closures = _drawn(reader, closures, reading)
    diffuse = emission = holdout = Expression.constant(0.0)
    specular = None
    for closure in closures:
        weight = closure.weight
        if closure.kind == HOLDOUT:
            holdout = holdout + weight
            continue
        values = _closure_values(reader, closure)
        _take_normals(values, reading)
        if "diffuse_color" in values:
            diffuse = diffuse + weight * Expression.of(values["diffuse_color"])
        if "specular_color" in values:
            rank = _mean_weight(reader, weight)
            if specular is None or rank > specular[0]:
                if specular is not None:
                    reader.note(specular[1].node, "a second glossy lobe: not rendered")
                specular = (rank, closure, values)
            else:
                reader.note(closure.node, "a second glossy lobe: not rendered")
        if "emission" in values:
            emission = emission + weight * Expression.of(values["emission"])
    _to_slot(reader, reading, "diffuse_color", diffuse)
    _to_slot(reader, reading, "emission", emission)
    if holdout.as_constant() != (0.0, 0.0, 0.0):
        _to_slot(reader, reading, "holdout", _clamped(holdout) if holdout.as_constant() is None
                 else min(max(scalar_of(holdout), 0.0), 1.0))
    if specular is not None:
        _, closure, values = specular
        for name, value in values.items():
            if name == "specular_color":
                _to_slot(reader, reading, name, closure.weight * Expression.of(value))
            elif name == "roughness":
                _to_slot(reader, reading, name, value)
            elif name not in ("diffuse_color", "emission", "normal_strength"):
                fields[name] = value
    else:
        fields["specular_color"] = (0.0, 0.0, 0.0)
        fields["layered_f0"] = -1.0
    _uv_transform(reader, fields)
    reading.decoded_slots = tuple(sorted(slot for slot, value in reading.textures.items()
                                         if isinstance(value, str) and slot not in COLOUR_SLOTS + ("normal_map",)
                                         and _is_srgb(reader.images[value])))


def _take_normals(values, reading):
    """A closure's normal map (and strength) and computed shading normal into the reading: the first closure's
    that has one."""
    if "normal_map" in values:
        image, strength = values.pop("normal_map"), values.pop("normal_strength")
        if "normal_map" not in reading.textures:
            reading.textures["normal_map"] = image
            reading.fields["normal_strength"] = strength
    if "shading_normal" in values:
        reading.textures.setdefault("shading_normal", values.pop("shading_normal"))


def _drawn(reader, closures, reading):
    """The closures but the transparent ones, weighted as the surface drawn over the coverage carries them
    (reflectance/coverage.py), the coverage into the reading's alpha slot."""
    transparent = [closure for closure in closures if closure.kind == TRANSPARENT]
    if not transparent:
        return closures
    others = [closure for closure in closures if closure.kind != TRANSPARENT]
    transparency = sum((Expression.of(closure.weight) for closure in transparent), Expression.constant(0.0))
    weights, alpha = coverage.drawn_weights([closure.weight for closure in others], transparency)
    _to_slot(reader, reading, "alpha", alpha)
    if reading.fields.get("alpha", 0.0) < 1.0 or "alpha" in reading.textures:
        reader.note(transparent[0].node, "transparency: shadows are cast as by an opaque surface")
    return [_Closure(closure.kind, weight, closure.node) for closure, weight in zip(others, weights)
            if isinstance(weight, Expression) or weight > 0.0]


def _uv_transform(reader, fields):
    """The one UV transform of the material's textures (the engine maps every texture of a material alike)."""
    transforms = list(dict.fromkeys(reader.uv_transforms))
    if transforms:
        fields["uv_transform"] = transforms[0]
        if len(transforms) > 1:
            reader.notes.append("textures under different Mapping nodes: the first one's mapping is used for all")


def _mean_weight(reader, weight):
    if not isinstance(weight, Expression):
        return float(weight)
    return weight.mean_value({name: _image_mean(reader.images[name]) for name in weight.images})[0]


def _to_slot(reader, reading, slot, value):
    """A parameter's Expression into the reading: a number or colour, a factor x image, or computed per pixel."""
    value = Expression.of(value)
    colour = slot in COLOUR_SLOTS
    constant = value.as_constant()
    if constant is not None:
        reading.fields[slot] = constant if colour else constant[0]
        return
    plain = value.as_factor_times_image(scalar=not colour)
    if plain is not None and (colour or len(set(plain[0])) == 1):
        factor, image = plain
        reading.fields[slot] = factor if colour else factor[0]
        reading.textures[slot] = image
        return
    reading.fields[slot] = (1.0, 1.0, 1.0) if colour else 1.0
    reading.textures[slot] = value


def _is_srgb(image):
    return not image.is_float and image.colorspace_settings.name == "sRGB"


def _image_mean(image):
    """The mean RGB of an image as stored (1 for an image without pixels)."""
    if image.size[0] == 0 or image.size[1] == 0 or image.channels == 0:
        return (1.0, 1.0, 1.0)
    pixels = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(pixels)
    pixels = pixels.reshape(-1, image.channels)
    return tuple(float(np.nanmean(pixels[:, min(k, image.channels - 1)])) for k in range(3))


def _normal_input(reader, node, values):
    """A Normal input fed by a Normal Map node (tangent space) over an image: the normal map and strength; by a
    Bump node: the shading normal computed per pixel."""
    out = follow(node.inputs["Normal"])
    if out is None:
        return
    source = out.node
    if source.type in normal_nodes.NODE_TYPES:
        normal = reader.value(node.inputs["Normal"], True)
        if normal != Expression.coordinates("WORLD_NORMAL"):      # (a constant height bumps nothing)
            values["shading_normal"] = normal
        return
    if source.type != "NORMAL_MAP":
        reader.note(source, "not read as a normal: the mesh normal is used")
        return
    if source.space != "TANGENT":
        reader.note(source, f"{source.space.lower()} space: the mesh normal is used")
        return
    colour = reader.value(source.inputs["Color"], True).as_factor_times_image()
    if colour is None:
        reader.note(source, "not an image: the mesh normal is used")
        return
    strength = scalar_of(reader.value(source.inputs["Strength"], False))
    if strength is None:
        reader.note(source, "a texture on Strength: 1 is used")
    values["normal_map"] = colour[1]
    values["normal_strength"] = 1.0 if strength is None else float(strength)


def _constant_input(reader, node, name, default=0.0):
    """A socket that must be a constant: its value, or (a texture on it) its default with a note."""
    if name not in node.inputs:
        return default
    value = reader.value(node.inputs[name], False)
    constant = scalar_of(value)
    if constant is None:
        reader.note(node, f"a texture on {name}: its value {_rounded(_default(node.inputs[name]))} is used")
        return float(_default(node.inputs[name]))
    return constant


def _constant_colour(reader, node, name, default):
    if name not in node.inputs:
        return default
    value = reader.value(node.inputs[name], True)
    constant = value.as_constant()
    if constant is None:
        reader.note(node, f"a texture on {name}: its value {_rounded(_default(node.inputs[name]))} is used")
        return _default(node.inputs[name])
    return constant


def _closure_values(reader, closure):
    """MaterialParams fields of one closure: colours and roughness as Expressions, the rest numbers, and the
    normal map's image name."""
    node, kind = closure.node, closure.kind
    values = {}
    if kind == "emission":
        return {"emission": reader.value(node.inputs["Color"], True) * reader.value(node.inputs["Strength"], False)}
    if kind == "diffuse":
        if _constant_input(reader, node, "Roughness") > 0:
            reader.note(node, "Oren-Nayar roughness: rendered as Lambert")
        values["diffuse_color"] = reader.value(node.inputs["Color"], True)
    elif kind == "glossy":
        anisotropy = _constant_input(reader, node, "Anisotropy")
        if node.distribution == "BECKMANN" and anisotropy != 0.0:
            reader.note(node, "anisotropic Beckmann: rendered as anisotropic Ward (its NDF, Ward's shadowing)")
        plain_ggx = node.distribution in ("GGX", "MULTI_GGX") and anisotropy == 0.0
        values.update(principled.glossy(reader.value(node.inputs["Color"], True),
                                        _width(reader, node, plain_ggx), node.distribution, anisotropy,
                                        _constant_input(reader, node, "Rotation")))
    else:
        values.update(_principled_values(reader, node))
    _normal_input(reader, node, values)
    return values


def _principled_values(reader, node):
    inputs = node.inputs
    optional = {name: _constant_input(reader, node, name, default)
                for name, default in (("Specular IOR Level", 0.5), ("Anisotropic", 0.0), ("Anisotropic Rotation", 0.0),
                                      ("Transmission Weight", 0.0),
                                      ("Coat Weight", 0.0), ("Sheen Weight", 0.0), ("Subsurface Weight", 0.0))}
    values = principled.principled(
        reader.value(inputs["Base Color"], True), reader.value(inputs["Metallic"], False),
        _width(reader, node, optional["Anisotropic"] == 0.0), _constant_input(reader, node, "IOR", 1.5),
        optional["Specular IOR Level"], _constant_colour(reader, node, "Specular Tint", (1.0, 1.0, 1.0)),
        optional["Anisotropic"], optional["Anisotropic Rotation"], optional["Transmission Weight"],
        reader.value(inputs["Emission Color"], True), reader.value(inputs["Emission Strength"], False),
        multiscatter=node.distribution == "MULTI_GGX")
    for name, what in (("Transmission Weight", "transmission"), ("Coat Weight", "the coat"),
                       ("Sheen Weight", "sheen"), ("Subsurface Weight", "subsurface scattering")):
        if optional[name] > 0.0:
            reader.note(node, f"{what} ({name} {optional[name]:.3g}) is not rendered")
    if optional["Anisotropic"] > 0.0:
        _tangent_input(reader, node)
    return values


def _tangent_input(reader, node):
    """An anisotropic lobe's Tangent input: a Tangent node over the UV map is the engine's UV tangent; Cycles'
    default (unlinked: radial about the object's Z) and other tangents are named."""
    out = follow(node.inputs["Tangent"]) if "Tangent" in node.inputs else None
    if out is None:
        reader.note(node, "Tangent unlinked (Cycles: radial about the object's Z): the UV map's tangent is used")
    elif out.node.type != "TANGENT" or out.node.direction_type != "UV_MAP":
        reader.note(out.node, "not read as the tangent: the UV map's tangent is used")


def _width(reader, node, plain_ggx):
    """The Roughness input: an Expression where it drives an isotropic GGX's roughness itself, else a number
    (the other models' widths are not linear in it: a texture's mean, named)."""
    roughness = reader.value(node.inputs["Roughness"], False)
    constant = scalar_of(roughness)
    if constant is not None or plain_ggx:
        return roughness if constant is None else constant
    mean = _mean_weight(reader, roughness)
    reader.note(node, f"a texture on Roughness of an anisotropic or non-GGX lobe: its mean {mean:.3g} is used")
    return mean
