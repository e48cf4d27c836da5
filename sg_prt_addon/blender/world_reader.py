"""A world's shader nodes read as the engine's environment: from the active World Output, a Background (or
Emission) shader's Color, an Environment Texture (equirectangular) with a Mapping node's rotation and scale
in front of it, an RGB or the socket's colour, and its Strength.  What cannot be read is named in one warning
(blender/export/world.py export_world) with what was used instead: another shader (a Sky Texture, a Mix of
backgrounds) renders the world colour."""
from dataclasses import dataclass, field

import numpy as np

from .node_graph import output_node
from .node_reader import SocketReader, follow, scalar_of


@dataclass
class WorldReading:
    colour: tuple = None          # the Background colour when no texture feeds it (None: world.color)
    strength: float = 1.0
    image: object = None          # the Environment Texture's bpy Image
    matrix: np.ndarray = None     # (3, 3): the map is read at normalize(matrix d) (None: identity)
    notes: list = field(default_factory=list)


def euler_xyz(angles):
    """Blender's XYZ Euler rotation matrix (Rz Ry Rx)."""
    (cx, cy, cz), (sx, sy, sz) = np.cos(angles), np.sin(angles)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def mapping_matrix(vector_type, rotation, scale):
    """What a Mapping node does to a direction: POINT and VECTOR R S, TEXTURE its inverse."""
    matrix = euler_xyz(np.asarray(rotation, np.float64)) @ np.diag(np.asarray(scale, np.float64))
    return np.linalg.inv(matrix) if vector_type == "TEXTURE" else matrix


def read_world(world):
    reader = SocketReader()
    reading = WorldReading(notes=reader.notes)
    output = output_node(world.node_tree, "OUTPUT_WORLD")
    surface = follow(output.inputs["Surface"]) if output is not None else None
    if surface is None or surface.node.type not in ("BACKGROUND", "EMISSION"):
        if surface is not None:
            reader.note(surface.node, "world shader not supported: the world colour is used")
        return reading
    shader = surface.node
    strength = scalar_of(reader.value(shader.inputs["Strength"], False))
    if strength is None:
        reader.note(shader, "a texture on Strength: its value is used")
        strength = float(shader.inputs["Strength"].default_value)
    reading.strength = float(strength)
    source = follow(shader.inputs["Color"])
    if source is None or source.node.type == "RGB":
        reading.colour = reader.value(shader.inputs["Color"], True).as_constant()
        return reading
    node = source.node
    if node.type != "TEX_ENVIRONMENT":
        reader.note(node, "not read as the world's colour: the world colour is used")
        return reading
    if node.projection != "EQUIRECTANGULAR":
        reader.note(node, f"{node.projection.lower()} projection: read as equirectangular")
    reading.image = node.image
    vector = follow(node.inputs["Vector"])
    if vector is None:
        return reading
    mapping = vector.node
    if mapping.type != "MAPPING" or mapping.vector_type == "NORMAL":
        reader.note(mapping, "not read as the environment's direction: the map is read unturned")
        return reading
    inputs = mapping.inputs
    for name in ("Rotation", "Scale", "Location", "Vector"):
        if name in inputs and inputs[name].is_linked and name != "Vector":
            reader.note(mapping, f"a linked {name}: its value is used")
    coordinates = follow(inputs["Vector"])
    if coordinates is not None and not (coordinates.node.type == "TEX_COORD"
                                        and coordinates.name in ("Generated", "Object")):
        reader.note(coordinates.node, "coordinates other than the view direction: the view direction is used")
    if mapping.vector_type in ("POINT", "TEXTURE") and np.any(np.asarray(inputs["Location"].default_value) != 0):
        reader.note(mapping, "a Location offset: ignored (a direction has no position)")
    reading.matrix = mapping_matrix(mapping.vector_type, inputs["Rotation"].default_value,
                                    inputs["Scale"].default_value)
    return reading
