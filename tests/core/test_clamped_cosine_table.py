"""spherical/clamped_cosine_table.py: the tabulated I(c, lambda) against the ring quadrature (asserted
error bounds, and a third of the closed form's), its row map and inverse, its edges."""
import numpy as np
import pytest

from sg_prt_addon.spherical import clamped_cosine as cc
from sg_prt_addon.spherical import clamped_cosine_table as ct


def random_arguments(low, high, count, seed):
    """lambda log-uniform in [low, high]; c uniform, a quarter of it within 0.05 of the horizon and
    a tenth within 0.002 (the knee of sharp lobes)."""
    rng = np.random.default_rng(seed)
    sharpness = np.exp(rng.uniform(np.log(low), np.log(high), count))
    cosine = rng.uniform(-1.0, 1.0, count)
    cosine[: count // 4] *= 0.05
    cosine[: count // 10] *= 0.04
    return cosine, sharpness


def errors(value, cosine, sharpness):
    """(max |error| / I(1, lambda), max relative error where I > 0.1 I(1, lambda)) against quadrature."""
    exact = cc.clamped_cosine_exact_from_cosine(cosine, sharpness)
    upper = cc.clamped_cosine_exact_from_cosine(np.ones_like(cosine), sharpness)
    lit = exact > 0.1 * upper
    return np.max(np.abs(value - exact) / upper), np.max(np.abs(value - exact)[lit] / exact[lit])


@pytest.mark.parametrize("low, high, absolute_bound, relative_bound", [
    (1e-6, 1e-3, 2e-4, 2e-4),       # below the table: G and R held at the first column (lambda 1e-4), I -> pi
    (1e-3, 1e4, 2.5e-4, 2.5e-3),    # the closed form's fitted range: 9.5e-4 and 7.7e-3 there
    (1e4, 1e6, 5e-4, 5e-4),
    (1e6, 1e8, 1.2e-3, 1e-3),       # the table's last decades (lights and the warp cap lambda at 1e6)
])
def test_error_against_quadrature(low, high, absolute_bound, relative_bound):
    cosine, sharpness = random_arguments(low, high, 40000, seed=int(abs(np.log10(low))))
    absolute, relative = errors(ct.clamped_cosine_from_table(cosine, sharpness), cosine, sharpness)
    print(f"lambda in [{low:g}, {high:g}]: max |error| / I(1) {absolute:.2e}, relative where lit {relative:.2e}")
    assert absolute <= absolute_bound
    assert relative <= relative_bound


def test_a_third_of_the_closed_forms_error():
    cosine, sharpness = random_arguments(1e-3, 1e4, 40000, seed=7)
    table = errors(ct.clamped_cosine_from_table(cosine, sharpness), cosine, sharpness)
    closed = errors(cc.clamped_cosine_from_cosine(cosine, sharpness), cosine, sharpness)
    assert table[0] <= closed[0] / 3 and table[1] <= closed[1] / 3


@pytest.mark.parametrize("sharpness", [1e-6, 1e-2, 1.0, 30.0, 1e4, 1e8])
def test_row_map_inverse_and_ends(sharpness):
    y = np.linspace(-1.0, 1.0, 2001)
    cosine = ct.cosine_of_row(y, sharpness)
    np.testing.assert_allclose(ct.row_coordinate(cosine, sharpness), y, atol=1e-12)
    assert np.all(np.diff(cosine) > 0)
    np.testing.assert_allclose(ct.row_coordinate(np.array([-1.0, 0.0, 1.0]), sharpness), [-1.0, 0.0, 1.0])


def test_table_layout():
    table = ct.clamped_cosine_table()
    assert table.shape == (ct.ROWS, ct.COLUMNS, 4) and table.dtype == np.float32
    assert np.all(np.isfinite(table)) and not table.flags.writeable
    np.testing.assert_allclose(table[-1, :, 0], 1.0, rtol=1e-6)                     # R(c = 1) = 1
    assert np.all((table[..., 0] >= 0) & (table[..., 0] <= 1 + 1e-6))
    assert np.all(np.diff(table[..., 0], axis=0) >= -1e-7)                         # I grows with c
    np.testing.assert_allclose(table[:, 0, 1], 1.0, rtol=1e-6)                      # G -> 1 as lambda -> 0
    np.testing.assert_allclose(table[:, -1, 1], 2.0 / 3.0, rtol=1e-5)               # G -> 2/3 as lambda -> inf
    assert np.all(table[..., 1] <= 1.0)                                             # never above pi


def test_broad_degenerate_and_huge_inputs():
    value = ct.clamped_cosine_from_table([0.3, 0.3, 0.3, 2.0, -2.0], [0.0, np.nan, -1.0, 5.0, 5.0])
    np.testing.assert_allclose(value[:3], np.pi)
    poles = cc.clamped_cosine_exact_from_cosine(np.array([1.0, -1.0]), 5.0)      # c clamped to +-1
    np.testing.assert_allclose(value[3:], poles, rtol=0, atol=1e-4 * poles[0])
    # past the last column pi / (1 + lambda / 3) carries the scale: no clamp of lambda (the closed form's GLSL has one)
    huge = ct.clamped_cosine_from_table(1.0, 1e12)
    np.testing.assert_allclose(huge, 2 * np.pi / 1e12, rtol=1e-4)


def test_sg_integral_matches_the_closed_form_within_its_error():
    rng = np.random.default_rng(3)
    axis = rng.normal(size=(5000, 3))
    normal = rng.normal(size=(5000, 3))
    sharpness = np.exp(rng.uniform(np.log(1e-3), np.log(1e4), 5000))
    amplitude = rng.uniform(0.0, 3.0, 5000)
    tabulated = ct.sg_clamped_cosine_integral_tabulated(axis, sharpness, amplitude, normal)
    exact = cc.sg_clamped_cosine_integral_exact(axis, sharpness, amplitude, normal)
    upper = amplitude * cc.clamped_cosine_exact_from_cosine(np.ones(5000), sharpness)
    assert np.max(np.abs(tabulated - exact) / np.maximum(upper, 1e-30)) <= 2.5e-4
