"""shaders/lib/env_prefilter.glsl (texture array on llvmpipe) against env_prefilter.lookup (numpy).

The numpy lookup already computes in float32 like the GPU; what is measured
here is the driver's bilinear filtering and the GLSL arithmetic.
"""
import numpy as np
import pytest

from sg_prt_addon.lighting import env_prefilter

N = 20000
LIB = ["sg.glsl", "env_prefilter.glsl"]


@pytest.fixture(scope="module")
def prefiltered():
    image = np.random.default_rng(7).random((16, 32, 3)).astype(np.float32) * 4
    return env_prefilter.prefilter_environment(image, size=64)


def _transform_source(prefiltered):
    """The per-layer (scale, offset) array as a GLSL constant (a uniform in the engine)."""
    count = prefiltered.sharpness.size
    pairs = [(float(prefiltered.texcoord_scale[k]), float(prefiltered.texcoord_offset[k])) for k in range(count)]
    pairs += [(0.0, 0.0)] * (32 - count)
    items = ", ".join(f"vec2({scale!r}, {offset!r})" for scale, offset in pairs)
    return (f"const vec2 TEST_TRANSFORMS[32] = vec2[32]({items});\n"
            f"const float TEST_LOG2_MIN = {prefiltered.log2_min_sharpness!r};\n"
            f"const float TEST_LEVELS_PER_OCTAVE = {prefiltered.levels_per_octave!r};\n"
            f"const int TEST_LAYER_COUNT = {count};\n"
            f"const vec4 TEST_MEAN = vec4({', '.join(repr(float(v)) for v in prefiltered.mean_radiance)}, 0.0);\n")


def _rgba(layers):
    return np.concatenate([layers, np.zeros(layers.shape[:-1] + (1,), np.float32)], axis=-1)


def _lookup_inputs(fuzz):
    axis = fuzz.unit_vectors(N)
    axis[:6] = [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, -1, 0], [0.7071068, 0, -0.7071068], [0, 0, 0]]
    # sharpness below, inside and above the levels 0.125..4096, and 0
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-6, 0.125, 4096.0, 1e6], fuzz.log_uniform(0.01, 2e4, N - 5)]))
    return axis, sharpness


def test_oct_encode_and_blend_parameter(glsl, fuzz, record_error, prefiltered):
    axis, sharpness = _lookup_inputs(fuzz)
    call = ("vec4(oct_encode(safe_normalize(p.xyz)), env_prefilter_blend_parameter(p.w, TEST_LOG2_MIN,"
            " TEST_LEVELS_PER_OCTAVE, TEST_LAYER_COUNT), 0.0)")
    out = glsl(LIB + [_transform_source(prefiltered)], call, {"p": np.c_[axis, sharpness]}, 3)
    coords = env_prefilter.oct_encode(env_prefilter.sg.normalize(axis))
    assert record_error("env_prefilter oct_encode, absolute", np.abs(out[:, :2] - coords).max()) <= 1e-6
    position = env_prefilter.blend_parameter(prefiltered, sharpness)
    assert record_error("env_prefilter blend_parameter, absolute", np.abs(out[:, 2] - position).max()) <= 1e-5


@pytest.mark.parametrize("content", ["prefiltered", "noise"])
def test_lookup(glsl, fuzz, record_error, prefiltered, content):
    """Against env_prefilter.lookup; 'noise' replaces the layers by white noise in [0, 1]
    (the worst case for the filtering weights), keeping the layout."""
    if content == "noise":
        prefiltered = env_prefilter.PrefilteredEnvironment(
            fuzz.rng.random(prefiltered.layers.shape).astype(np.float32), prefiltered.sharpness,
            prefiltered.content_size, prefiltered.texcoord_scale, prefiltered.texcoord_offset,
            prefiltered.levels_per_octave, prefiltered.mean_radiance)
    axis, sharpness = _lookup_inputs(fuzz)
    amplitude = fuzz.uniform(0.0, 2.0, N)
    call = """
    vec4 value = env_prefilter_lookup(environment, p.xyz, p.w, TEST_LOG2_MIN, TEST_LEVELS_PER_OCTAVE,
                                      TEST_LAYER_COUNT, TEST_TRANSFORMS, TEST_MEAN);
    vec4 integral = env_prefilter_lookup_integral(environment, p.xyz, p.w, a.x, TEST_LOG2_MIN,
                                                  TEST_LEVELS_PER_OCTAVE, TEST_LAYER_COUNT, TEST_TRANSFORMS,
                                                  TEST_MEAN);
    result = a.y > 0.5 ? integral : value;
    """
    textures = {"environment": _rgba(prefiltered.layers)}
    source = LIB + [_transform_source(prefiltered)]
    out = glsl(source, call, {"p": np.c_[axis, sharpness], "a": np.c_[amplitude, np.zeros(N)]}, 3, textures)
    expected = env_prefilter.lookup(prefiltered, axis, sharpness)
    peak = np.abs(prefiltered.layers).max()
    # llvmpipe filters float textures with float weights (measured 4e-6); discrete GPUs
    # commonly use 8-bit weights, which would be up to 1/512 of the texel contrast
    assert record_error(f"env_prefilter lookup ({content}), absolute / max layer value",
                        np.abs(out - expected).max() / peak) <= 2e-5
    integral = glsl(source, call, {"p": np.c_[axis, sharpness], "a": np.c_[amplitude, np.ones(N)]}, 3, textures)
    expected_integral = env_prefilter.lookup_integral(prefiltered, axis, sharpness, amplitude)
    scale = env_prefilter.sg.sphere_integral(sharpness, amplitude)[:, None] * peak + 1e-30
    assert np.all(np.abs(integral - expected_integral) <= 2e-5 * scale)
