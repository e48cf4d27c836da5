"""RGB Curves, Vector Curves and Float Curve read as node_functions.curves: each node's curves tabulated as
Cycles tabulates them (TABLE_SIZE evaluations evenly over the span of the curves' points; RGB Curves' channels
through the combined curve first), looked up per pixel; a Color Ramp's table likewise (ramp_value).  `value(reader, node, out)` is what
node_reader.SocketReader reads for an output of one of NODE_TYPES."""
import numpy as np

from ..reflectance.texture_expression import Expression
from .node_graph import enabled_inputs

NODE_TYPES = ("CURVE_RGB", "CURVE_VEC", "CURVE_FLOAT")
TABLE_SIZE = 256            # Cycles' RAMP_TABLE_SIZE
# node type -> (its curves a table reads, the value input, whether the value is a colour)
INPUTS = {"CURVE_RGB": (4, "Color", True), "CURVE_VEC": (3, "Vector", True), "CURVE_FLOAT": (1, "Value", False)}


def curve_table(mapping, node_type):
    """(min_x, max_x, rows): the node's curves evaluated at TABLE_SIZE positions over the span of their points'
    x, as RGB rows (a Float Curve's value on all three)."""
    count = INPUTS[node_type][0]
    mapping.initialize()
    curves = [mapping.curves[k] for k in range(count)]
    xs = [point.location[0] for curve in curves for point in curve.points]
    min_x, max_x = (min(xs), max(xs)) if xs else (0.0, 1.0)
    if max_x <= min_x:
        max_x = min_x + 1.0
    positions = np.float32(min_x) + np.arange(TABLE_SIZE, dtype=np.float32) / np.float32(TABLE_SIZE - 1) \
        * np.float32(max_x - min_x)
    rows = []
    for t in positions:
        t = float(t)
        if node_type == "CURVE_RGB":
            combined = mapping.evaluate(curves[3], t)
            row = [mapping.evaluate(curves[k], combined) for k in range(3)]
        elif node_type == "CURVE_VEC":
            row = [mapping.evaluate(curves[k], t) for k in range(3)]
        else:
            row = [mapping.evaluate(curves[0], t)] * 3
        rows.append(tuple(float(np.float32(v)) for v in row))
    return float(min_x), float(max_x), tuple(rows)


def ramp_value(ramp, output, fac):
    """A Color Ramp's Color or Alpha at `fac` (an Expression) through its table: TABLE_SIZE evaluations of the
    ramp (ColorRamp.evaluate: every interpolation and colour mode) over [0, 1], looked up linearly between
    entries, clamped to [0, 1], as Cycles' svm_node_rgb_ramp does (for all but Constant interpolation, which
    blends nothing: node_reader reads it from its stops)."""
    rows = []
    for k in range(TABLE_SIZE):
        rgba = ramp.evaluate(k / (TABLE_SIZE - 1))
        row = (rgba[3],) * 3 if output == "Alpha" else tuple(rgba[:3])
        rows.append(tuple(float(np.float32(v)) for v in row))
    return Expression.function("curves", (0.0, 1.0, False, tuple(rows)), (Expression.constant(1.0), fac))


def value(reader, node, out):
    """The Expression of the curves node's output (reader: the node_reader.SocketReader)."""
    _, name, colour = INPUTS[node.type]
    fac, source = enabled_inputs(node, "Factor" if node.type == "CURVE_FLOAT" else "Fac", name)
    fac = reader.value(fac, False) if fac is not None else Expression.constant(1.0)
    min_x, max_x, rows = curve_table(node.mapping, node.type)
    extrapolate = getattr(node.mapping, "extend", "EXTRAPOLATED") == "EXTRAPOLATED"
    return Expression.function("curves", (min_x, max_x, extrapolate, rows), (fac, reader.value(source, colour)))
