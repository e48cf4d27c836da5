"""shaders/lib/node_functions.glsl (float32, llvmpipe) against sg_prt_addon/reflectance/node_functions.py
(float32): every Math operation, Clamp, Map Range, the Mix blends, the colour nodes, Mapping, Vector Math,
Fresnel, Layer Weight and the procedural textures, over inputs that cross their edges (zero, negative, beyond
one)."""
import numpy as np
import pytest

from sg_prt_addon.reflectance import node_functions
from sg_prt_addon.techniques import material_textures

# pure functions of llvmpipe's float32: one Blender's run answers for all (the numpy mirrors' noise is slow)
pytestmark = pytest.mark.one_tier

N = 4096
LIB = [material_textures.noise_offsets_source(), "node_functions.glsl"]


def _inputs(fuzz):
    """Three (N, 3) inputs: a spread over [-3, 3] with exact zeros, integers and halves mixed in."""
    values = []
    for _ in range(3):
        x = fuzz.rng.uniform(-3.0, 3.0, (N, 3))
        special = fuzz.rng.integers(0, 6, (N, 3))
        x = np.where(special == 0, 0.0, np.where(special == 1, np.round(x), np.where(special == 2, np.round(x * 2) / 2, x)))
        values.append(x.astype(np.float32))
    return values


def _run(glsl, call, args):
    inputs = {name: np.c_[value, np.zeros(N)] for name, value in zip("abcdef", args)}
    return glsl(LIB, f"result = vec4({call}, 0.0);", inputs, 3)


def _close(record_error, label, got, expected, bound=2e-5):
    """The largest error, relative where the value passes 1, absolute below (non-finite references left out)."""
    expected = np.asarray(expected, np.float64)
    finite = np.isfinite(expected) & (np.abs(expected) < 1e6)
    error = np.abs(got - expected) / np.maximum(np.abs(expected), 1.0)
    return record_error(f"node_functions {label}", np.max(np.where(finite, error, 0.0)))


# operations with a jump where float32 rounding of a quotient or sum may fall either side: a few edge points
JUMPS = {"ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO", "WRAP", "SNAP", "PINGPONG",
         "LESS_THAN", "GREATER_THAN", "COMPARE", "SIGN", "POWER"}


@pytest.mark.parametrize("operation", sorted(node_functions.MATH))
def test_math_operation(glsl, fuzz, record_error, operation):
    a, b, c = _inputs(fuzz)
    if operation in ("SINH", "COSH", "EXPONENT", "TANGENT"):
        a = a * np.float32(0.5)                     # keep away from float32 overflow and tan's poles
    got = _run(glsl, f"node_math_{operation.lower()}(a.xyz, b.xyz, c.xyz)", (a, b, c))
    expected = np.asarray(node_functions.math(operation, a, b, c), np.float64)
    with np.errstate(invalid="ignore"):
        error = np.where(np.isfinite(expected), np.abs(got - expected) / np.maximum(np.abs(expected), 1.0), 0.0)
    if operation in JUMPS:
        # at a jump the two sides differ by the jump: allowed at a handful of points
        assert np.mean(error > 1e-4) < 0.002, (operation, np.mean(error > 1e-4))
        error = np.where(error > 1e-4, 0.0, error)
    assert record_error(f"node_functions math {operation}", error.max()) < 2e-5


@pytest.mark.parametrize("clamp_type", ["MINMAX", "RANGE"])
def test_clamp(glsl, fuzz, record_error, clamp_type):
    a, b, c = _inputs(fuzz)
    name = "node_clamp" if clamp_type == "MINMAX" else "node_clamp_range"
    got = _run(glsl, f"{name}(a.xyz, b.xyz, c.xyz)", (a, b, c))
    assert _close(record_error, f"clamp {clamp_type}", got, node_functions.clamp(a, b, c, clamp_type)) < 1e-6


@pytest.mark.parametrize("interpolation", node_functions.MAP_RANGE_INTERPOLATIONS)
@pytest.mark.parametrize("clamped", [True, False])
def test_map_range(glsl, fuzz, record_error, interpolation, clamped):
    value, low, high = _inputs(fuzz)
    to_low, to_high, steps = _inputs(fuzz)
    steps = np.abs(np.round(steps * 2))
    index = node_functions.MAP_RANGE_INTERPOLATIONS.index(interpolation)
    got = _run(glsl, f"node_map_range(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz, f.xyz, {index}, {str(clamped).lower()})",
               (value, low, high, to_low, to_high, steps))
    expected = node_functions.map_range(value, low, high, to_low, to_high, steps, interpolation, clamped)
    error = np.abs(got - expected) / np.maximum(np.abs(expected), 1.0)
    if interpolation == "STEPPED":        # floor of a quotient at a step edge
        assert np.mean(error > 1e-4) < 0.002
        error = np.where(error > 1e-4, 0.0, error)
    assert record_error(f"node_functions map_range {interpolation} clamped={clamped}", error.max()) < 1e-4


