"""Property tests of spherical/sg.py against independent numerical integration.

Quadrature on the sphere is done around a chosen pole with the substitution
t = scale (1 - cos theta) (Gauss-Legendre in t, trapezoid in phi), so lobes
from sharpness 1e-4 to 1e4 are resolved to ~1e-12 relative.
"""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sg_prt_addon.spherical import sg

SETTINGS = settings(max_examples=25, deadline=None)
log_sharpness = st.floats(np.log(1e-4), np.log(1e4))
sharpness_st = log_sharpness.map(np.exp)
seed_st = st.integers(0, 2**31 - 1)


def random_unit(rng, n=None):
    v = rng.normal(size=(3,) if n is None else (n, 3))
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def frame(pole):
    """Orthonormal (tangent, bitangent, pole) for a unit pole."""
    helper = np.array([1.0, 0, 0]) if abs(pole[0]) < 0.9 else np.array([0, 1.0, 0])
    tangent = np.cross(helper, pole)
    tangent /= np.linalg.norm(tangent)
    return tangent, np.cross(pole, tangent), pole


def sphere_quadrature(func, pole, scale, t_max=None, n_t=200, n_phi=64):
    """Integral of func(v) over {t <= t_max} with t = scale (1 - v.pole); func must decay like exp(-t).

    The t range is cut at 80 (e^-80 relative) and split in [0, 1], [1, 80] so
    that both broad and sharp lobes are integrated accurately.
    """
    t_end = 2 * scale if t_max is None else t_max
    t_end = min(t_end, 80.0)
    nodes, weights = np.polynomial.legendre.leggauss(n_t)
    pieces = [(0.0, min(1.0, t_end)), (min(1.0, t_end), t_end)]
    ts, wts = [], []
    for a, b in pieces:
        if b > a:
            ts.append(0.5 * (b - a) * nodes + 0.5 * (a + b))
            wts.append(0.5 * (b - a) * weights)
    t = np.concatenate(ts)
    w_t = np.concatenate(wts)
    cos_theta = 1 - t / scale
    sin_theta = np.sqrt(np.clip((t / scale) * (2 - t / scale), 0, None))
    phi = np.arange(n_phi) * (2 * np.pi / n_phi)
    tangent, bitangent, pole = frame(np.asarray(pole, float))
    v = (sin_theta[:, None, None] * (np.cos(phi)[None, :, None] * tangent + np.sin(phi)[None, :, None] * bitangent)
         + cos_theta[:, None, None] * pole)
    values = func(v)  # (n_t, n_phi)
    # d(omega) = sin(theta) d(theta) d(phi) = dt / scale d(phi)
    return np.sum(values * w_t[:, None]) * (2 * np.pi / n_phi) / scale


def direct_sg(v, axis, sharpness, amplitude=1.0):
    return amplitude * np.exp(sharpness * (v @ np.asarray(axis) - 1))


@SETTINGS
@given(sharpness_st, st.floats(0, 10), seed_st)
def test_evaluate_matches_definition(sharpness, amplitude, seed):
    rng = np.random.default_rng(seed)
    axis = random_unit(rng)
    # directions near the axis too, where v.p - 1 cancels
    v = sg.normalize(axis + rng.normal(size=(50, 3)) * rng.choice([1e-4, 1e-2, 1.0], size=(50, 1)))
    got = sg.evaluate(v, axis, sharpness, amplitude)
    want = direct_sg(v, axis, sharpness, amplitude)
    assert np.allclose(got, want, rtol=1e-9 * max(1.0, sharpness), atol=1e-300)


@SETTINGS
@given(sharpness_st, sharpness_st, st.floats(0.1, 5), st.floats(0.1, 5), seed_st)
def test_product_is_pointwise_product(l1, l2, mu1, mu2, seed):
    rng = np.random.default_rng(seed)
    p1, p2 = random_unit(rng), random_unit(rng)
    if seed % 3 == 0:
        p2 = sg.normalize(-p1 + 1e-3 * rng.normal(size=3))  # nearly opposite
    axis, lam, mu = sg.product(p1, l1, mu1, p2, l2, mu2)
    assert abs(np.linalg.norm(axis) - 1) < 1e-12
    v = random_unit(rng, 100)
    if mu == 0:  # legitimately underflowed: the true maximum of G1 G2 must be below the smallest double
        assert np.linalg.norm(l1 * p1 + l2 * p2) - l1 - l2 + np.log(mu1 * mu2) < np.log(1e-300)
        return
    # compare logarithms so that tiny values still count
    log_want = np.log(mu1 * mu2) + l1 * (v @ p1 - 1) + l2 * (v @ p2 - 1)
    log_got = np.log(mu) + lam * (v @ axis - 1)
    assert np.allclose(log_got, log_want, rtol=0, atol=1e-10 * (1 + l1 + l2))


def test_product_of_exactly_opposite_equal_lobes_is_constant():
    axis, lam, mu = sg.product([0, 0, 1.0], 3.0, 2.0, [0, 0, -1.0], 3.0, 1.5)
    assert lam == 0 and np.isclose(mu, 3.0 * np.exp(-6.0))
    assert np.allclose(axis, [0, 0, 1])


