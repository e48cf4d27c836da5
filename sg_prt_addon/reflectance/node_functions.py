"""Blender's shader-node functions that are not sums of products, as Cycles and EEVEE define them (Math, Clamp,
Map Range, Color Ramp, the Mix node's blend modes, Hue/Saturation/Value, Gamma, Brightness/Contrast, Mapping,
Vector Math, Fresnel, Layer Weight, Bump, the curves, the Checker, Gradient, Noise, Wave, Magic and White Noise
textures; the Voronoi texture in reflectance/voronoi.py), on (..., 3) float32 arrays: a scalar socket is its
value on all three channels.  shaders/lib/node_functions.glsl is their GLSL (each `node_<name>` there mirrors
<name> here); reflectance.texture_expression applies them to per-pixel values.

Every function takes its inputs as (..., 3) arrays and returns one; `params` are numbers fixed in the node.
"""
import numpy as np

from . import voronoi

FLOAT = np.float32


def _safe_divide(a, b):
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(b != 0, a / np.where(b != 0, b, 1), FLOAT(0))


def _power(a, b):
    """a^b; a negative a only to a near-integer b (its nearest integer), else 0."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        fraction = np.mod(np.abs(b), 1)
        near_integer = (fraction > 0.999) | (fraction < 0.001)
        negative = np.where(near_integer, np.power(a, np.floor(b + 0.5)), 0)
        return np.where(a >= 0, np.power(np.maximum(a, 0), b), negative)


def _logarithm(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        ok = (a > 0) & (b > 0)
        return np.where(ok, np.log2(np.where(ok, a, 1)) / np.log2(np.where(ok, b, 2)), 0)


def _modulo(a, b):
    """C's fmod (the sign of a), 0 where b is 0."""
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(b != 0, np.fmod(a, np.where(b != 0, b, 1)), 0)


