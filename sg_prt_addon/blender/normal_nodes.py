"""Nodes whose output is a shading normal, read per pixel: the Bump node (node_functions.bump_normal, from the
height's differences across the pixel, GLSL derivatives).  `value(reader, node, out)` is what
node_reader.SocketReader reads for an output of one of NODE_TYPES."""
from ..reflectance.texture_expression import Expression
from .node_graph import enabled_inputs

NODE_TYPES = ("BUMP",)


def surface_normal(reader, socket):
    """A Normal input's value: its link, or the surface's normal (world space) where it is unlinked."""
    return reader.value(socket, True) if socket.is_linked else Expression.coordinates("WORLD_NORMAL")


def value(reader, node, out):
    """The Bump node's Normal: its Height's gradient over the surface about its Normal (unlinked: the surface's),
    at the pixel's scale (Cycles 4's Filter Width is a tenth of a pixel: the differences differ by the height's
    curvature over a pixel).  A constant height leaves the normal."""
    strength, distance, height, normal = enabled_inputs(node, "Strength", "Distance", "Height", "Normal")
    normal = surface_normal(reader, normal)
    height = reader.value(height, False)
    if height.as_constant() is not None:
        return normal
    values = (reader.value(strength, False), reader.value(distance, False), height, normal,
              Expression.coordinates("POSITION"))
    return Expression.function("bump", (bool(node.invert),), values)
