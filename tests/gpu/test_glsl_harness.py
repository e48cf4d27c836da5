"""The GLSL harness itself: row layout, batching beyond one draw, textures, errors."""
import numpy as np
import pytest

from validation import glsl_harness


def test_rows_and_components(glsl):
    values = np.arange(12.0).reshape(4, 3)
    out = glsl([], "vec4(a.xyz * 2.0, float(row))", {"a": values}, 4)
    assert out.dtype == np.float32 and out.shape == (4, 4)
    assert np.array_equal(out[:, :3], values * 2) and np.array_equal(out[:, 3], np.arange(4))
    single = glsl([], "vec4(a.x + b.x)", {"a": np.ones(5), "b": np.arange(5.0)}, 1)
    assert single.shape == (5,) and np.array_equal(single, np.arange(5.0) + 1)


def test_more_rows_than_one_draw(glsl):
    """1024 x 1024 rows per draw: 1.2e6 rows need two, each row must land on its own texel."""
    count = glsl_harness.MAX_ROWS_PER_DRAW + 200_001
    values = np.arange(count, dtype=np.float64) % 4096
    out = glsl([], "vec4(a.x, float(row), 0.0, 0.0)", {"a": values}, 2)
    assert np.array_equal(out[:, 0], values)
    assert np.array_equal(out[:, 1], np.arange(count) % glsl_harness.MAX_ROWS_PER_DRAW)


def test_shader_is_reused(glsl):
    before = len(glsl_harness._shader_cache)
    glsl([], "vec4(a.x + 17.0)", {"a": np.zeros(3)}, 1)
    glsl([], "vec4(a.x + 17.0)", {"a": np.ones(1000)}, 1)
    assert len(glsl_harness._shader_cache) == before + 1


def test_textures_keep_numpy_layout(glsl):
    """numpy [row, col] is texel (x = col, y = row); array layers in order."""
    image = np.random.default_rng(0).random((3, 5, 4)).astype(np.float32)
    stack = np.random.default_rng(1).random((2, 3, 5, 4)).astype(np.float32)
    rows, cols = np.meshgrid(np.arange(3), np.arange(5), indexing="ij")
    inputs = {"c": np.c_[cols.ravel(), rows.ravel()]}
    flat = glsl([], "texelFetch(image, ivec2(c.xy), 0)", inputs, 4, {"image": image})
    assert np.array_equal(flat, image.reshape(-1, 4))
    layer = glsl([], "texelFetch(stack, ivec3(c.xy, 1), 0)", inputs, 4, {"stack": stack})
    assert np.array_equal(layer, stack[1].reshape(-1, 4))


def test_compile_error_quotes_the_line(blender):
    source = "float broken(float x)\n{\n  return x * undefined_name;\n}\n"
    with pytest.raises(glsl_harness.GlslCompileError) as error:
        glsl_harness.run_glsl([source], "vec4(broken(a.x))", {"a": np.zeros(2)}, 1)
    message = str(error.value)
    assert "undefined_name" in message and "line 3" in message
    assert "    3>   return x * undefined_name;" in message


def test_bad_inputs_are_rejected(glsl):
    with pytest.raises(ValueError):
        glsl([], "vec4(0.0)", {"a": np.zeros((3, 5))}, 1)
    with pytest.raises(ValueError):
        glsl([], "vec4(0.0)", {"a": np.zeros(3), "b": np.zeros(4)}, 1)
    with pytest.raises(ValueError):
        glsl([], "vec4(0.0)", {"row": np.zeros(3)}, 1)