def _floored_modulo(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(b != 0, b, 1)
        return np.where(b != 0, a - np.floor(a / safe) * safe, 0)


def _wrap(a, high, low):
    span = high - low
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(span != 0, span, 1)
        return np.where(span != 0, a - span * np.floor((a - low) / safe), low)


def _pingpong(a, b):
    with np.errstate(invalid="ignore", divide="ignore"):
        safe = np.where(b != 0, b, 1)
        fraction = (a - safe) / (safe * 2)
        return np.where(b != 0, np.abs((fraction - np.floor(fraction)) * safe * 2 - safe), 0)


def _smooth_min(a, b, c):
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.maximum(c - np.abs(a - b), 0) / np.where(c != 0, c, 1)
        return np.where(c != 0, np.minimum(a, b) - h * h * h * c / 6, np.minimum(a, b))


def _inverse_sqrt(a):
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(a > 0, 1 / np.sqrt(np.where(a > 0, a, 1)), 0)


# The Math node's operations that are not sums of products: operation -> (function of (a, b, c), inputs used)
MATH = {
    "DIVIDE": (lambda a, b, c: _safe_divide(a, b), 2),
    "POWER": (lambda a, b, c: _power(a, b), 2),
    "LOGARITHM": (lambda a, b, c: _logarithm(a, b), 2),
    "SQRT": (lambda a, b, c: np.sqrt(np.maximum(a, 0)), 1),
    "INVERSE_SQRT": (lambda a, b, c: _inverse_sqrt(a), 1),
    "ABSOLUTE": (lambda a, b, c: np.abs(a), 1),
    "EXPONENT": (lambda a, b, c: np.exp(a), 1),
    "MINIMUM": (lambda a, b, c: np.minimum(a, b), 2),
    "MAXIMUM": (lambda a, b, c: np.maximum(a, b), 2),
    "LESS_THAN": (lambda a, b, c: (a < b).astype(FLOAT), 2),
    "GREATER_THAN": (lambda a, b, c: (a > b).astype(FLOAT), 2),
    "SIGN": (lambda a, b, c: np.sign(a), 1),
    "COMPARE": (lambda a, b, c: (np.abs(a - b) <= np.maximum(c, 1e-5)).astype(FLOAT), 3),
    "SMOOTH_MIN": (lambda a, b, c: _smooth_min(a, b, c), 3),
    "SMOOTH_MAX": (lambda a, b, c: -_smooth_min(-a, -b, c), 3),
    "ROUND": (lambda a, b, c: np.floor(a + 0.5), 1),
    "FLOOR": (lambda a, b, c: np.floor(a), 1),
    "CEIL": (lambda a, b, c: np.ceil(a), 1),
    "TRUNC": (lambda a, b, c: np.trunc(a), 1),
    "FRACT": (lambda a, b, c: a - np.floor(a), 1),
    "MODULO": (lambda a, b, c: _modulo(a, b), 2),
    "FLOORED_MODULO": (lambda a, b, c: _floored_modulo(a, b), 2),
    "WRAP": (lambda a, b, c: _wrap(a, b, c), 3),
    "SNAP": (lambda a, b, c: np.floor(_safe_divide(a, b)) * b, 2),
    "PINGPONG": (lambda a, b, c: _pingpong(a, b), 2),
    "SINE": (lambda a, b, c: np.sin(a), 1),
    "COSINE": (lambda a, b, c: np.cos(a), 1),
    "TANGENT": (lambda a, b, c: np.tan(a), 1),
    "SINH": (lambda a, b, c: np.sinh(a), 1),
    "COSH": (lambda a, b, c: np.cosh(a), 1),
    "TANH": (lambda a, b, c: np.tanh(a), 1),
    "ARCSINE": (lambda a, b, c: np.arcsin(np.clip(a, -1, 1)), 1),          # Cycles' safe_asinf clamps
    "ARCCOSINE": (lambda a, b, c: np.arccos(np.clip(a, -1, 1)), 1),
    "ARCTANGENT": (lambda a, b, c: np.arctan(a), 1),
    "ARCTAN2": (lambda a, b, c: np.where((a == 0) & (b == 0), 0, np.arctan2(a, b)), 2),
    "RADIANS": (lambda a, b, c: np.radians(a), 1),
    "DEGREES": (lambda a, b, c: np.degrees(a), 1),
}


def math(operation, a, b, c):
    """The Math node's `operation` (one of MATH) of (..., 3) inputs."""
    with np.errstate(over="ignore", invalid="ignore"):
        return np.asarray(MATH[operation][0](*(np.asarray(x, FLOAT) for x in (a, b, c))), FLOAT)


def clamp(value, low, high, clamp_type="MINMAX"):
    """Clamp: MINMAX clamps to [low, high] (high where low > high, as min(max(v, low), high)); RANGE to the
    interval between them whichever is larger."""
    if clamp_type == "RANGE":
        low, high = np.minimum(low, high), np.maximum(low, high)
    return np.minimum(np.maximum(value, low), high).astype(FLOAT)


def map_range(value, from_min, from_max, to_min, to_max, steps, interpolation="LINEAR", clamped=True):
    """Map Range (float): LINEAR, STEPPED (`steps`), SMOOTHSTEP, SMOOTHERSTEP; a zero source range gives 0
    (as Blender's safe division); clamped to the target range where asked (LINEAR and STEPPED)."""
    span = from_max - from_min
    factor = _safe_divide(value - from_min, span)
    if interpolation == "STEPPED":
        factor = np.where(steps > 0, np.floor(factor * (steps + 1)) / np.where(steps > 0, steps, 1), 0)
    elif interpolation in ("SMOOTHSTEP", "SMOOTHERSTEP"):
        # Blender's smoothstep over the source range, reversed where from_min > from_max
        edge0, edge1 = np.minimum(from_min, from_max), np.maximum(from_min, from_max)
        t = np.clip(_safe_divide(value - edge0, edge1 - edge0), 0, 1)
        t = t * t * (3 - 2 * t) if interpolation == "SMOOTHSTEP" else t * t * t * (t * (t * 6 - 15) + 10)
        factor = np.where(from_min > from_max, 1 - t, t)
    out = to_min + factor * (to_max - to_min)
    if clamped and interpolation in ("LINEAR", "STEPPED"):
        out = np.where(to_min > to_max, np.clip(out, to_max, to_min), np.clip(out, to_min, to_max))
    return out.astype(FLOAT)


def color_ramp(fac, positions, colours, interpolation="LINEAR"):
    """Color Ramp's colour (RGBA: (..., 4)) at Fac (..., 3; its first channel): the stops' colours (K, 4)
    at positions (K,) sorted; LINEAR, EASE (smoothstep between stops) or CONSTANT (the stop at or below);
    clamped to the first and last stops."""
    x = np.clip(np.asarray(fac, FLOAT)[..., :1], 0, 1)
    positions = np.asarray(positions, FLOAT)
    colours = np.asarray(colours, FLOAT)
    out = np.broadcast_to(colours[0], x.shape[:-1] + (4,)).astype(FLOAT)
    for k in range(1, len(positions)):
        if interpolation == "CONSTANT":
            t = (x >= positions[k]).astype(FLOAT)
        else:
            t = np.clip(_safe_divide(x - positions[k - 1], np.full_like(x, positions[k] - positions[k - 1])), 0, 1)
            t = np.where(positions[k] > positions[k - 1], t, (x >= positions[k]).astype(FLOAT))
            if interpolation == "EASE":
                t = t * t * (3 - 2 * t)
        out = out + t * (colours[k] - out)
    return out


def curve_lookup(column, position, extrapolate):
    """Cycles' ramp lookup of a curve's table `column` (T,) at relative positions (...,): linear between its T
    evenly spaced entries over [0, 1]; outside, the end segments' slopes extended (extrapolate) or the ends."""
    column = np.asarray(column, FLOAT)
    last = len(column) - 1
    f = np.asarray(position, FLOAT)
    scaled = np.clip(f, FLOAT(0), FLOAT(1)) * FLOAT(last)
    index = np.clip(scaled.astype(np.int64), 0, last)
    t = (scaled - index).astype(FLOAT)
    low = column[index]
    inside = np.where(t > 0, (FLOAT(1) - t) * low + t * column[np.minimum(index + 1, last)], low)
    if not extrapolate:
        return inside.astype(FLOAT)
    below = column[0] + (column[0] - column[1]) * -f * FLOAT(last)
    above = column[last] + (column[last] - column[last - 1]) * (f - FLOAT(1)) * FLOAT(last)
    return np.where(f < 0, below, np.where(f > 1, above, inside)).astype(FLOAT)


def curves(settings, fac, value):
    """RGB, Vector and Float Curves (settings: min_x, max_x, extrapolate, the table's rows: T RGB triples, the
    curves evaluated at T positions evenly over [min_x, max_x]): each channel through its column at
    (value - min_x) / (max_x - min_x), mixed with the input by Fac."""
    min_x, max_x, extrapolate, table = settings
    table = np.asarray(table, FLOAT)
    value = np.asarray(value, FLOAT)
    relative = (value - FLOAT(min_x)) / FLOAT(max_x - min_x)
    curved = np.stack([curve_lookup(table[:, k], relative[..., k], extrapolate) for k in range(3)], axis=-1)
    fac = np.asarray(fac, FLOAT)[..., :1]
    return ((FLOAT(1) - fac) * value + fac * curved).astype(FLOAT)


def _rgb_to_hsv(rgb):
    r, g = rgb[..., 0], rgb[..., 1]
    high = np.max(rgb, axis=-1)
    low = np.min(rgb, axis=-1)
    delta = high - low
    s = np.where(high != 0, _safe_divide(delta, high), 0)
    safe = np.where(delta != 0, delta, 1)
    c = (high[..., None] - rgb) / safe[..., None]
    h = np.where(r == high, c[..., 2] - c[..., 1], np.where(g == high, 2 + c[..., 0] - c[..., 2],
                                                             4 + c[..., 1] - c[..., 0]))
    h = np.where(s != 0, h / 6, 0)
    h = np.where(h < 0, h + 1, h)
    return np.stack([h, s, high], axis=-1)


def _hsv_to_rgb(hsv):
    h, s, v = hsv[..., 0], hsv[..., 1], hsv[..., 2]
    h = (h - np.floor(h)) * 6
    i = np.floor(h)
    f = h - i
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    choices = [np.stack(c, -1) for c in ((v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q))]
    index = np.clip(i, 0, 5).astype(int)
    out = np.choose(index[..., None], choices)
    return np.where((s == 0)[..., None], v[..., None], out)


def hue_saturation_value(colour, hue, saturation, value, factor):
    """Hue/Saturation/Value: the hue turned by hue - 0.5, saturation and value scaled (saturation clamped to
    [0, 1]), mixed with the input by factor; negative channels made 0."""
    hsv = _rgb_to_hsv(colour)
    h = hsv[..., 0] + hue[..., 0] + 0.5
    h = h - np.floor(h)
    s = np.clip(hsv[..., 1] * saturation[..., 0], 0, 1)
    v = hsv[..., 2] * value[..., 0]
    out = _hsv_to_rgb(np.stack([h, s, v], -1))
    out = colour + factor * (out - colour)
    return np.maximum(out, 0).astype(FLOAT)


def gamma(colour, exponent):
    """Gamma: each positive channel to the power `exponent` (others kept)."""
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return np.where(colour > 0, np.power(np.maximum(colour, 0), exponent), colour).astype(FLOAT)


def brightness_contrast(colour, bright, contrast):
    """Brightness/Contrast: a = 1 + contrast, b = bright - contrast / 2, max(a c + b, 0)."""
    return np.maximum((1 + contrast) * colour + bright - contrast * 0.5, 0).astype(FLOAT)


def mix(blend, factor, a, b):
    """The Mix node's colour blends that are not sums of products, as Blender's GPU and Cycles define them
    (factor (..., 3) on every channel)."""
    t = factor
    s = 1 - t
    with np.errstate(invalid="ignore", divide="ignore"):
        if blend == "SCREEN":
            return 1 - (s + t * (1 - b)) * (1 - a)
        if blend == "OVERLAY":
            return np.where(a < 0.5, a * (s + 2 * t * b), 1 - (s + 2 * t * (1 - b)) * (1 - a))
        if blend == "DIVIDE":
            return np.where(b != 0, s * a + t * a / np.where(b != 0, b, 1), a)
        if blend == "DIFFERENCE":
            return a + t * (np.abs(a - b) - a)
        if blend == "EXCLUSION":
            return np.maximum(a + t * (a + b - 2 * a * b - a), 0)
        if blend == "DARKEN":
            return a + t * (np.minimum(a, b) - a)
        if blend == "LIGHTEN":
            return a + t * (np.maximum(a, b) - a)
        if blend == "DODGE":
            tmp = 1 - t * b
            return np.where(a != 0, np.where(tmp <= 0, 1, np.minimum(a / np.where(tmp > 0, tmp, 1), 1)), a)
        if blend == "BURN":
            tmp = s + t * b
            return np.where(tmp <= 0, 0, np.clip(1 - (1 - a) / np.where(tmp > 0, tmp, 1), 0, 1))
        if blend == "SOFT_LIGHT":
            screen = 1 - (1 - b) * (1 - a)
            return s * a + t * ((1 - a) * b * a + a * screen)
        if blend == "LINEAR_LIGHT":
            return a + t * (2 * b - 1)
    if blend in ("HUE", "SATURATION", "VALUE", "COLOR"):
        return _mix_hsv(blend, t, a, b)
    raise KeyError(blend)


def _mix_hsv(blend, t, a, b):
    """The Mix node's HSV blends: HUE and COLOR take b's hue (and COLOR its saturation) where b has a hue,
    SATURATION and VALUE mix a's saturation or value toward b's (SATURATION where a has one)."""
    hsv_a, hsv_b = _rgb_to_hsv(a), _rgb_to_hsv(b)
    t1 = t[..., :1]
    if blend in ("HUE", "COLOR"):
        taken = hsv_a.copy()
        taken[..., 0] = hsv_b[..., 0]
        if blend == "COLOR":
            taken[..., 1] = hsv_b[..., 1]
        turned = a + t1 * (_hsv_to_rgb(taken) - a)
        return np.where(hsv_b[..., 1:2] != 0, turned, a)
    channel = 1 if blend == "SATURATION" else 2
    mixed = hsv_a.copy()
    mixed[..., channel] = (1 - t1[..., 0]) * hsv_a[..., channel] + t1[..., 0] * hsv_b[..., channel]
    out = _hsv_to_rgb(mixed)
    return np.where(hsv_a[..., 1:2] != 0, out, a) if blend == "SATURATION" else out


# Blend modes that `mix` computes (Mix, Add, Multiply and Subtract are sums of products, in the algebra)
MIX_BLENDS = ("SCREEN", "OVERLAY", "DIVIDE", "DIFFERENCE", "EXCLUSION", "DARKEN", "LIGHTEN", "DODGE", "BURN",
              "SOFT_LIGHT", "LINEAR_LIGHT", "HUE", "SATURATION", "VALUE", "COLOR")


def _dot(a, b):
    return np.sum(a * b, axis=-1, keepdims=True)


def _safe_normalize(a):
    length = np.sqrt(_dot(a, a))
    return np.where(length != 0, a / np.where(length != 0, length, 1), 0)


def euler_matrix(rotation):
    """(..., 3, 3) rotation of Blender's XYZ Euler angles (..., 3): Z after Y after X."""
    cx, cy, cz = (np.cos(rotation[..., k]) for k in range(3))
    sx, sy, sz = (np.sin(rotation[..., k]) for k in range(3))
    rows = [[cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz],
            [cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz],
            [-sy, cy * sx, cy * cx]]
    return np.stack([np.stack(row, -1) for row in rows], -2)


def mapping(mapping_type, vector, location, rotation, scale):
    """The Mapping node: POINT R (v s) + l, TEXTURE its inverse R^T (v - l) / s, VECTOR R (v s), NORMAL
    normalize(R (v / s)) (a zero scale divides to 0)."""
    matrix = euler_matrix(rotation)

    def turn(v, transpose=False):
        return np.einsum("...ji,...j->...i" if transpose else "...ij,...j->...i", matrix, v)

    if mapping_type == "TEXTURE":
        return _safe_divide(turn(vector - location, transpose=True), scale).astype(FLOAT)
    if mapping_type == "NORMAL":
        return _safe_normalize(turn(_safe_divide(vector, scale))).astype(FLOAT)
    turned = turn(vector * scale)
    return (turned + location if mapping_type == "POINT" else turned).astype(FLOAT)


# The Vector Math node's operations across the three components (the others are per component: the algebra
# and MATH); DOT_PRODUCT, DISTANCE and LENGTH give a number on all three
VECTOR_MATH = ("CROSS_PRODUCT", "PROJECT", "REFLECT", "DOT_PRODUCT", "DISTANCE", "LENGTH", "NORMALIZE")


def vector_math(operation, a, b):
    if operation == "CROSS_PRODUCT":
        return np.cross(a, b).astype(FLOAT)
    if operation == "PROJECT":
        length2 = _dot(b, b)
        return np.where(length2 != 0, b * _dot(a, b) / np.where(length2 != 0, length2, 1), 0).astype(FLOAT)
    if operation == "REFLECT":
        n = _safe_normalize(b)
        return (a - 2 * _dot(n, a) * n).astype(FLOAT)
    if operation == "NORMALIZE":
        return _safe_normalize(a).astype(FLOAT)
    value = {"DOT_PRODUCT": lambda: _dot(a, b), "DISTANCE": lambda: np.sqrt(_dot(a - b, a - b)),
             "LENGTH": lambda: np.sqrt(_dot(a, a))}[operation]()
    return np.repeat(value, 3, axis=-1).astype(FLOAT)


def tex_checker(output, vector, colour1, colour2, scale):
    """Checker Texture's Color or Fac (output) at vector x scale (Cycles' svm_checker: the cell's parity, the
    coordinates nudged off the cell edges)."""
    p = (vector * scale + FLOAT(0.000001)) * FLOAT(0.999999)
    cells = np.abs(np.floor(p).astype(np.int64)) % 2
    fac = ((cells[..., 0] == cells[..., 1]) == (cells[..., 2] == 1)).astype(FLOAT)[..., None]
    if output == "Fac":
        return np.repeat(fac, 3, axis=-1)
    return np.where(fac == 1, colour1, colour2).astype(FLOAT)


GRADIENTS = ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "RADIAL", "QUADRATIC_SPHERE", "SPHERICAL")


