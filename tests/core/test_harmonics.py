"""Real spherical harmonics (sg_prt_addon/harmonics, kautz2002): the basis against scipy's associated
Legendre functions and known constants, orthonormality, exact rotation by the recurrence and by the zyz
method against projecting the rotated function, orders 2-8, and the closed-form projections."""
import math

import numpy as np
import pytest
import scipy.special
from scipy.spatial.transform import Rotation

from sg_prt_addon.harmonics import basis, projection, rotation

ORDERS = range(2, 9)


def _random_directions(count, seed=0):
    d = np.random.default_rng(seed).normal(size=(count, 3))
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def test_basis_matches_scipy_legendre_with_the_condon_shortley_phase():
    d = _random_directions(200)
    theta, phi = np.arccos(d[:, 2]), np.arctan2(d[:, 1], d[:, 0])
    y = basis.evaluate(d, 8)
    for band in range(8):
        for m in range(-band, band + 1):
            k = basis.normalization(band, m)
            legendre = scipy.special.lpmv(abs(m), band, np.cos(theta))      # includes (-1)^m
            if m == 0:
                expected = k * legendre
            elif m > 0:
                expected = math.sqrt(2) * k * legendre * np.cos(m * phi)
            else:
                expected = math.sqrt(2) * k * legendre * np.sin(-m * phi)
            np.testing.assert_allclose(y[:, basis.index(band, m)], expected, atol=1e-12)


def test_first_bands_are_the_usual_constants():
    x, y, z = 0.36, 0.48, 0.8
    values = basis.evaluate(np.array([x, y, z]), 3)
    expected = [0.282095, -0.488603 * y, 0.488603 * z, -0.488603 * x, 1.092548 * x * y, -1.092548 * y * z,
                0.315392 * (3 * z * z - 1), -1.092548 * x * z, 0.546274 * (x * x - y * y)]
    np.testing.assert_allclose(values, expected, rtol=2e-6)


@pytest.mark.parametrize("order", ORDERS)
def test_basis_is_orthonormal(order):
    directions, weights = projection.exact_quadrature(order)
    y = basis.evaluate(directions, order)
    np.testing.assert_allclose((y * weights[:, None]).T @ y, np.eye(order * order), atol=1e-12)


def _rotations():
    generic = list(Rotation.random(4, random_state=7).as_matrix())
    # the Euler decomposition's singular cases: beta = 0, beta = pi, and the identity
    return generic + [rotation.axis_rotation(2, 0.7), rotation.axis_rotation(0, math.pi) @ rotation.axis_rotation(2, 0.3),
                      np.eye(3), rotation.axis_rotation(1, math.pi)]


@pytest.mark.parametrize("order", ORDERS)
def test_rotation_equals_projecting_the_rotated_function(order):
    """Measured: both methods within 4e-15 of the projection (the bound the issue sets: 1e-5)."""
    rng = np.random.default_rng(order)
    directions, weights = projection.exact_quadrature(order)
    worst = {"recurrence": 0.0, "zyz": 0.0}
    for r in _rotations():
        c = rng.normal(size=order * order)
        # g(s) = f(R^T s): the rotated function, projected exactly
        rotated = projection.project_samples(directions, basis.reconstruct(c, directions @ r), weights, order)
        worst["recurrence"] = max(worst["recurrence"], np.max(np.abs(rotation.rotate(c, r) - rotated)))
        worst["zyz"] = max(worst["zyz"], np.max(np.abs(rotation.rotate_zyz(c, r) - rotated)))
    print(order, worst)
    assert max(worst.values()) < 1e-12


def test_rotation_matrices_are_orthogonal_and_compose():
    a, b = Rotation.random(2, random_state=11).as_matrix()
    ma, mb, mab = (rotation.rotation_matrix(r, 6) for r in (a, b, a @ b))
    np.testing.assert_allclose(ma @ ma.T, np.eye(36), atol=1e-12)
    np.testing.assert_allclose(ma @ mb, mab, atol=1e-12)
    np.testing.assert_allclose(rotation.band1_matrix(a), rotation.band_matrices(a, 2)[1], atol=1e-15)


def test_a_rotated_function_is_the_function_at_the_turned_directions():
    r = Rotation.random(random_state=5).as_matrix()
    c = np.random.default_rng(2).normal(size=25)
    d = _random_directions(50, seed=4)
    np.testing.assert_allclose(basis.reconstruct(rotation.rotate(c, r), d), basis.reconstruct(c, d @ r), atol=1e-12)


def test_flop_counts_of_order_five():
    """The block-diagonal matrix: 165 multiply-adds a colour (330 flops); zyz: about 1.3x that with no
    matrix to build; the recurrence builds the matrix first (5.6x)."""
    counts = rotation.flop_counts(5)
    assert counts["matrix"] == 330
    assert counts["matrix"] < counts["zyz"] < 1.5 * counts["matrix"] < counts["recurrence"]
    assert counts["x90_nonzero"] < 165 / 3


# ----------------------------------------------------------------------------- projections

def _hemisphere_rule(axis, count=64):
    """A rule exact for polynomials over the hemisphere about ``axis`` (Gauss-Legendre on [0, 1] x phi)."""
    t, w = np.polynomial.legendre.leggauss(count)
    z, wz = 0.5 * (t + 1), 0.5 * w
    phi = (np.arange(2 * count) + 0.5) * np.pi / count
    r = np.sqrt(1 - z * z)
    local = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
    frame = Rotation.align_vectors([axis], [[0, 0, 1]])[0].as_matrix()
    weights = np.broadcast_to(wz[:, None] * np.pi / count, (count, 2 * count))
    return local.reshape(-1, 3) @ frame.T, weights.reshape(-1)