@pytest.mark.parametrize("blend", node_functions.MIX_BLENDS)
def test_mix_blend(glsl, fuzz, record_error, blend):
    t, a, b = _inputs(fuzz)
    t = np.clip(t * 0.3 + 0.5, 0.0, 1.0)            # the factor a node clamps
    a, b = np.abs(a) * np.float32(0.5), np.abs(b) * np.float32(0.5)
    got = _run(glsl, f"node_mix_{blend.lower()}(a.xyz, b.xyz, c.xyz)", (t, a, b))
    assert _close(record_error, f"mix {blend}", got, node_functions.mix(blend, t, a, b)) < 2e-5


def test_colour_functions(glsl, fuzz, record_error):
    colour, hue, other = _inputs(fuzz)
    colour = np.abs(colour) * np.float32(0.4)
    hue = np.repeat(np.abs(hue[:, :1]) * np.float32(0.3), 3, axis=1)
    saturation = np.repeat(np.abs(other[:, :1]), 3, axis=1)
    value = np.repeat(np.abs(other[:, 1:2]), 3, axis=1)
    factor = np.repeat(np.clip(other[:, 2:] * 0.3 + 0.5, 0, 1), 3, axis=1)
    got = _run(glsl, "node_hue_saturation_value(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz)",
               (colour, hue, saturation, value, factor))
    expected = node_functions.hue_saturation_value(colour, hue, saturation, value, factor)
    assert _close(record_error, "hue_saturation_value", got, expected) < 5e-5
    got = _run(glsl, "node_gamma(a.xyz, b.xyz)", (colour, hue * 5))
    assert _close(record_error, "gamma", got, node_functions.gamma(colour, hue * 5)) < 2e-5
    got = _run(glsl, "node_brightness_contrast(a.xyz, b.xyz, c.xyz)", (colour, hue - 0.2, saturation - 0.5))
    expected = node_functions.brightness_contrast(colour, hue - 0.2, saturation - 0.5)
    assert _close(record_error, "brightness_contrast", got, expected) < 1e-6


@pytest.mark.parametrize("mapping_type", ["POINT", "TEXTURE", "VECTOR", "NORMAL"])
def test_mapping(glsl, fuzz, record_error, mapping_type):
    vector, location, rotation = _inputs(fuzz)
    scale = _inputs(fuzz)[0]
    index = ("POINT", "TEXTURE", "VECTOR", "NORMAL").index(mapping_type)
    got = _run(glsl, f"node_mapping(a.xyz, b.xyz, c.xyz, d.xyz, {index})", (vector, location, rotation, scale))
    expected = node_functions.mapping(mapping_type, vector, location, rotation, scale)
    assert _close(record_error, f"mapping {mapping_type}", got, expected) < 5e-5


@pytest.mark.parametrize("operation", node_functions.VECTOR_MATH)
def test_vector_math(glsl, fuzz, record_error, operation):
    a, b, _ = _inputs(fuzz)
    got = _run(glsl, f"node_vector_{operation.lower()}(a.xyz, b.xyz)", (a, b))
    assert _close(record_error, f"vector_math {operation}", got, node_functions.vector_math(operation, a, b)) < 2e-5


def test_checker_and_gradients(glsl, fuzz, record_error):
    vector, colour1, colour2 = _inputs(fuzz)
    scale = np.full_like(vector, 2.5)
    for output, flag in (("Color", "true"), ("Fac", "false")):
        got = _run(glsl, f"node_tex_checker(a.xyz, b.xyz, c.xyz, d.xyz, {flag})", (vector, colour1, colour2, scale))
        expected = node_functions.tex_checker(output, vector, colour1, colour2, scale)
        # a cell's edge one rounding off: the other cell, at a few points
        assert np.mean(np.abs(got - expected).max(axis=1) > 1e-5) < 0.002
    vector = vector * np.float32(0.4) + np.float32(0.01)       # no signed zeros: atan2(0, -0) is pi in C
    for index, gradient_type in enumerate(node_functions.GRADIENTS):
        got = _run(glsl, f"node_tex_gradient(a.xyz, {index})", (vector,))
        expected = node_functions.tex_gradient(gradient_type, vector)
        assert _close(record_error, f"gradient {gradient_type}", got, expected) < 2e-5


