"""A light's visible fraction from the SSDF (techniques.sg_shading.light_cap_visibility): the disc of the light's
cap beyond the boundary at the SSDF's distance, against the exact cosine-weighted share of the cap that a
half-plane leaves visible, and beside eq. 30's fh of the light's SG, which it replaced."""
import numpy as np
import pytest

from sg_prt_addon.lighting import lights
from sg_prt_addon.spherical import hemisphere
from sg_prt_addon.visibility import BakeOptions, decode, hemisphere_map
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer

TILT = 0.7     # the lights' sweep, turned 40 degrees off the normal: the cosine varies across the cap


def _cap_directions(axis, radius, count=200_000, seed=0):
    """Uniform directions (count, 3) in the cap of half-angle radius about axis."""
    rng = np.random.default_rng(seed)
    cosine = 1 - rng.random(count) * (1 - np.cos(radius))
    sine = np.sqrt(1 - cosine ** 2)
    phi = 2 * np.pi * rng.random(count)
    t = np.cross(axis, [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t)
    return np.stack([sine * np.cos(phi), sine * np.sin(phi), cosine], -1) @ np.stack([t, np.cross(axis, t), axis])


def _sweep(radius):
    """Light axes (K, 3) whose caps cross the great circle x = 0 (the edge of the half-plane {z = 1, x < 0} seen
    from the origin), and the exact cosine-weighted share of each cap on its visible side x > 0."""
    tilt = np.array([[1, 0, 0], [0, np.cos(TILT), -np.sin(TILT)], [0, np.sin(TILT), np.cos(TILT)]])
    alpha = np.linspace(-2 * radius, 2 * radius, 41)
    axes = np.stack([np.sin(alpha), np.zeros_like(alpha), np.cos(alpha)], -1) @ tilt.T
    exact = []
    for axis in axes:
        d = _cap_directions(axis, radius)
        w = np.maximum(d[:, 2], 0)
        exact.append((w * (d[:, 0] > 0)).sum() / w.sum())
    return axes, np.array(exact)


def _cap_fraction(theta_d, axes, radius):
    return hemisphere.disc_coverage(theta_d, radius) / hemisphere.disc_coverage(np.arcsin(axes[:, 2]), radius)


@pytest.mark.parametrize("radius, bound", [(0.05, 0.005), (0.15, 0.005), (0.4, 0.02)])
def test_cap_beyond_an_exact_boundary(radius, bound):
    """With the exact SSDF (the angle to the great circle x = 0): the cap's share is exact but for the
    cosine's variation across it and the disc's curvature; fh's Gaussian penumbra is wider, with tails past the
    cap.  Monte Carlo noise of the exact shares: about 1e-3."""
    axes, exact = _sweep(radius)
    theta_d = np.arcsin(axes[:, 0])
    sharpness = np.log(10.0) / np.sin(radius) ** 2                       # lighting.lights' cap sharpness
    assert lights.cap_radius(sharpness) == pytest.approx(radius, rel=1e-12)
    cap_error = np.abs(_cap_fraction(theta_d, axes, radius) - exact).max()
    fh = hemisphere.fh_normalized(theta_d, sharpness) / hemisphere.fh_normalized(np.arcsin(axes[:, 2]), sharpness)
    fh_error = np.abs(fh - exact).max()
    print(f"radius {radius}: cap {cap_error:.4f}, fh {fh_error:.4f}")
    assert cap_error <= bound                  # measured 0.0025, 0.0029, 0.0127
    assert fh_error >= 0.06                    # measured 0.066-0.068


def test_cap_beyond_the_baked_boundary():
    """The same sweep with the SSDF baked from rays (32 x 32, x5 refinement, a quad for the half-plane) and
    decoded at the light's axis, as the shader does: the SSDF's own error (about 0.01 rad) comes on top."""
    radius = 0.15
    quad = np.array([[-20.0, -20.0, 1.0], [0.0, -20.0, 1.0], [0.0, 20.0, 1.0], [-20.0, 20.0, 1.0]])
    tracer = RayTracer(quad, np.array([[0, 1, 2], [0, 2, 3]]), threads=1)
    try:
        image = bake_ssdf(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), tracer, BakeOptions(32, 5))[0]
    finally:
        tracer.close()
    axes, exact = _sweep(radius)
    frame = hemisphere_map.local_frame(np.array([[0.0, 0.0, 1.0]]))[0]
    theta_d = decode.decode_image(image.reshape(32, 32).astype(np.float64), axes @ frame.T)
    error = np.abs(_cap_fraction(theta_d, axes, radius) - exact).max()
    print(f"baked SSDF: cap {error:.4f}")
    assert error <= 0.025                      # measured 0.011