def test_cap_projection_against_quadrature_of_the_cap():
    axis = np.array([0.3, -0.5, 0.81])
    axis /= np.linalg.norm(axis)
    for half_angle in (0.05, 0.4, 1.2, 2.5):
        coefficients = projection.cap_coefficients(axis, half_angle, [1.0, 2.0], 8)
        # the cap's own rule: Gauss-Legendre over z in [cos(half_angle), 1] about the axis
        t, w = np.polynomial.legendre.leggauss(40)
        low = math.cos(half_angle)
        z, wz = low + (1 - low) * 0.5 * (t + 1), (1 - low) * 0.5 * w
        phi = (np.arange(80) + 0.5) * 2 * np.pi / 80
        r = np.sqrt(1 - z * z)
        local = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
        frame = Rotation.align_vectors([axis], [[0, 0, 1]])[0].as_matrix()
        directions = local.reshape(-1, 3) @ frame.T
        weights = np.broadcast_to(wz[:, None] * 2 * np.pi / 80, (40, 80)).reshape(-1)
        expected = projection.project_samples(directions, np.ones((len(weights), 2)) * [1.0, 2.0], weights, 8)
        np.testing.assert_allclose(coefficients, expected, atol=1e-12)


@pytest.mark.slow_maths
def test_clamped_cosine_and_irradiance_by_funk_hecke():
    """Irradiance of a band-limited radiance by the closed-form A_l equals the integral over the
    hemisphere, by a rule exact for it, to float precision."""
    zonal = projection.clamped_cosine_zonal(8)
    numeric = projection.profile_zonal(lambda t: np.maximum(t, 0.0), 8, node_count=4000)
    np.testing.assert_allclose(zonal, numeric, atol=2e-7)
    np.testing.assert_allclose(zonal[:3] / [basis.normalization(b, 0) for b in range(3)],
                               [np.pi, 2 * np.pi / 3, np.pi / 4], rtol=1e-14)
    radiance = np.random.default_rng(9).normal(size=(25, 3))
    irradiance = projection.convolve_zonal(radiance, projection.clamped_cosine_zonal(5))
    for normal in _random_directions(5, seed=3):
        directions, weights = _hemisphere_rule(normal)
        direct = (basis.reconstruct(radiance, directions) * (directions @ normal)[:, None] * weights[:, None]).sum(0)
        np.testing.assert_allclose(basis.reconstruct(irradiance, normal), direct, atol=1e-11)


def test_equirect_projection_recovers_a_band_limited_environment():
    """A band-limited function drawn into a 128 x 256 equirect image: texel-centre quadrature recovers its
    coefficients to 3e-4 of their scale (measured 1.4e-4: the midpoint rule in elevation)."""
    from sg_prt_addon.lighting import equirect

    c = np.random.default_rng(4).normal(size=(25, 3))
    image = basis.reconstruct(c, equirect.texel_directions(128, 256))
    error = np.max(np.abs(projection.project_equirect(image, 5) - c)) / np.max(np.abs(c))
    print(error)
    assert error < 3e-4


@pytest.mark.parametrize("window", projection.WINDOWS)
def test_windows_trade_ringing_for_blur(window):
    """A point light (a delta) expanded to order 8: unwindowed, its reconstruction rings (a negative lobe of
    -0.139 of the peak, half-maximum at 0.280 rad); windowed, Hanning -0.029 at 0.393 rad, Lanczos -0.045
    at 0.349 rad: a third of the ringing or less, for a lobe 1.25-1.4x as wide."""
    order = 8
    delta = projection.rotate_zonal([basis.normalization(b, 0) for b in range(order)], [0, 0, 1])
    theta = np.linspace(0, np.pi, 2001)
    along = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], -1)

    def profile(factors):
        values = basis.reconstruct(projection.apply_window(delta, factors), along)
        half = theta[np.argmax(values < 0.5 * values[0])]
        return values.min() / values[0], half

    plain_ringing, plain_half = profile(projection.window_factors(None, order))
    ringing, half = profile(projection.window_factors(window, order))
    print(window, plain_ringing, plain_half, ringing, half)
    assert plain_ringing < -0.1
    assert abs(ringing) < 0.35 * abs(plain_ringing) and half > 1.2 * plain_half
    np.testing.assert_allclose(projection.window_factors(window, order)[0], 1.0)


def test_light_zonal_factors_in_float32():
    """The shader's cap and SG factors (mirrored by projection.cap_factors and sg_factors, float32) against
    the exact cap projection and i_l / i_0 (scipy): within 7e-5 everywhere, the series/recurrence switches
    included (measured 6.2e-5 at the cap's switch, 2.5e-7 for SGs)."""
    normalization = np.array([basis.normalization(band, 0) for band in range(8)])
    for epsilon in (1e-6, 1e-4, 9.9e-4, 1e-3, 0.01, 0.3, 1.0, 1.9):
        zonal = projection.cap_zonal(math.acos(1 - epsilon), 8) / normalization
        np.testing.assert_allclose(projection.cap_factors(epsilon, 8, np.float32), zonal / zonal[0], atol=7e-5)
    for sharpness in (1e-3, 0.5, 3.0, 9.9, 10.0, 30.0, 100.0, 400.0):
        exact = [scipy.special.spherical_in(band, sharpness) / scipy.special.spherical_in(0, sharpness)
                 for band in range(8)]
        np.testing.assert_allclose(projection.sg_factors(sharpness, 8, np.float32), exact, atol=1e-6)
    # a sun's sharpness (1e5): the factors tend to exp(-l (l + 1) / (2 lambda)), all but 1
    np.testing.assert_allclose(projection.sg_factors(1e5, 8), np.exp(-np.arange(8) * np.arange(1, 9) / 2e5),
                               atol=1e-8)
