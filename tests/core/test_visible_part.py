"""A partly occluded lobe reads the environment where its visible part lies (techniques.sg.sg_shading's
visible_part_axes): the truncated Gaussian's moments it turns and narrows the lobe by, against scipy's; the side
the SSDF shows it and the radiance it then reads, on a lobe crossing a half-plane's edge under an environment
brighter past the edge (validation.visibility_cases.lobe_edge_radiance), against quadrature over the sphere."""
import numpy as np
import pytest

from validation import visibility_cases


def test_probit_is_the_normal_quantile():
    """techniques.sg.sg_shading.probit (Abramowitz and Stegun 26.2.23, float32) against scipy's normal quantile."""
    from scipy.stats import norm

    from sg_prt_addon.techniques.sg.sg_shading import probit

    v = np.linspace(1e-4, 1 - 1e-4, 20001)
    assert np.max(np.abs(probit(v) - norm.ppf(v))) < 1e-3          # measured 4.5e-4 (A&S's bound)
    assert np.all(np.isfinite(probit(np.array([0.0, 1e-30, 0.5, 1.0]))))


def test_visible_part_offset_is_the_truncated_gaussian_mean():
    """techniques.sg.sg_shading.visible_part_offset against phi(Phi^-1(v)) / v, the mean of a unit Gaussian cut so that
    the fraction v is kept, over v in [1e-3, 1)."""
    from scipy.stats import norm

    from sg_prt_addon.techniques.sg.sg_shading import visible_part_offset

    v = np.linspace(1e-3, 1 - 1e-5, 20001)
    exact = norm.pdf(norm.ppf(v)) / v
    error = np.abs(visible_part_offset(v) / exact - 1)
    assert error[v <= 0.99].max() < 0.003          # measured 1.0e-3
    assert error.max() < 0.005                     # measured 1.5e-3 (float32's 1 - v near 1, where m -> 0)
    assert visible_part_offset(1.0) < 1e-4 and np.isfinite(visible_part_offset(0.0))


def test_visible_part_narrowing_is_the_truncated_gaussian_width():
    """techniques.sg.sg_shading.visible_part_narrowing against 2 / (1 + var), var = 1 - z m - m^2 the exact variance
    across the boundary of a unit Gaussian cut to the fraction v (floored at VISIBLE_PART_MIN_VARIANCE): 1 for an
    unoccluded lobe, growing as less of it is kept."""
    from scipy.stats import norm, truncnorm

    from sg_prt_addon.techniques.sg.sg_shading import VISIBLE_PART_MIN_VARIANCE, visible_part_narrowing

    v = np.linspace(1e-3, 1 - 1e-5, 2001)
    variance = truncnorm.var(-norm.ppf(v), np.inf)
    exact = 2 / (1 + np.clip(variance, VISIBLE_PART_MIN_VARIANCE, 1))
    narrowing = visible_part_narrowing(v)
    assert np.max(np.abs(narrowing / exact - 1)) < 0.015         # measured 1.1e-2, at v = 1.5e-3
    assert narrowing[-1] == pytest.approx(1.0, abs=1e-3) and np.all(np.diff(narrowing) <= 1e-6)


@pytest.mark.parametrize("sharpness, bound, axis_error, side_degrees", [(10.0, 0.12, 0.6, 6.0), (30.0, 0.035, 0.45, 3.5),
                                                                     (100.0, 0.01, 0.3, 3.5)])
def test_visible_part_reads_the_light_past_the_edge(sharpness, bound, axis_error, side_degrees):
    """Lobes swept across the edge (+-2 widths) where at least 5% of them is visible: the visible part's mean
    radiance read at the visible part (the baked 32 x 32 SSDF's side) against quadrature, and read at the lobe's
    axis (the product of averages it replaced), which misses the brighter light past the edge; the side's angle to
    the edge's open side, everywhere on the sweep."""
    result = visibility_cases.lobe_edge_radiance(sharpness)
    keep = result["visible"] >= 0.05
    part = np.abs(result["visible part"] / result["exact"] - 1)[keep]
    axis = np.abs(result["axis"] / result["exact"] - 1)[keep]
    print(f"sharpness {sharpness}: visible part {part.max():.4f} (mean {part.mean():.4f}), axis {axis.max():.4f}")
    assert part.max() < bound              # measured 0.095, 0.024, 0.006
    assert axis.max() > axis_error         # measured 0.66, 0.50, 0.32
    # the side read off the SSDF (its gradient at the product with the cosine lobe) against the edge's open side
    assert np.degrees(result["side angle"]).max() < side_degrees       # measured 4.7, 2.4, 2.2 degrees
