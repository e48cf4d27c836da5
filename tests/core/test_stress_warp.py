"""Stress: 1e6 random inputs per dtype and mode through warp_lobes / brdf_slice_lobes: no NaN/Inf."""
import functools

import numpy as np
import pytest

from sg_prt_addon.spherical import warp

COUNT = 1_000_000


@functools.lru_cache(maxsize=2)
def random_inputs(dtype, seed=7):
    rng = np.random.default_rng(seed)
    # NDF lobe axes anywhere on the sphere (below the horizon too)
    axis = rng.normal(size=(COUNT, 3))
    axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
    # views in the upper hemisphere, a tenth exactly in the tangent plane (wo.z = 0)
    wo = rng.normal(size=(COUNT, 3))
    wo[:, 2] = np.abs(wo[:, 2])
    wo[: COUNT // 10, 2] = 0
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo[COUNT // 10: COUNT // 10 + 1000] = (1.0, 0.0, 0.0)            # exactly along the tangent
    wo[-1000:] = (0.0, 0.0, 1.0)                                      # normal incidence
    axis[-2000:-1000] = wo[-2000:-1000]                               # lobe axis = view
    axis[-3000:-2000] = -wo[-3000:-2000]                              # lobe axis opposite the view
    axis[:1000] = (0.0, 0.0, 1.0)                                     # grazing view, lobe at the normal
    sharpness = 10.0 ** rng.uniform(-4, 6, COUNT)
    amplitude = rng.uniform(0, 10, COUNT)
    amplitude[::7] = 0
    cast = lambda a: np.ascontiguousarray(a, dtype)                   # noqa: E731
    return cast(axis[:, None]), cast(sharpness[:, None]), cast(amplitude[:, None]), cast(wo)


def m_factor_with_poles(wo, wi):
    # 1/(4 |n.wi| n.wo): infinite on the horizon, like an unguarded Mo
    return 1 / (4 * np.abs(wi[..., 2]) * wo[..., 2])


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
@pytest.mark.parametrize("mode", warp.MODES)
def test_warp_stress(dtype, mode):
    axis, sharpness, amplitude, wo = random_inputs(dtype)
    # one call covers warp_lobes and the Mo product (whose own infinities are expected and zeroed)
    with np.errstate(over="raise", invalid="raise"):
        out_axis, out_sharpness, out_amplitude = warp.brdf_slice_lobes(
            axis, sharpness, amplitude, wo, m_factor_with_poles, mode=mode)
    assert out_axis.dtype == out_sharpness.dtype == out_amplitude.dtype == dtype
    assert np.all(np.isfinite(out_axis)) and np.all(np.isfinite(out_amplitude))
    assert np.all(np.isfinite(out_sharpness))
    assert np.all(out_sharpness > 0) and np.all(out_sharpness <= warp.MAX_WARPED_SHARPNESS)
    assert np.all(out_amplitude >= 0)
    assert np.all(np.abs(np.sum(out_axis * out_axis, axis=-1) - 1) < 1e-5)


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_zero_sharpness_and_degenerate_vectors(dtype):
    axis = np.array([[0, 0, 1], [0, 0, 0], [1, 0, 0]], dtype)[:, None]  # middle: zero-length axis
    wo = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 1]], dtype)              # first: zero-length view
    for mode in warp.MODES:
        out = warp.warp_lobes(axis, np.zeros((3, 1), dtype), np.ones((3, 1), dtype), wo, mode=mode)
        assert all(np.all(np.isfinite(a)) for a in out)
        assert np.all(out[1] == 0)