@pytest.mark.parametrize("noise_type", node_functions.NOISE_TYPES)
def test_noise_texture(glsl, fuzz, record_error, noise_type):
    """The Noise Texture (every type, Fac and Color, with distortion and a fractional detail) against the numpy
    mirror of Cycles' noise: the same lookup3 hash and Perlin gradients, float32 on both sides."""
    count = 512                     # the numpy mirror's octave loops are slow: fewer points
    vector = fuzz.rng.uniform(-4.0, 4.0, (count, 3)).astype(np.float32)
    params = [np.full((count, 3), value, np.float32) for value in (1.7, 3.4, 0.55, 2.1, 0.3, 1.2, 0.4)]
    index = node_functions.NOISE_TYPES.index(noise_type)
    for colour in (False, True):
        call = (f"node_tex_noise(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz, f.xyz, g.xyz, h.xyz, {index}, true, "
                f"{str(colour).lower()})")
        names = "abcdefgh"
        inputs = {name: np.c_[value, np.zeros(count)] for name, value in zip(names, [vector] + params)}
        got = glsl(LIB, f"result = vec4({call}, 0.0);", inputs, 3)
        expected = node_functions.tex_noise((noise_type, True, "Color" if colour else "Fac"), vector, *params)
        assert _close(record_error, f"noise {noise_type} colour={colour}", got, expected) < 1e-4


@pytest.mark.parametrize("settings", [("BANDS", "X", "X", "SIN", "Fac"), ("BANDS", "DIAGONAL", "X", "SAW", "Fac"),
                                      ("BANDS", "Z", "X", "TRI", "Fac"), ("RINGS", "X", "SPHERICAL", "SIN", "Fac"),
                                      ("RINGS", "X", "Y", "SAW", "Fac")])
def test_wave_texture(glsl, fuzz, record_error, settings):
    """The Wave texture (types, directions, profiles, with distortion) against its numpy mirror."""
    count = 512
    vector = fuzz.rng.uniform(-2.0, 2.0, (count, 3)).astype(np.float32)
    params = [np.full((count, 3), value, np.float32) for value in (1.3, 2.5, 2.0, 1.5, 0.6, 0.4)]
    inputs = {name: np.c_[value, np.zeros(count)] for name, value in zip("abcdefg", [vector] + params)}
    wave_type, bands, rings, profile, _ = settings
    flags = (f"{0 if wave_type == 'BANDS' else 1}, {node_functions.WAVE_DIRECTIONS.index(bands)}, "
             f"{node_functions.WAVE_DIRECTIONS.index(rings)}, {node_functions.WAVE_PROFILES.index(profile)}")
    got = glsl(LIB, f"result = vec4(node_tex_wave(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz, f.xyz, g.xyz, "
               f"{flags}), 0.0);", inputs, 3)
    error = np.abs(got - node_functions.tex_wave(settings, vector, *params)).max(axis=1)
    # the saw and triangle profiles jump: a point one rounding off lands on the other side
    assert np.mean(error > 1e-3) < 0.01, np.mean(error > 1e-3)
    assert record_error(f"node_functions wave {settings[:4]}", np.where(error > 1e-3, 0.0, error).max()) < 1e-4


@pytest.mark.parametrize("depth", [0, 3, 10])
def test_magic_texture(glsl, fuzz, record_error, depth):
    """The Magic texture's Color and Fac against its numpy mirror: each level of its depth takes the sine or
    cosine of the last times the distortion (2.5 here), so GLSL's sin and cos rounding grows with it: a bound of
    1e-5 + 2e-6 x 2.5^depth (measured 7e-7, 2.7e-5, 3.8e-3 at depths 0, 3, 10)."""
    count = 512
    vector = fuzz.rng.uniform(-2.0, 2.0, (count, 3)).astype(np.float32)
    scale, distortion = (np.full((count, 3), value, np.float32) for value in (1.3, 2.5))
    inputs = {name: np.c_[value, np.zeros(count)] for name, value in zip("abc", (vector, scale, distortion))}
    for colour in (True, False):
        got = glsl(LIB, f"result = vec4(node_tex_magic(a.xyz, b.xyz, c.xyz, {depth}, "
                   f"{str(colour).lower()}), 0.0);", inputs, 3)
        expected = node_functions.tex_magic((depth, "Color" if colour else "Fac"), vector, scale, distortion)
        assert _close(record_error, f"magic depth {depth} colour={colour}", got, expected) < 1e-5 + 2e-6 * 2.5 ** depth