def tex_gradient(gradient_type, vector):
    """Gradient Texture's Fac (on all three) of its type at vector, clamped to [0, 1] (Cycles' svm_gradient)."""
    x, y, z = vector[..., 0], vector[..., 1], vector[..., 2]
    if gradient_type == "LINEAR":
        value = x
    elif gradient_type == "QUADRATIC":
        value = np.maximum(x, 0) ** 2
    elif gradient_type == "EASING":
        r = np.clip(x, 0, 1)
        value = 3 * r * r - 2 * r * r * r
    elif gradient_type == "DIAGONAL":
        value = (x + y) * 0.5
    elif gradient_type == "RADIAL":
        value = np.arctan2(y, x) / (2 * np.pi) + 0.5
    else:
        r = np.maximum(FLOAT(0.999999) - np.sqrt(x * x + y * y + z * z), 0)
        value = r * r if gradient_type == "QUADRATIC_SPHERE" else r
    return np.repeat(np.clip(value, 0, 1)[..., None], 3, axis=-1).astype(FLOAT)


def fresnel_dielectric_cos(cosine, eta):
    """A dielectric's Fresnel reflectance at |cosine| for the relative index eta (total internal reflection: 1)."""
    c = np.abs(cosine)
    g = eta * eta - 1 + c * c
    root = np.sqrt(np.maximum(g, 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (root - c) / (root + c)
        b = (c * (root + c) - 1) / (c * (root - c) + 1)
        value = 0.5 * a * a * (1 + b * b)
    return np.where(g > 0, value, 1).astype(FLOAT)


def _facing(normal, incoming):
    """(cosine of the view to the normal, whether the surface faces away from the view)."""
    cosine = _dot(normal, incoming)[..., 0]
    return cosine, cosine < 0


def fresnel(ior, normal, incoming):
    """The Fresnel node: fresnel_dielectric_cos at the view, the index inverted where the surface faces away."""
    cosine, backfacing = _facing(normal, incoming)
    eta = np.maximum(ior[..., 0], FLOAT(1e-5))
    eta = np.where(backfacing, 1 / eta, eta)
    return np.repeat(fresnel_dielectric_cos(cosine, eta)[..., None], 3, axis=-1)


def layer_weight(output, blend, normal, incoming):
    """The Layer Weight node's Fresnel (of the index 1 / (1 - blend)) or Facing (1 - |cos|^(2 blend) below half,
    ^(0.5 / (1 - blend)) above)."""
    cosine, backfacing = _facing(normal, incoming)
    blend = blend[..., 0]
    if output == "Fresnel":
        eta = np.maximum(1 - blend, FLOAT(1e-5))
        eta = np.where(backfacing, eta, 1 / eta)
        value = fresnel_dielectric_cos(cosine, eta)
    else:
        clamped = np.clip(blend, 0, 1 - 1e-5)
        exponent = np.where(clamped < 0.5, 2 * clamped, 0.5 / (1 - clamped))
        with np.errstate(divide="ignore", invalid="ignore"):
            value = 1 - np.where(blend != 0.5, np.power(np.abs(cosine), exponent), np.abs(cosine))
    return np.repeat(np.asarray(value, FLOAT)[..., None], 3, axis=-1)


def bump_normal(strength, distance, height_dx, height_dy, position_dx, position_dy, normal, invert=False):
    """The Bump node's normal (Cycles' svm_node_set_bump) from the height's and the position's differences
    across a pixel (..., 3 each; the heights' first channel): the surface gradient of the height in the
    tangent plane of `normal` moves it by Distance, mixed back toward it by Strength (clamped to [0, 1])."""
    normal = np.asarray(normal, FLOAT)
    position_dx, position_dy = np.asarray(position_dx, FLOAT), np.asarray(position_dy, FLOAT)
    rx, ry = np.cross(position_dy, normal), np.cross(normal, position_dx)
    det = np.sum(position_dx * rx, axis=-1, keepdims=True)
    gradient = np.asarray(height_dx, FLOAT)[..., :1] * rx + np.asarray(height_dy, FLOAT)[..., :1] * ry
    distance = np.asarray(distance, FLOAT)[..., :1] * FLOAT(-1 if invert else 1)
    strength = np.clip(np.asarray(strength, FLOAT)[..., :1], 0, 1)
    bumped = _safe_normalize(np.abs(det) * normal - distance * np.sign(det) * gradient)
    return _safe_normalize(strength * bumped + (FLOAT(1) - strength) * normal).astype(FLOAT)


# Color Ramp's outputs a Function reads
RAMP_OUTPUTS = ("Color", "Alpha")
MAP_RANGE_INTERPOLATIONS = ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")


def apply(name, settings, args):
    """The node function `name` with the node's fixed `settings` of its inputs' values `args` ((..., 3)
    each): what texture_expression.Function computes (names: math (operation,), clamp (type,), map_range
    (interpolation, clamped), color_ramp (interpolation, positions, RGBA colours, output), curves (min_x,
    max_x, extrapolate, table), mix (blend,),
    hue_saturation_value, gamma, brightness_contrast, mapping (type,), vector_math (operation,), tex_checker
    (output,), tex_gradient (type,), tex_noise (type, normalize, output), tex_wave (type, bands direction,
    rings direction, profile, output), tex_magic (depth, output), tex_white_noise (dimensions, output), tex_voronoi
    (feature, metric, normalize, output: reflectance/voronoi.py), fresnel,
    layer_weight (output,)); bump (invert,) needs its inputs' differences across the pixel: bump_normal."""
    args = [np.asarray(a, FLOAT) for a in args]
    return _CALLS[name](settings, args)


def _no_derivatives(name):
    raise ValueError(f"{name} takes its inputs' differences across the pixel: a shader computes it (GLSL dFdx, "
                     "dFdy), a value at a point alone has none (node_functions.bump_normal from the differences)")


def _ramp_output(settings, args):
    interpolation, positions, colours, output = settings
    rgba = color_ramp(args[0], positions, colours, interpolation)
    return rgba[..., :3] if output == "Color" else np.repeat(rgba[..., 3:], 3, axis=-1)


# name -> the call of its function with the node's settings and the inputs' values (apply)
_CALLS = {
    "math": lambda settings, args: math(settings[0], *args),
    "clamp": lambda settings, args: clamp(*args, clamp_type=settings[0]),
    "map_range": lambda settings, args: map_range(*args, interpolation=settings[0], clamped=settings[1]),
    "color_ramp": _ramp_output,
    "curves": lambda settings, args: curves(settings, *args),
    "mix": lambda settings, args: np.asarray(mix(settings[0], *args), FLOAT),
    "mapping": lambda settings, args: mapping(settings[0], *args),
    "vector_math": lambda settings, args: vector_math(settings[0], *args),
    "tex_checker": lambda settings, args: tex_checker(settings[0], *args),
    "tex_gradient": lambda settings, args: tex_gradient(settings[0], *args),
    "tex_noise": lambda settings, args: tex_noise(settings, *args),
    "tex_wave": lambda settings, args: tex_wave(settings, *args),
    "tex_magic": lambda settings, args: tex_magic(settings, *args),
    "tex_white_noise": lambda settings, args: tex_white_noise(settings, *args),
    "tex_voronoi": lambda settings, args: voronoi.tex_voronoi(settings, *args),
    "tex_brick": lambda settings, args: tex_brick(settings, *args),
    "fresnel": lambda settings, args: fresnel(*args),
    "layer_weight": lambda settings, args: layer_weight(settings[0], *args),
    "bump": lambda settings, args: _no_derivatives("bump"),
    "hue_saturation_value": lambda settings, args: hue_saturation_value(*args),
    "gamma": lambda settings, args: gamma(*args),
    "brightness_contrast": lambda settings, args: brightness_contrast(*args),
}


# ----------------------------------------------------------------------------- noise
# Cycles' Perlin noise (kernel/svm/noise.h, fractal_noise.h, noisetex.h; Bob Jenkins' lookup3 hash of
# util/hash.h): the Noise Texture's values, bit for bit where float32 rounding agrees.

_U32 = np.uint32


def _rot(x, k):
    return (x << _U32(k)) | (x >> _U32(32 - k))


# lookup3's final mixing: (register mixed, register it takes, rotation), in order
_FINAL_STEPS = ((2, 1, 14), (0, 2, 11), (1, 0, 25), (2, 1, 16), (0, 2, 4), (1, 0, 14), (2, 1, 24))


def _final(a, b, c):
    registers = [a, b, c]
    for target, source, rotation in _FINAL_STEPS:
        registers[target] ^= registers[source]
        registers[target] -= _rot(registers[source], rotation)
    return registers[2]


# lookup3's mix: (register changed, register subtracted and rotated in, register it then adds to, rotation)
_MIX_STEPS = ((0, 2, 1, 4), (1, 0, 2, 6), (2, 1, 0, 8), (0, 2, 1, 16), (1, 0, 2, 19), (2, 1, 0, 4))


def _mix(a, b, c):
    registers = [a, b, c]
    for target, source, added, rotation in _MIX_STEPS:
        registers[target] -= registers[source]
        registers[target] ^= _rot(registers[source], rotation)
        registers[source] += registers[added]
    return registers


def hash_uint(*keys):
    """lookup3's hash of one to four uint32 keys (arrays broadcast)."""
    keys = [np.asarray(k).astype(np.int64).astype(_U32) for k in keys]
    shape = np.broadcast_shapes(*(k.shape for k in keys))
    start = _U32((0xDEADBEEF + (len(keys) << 2) + 13) & 0xFFFFFFFF)
    a, b, c = (np.full(shape, start, _U32) for _ in range(3))
    with np.errstate(over="ignore"):
        for register, key in zip((a, b, c), keys[:3]):
            register += key
        if len(keys) == 4:
            a, b, c = _mix(a, b, c)
            a += keys[3]
        return _final(a, b, c)


def hash_floats(*values):
    """Cycles' hash_float<n>_to_float of one to four floats' bits: the uint hash over 0xFFFFFFFF, in float32."""
    bits = [np.asarray(v, FLOAT).view(_U32) for v in values]
    return (hash_uint(*bits).astype(FLOAT) / FLOAT(0xFFFFFFFF)).astype(FLOAT)


def hash_float2_to_float(x, y):
    """Cycles' hash of two floats' bits to [0, 1]."""
    bits = [np.asarray(v, FLOAT).view(_U32) for v in (x, y)]
    return (hash_uint(*bits).astype(np.float64) / 0xFFFFFFFF).astype(FLOAT)


def random_float3_offset(seed):
    """The Noise Texture's offset of seed `seed`: each component 100 + a hash of (seed, k) x 100."""
    return np.array([FLOAT(100) + hash_float2_to_float(FLOAT(seed), FLOAT(k)) * FLOAT(100) for k in range(3)],
                    FLOAT)


def _fade(t):
    return t * t * t * (t * (t * FLOAT(6) - FLOAT(15)) + FLOAT(10))


def _grad3(h, x, y, z):
    h = (h & _U32(15)).astype(np.int64)
    u = np.where(h < 8, x, y)
    vt = np.where((h == 12) | (h == 14), x, z)
    v = np.where(h < 4, y, vt)
    return np.where(h & 1, -u, u) + np.where(h & 2, -v, v)


def perlin_3d(p):
    """Perlin noise of points (..., 3) float32."""
    cell = np.floor(p)
    f = (p - cell).astype(FLOAT)
    cell = cell.astype(np.int64)
    u, v, w = (_fade(f[..., k]) for k in range(3))
    corners = {}
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                h = hash_uint(cell[..., 0] + dx, cell[..., 1] + dy, cell[..., 2] + dz)
                corners[dx, dy, dz] = _grad3(h, f[..., 0] - dx, f[..., 1] - dy, f[..., 2] - dz)
    x1, y1, z1 = FLOAT(1) - u, FLOAT(1) - v, FLOAT(1) - w
    return (z1 * (y1 * (corners[0, 0, 0] * x1 + corners[1, 0, 0] * u) + v * (corners[0, 1, 0] * x1 + corners[1, 1, 0] * u))
            + w * (y1 * (corners[0, 0, 1] * x1 + corners[1, 0, 1] * u)
                   + v * (corners[0, 1, 1] * x1 + corners[1, 1, 1] * u))).astype(FLOAT)


def snoise_3d(p):
    """Signed noise in about [-1, 1]: each coordinate repeated every 100000 (shifted by half past 1e6), Perlin
    noise scaled by 0.982."""
    p = np.asarray(p, FLOAT)
    p = (np.fmod(p, FLOAT(100000)) + np.where(np.abs(p) >= 1e6, FLOAT(0.5), FLOAT(0))).astype(FLOAT)
    return (FLOAT(0.982) * perlin_3d(p)).astype(FLOAT)


NOISE_TYPES = ("FBM", "MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HETERO_TERRAIN")


def _noise_fractal(noise_type, p, detail, roughness, lacunarity, offset, gain, normalize):
    """One fractal of snoise_3d at points p (N, 3), its parameters (N,) each."""
    octaves = np.floor(detail).astype(np.int64)
    remainder = detail - np.floor(detail)
    count = int(octaves.max(initial=0))
    if noise_type == "FBM":
        fscale, amp = np.ones_like(detail), np.ones_like(detail)
        total, maxamp = np.zeros_like(detail), np.zeros_like(detail)
        for i in range(count + 1):
            live = i <= octaves
            t = snoise_3d(p * fscale[:, None])
            total = np.where(live, total + t * amp, total)
            maxamp = np.where(live, maxamp + amp, maxamp)
            amp = np.where(live, amp * roughness, amp)
            fscale = np.where(live, fscale * lacunarity, fscale)
        t = snoise_3d(p * fscale[:, None])
        total2 = total + t * amp
        if normalize:
            low = FLOAT(0.5) * total / maxamp + FLOAT(0.5)
            high = FLOAT(0.5) * total2 / (maxamp + amp) + FLOAT(0.5)
        else:
            low, high = total, total2
        return np.where(remainder != 0, low + remainder * (high - low), low)
    if noise_type == "MULTIFRACTAL":
        value, power = np.ones_like(detail), np.ones_like(detail)
        for i in range(count + 1):
            live = i <= octaves
            value = np.where(live, value * (power * snoise_3d(p) + 1), value)
            power = np.where(live, power * roughness, power)
            p = np.where(live[:, None], p * lacunarity[:, None], p)
        return np.where(remainder != 0, value * (remainder * power * snoise_3d(p) + 1), value)
    if noise_type == "HETERO_TERRAIN":
        power = roughness.copy()
        value = offset + snoise_3d(p)
        p = p * lacunarity[:, None]
        for i in range(1, count + 1):
            live = i <= octaves
            increment = (snoise_3d(p) + offset) * power * value
            value = np.where(live, value + increment, value)
            power = np.where(live, power * roughness, power)
            p = np.where(live[:, None], p * lacunarity[:, None], p)
        increment = (snoise_3d(p) + offset) * power * value
        return np.where(remainder != 0, value + remainder * increment, value)
    if noise_type == "HYBRID_MULTIFRACTAL":
        power, value, weight = np.ones_like(detail), np.zeros_like(detail), np.ones_like(detail)
        for i in range(count + 1):
            live = (weight > 0.001) & (i <= octaves)
            weight = np.where(live, np.minimum(weight, 1), weight)
            signal = (snoise_3d(p) + offset) * power
            power = np.where(live, power * roughness, power)
            value = np.where(live, value + weight * signal, value)
            weight = np.where(live, weight * gain * signal, weight)
            p = np.where(live[:, None], p * lacunarity[:, None], p)
        live = (remainder != 0) & (weight > 0.001)
        signal = (snoise_3d(p) + offset) * power
        return np.where(live, value + remainder * np.minimum(weight, 1) * signal, value)
    # RIDGED_MULTIFRACTAL
    power = roughness.copy()
    signal = offset - np.abs(snoise_3d(p))
    signal = signal * signal
    value = signal
    for i in range(1, count + 1):
        live = i <= octaves
        p = np.where(live[:, None], p * lacunarity[:, None], p)
        weight = np.clip(signal * gain, 0, 1)
        new_signal = offset - np.abs(snoise_3d(p))
        new_signal = new_signal * new_signal * weight
        value = np.where(live, value + new_signal * power, value)
        signal = np.where(live, new_signal, signal)
        power = np.where(live, power * roughness, power)
    return value


def tex_noise(settings, vector, scale, detail, roughness, lacunarity, offset, gain, distortion):
    """The Noise Texture in 3D (settings: noise type, normalize, output "Fac" or "Color"): the vector times
    the scale, distorted by noise at three offsets, a fractal of snoise_3d; its Color is that and the fractal
    at two more offsets."""
    noise_type, normalize, output = settings
    shape = np.shape(vector)[:-1]
    flat = [np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, scale, detail, roughness, lacunarity, offset, gain,
                                                          distortion)]
    vector, scale, detail, roughness, lacunarity, offset, gain, distortion = flat
    scalars = [a[:, 0] for a in (detail, roughness, lacunarity, offset, gain, distortion)]
    detail, roughness, lacunarity, offset, gain, distortion = scalars
    detail = np.clip(detail, 0, 15)
    roughness = np.maximum(roughness, 0)
    p = (vector * scale[:, :1]).astype(FLOAT)
    distorted = np.stack([snoise_3d(p + random_float3_offset(k)) for k in range(3)], axis=-1) * distortion[:, None]
    p = np.where((distortion != 0)[:, None], p + distorted, p).astype(FLOAT)

    def fractal(point):
        return _noise_fractal(noise_type, point, detail, roughness, lacunarity, offset, gain, normalize)

    value = fractal(p)
    if output == "Fac":
        out = np.repeat(value[:, None], 3, axis=-1)
    else:
        out = np.stack([value, fractal(p + random_float3_offset(3)), fractal(p + random_float3_offset(4))], axis=-1)
    return out.reshape(shape + (3,)).astype(FLOAT)


def brick_noise(n):
    """Cycles' fast integer noise of the Brick texture, in [0, 1) (uint32 n, wrapping)."""
    with np.errstate(over="ignore"):
        n = (np.asarray(n).astype(np.int64).astype(_U32) + _U32(1013)) & _U32(0x7FFFFFFF)
        n = (n >> _U32(13)) ^ n
        nn = (n * (n * n * _U32(60493) + _U32(19990303)) + _U32(1376312589)) & _U32(0x7FFFFFFF)
    return (FLOAT(0.5) * (nn.astype(FLOAT) / FLOAT(1073741824.0))).astype(FLOAT)


def tex_brick(settings, vector, colour1, colour2, mortar, scale, mortar_size, mortar_smooth, bias, brick_width,
              row_height):
    """The Brick Texture (Cycles' svm_brick; settings: offset, offset frequency, squash, squash frequency,
    output "Color" or "Fac"): rows of bricks, every offset-frequency-th row shifted, every squash-frequency-th
    squashed, each brick's tint an integer noise of its row and number, the mortar where a brick's edge is
    nearer than Mortar Size (smoothed by Mortar Smooth)."""
    offset_amount, offset_frequency, squash_amount, squash_frequency, output = settings
    shape = np.shape(vector)[:-1]
    arrays = [np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, colour1, colour2, mortar, scale, mortar_size,
                                                              mortar_smooth, bias, brick_width, row_height)]
    vector, colour1, colour2, mortar = arrays[:4]
    scale, mortar_size, mortar_smooth, bias, width, height = (a[:, 0] for a in arrays[4:])
    p = vector * scale[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        row = np.floor(p[:, 1] / height).astype(np.int64)
        offset = np.zeros_like(width)
        if offset_frequency and squash_frequency:
            width = np.where(np.fmod(row, squash_frequency) != 0, width, width * FLOAT(squash_amount)).astype(FLOAT)
            offset = np.where(np.fmod(row, offset_frequency) != 0, FLOAT(0), width * FLOAT(offset_amount))
        brick = np.floor((p[:, 0] + offset) / width).astype(np.int64)
        x = (p[:, 0] + offset) - width * brick
        y = p[:, 1] - height * row
        tint = np.clip(brick_noise((row << 16) + (brick & 0xFFFF)) + bias, 0, 1).astype(FLOAT)
        nearest = np.minimum(np.minimum(x, y), np.minimum(width - x, height - y))
        ramp = FLOAT(1) - nearest / mortar_size
        smooth = np.where(ramp < mortar_smooth, _smoothstep01(ramp / mortar_smooth), FLOAT(1))
        fac = np.where(nearest >= mortar_size, FLOAT(0), np.where(mortar_smooth == 0, FLOAT(1), smooth))
    fac = fac.astype(FLOAT)
    tinted = np.where((fac != 1)[:, None], (FLOAT(1) - tint[:, None]) * colour1 + tint[:, None] * colour2, colour1)
    out = tinted * (FLOAT(1) - fac[:, None]) + mortar * fac[:, None] if output == "Color" else \
        np.repeat(fac[:, None], 3, axis=-1)
    return out.reshape(shape + (3,)).astype(FLOAT)


def _smoothstep01(t):
    """Cycles' smoothstepf: 3t^2 - 2t^3 (no clamp: its callers keep t in [0, 1])."""
    return (t * t * (FLOAT(3) - FLOAT(2) * t)).astype(FLOAT)


NOISE_DIMENSIONS = ("1D", "2D", "3D", "4D")


def tex_white_noise(settings, vector, w):
    """The White Noise Texture (settings: dimensions, output "Value" or "Color"): a hash of the coordinates'
    bits (1D: W; 2D: x, y; 3D: x, y, z; 4D: x, y, z, W); its Color hashes them with 1 and 2 appended (4D: the
    coordinates in two other orders)."""
    dimensions, output = settings
    shape = np.shape(vector)[:-1]
    vector, w = (np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, w))
    keys = {"1D": [w[:, 0]], "2D": [vector[:, 0], vector[:, 1]], "3D": [vector[:, k] for k in range(3)],
            "4D": [vector[:, 0], vector[:, 1], vector[:, 2], w[:, 0]]}[dimensions]
    value = hash_floats(*keys)
    if output == "Value":
        out = np.repeat(value[:, None], 3, axis=-1)
    elif dimensions == "4D":
        x, y, z, fourth = keys
        out = np.stack([value, hash_floats(z, x, fourth, y), hash_floats(fourth, z, y, x)], axis=-1)
    else:
        one, two = np.full(len(value), FLOAT(1)), np.full(len(value), FLOAT(2))
        out = np.stack([value, hash_floats(*keys, one), hash_floats(*keys, two)], axis=-1)
    return out.reshape(shape + (3,)).astype(FLOAT)


