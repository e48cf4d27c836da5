"""Fixtures for GLSL tests on Mesa llvmpipe through a RenderEngine (gpu works only inside render()).

- `blender`: session-wide; imports pip `bpy` (skips the tests if it is
  missing) and resets it to empty factory settings once.
- `glsl`: a callable `glsl(library, call, inputs, output_components=4,
  textures=None)` around validation.glsl_harness.run_glsl, where
  `library` lists shaders/lib file names ("sg.glsl") and/or raw GLSL sources.
- `fuzz`: a `Fuzz` (numpy rng seeded from the test name) generating
  float32-exact inputs, including the degenerate ones of the stress tests.
- `record_error`: `record_error(label, value)` returns value and lists it
  under "measured max errors" in the pytest summary.
"""
import zlib

import numpy as np
import pytest


@pytest.fixture(scope="session")
def blender():
    bpy = pytest.importorskip("bpy")
    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy


@pytest.fixture(scope="session")
def glsl(blender):
    from validation import glsl_harness

    def run(library, call, inputs, output_components=4, textures=None):
        sources = []
        for item in library:
            if item.endswith(".glsl") and "\n" not in item:
                sources.extend(glsl_harness.load_library(item))
            else:
                sources.append(item)
        return glsl_harness.run_glsl(sources, call, inputs, output_components, textures)

    glsl_harness.register()
    yield run


class Fuzz:
    """Random float32-representable inputs (numpy rng) shared by the GLSL tests.

    Every generator returns float64 arrays whose values are exactly float32,
    so the numpy reference sees the same inputs as the GLSL kernel.
    """

    def __init__(self, seed):
        self.rng = np.random.default_rng(seed)

    @staticmethod
    def f32(values):
        return np.asarray(values, np.float32).astype(np.float64)

    def unit_vectors(self, count):
        v = self.rng.normal(size=(count, 3))
        return self.f32(v / np.linalg.norm(v, axis=1, keepdims=True))

    def log_uniform(self, low, high, count):
        return self.f32(np.exp(self.rng.uniform(np.log(low), np.log(high), count)))

    def uniform(self, low, high, count):
        return self.f32(self.rng.uniform(low, high, count))

    def near(self, vectors, spread):
        """Unit vectors within about `spread` radians of `vectors` (opposite axes: pass -v)."""
        v = vectors + spread * self.rng.normal(size=vectors.shape)
        return self.f32(v / np.linalg.norm(v, axis=1, keepdims=True))

    def stress_vectors(self, count):
        """Unit vectors, with 1/8 each exact poles, tiny, zero and huge (non-normalised) vectors."""
        v = self.unit_vectors(count)
        kind = self.rng.integers(0, 8, count)
        v[kind == 1] = [0.0, 0.0, 1.0]
        v[kind == 2] = [0.0, 0.0, -1.0]
        v[kind == 3] *= 1e-30
        v[kind == 4] = 0.0
        v[kind == 5] *= 1e30
        return self.f32(v)

    def stress_sharpness(self, count):
        """Log-uniform 1e-4..1e6, with exact 0, 1e-4 and 1e6 mixed in."""
        s = self.log_uniform(1e-4, 1e6, count)
        kind = self.rng.integers(0, 8, count)
        s[kind == 1] = 0.0
        s[kind == 2] = 1e-4
        s[kind == 3] = 1e6
        return self.f32(s)

    def stress_amplitude(self, count):
        a = self.log_uniform(1e-3, 1e3, count)
        a[self.rng.integers(0, 4, count) == 0] = 0.0
        return self.f32(a)

    @staticmethod
    def relative_error(actual, expected, floor):
        """|actual - expected| / max(|expected|, floor), elementwise (floor: the absolute-error scale)."""
        actual = np.asarray(actual, np.float64)
        expected = np.asarray(expected, np.float64)
        return np.abs(actual - expected) / np.maximum(np.abs(expected), floor)


@pytest.fixture
def bakes():
    """engine_fixtures.bake_objects for a test, every bake cleared after it."""
    import engine_fixtures as fx

    yield fx.bake_objects
    fx.clear_bakes()


@pytest.fixture
def fuzz(request):
    """A Fuzz seeded from the test's name: reproducible, different per test."""
    return Fuzz(zlib.crc32(request.node.name.encode()))


_measured_errors = {}


@pytest.fixture
def record_error():
    """record_error(label, value): a measured max error, listed in the pytest summary."""
    def record(label, value):
        _measured_errors[label] = float(value)
        return float(value)
    return record


def pytest_terminal_summary(terminalreporter):
    if _measured_errors:
        terminalreporter.section("GLSL (float32) vs numpy (float64): measured max errors")
        for label, value in sorted(_measured_errors.items()):
            terminalreporter.write_line(f"{label:60s} {value:.3g}")