@pytest.mark.parametrize("dimensions", node_functions.NOISE_DIMENSIONS)
def test_white_noise_texture(glsl, fuzz, record_error, dimensions):
    """The White Noise texture's Value and Color: the same lookup3 hash of the same float bits, so equal to the
    last bit (float32 division on both sides)."""
    vector, w, _ = _inputs(fuzz)
    index = node_functions.NOISE_DIMENSIONS.index(dimensions)
    for output in ("Value", "Color"):
        got = _run(glsl, f"node_tex_white_noise(a.xyz, b.xyz, {index}, {str(output == 'Color').lower()})",
                   (vector, w))
        expected = node_functions.tex_white_noise((dimensions, output), vector, w)
        assert record_error(f"node_functions white noise {dimensions} {output}",
                            np.abs(got - expected).max()) == 0.0


@pytest.mark.parametrize("extrapolate", [True, False])
def test_curves(glsl, fuzz, record_error, extrapolate):
    """A curves node's GLSL helper (its table a constant array) against node_functions.curves, inside the
    points' span and past it (extended by the end slopes, or held)."""
    table = tuple(tuple(float(v) for v in row) for row in fuzz.rng.uniform(-1.0, 2.0, (256, 3)).astype(np.float32))
    settings = (-0.5, 1.5, extrapolate, table)
    helpers = {}
    name = material_textures._curves_helper(settings, helpers)
    fac, value, _ = _inputs(fuzz)
    fac = np.abs(fac) / 3.0
    source = helpers[settings][1] + "\n"
    got = glsl([source], f"result = vec4({name}(a.xyz, b.xyz), 0.0);",
               {"a": np.c_[fac, np.zeros(N)], "b": np.c_[value, np.zeros(N)]}, 3)
    expected = node_functions.curves(settings, fac, value)
    assert _close(record_error, f"curves extrapolate={extrapolate}", got, expected) < 1e-5


def test_bump_normal(glsl, fuzz, record_error):
    """The Bump node's normal from the height's and the position's differences across the pixel (inverted and
    not, strengths past [0, 1]) against node_functions.bump_normal."""
    normal = fuzz.rng.normal(size=(N, 3)).astype(np.float32)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    dpdx, dpdy = (fuzz.rng.normal(scale=0.01, size=(N, 3)).astype(np.float32) for _ in range(2))
    heights = fuzz.rng.normal(scale=0.02, size=(N, 3)).astype(np.float32)
    strength, distance = (fuzz.rng.uniform(-0.5, 1.5, (N, 3)).astype(np.float32) for _ in range(2))
    inputs = {name: np.c_[value, np.zeros(N)] for name, value in zip("abcdef", (strength, distance, heights, dpdx,
                                                                               dpdy, normal))}
    for invert in (False, True):
        got = glsl(LIB, f"result = vec4(node_bump_normal(a.xyz, b.xyz, c.x, c.y, d.xyz, e.xyz, f.xyz, "
                   f"{str(invert).lower()}), 0.0);", inputs, 3)
        expected = node_functions.bump_normal(strength, distance, heights[:, :1], heights[:, 1:2], dpdx, dpdy,
                                              normal, invert)
        assert _close(record_error, f"bump invert={invert}", got, expected) < 1e-5


@pytest.mark.parametrize("feature, metric, detail", [
    ("F1", "EUCLIDEAN", 0.0), ("F2", "MANHATTAN", 0.0), ("SMOOTH_F1", "EUCLIDEAN", 0.0), ("F1", "CHEBYCHEV", 2.5),
    ("F2", "MINKOWSKI", 1.0), ("DISTANCE_TO_EDGE", "EUCLIDEAN", 1.5), ("N_SPHERE_RADIUS", "EUCLIDEAN", 0.0)])