WAVE_DIRECTIONS = ("X", "Y", "Z", "DIAGONAL", "SPHERICAL")
WAVE_PROFILES = ("SIN", "SAW", "TRI")


def tex_wave(settings, vector, scale, distortion, detail, detail_scale, detail_roughness, phase):
    """The Wave Texture (Cycles' svm_wave; settings: BANDS or RINGS, the bands' and the rings' direction, the
    profile, the output): its Fac on all three (its Color is the same grey)."""
    wave_type, bands_direction, rings_direction, profile, _ = settings
    shape = np.shape(vector)[:-1]
    vector, scale, distortion, detail, detail_scale, detail_roughness, phase = (
        np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, scale, distortion, detail, detail_scale,
                                                       detail_roughness, phase))
    p = ((vector * scale[:, :1] + FLOAT(0.000001)) * FLOAT(0.999999)).astype(FLOAT)
    if wave_type == "BANDS":
        n = p[:, "XYZ".index(bands_direction)] * FLOAT(20) if bands_direction != "DIAGONAL" \
            else (p[:, 0] + p[:, 1] + p[:, 2]) * FLOAT(10)
    else:
        keep = {"X": (0, 1, 1), "Y": (1, 0, 1), "Z": (1, 1, 0)}.get(rings_direction, (1, 1, 1))
        n = np.sqrt(np.sum((p * np.asarray(keep, FLOAT)) ** 2, axis=-1)) * FLOAT(20)
    n = n + phase[:, 0]
    fbm = _noise_fractal("FBM", p * detail_scale[:, :1], detail[:, 0], detail_roughness[:, 0],
                         np.full(len(p), FLOAT(2)), None, None, True)
    n = np.where(distortion[:, 0] != 0, n + distortion[:, 0] * (fbm * FLOAT(2) - FLOAT(1)), n)
    if profile == "SIN":
        value = FLOAT(0.5) + FLOAT(0.5) * np.sin(n - FLOAT(np.pi / 2))
    else:
        n = n / FLOAT(2 * np.pi)
        value = n - np.floor(n) if profile == "SAW" else np.abs(n - np.floor(n + FLOAT(0.5))) * FLOAT(2)
    return np.repeat(value[:, None], 3, axis=-1).reshape(shape + (3,)).astype(FLOAT)


