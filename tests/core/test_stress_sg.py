"""Stress: 10^6 hostile inputs through every fast kernel of sg.py, hemisphere.py and
clamped_cosine.py, in float64 and float32.  Asserts no NaN/Inf, no warnings
(overflow, invalid, divide; underflow to 0 is fine) and outputs inside their mathematical range."""
import functools
import warnings

import numpy as np
import pytest

from sg_prt_addon.spherical import clamped_cosine as cc
from sg_prt_addon.spherical import hemisphere, sg
from validation import paper_forms

N = 1_000_000
DTYPES = [np.float64, np.float32]


def _unit(rng, n):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


@functools.lru_cache(maxsize=1)
def _hostile_inputs_float64(seed=7):
    rng = np.random.default_rng(seed)
    sharpness = np.exp(rng.uniform(np.log(1e-4), np.log(1e6), N))
    sharpness[rng.random(N) < 0.01] = 0.0
    sharpness[rng.random(N) < 0.01] = 1e6
    sharpness2 = np.exp(rng.uniform(np.log(1e-4), np.log(1e6), N))
    sharpness2[: N // 10] = sharpness[: N // 10]  # equal sharpness with opposite axes: constant product

    axis1 = _unit(rng, N)
    axis2 = _unit(rng, N)
    tenth = N // 10
    axis2[:tenth] = -axis1[:tenth]                                     # exactly opposite
    nearly = -axis1[tenth:2 * tenth] + 1e-7 * rng.normal(size=(tenth, 3))
    axis2[tenth:2 * tenth] = nearly / np.linalg.norm(nearly, axis=-1, keepdims=True)  # nearly opposite
    axis2[2 * tenth:3 * tenth] = axis1[2 * tenth:3 * tenth]            # equal

    amplitude1 = rng.uniform(0, 10, N)
    amplitude1[rng.random(N) < 0.05] = 0.0
    amplitude2 = rng.uniform(0, 10, N)

    normal = _unit(rng, N)
    grazing = np.cross(axis1[:tenth], _unit(rng, tenth))               # exactly on the horizon
    normal[:tenth] = grazing / np.linalg.norm(grazing, axis=-1, keepdims=True)
    near = normal[:tenth] + 1e-6 * axis1[:tenth]                      # grazing within 1e-6
    normal[tenth:2 * tenth] = near / np.linalg.norm(near, axis=-1, keepdims=True)
    normal[2 * tenth:2 * tenth + tenth // 2] = 0.0                    # degenerate normals
    normal[3 * tenth:4 * tenth] = axis1[3 * tenth:4 * tenth]          # normal on the axis
    normal[4 * tenth:5 * tenth] = -axis1[4 * tenth:5 * tenth]         # normal opposite

    theta_d = rng.uniform(-4, 4, N)
    theta_d[:tenth] = np.pi / 2
    theta_d[tenth:2 * tenth] = -np.pi / 2
    theta_d[2 * tenth:3 * tenth] = 0.0

    return dict(sharpness=sharpness, sharpness2=sharpness2, axis1=axis1, axis2=axis2,
                amplitude1=amplitude1, amplitude2=amplitude2, normal=normal, theta_d=theta_d)


def _hostile_inputs(dtype):
    """The same hostile set in each dtype (generated once, cast)."""
    return {name: np.ascontiguousarray(value, dtype) for name, value in _hostile_inputs_float64().items()}


@pytest.fixture(scope="module", params=DTYPES, ids=lambda d: d.__name__)
def inputs(request):
    return request.param, _hostile_inputs(request.param)


def _check(values, dtype, low=None, high=None, tolerance=0.0):
    values = np.asarray(values)
    assert values.dtype == dtype
    assert np.all(np.isfinite(values))
    slack = tolerance * (np.abs(high) if high is not None and np.ndim(high) else 1.0)
    if low is not None:
        assert np.all(values >= low - slack)
    if high is not None:
        assert np.all(values <= high + slack)


@pytest.fixture(autouse=True)
def _warnings_are_errors():
    with warnings.catch_warnings(), np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
        warnings.simplefilter("error")
        yield


def test_sg_kernels(inputs):
    dtype, x = inputs
    eps = 1e-5 if dtype == np.float32 else 1e-12
    lam1, lam2, a1, a2, p1, p2 = x["sharpness"], x["sharpness2"], x["amplitude1"], x["amplitude2"], x["axis1"], x["axis2"]

    _check(sg.one_minus_exp_over_x(lam1), dtype, 0, 1)
    _check(sg.evaluate(p2, p1, lam1, a1), dtype, 0, a1, eps)

    axis, sharp, amp = sg.product(p1, lam1, a1, p2, lam2, a2)
    _check(axis, dtype, -1, 1, eps)
    _check(sharp, dtype, 0, lam1 + lam2, eps)
    _check(amp, dtype, 0, a1 * a2, eps)
    norms = np.linalg.norm(axis, axis=-1)
    assert np.all(np.abs(norms - 1) < (1e-3 if dtype == np.float32 else 1e-9))

    sphere1 = sg.sphere_integral(lam1, a1)
    _check(sphere1, dtype, 0, 4 * np.pi * a1, eps)
    hemi1 = sg.axis_hemisphere_integral(lam1, a1)
    _check(hemi1, dtype, 0.5 * sphere1, sphere1, eps)  # the upper hemisphere holds at least half

    inner = sg.inner_product(p1, lam1, a1, p2, lam2, a2)
    bound = np.minimum(a2 * sphere1, a1 * sg.sphere_integral(lam2, a2))  # G2 <= mu2, G1 <= mu1
    _check(inner, dtype, 0, bound, 1e-4 if dtype == np.float32 else 1e-9)

    rotation = np.asarray([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], dtype)
    rotated = sg.rotate(p1, rotation)
    _check(rotated, dtype, -1, 1, eps)

    _check(sg.normalize(x["normal"]), dtype, -1, 1, eps)
    positive = lam1[lam1 > 0]
    area = sg.support_area(positive)
    _check(area, dtype, 0)
    _check(sg.sharpness_from_area(area), dtype, 0)

    lobes = 8
    mixture = sg.mixture_evaluate(p2[: N // lobes], p1.reshape(-1, lobes, 3)[: N // lobes],
                                  lam1.reshape(-1, lobes)[: N // lobes], a1.reshape(-1, lobes)[: N // lobes])
    _check(mixture, dtype, 0, np.sum(a1.reshape(-1, lobes), axis=-1)[: N // lobes], eps)


def test_hemisphere_kernels(inputs):
    dtype, x = inputs
    eps = 1e-5 if dtype == np.float32 else 1e-12
    lam, amplitude, theta_d = x["sharpness"], x["amplitude1"], x["theta_d"]

    fhn = hemisphere.fh_normalized(theta_d, lam)
    _check(fhn, dtype, 0, 1)
    # fh_hat >= e^-lambda (the opposite hemisphere), up to the approximation's error
    assert np.all(fhn >= np.exp(-lam.astype(np.float64)) - 3e-3)
    _check(paper_forms.fh_normalized_paper(theta_d, lam), dtype, 0, 1)
    _check(hemisphere.fh(theta_d, lam), dtype, 0, sg.axis_hemisphere_integral(lam), 1e-6)

    integral = hemisphere.hemisphere_integral(x["axis1"], lam, amplitude, x["normal"])
    _check(integral, dtype, 0, amplitude * sg.axis_hemisphere_integral(lam), eps)

    axis, sharp, scaled = hemisphere.visibility_product(x["axis1"], lam, amplitude, theta_d)
    assert np.array_equal(sharp, lam) and axis is x["axis1"]
    _check(scaled, dtype, 0, amplitude, eps)
    preserved = hemisphere.visibility_product_integral_preserving(x["axis1"], lam, amplitude, theta_d)[2]
    _check(preserved, dtype, 0, amplitude, eps)

    _check(hemisphere.erf_approx(theta_d * lam), dtype, -1, 1)


def test_clamped_cosine_kernels(inputs):
    dtype, x = inputs
    lam, amplitude = x["sharpness"], x["amplitude1"]
    fast = cc.sg_clamped_cosine_integral(x["axis1"], lam, amplitude, x["normal"])
    # I(c) <= I(1) = I_up = (2 pi / lambda) upper (pi for lambda = 0)
    pole_upper, _ = cc._pole_integrals(lam.astype(np.float64))
    safe = np.where(lam > 0, lam, 1.0)
    upper = amplitude * np.where(lam > 0, 2 * np.pi / safe * pole_upper, np.pi)
    _check(fast, dtype, 0, upper, 1e-5 if dtype == np.float32 else 1e-12)
    paper = paper_forms.sg_clamped_cosine_integral_paper(x["axis1"], lam, amplitude, x["normal"])
    _check(paper, dtype, 0)
