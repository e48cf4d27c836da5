"""1e6 random light evaluations and prefilter lookups, in float32 and float64: never NaN or Inf.

Covers shading points on and inside the light, zero distance, radius 0, huge and tiny
scales, zero and non-finite axes, sharpness 0, inside and far outside the level range."""
import numpy as np
import pytest

from sg_prt_addon.lighting import env_prefilter, lights
from sg_prt_addon.spherical import sg

COUNT = 1_000_000


def _finite(*arrays):
    return all(np.all(np.isfinite(a)) for a in arrays)


@pytest.fixture(scope="module")
def prefiltered():
    image = np.random.default_rng(0).random((32, 64, 3)) * 10
    image[5, 7] = 1e4  # a sun
    return env_prefilter.prefilter_environment(image, size=32)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_point_and_sphere_lights(dtype):
    rng = np.random.default_rng(1)
    scale = 10.0 ** rng.uniform(-6, 6, (COUNT, 1))
    light = (rng.normal(size=(COUNT, 3)) * scale).astype(dtype)
    offset = rng.normal(size=(COUNT, 3)) * scale * 10.0 ** rng.uniform(-8, 2, (COUNT, 1))
    x = (light + offset).astype(dtype)
    x[:1000] = light[:1000]  # zero distance
    radius = (scale[:, 0] * 10.0 ** rng.uniform(-3, 1, COUNT)).astype(dtype)
    radius[1000:2000] = 0  # point lights
    radius[2000:3000] = np.linalg.norm(offset[2000:3000], axis=1)  # shading point on the light's surface
    intensity = (10.0 ** rng.uniform(-3, 6, COUNT)).astype(dtype)
    for model in ("energy", "paper"):
        axis, sharpness, amplitude = lights.sphere_light_sg(x, light, radius, intensity, model)
        assert axis.dtype == dtype and sharpness.dtype == dtype and amplitude.dtype == dtype
        assert _finite(axis, sharpness, amplitude)
        assert np.all(sharpness > 0) and np.all(sharpness <= lights.MAX_SHARPNESS) and np.all(amplitude >= 0)
        np.testing.assert_allclose(np.linalg.norm(axis.astype(np.float64), axis=1), 1.0, atol=1e-5)
        # downstream SG algebra stays finite
        assert _finite(sg.sphere_integral(sharpness, amplitude))


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_directional_and_spot_lights(dtype):
    rng = np.random.default_rng(2)
    n = COUNT // 4
    direction = rng.normal(size=(n, 3)).astype(dtype)
    direction[:100] = 0  # degenerate direction
    half_angle = rng.uniform(0, np.pi, n).astype(dtype)
    half_angle[100:200] = 0
    axis, sharpness, amplitude = lights.directional_light_sg(direction, half_angle, rng.random((n, 3)).astype(dtype))
    assert amplitude.dtype == dtype and _finite(axis, sharpness, amplitude)
    x = rng.normal(size=(n, 3)).astype(dtype)
    axis, sharpness, amplitude = lights.spot_light_sg(x, x * dtype(0.5), direction, rng.uniform(0, np.pi, n),
                                                      rng.uniform(0, 1, n), 100.0)
    assert _finite(axis, sharpness, amplitude) and np.all(amplitude >= 0)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_prefilter_lookups(prefiltered, dtype):
    rng = np.random.default_rng(3)
    axis = rng.normal(size=(COUNT, 3)).astype(dtype)
    axis[:1000] = 0  # zero-length axes
    axis[1000:2000] = [0, 0, -1]  # the octahedron's folded corner
    axis[2000:3000] = [1, 0, 0]  # on a crease
    sharpness = (10.0 ** rng.uniform(-12, 9, COUNT)).astype(dtype)
    sharpness[:500] = 0
    values = env_prefilter.lookup(prefiltered, axis, sharpness)
    assert values.shape == (COUNT, 3) and _finite(values) and np.all(values >= 0)
    integral = env_prefilter.lookup_integral(prefiltered, axis[:100_000], sharpness[:100_000])
    assert _finite(integral)
