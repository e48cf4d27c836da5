"""Point, sphere, spot and directional lights as SGs (wang2009 eq. 32-33) against exact cap integrals."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sg_prt_addon.lighting import lights
from sg_prt_addon.spherical import sg
from validation import exact_references


def _cap_true_integral(distance, radius, intensity):
    """Radiance integral of a uniform sphere light: L_e * Omega_cap, L_e = I / (pi r^2)."""
    sin_half = min(radius / distance, 1.0)
    omega = 2 * np.pi * sin_half ** 2 / (1 + np.sqrt(1 - sin_half ** 2))  # 2 pi (1 - cos), no cancellation
    return intensity / (np.pi * radius ** 2) * omega


def test_blender_unit_helpers():
    assert lights.blender_point_light_intensity(4 * np.pi) == pytest.approx(1.0)
    assert lights.blender_sun_irradiance(3.0) == pytest.approx(3.0)
    # sun radiance over its disc integrates to the strength for a small disc
    angle = 0.01
    radiance = lights.blender_sun_radiance(2.0, angle)
    assert radiance * 2 * np.pi * (1 - np.cos(angle / 2)) == pytest.approx(2.0, rel=1e-4)


@settings(max_examples=25, deadline=None)
@given(distance=st.floats(0.05, 100.0), radius=st.floats(1e-3, 5.0), intensity=st.floats(1e-3, 1e3))
def test_energy_model_carries_the_cap_radiance_integral(distance, radius, intensity):
    axis, sharpness, amplitude = lights.sphere_light_sg(np.zeros(3), [0.0, 0.0, distance], radius, intensity)
    if radius <= distance:
        expected = _cap_true_integral(distance, radius, intensity)
        assert float(sg.sphere_integral(sharpness, amplitude)) == pytest.approx(expected, rel=1e-9)
        expected_sharpness = min(np.log(10) * distance ** 2 / radius ** 2, lights.MAX_SHARPNESS)
        assert float(sharpness) == pytest.approx(expected_sharpness, rel=1e-9)
    np.testing.assert_allclose(axis, [0, 0, 1], atol=1e-12)


@settings(max_examples=25, deadline=None)
@given(distance=st.floats(0.01, 100.0), radius=st.floats(1e-3, 5.0), intensity=st.floats(1e-3, 1e3))
def test_soft_falloff_is_a_disk_facing_the_point(distance, radius, intensity):
    """Blender's Soft Falloff (Cycles: a disk of the radius at the light, facing the shading point, radiance
    I / (pi r^2)): a cone of tan a = r / d, its radiance integral I / (pi r^2) 2 pi (1 - cos a), whatever d
    against r (no inside: the disk is never entered)."""
    _, sharpness, amplitude = lights.sphere_light_sg(np.zeros(3), [0.0, 0.0, distance], radius, intensity,
                                                     soft_falloff=True)
    half_angle = np.arctan2(radius, distance)
    one_minus_cos = np.sin(half_angle) ** 2 / (1 + np.cos(half_angle))        # 1 - cos a without cancellation
    expected = intensity / (np.pi * radius ** 2) * 2 * np.pi * one_minus_cos
    assert float(sg.sphere_integral(sharpness, amplitude)) == pytest.approx(expected, rel=1e-9)
    expected_sharpness = min(np.log(10) / np.sin(half_angle) ** 2, lights.MAX_SHARPNESS)
    assert float(sharpness) == pytest.approx(expected_sharpness, rel=1e-9)


def test_radius_zero_is_an_inverse_square_point_light():
    for distance in (0.5, 2.0, 10.0):
        _, sharpness, amplitude = lights.point_light_sg(np.zeros(3), [distance, 0, 0], intensity=5.0)
        assert float(sharpness) == lights.MAX_SHARPNESS
        assert float(sg.sphere_integral(sharpness, amplitude)) == pytest.approx(5.0 / distance ** 2, rel=1e-9)


def _max_error_against_exact(model, caps, lobe_sharpness):
    """Max over caps, lobe sharpness and lobe offsets of |<SG light, G_b> - <cap, G_b>| / max_offset <cap, G_b>."""
    worst = 0.0
    for cap in caps:
        distance, radius = 1.0, np.sin(cap)
        intensity = np.pi * radius ** 2  # unit radiance sphere
        axis, sharpness, amplitude = lights.sphere_light_sg(np.zeros(3), [0, 0, distance], radius, intensity, model)
        for lam in lobe_sharpness:
            offsets = np.linspace(0, min(cap + 4 / np.sqrt(lam) + 0.2, np.pi), 25)
            exact = exact_references.cap_sg_inner_product_reference(cap, lam, offsets)
            lobe_axis = np.stack([np.sin(offsets), 0 * offsets, np.cos(offsets)], -1)
            approx = sg.inner_product(axis, sharpness, amplitude, lobe_axis, lam, 1.0)
            worst = max(worst, float(np.max(np.abs(approx - exact)) / exact.max()))
    return worst


@pytest.mark.slow_maths
def test_sphere_light_against_exact_cap_quadrature():
    small_caps = [0.01, 0.05, 0.1]
    # broad (diffuse, clamped-cosine-like) lobes: the energy model is near exact, the paper's is off by ~r^2/d^2
    diffuse = _max_error_against_exact("energy", small_caps, [1.0, 2.133, 4.0])
    diffuse_paper = _max_error_against_exact("paper", small_caps, [1.0, 2.133, 4.0])
    assert diffuse < 0.01  # measured 0.0072
    assert diffuse_paper > 0.9
    # glossy lobes up to 100: measured 0.113 (an SG cannot be flat-topped like the disc)
    glossy = _max_error_against_exact("energy", small_caps, [10.0, 30.0, 100.0])
    assert glossy < 0.13
    assert glossy < _max_error_against_exact("paper", small_caps, [10.0, 30.0, 100.0])


def test_cap_reference_quadrature_is_exact_for_known_cases():
    cap = 0.3
    # sharpness 0: the cap's solid angle
    assert float(exact_references.cap_sg_inner_product_reference(cap, 0.0, 0.0)) == pytest.approx(2 * np.pi * (1 - np.cos(cap)), rel=1e-12)
    # centred lobe: closed form 2 pi (1 - exp(-lambda (1 - cos cap))) / lambda
    lam = 50.0
    expected = 2 * np.pi * -np.expm1(-lam * (1 - np.cos(cap))) / lam
    assert float(exact_references.cap_sg_inner_product_reference(cap, lam, 0.0)) == pytest.approx(expected, rel=1e-10)


def test_directional_light_units():
    axis, sharpness, amplitude = lights.directional_light_sg([0, 0, 2.0], 0.0, 3.0)
    assert float(sg.sphere_integral(sharpness, amplitude)) == pytest.approx(3.0, rel=1e-9)
    half = np.radians(5.0)
    axis, sharpness, amplitude = lights.directional_light_sg([1.0, 0, 0], half, [1.0, 2.0, 3.0])
    assert amplitude.shape == (3,)
    expected = 2 * np.array([1.0, 2.0, 3.0]) / (1 + np.cos(half))
    np.testing.assert_allclose(sg.sphere_integral(sharpness, amplitude), expected, rtol=1e-6)
    np.testing.assert_allclose(axis, [1, 0, 0])


def test_spot_light_falloff():
    positions = np.array([[0, 0, 0.0], [5.0, 0, 0], [1.82, 0, 0]])  # inside, outside (45 deg), blend (20 deg)
    axis, sharpness, amplitude = lights.spot_light_sg(positions, [0, 0, 5.0], [0, 0, -1.0], np.radians(45), 0.5, 10.0)
    _, _, plain = lights.point_light_sg(positions, [0, 0, 5.0], 10.0)
    assert amplitude[0] == pytest.approx(plain[0])
    assert amplitude[1] == 0.0
    assert 0 < amplitude[2] < plain[2]


def test_colour_and_dtype():
    x = np.zeros((4, 3), np.float32)
    axis, sharpness, amplitude = lights.sphere_light_sg(x, np.float32([0, 1, 0]), 0.1, np.float32([1, 2, 3]))
    assert axis.dtype == np.float32 and sharpness.dtype == np.float32 and amplitude.dtype == np.float32
    assert amplitude.shape == (4, 3)