@SETTINGS
@given(sharpness_st, sharpness_st, seed_st)
def test_inner_product_against_quadrature(l1, l2, seed):
    rng = np.random.default_rng(seed)
    p1, p2 = random_unit(rng), random_unit(rng)
    summed = l1 * p1 + l2 * p2
    scale = np.linalg.norm(summed)
    pole = summed / scale
    # integrand divided by its maximum exp(scale - l1 - l2), which is put back afterwards
    log_peak = scale - l1 - l2
    quad = sphere_quadrature(lambda v: np.exp(l1 * (v @ p1 - 1) + l2 * (v @ p2 - 1) - log_peak), pole, scale)
    want_log = np.log(quad) + log_peak
    got = sg.inner_product(p1, l1, 1.3, p2, l2, 0.7) / (1.3 * 0.7)
    if want_log < np.log(1e-290):  # the true value is subnormal or underflows: only ask for that
        assert got < 1e-280
    else:
        assert abs(np.log(got) - want_log) < 1e-9


@SETTINGS
@given(sharpness_st, st.floats(0.1, 10))
def test_sphere_and_axis_hemisphere_integrals_against_quadrature(sharpness, amplitude):
    pole = np.array([0.3, -0.5, 0.8])
    pole /= np.linalg.norm(pole)
    lobe = lambda v: direct_sg(v, pole, sharpness, amplitude)
    full = sphere_quadrature(lobe, pole, sharpness)
    half = sphere_quadrature(lobe, pole, sharpness, t_max=sharpness)  # cos(theta) >= 0
    assert np.isclose(sg.sphere_integral(sharpness, amplitude), full, rtol=1e-10)
    assert np.isclose(sg.axis_hemisphere_integral(sharpness, amplitude), half, rtol=1e-10)


@pytest.mark.parametrize("x", [0.0, 1e-300, 1e-13, 1e-8, 1e-3, 0.5, 1.0, 30.0, 1e6])
def test_one_minus_exp_over_x(x):
    want = 1.0 if x == 0 else -np.expm1(-x) / x
    assert np.isclose(sg.one_minus_exp_over_x(x), want, rtol=1e-14)


@SETTINGS
@given(seed_st)
def test_rotation_preserves_lobe_values(seed):
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    axis, v = random_unit(rng), random_unit(rng, 20)
    rotated = sg.rotate(axis, q)
    assert np.isclose(np.linalg.norm(rotated), 1)
    assert np.allclose(sg.evaluate(v @ q.T, rotated, 7.0), sg.evaluate(v, axis, 7.0), rtol=1e-12)
    stacked = sg.rotate(np.stack([axis, axis]), np.stack([q, q.T]))
    assert np.allclose(stacked, [q @ axis, q.T @ axis])


def test_normalize_degenerate_inputs():
    v = np.array([[0, 0, 0], [np.nan, 1, 0], [np.inf, 0, 0], [3, 0, 4], [1e-30, 0, 0]], float)
    out = sg.normalize(v)
    assert np.allclose(out[:3], [0, 0, 1])
    assert np.allclose(out[3], [0.6, 0, 0.8])
    assert np.allclose(np.linalg.norm(out, axis=-1), 1)
    assert sg.normalize(v.astype(np.float32)).dtype == np.float32


@SETTINGS
@given(sharpness_st, st.floats(0.01, 0.5))
def test_support_area_is_where_lobe_reaches_epsilon(sharpness, epsilon):
    area = sg.support_area(sharpness, epsilon)
    assert np.isclose(sg.sharpness_from_area(area, epsilon), sharpness)
    if area < 4 * np.pi:
        # a cap of solid angle A has boundary cos(theta) = 1 - A / (2 pi)
        cos_edge = 1 - area / (2 * np.pi)
        edge = np.array([np.sqrt(1 - cos_edge**2), 0, cos_edge])
        assert np.isclose(sg.evaluate(edge, [0, 0, 1.0], sharpness), epsilon, rtol=1e-9)


def test_mixture_evaluate_is_sum_of_lobes():
    rng = np.random.default_rng(3)
    axes = random_unit(rng, 4)
    lam = np.array([0.5, 3, 30, 300.0])
    mu = np.array([1, 2, 0.5, 0.0])
    v = random_unit(rng, 10)
    want = sum(sg.evaluate(v, axes[j], lam[j], mu[j]) for j in range(4))
    assert np.allclose(sg.mixture_evaluate(v, axes, lam, mu), want)


def test_float32_in_float32_out():
    f = np.float32
    p1, p2 = np.array([0, 0, 1], f), np.array([0, 1, 0], f)
    axis, lam, mu = sg.product(p1, f(1e6), f(1), p2, f(1e6), f(1))
    assert axis.dtype == lam.dtype == mu.dtype == np.float32
    assert sg.inner_product(p1, f(2), f(1), p2, f(3), f(1)).dtype == np.float32
    assert sg.sphere_integral(f(1e-4), f(1)).dtype == np.float32
    assert sg.evaluate(p1, p2, f(5), f(1)).dtype == np.float32
