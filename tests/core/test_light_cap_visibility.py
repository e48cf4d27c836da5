"""A light's visible fraction from the SSDF (techniques.sg.sg_shading.light_cap_visibility): the disc of the light's
cap beyond the boundary at the SSDF's distance, against the exact cosine-weighted share of the cap that a
half-plane leaves visible (validation.visibility_cases), and beside eq. 30's fh of the light's SG, which it
replaced."""
import numpy as np
import pytest

from sg_prt_addon.lighting import lights
from validation import visibility_cases


def test_cap_radius_inverts_the_cap_sharpness():
    radius = np.array([1e-4, 0.05, 0.4, 1.2, np.pi / 2])
    assert np.allclose(lights.cap_radius(np.log(10.0) / np.sin(radius) ** 2), radius, rtol=1e-12)
    assert lights.cap_radius(1.0) == pytest.approx(np.pi / 2)            # broader than a hemisphere: clamped


@pytest.mark.parametrize("radius, bound", [(0.05, 0.005), (0.15, 0.005), (0.4, 0.02)])
def test_cap_beyond_an_exact_boundary(radius, bound):
    """With the exact SSDF (the angle to the edge's great circle): the cap's share is exact but for the cosine's
    variation across it and the disc's curvature; fh's Gaussian penumbra is wider, with tails past the cap."""
    cap, fh = visibility_cases.cap_share_errors(radius)
    print(f"radius {radius}: cap {cap.max():.4f}, fh {fh.max():.4f}")
    assert cap.max() <= bound                  # measured 0.0025, 0.0029, 0.0127 (Monte Carlo noise ~1e-3)
    assert fh.max() >= 0.06                    # measured 0.066-0.068


def test_cap_beyond_the_baked_boundary():
    """The same sweep (cap radius 0.15) with the SSDF baked from rays (32 x 32, x5 refinement) and read at the
    light's axis, as the shader reads it: the SSDF's own error (about 0.01 rad) comes on top."""
    cap, fh = visibility_cases.cap_share_errors(0.15, baked=True)
    print(f"baked SSDF: cap {cap.max():.4f}, fh {fh.max():.4f}")
    assert cap.max() <= 0.025                  # measured 0.011
    assert fh.max() >= 2 * cap.max()