def tex_magic(settings, vector, scale, distortion):
    """The Magic Texture (Cycles' svm_magic; settings: turbulence depth, output): its Color, or its Fac (the
    colour's mean) on all three."""
    depth, output = settings
    shape = np.shape(vector)[:-1]
    vector, scale, distortion = (np.asarray(a, FLOAT).reshape(-1, 3) for a in (vector, scale, distortion))
    p = vector * scale[:, :1]
    d = distortion[:, 0]
    x = np.sin((p[:, 0] + p[:, 1] + p[:, 2]) * FLOAT(5))
    y = np.cos((-p[:, 0] + p[:, 1] - p[:, 2]) * FLOAT(5))
    z = -np.cos((-p[:, 0] - p[:, 1] + p[:, 2]) * FLOAT(5))
    if depth > 0:
        x, y, z = x * d, y * d, z * d
        y = -np.cos(x - y + z) * d
    steps = [("x", lambda x, y, z: np.cos(x - y - z)), ("z", lambda x, y, z: np.sin(-x - y - z)),
             ("x", lambda x, y, z: -np.cos(-x + y - z)), ("y", lambda x, y, z: -np.sin(-x + y + z)),
             ("y", lambda x, y, z: -np.cos(-x + y + z)), ("x", lambda x, y, z: np.cos(x + y + z)),
             ("z", lambda x, y, z: np.sin(x + y - z)), ("x", lambda x, y, z: -np.cos(-x - y + z)),
             ("y", lambda x, y, z: -np.sin(x - y + z))]
    for level, (target, step) in enumerate(steps, start=2):
        if depth < level:
            break
        value = step(x, y, z) * d
        x, y, z = (value if target == "x" else x, value if target == "y" else y, value if target == "z" else z)
    divisor = np.where(d != 0, d * FLOAT(2), FLOAT(1))
    colour = np.stack([FLOAT(0.5) - x / divisor, FLOAT(0.5) - y / divisor, FLOAT(0.5) - z / divisor], axis=-1)
    if output == "Fac":
        colour = np.repeat(np.mean(colour, axis=-1, keepdims=True), 3, axis=-1)
    return colour.reshape(shape + (3,)).astype(FLOAT)