def test_voronoi_texture(glsl, fuzz, record_error, feature, metric, detail):
    """The Voronoi texture (features, metrics, fractal detail with a fractional octave, normalized) against its
    numpy mirror, every output: the same PCG hash of the same cells; the distances' float32 rounding apart,
    equal where no two points are nearly equally near (a few points may take the other)."""
    from sg_prt_addon.reflectance import voronoi

    count = 512
    vector = fuzz.rng.uniform(-3.0, 3.0, (count, 3)).astype(np.float32)
    params = [np.full((count, 3), value, np.float32) for value in (2.3, detail, 0.6, 2.1, 0.7, 1.3, 0.85)]
    inputs = {name: np.c_[value, np.zeros(count)] for name, value in zip("abcdefgh", [vector] + params)}
    for output in voronoi.OUTPUTS:
        flags = (f"{voronoi.FEATURES.index(feature)}, {voronoi.METRICS.index(metric)}, true, "
                 f"{voronoi.OUTPUTS.index(output)}")
        got = glsl(LIB + ["voronoi.glsl"], f"result = vec4(node_tex_voronoi(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz, "
                   f"f.xyz, g.xyz, h.xyz, {flags}), 0.0);", inputs, 3)
        expected = voronoi.tex_voronoi((feature, metric, True, output), vector, *params)
        error = np.abs(got - expected).max(axis=1) / np.maximum(np.abs(expected).max(axis=1), 1.0)
        assert np.mean(error > 1e-4) < 0.01, (output, np.mean(error > 1e-4))
        assert record_error(f"voronoi {feature} {metric} detail {detail} {output}",
                            np.where(error > 1e-4, 0.0, error).max()) < 1e-4


@pytest.mark.parametrize("settings", [(0.5, 2, 1.0, 2, "Color"), (0.3, 3, 0.6, 2, "Fac"), (0.0, 0, 1.0, 0, "Color")])
def test_brick_texture(glsl, fuzz, record_error, settings):
    """The Brick texture (offset and squashed rows, negative rows and bricks, smooth and hard mortar) against its
    numpy mirror: the same integer noise; a point on a brick's edge may fall either side of it."""
    count = 2048
    vector = fuzz.rng.uniform(-3.0, 3.0, (count, 3)).astype(np.float32)
    params = [np.full((count, 3), value, np.float32) for value in
              ((0.8, 0.2, 0.1), (0.1, 0.3, 0.7), (0.9, 0.9, 0.85), 2.5, 0.04, 0.4, 0.1, 0.5, 0.25)]
    params[5][count // 2:] = 0.0                    # hard mortar in half the points
    inputs = {name: np.c_[value, np.zeros(count)] for name, value in zip("abcdefghij", [vector] + params)}
    offset, offset_frequency, squash, squash_frequency, output = settings
    got = glsl(LIB, f"result = vec4(node_tex_brick(a.xyz, b.xyz, c.xyz, d.xyz, e.xyz, f.xyz, g.xyz, h.xyz, i.xyz, "
               f"j.xyz, {offset}, {offset_frequency}, {squash}, {squash_frequency}, "
               f"{str(output == 'Color').lower()}), 0.0);", inputs, 3)
    expected = node_functions.tex_brick(settings, vector, *params)
    error = np.abs(got - expected).max(axis=1)
    assert np.mean(error > 1e-4) < 0.005, np.mean(error > 1e-4)
    # the mortar's ramp divides by Mortar Size (0.04): the positions' rounding grows 25 times (2.2e-5 measured)
    assert record_error(f"node_functions brick {settings}", np.where(error > 1e-4, 0.0, error).max()) < 5e-5


def test_fresnel_and_layer_weight(glsl, fuzz, record_error):
    """Fresnel and Layer Weight (both outputs) against their numpy mirrors, over views from either side of the
    normal (a surface seen from behind inverts the index)."""
    count = 2048
    normal = fuzz.unit_vectors(count).astype(np.float32)
    incoming = fuzz.unit_vectors(count).astype(np.float32)
    value = np.repeat(fuzz.rng.uniform(0.0, 3.0, (count, 1)), 3, axis=1).astype(np.float32)
    blend = np.repeat(fuzz.rng.uniform(0.0, 1.0, (count, 1)), 3, axis=1).astype(np.float32)
    blend[::7] = 0.5
    inputs = {name: np.c_[v, np.zeros(count)] for name, v in zip("abcd", (value, normal, incoming, blend))}
    got = glsl(LIB, "result = vec4(node_fresnel(a.xyz, b.xyz, c.xyz), 0.0);", inputs, 3)
    assert _close(record_error, "fresnel", got, node_functions.fresnel(value, normal, incoming)) < 2e-5
    for output, flag in (("Fresnel", "true"), ("Facing", "false")):
        got = glsl(LIB, f"result = vec4(node_layer_weight(d.xyz, b.xyz, c.xyz, {flag}), 0.0);", inputs, 3)
        expected = node_functions.layer_weight(output, blend, normal, incoming)
        assert _close(record_error, f"layer_weight {output}", got, expected) < 2e-5
