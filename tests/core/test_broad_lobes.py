"""visibility.broad_lobes: the visible fraction of broad lobes by a quadrature of the SSDF over the
hemisphere, against the exact fraction under a spherical cap occluder (closed-form SSDF, a dense
Fibonacci quadrature of the lobe over the visible set), beside eq. 30's half-space reading at the lobe's
axis, which it replaces for broad lobes (the per-vertex pass of the diffuse lobes)."""
import numpy as np
import pytest

from sg_prt_addon.spherical import clamped_cosine, hemisphere, sg
from sg_prt_addon.visibility import broad_lobes

DENSE = 400_000


def _cap_ssdf(direction, centre, radius):
    """Signed angle (+ visible) to the occluded set: below the horizon, or within `radius` of `centre` (a
    cap wholly above the horizon)."""
    elevation = np.arcsin(np.clip(direction[..., 2], -1, 1))
    to_cap = np.arccos(np.clip(direction @ centre, -1, 1)) - radius
    return np.where(to_cap < 0, to_cap, np.minimum(elevation, to_cap))


def _exact(axes, sharpness, centre, radius):
    points = broad_lobes.quadrature_points(DENSE)       # equal-area cells, dense
    visible = np.arccos(np.clip(points @ centre, -1, 1)) >= radius
    lobe = np.exp(sharpness * (axes @ points.T - 1.0)) * points[:, 2]
    return (lobe * visible).sum(-1) / lobe.sum(-1)


def _eq30(axes, sharpness, centre, radius):
    """The half-space reading at the axis of the lobe's product with the cosine (lobe_visibility's)."""
    cosine_sharpness, _ = clamped_cosine.clamped_cosine_lobe()
    n = np.array([0.0, 0.0, 1.0])
    axis, lam, _ = sg.product(axes, np.full(len(axes), sharpness), 1.0, n, cosine_sharpness, 1.0)
    visible = hemisphere.fh_normalized(_cap_ssdf(axis, centre, radius), lam)
    return np.clip(visible / hemisphere.fh_normalized_from_sine(axis[:, 2], lam), 0, 1)


def _quadrature(axes, sharpness, centre, radius):
    theta = _cap_ssdf(broad_lobes.quadrature_points(), centre, radius)
    coverage = broad_lobes.cell_coverage(theta, broad_lobes.cell_radius())[None]
    return broad_lobes.quadrature_visible_fraction(coverage, axes[None], np.full((1, len(axes)), sharpness))[0]


def _axes(count=24, seed=0):
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(count, 3))
    axes[:, 2] = np.abs(axes[:, 2]) + 0.3
    axes[0] = [0.0, 0.0, 1.0]
    return axes / np.linalg.norm(axes, axis=1, keepdims=True)


def test_open_sky_is_wholly_visible():
    points = broad_lobes.quadrature_points()
    coverage = broad_lobes.cell_coverage(np.arcsin(points[:, 2]), broad_lobes.cell_radius())[None]
    axes = _axes()
    for sharpness in (0.0, 3.0, 30.0):
        fraction = broad_lobes.quadrature_visible_fraction(coverage, axes[None], np.full((1, len(axes)), sharpness))
        assert np.allclose(fraction, 1.0, atol=1e-12)


def test_points_are_equal_area_cells_of_the_hemisphere():
    points = broad_lobes.quadrature_points()
    assert np.allclose(np.linalg.norm(points, axis=1), 1.0)
    assert np.all(points[:, 2] > 0)
    # each point holds 1/32 of the cosine-weighted hemisphere's mass on average: the z's are the cells'
    # centres of a uniform partition of z in [0, 1]
    assert np.allclose(np.sort(points[:, 2]), (np.arange(32) + 0.5) / 32)
    assert broad_lobes.cell_coverage(0.0, 0.25) == pytest.approx(0.5)
    assert broad_lobes.cell_coverage(0.25, 0.25) == pytest.approx(1.0)
    assert broad_lobes.cell_coverage(-1.0, 0.25) == pytest.approx(0.0)


@pytest.mark.parametrize("cap", [(0.6, 0.25), (0.9, 0.4), (1.0, 0.15)])
def test_quadrature_against_a_cap_occluder(cap):
    """A cap of angular radius `radius` whose centre is `tilt` from the normal: the occluder eq. 30 reads
    as a half of the sky beyond the nearest boundary.  Largest absolute error of the visible fraction over
    24 lobe axes, measured (quadrature / eq. 30): lambda 0: 0.019 / 0.218, 0.005 / 0.109, 0.012 / 0.074;
    lambda 2: 0.034 / 0.376, 0.009 / 0.220, 0.027 / 0.187; lambda 5: 0.043 / 0.450, 0.015 / 0.190,
    0.044 / 0.200 (the three caps in order)."""
    tilt, radius = cap
    centre = np.array([np.sin(tilt), 0.0, np.cos(tilt)])
    axes = _axes()
    for sharpness, bound in ((0.0, 0.03), (2.0, 0.05), (5.0, 0.065)):
        exact = _exact(axes, sharpness, centre, radius)
        quadrature = np.abs(_quadrature(axes, sharpness, centre, radius) - exact).max()
        eq30 = np.abs(_eq30(axes, sharpness, centre, radius) - exact).max()
        print(f"cap {cap} lambda {sharpness}: quadrature {quadrature:.4f}, eq. 30 {eq30:.4f}")
        assert quadrature < bound
        assert quadrature < 0.3 * eq30


def test_hand_over_to_eq30():
    assert broad_lobes.quadrature_weight(0.0) == 1.0
    assert broad_lobes.quadrature_weight(broad_lobes.QUADRATURE_SHARPNESS_START) == 1.0
    assert broad_lobes.quadrature_weight(broad_lobes.QUADRATURE_SHARPNESS_END) == 0.0
    assert broad_lobes.quadrature_weight(1e4) == 0.0
    middle = 0.5 * (broad_lobes.QUADRATURE_SHARPNESS_START + broad_lobes.QUADRATURE_SHARPNESS_END)
    assert broad_lobes.quadrature_weight(middle) == pytest.approx(0.5)
