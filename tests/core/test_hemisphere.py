"""fh (wang2009 eq. 25-31): exact quadrature against closed forms and an
independent ring-fraction quadrature; the fast form against the exact one."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, special

from benchmarks.accuracy.hemisphere import triple_product_case
from sg_prt_addon.spherical import hemisphere, sg
from validation import paper_forms

SETTINGS = settings(max_examples=15, deadline=None)
log_sharpness = st.floats(np.log(1e-4), np.log(1e6)).map(np.exp)
theta_st = st.floats(-np.pi / 2, np.pi / 2)


def sphere_minus_upper(lam):
    """Integral over the hemisphere opposite the axis, (2 pi / lambda) e^-lambda (1 - e^-lambda), no cancellation."""
    return sg.TWO_PI * np.exp(-lam) * sg.one_minus_exp_over_x(lam)


def fh_ring_fraction(theta_d, lam):
    """Independent reference: rings around the lobe axis at polar angle theta, each in the hemisphere for the
    fraction arccos(-cot(theta) tan(theta_d)) / pi of its length, integrated over theta.

    The quadrature is shown where the integrand turns: the rings just past |theta_d| (from all in or out to
    half in: a step within a few theta_d, tiny when theta_d is) and the lobe's width 1 / sqrt(lambda).  The lobe
    is factored as e^(-lambda (1 - cos theta)) (2 sin^2(theta / 2) for 1 - cos, no cancellation).
    """
    def integrand(theta):
        with np.errstate(divide="ignore"):      # the poles' rings have no length: their ratio is not needed
            cosine_ratio = np.clip(-np.cos(theta) / np.sin(theta) * np.tan(theta_d), -1.0, 1.0)
        return np.exp(-lam * 2.0 * np.sin(theta / 2.0) ** 2) * np.sin(theta) * np.arccos(cosine_ratio) / np.pi

    edge = abs(theta_d)
    width = 1.0 / np.sqrt(lam)
    points = {edge * k for k in (1.0, 1.1, 2.0, 10.0, 100.0)} | {width * k for k in (1.0, 3.0, 10.0, 30.0)}
    points = sorted(p for p in points if 0.0 < p < np.pi - edge) + [np.pi - edge]
    bounds = [0.0] + points + [np.pi]
    total = sum(integrate.quad(integrand, a, b, epsabs=0, epsrel=1e-12, limit=500)[0]
                for a, b in zip(bounds[:-1], bounds[1:]) if b > a)
    return sg.TWO_PI * total


@pytest.mark.parametrize("lam", [1e-4, 0.1, 1.0, 10.0, 300.0, 1e4, 1e6])
def test_exact_anchors(lam):
    upper = sg.axis_hemisphere_integral(lam)
    sphere = sg.sphere_integral(lam)
    assert np.isclose(hemisphere.fh_exact(np.pi / 2, lam), upper, rtol=1e-10)
    assert np.isclose(hemisphere.fh_exact(0.0, lam), 0.5 * sphere, rtol=1e-10)
    assert np.isclose(hemisphere.fh_exact(-np.pi / 2, lam), sphere_minus_upper(lam), rtol=1e-9, atol=0)
    # beyond +-pi/2 the hemispherical reconstruction saturates
    assert hemisphere.fh_exact(2.5, lam) == hemisphere.fh_exact(np.pi / 2, lam)
    assert np.isclose(hemisphere.fh_normalized_exact(np.pi / 2, lam), 1.0, rtol=1e-10)


@SETTINGS
@given(theta_st, log_sharpness)
def test_exact_complement_and_ring_fraction(theta_d, lam):
    a, b = hemisphere.fh_exact(theta_d, lam), hemisphere.fh_exact(-theta_d, lam)
    assert np.isclose(a + b, sg.sphere_integral(lam), rtol=1e-9)
    reference = fh_ring_fraction(theta_d, lam)
    assert np.isclose(a, reference, rtol=1e-8, atol=1e-290)


def test_erf_approx():
    y = np.linspace(-8, 8, 20001)
    error = np.abs(hemisphere.erf_approx(y) - special.erf(y))
    assert error.max() < 1.1e-4
    assert hemisphere.erf_approx(np.float32(0.3)).dtype == np.float32
    assert np.all(hemisphere.erf_approx(-y) == -hemisphere.erf_approx(y))


def random_theta_lambda(rng, n, lam_low, lam_high):
    lam = np.exp(rng.uniform(np.log(lam_low), np.log(lam_high), n))
    theta = rng.uniform(-np.pi, np.pi, n)
    # half of them inside the transition band, |theta_d| of a few 1/sqrt(lambda)
    theta[: n // 2] = rng.normal(0, 2 / np.sqrt(lam[: n // 2]))
    return theta, lam


@pytest.mark.parametrize("lam_low, lam_high, bound", [(0.1, 1e5, 0.002), (1e-4, 0.1, 0.002), (1e5, 1e6, 0.002)])
def test_fast_normalized_against_exact(lam_low, lam_high, bound):
    rng = np.random.default_rng(7)
    theta, lam = random_theta_lambda(rng, 600, lam_low, lam_high)
    exact = hemisphere.fh_normalized_exact(theta, lam)
    fast = hemisphere.fh_normalized(theta, lam)
    assert np.max(np.abs(fast - exact)) <= bound  # measured 0.00144 over [0.1, 1e5]
    fast32 = hemisphere.fh_normalized(theta.astype(np.float32), lam.astype(np.float32))
    assert fast32.dtype == np.float32
    assert np.max(np.abs(fast32 - exact)) <= bound + 1e-5


def test_paper_sigmoid_is_far_off():
    """spherical/hemisphere.py fh_normalized_paper: the printed appendix sigmoid is off by 0.2-0.5 for lambda <= 100."""
    theta = np.linspace(-np.pi / 2, np.pi / 2, 41)
    lam = np.array([0.5, 5.0, 50.0])[:, None]
    error = np.abs(paper_forms.fh_normalized_paper(theta, lam) - hemisphere.fh_normalized_exact(theta, lam))
    assert 0.2 < error.max() < 0.7


@SETTINGS
@given(log_sharpness, st.floats(0, np.pi / 2))
def test_fast_structure(lam, theta_d):
    """fh_hat(t) + fh_hat(-t) = 1 + e^-lambda (complementary hemispheres), endpoints exact, monotone."""
    a, b = hemisphere.fh_normalized(theta_d, lam), hemisphere.fh_normalized(-theta_d, lam)
    assert np.isclose(a + b, 1 + np.exp(-lam), rtol=0, atol=1e-12)
    assert np.isclose(hemisphere.fh_normalized(np.pi / 2, lam), 1.0, atol=1e-12)
    assert np.isclose(hemisphere.fh_normalized(-np.pi / 2, lam), np.exp(-lam), atol=1e-12)
    grid = hemisphere.fh_normalized(np.linspace(-np.pi / 2, np.pi / 2, 401), lam)
    assert np.all(np.diff(grid) >= -1e-15)


def test_hemisphere_integral_any_normal():
    rng = np.random.default_rng(11)
    n = 200
    axis = sg.normalize(rng.normal(size=(n, 3)))
    lam = np.exp(rng.uniform(np.log(1e-3), np.log(1e5), n))
    # normals near the lobe's horizon, where the integral changes fastest
    normal = sg.normalize(rng.normal(size=(n, 3)))
    normal -= np.sum(normal * axis, -1, keepdims=True) * axis * rng.uniform(0.9, 1.0, (n, 1))
    amplitude = rng.uniform(0, 3, n)
    exact = hemisphere.hemisphere_integral_exact(axis, lam, amplitude, normal)
    fast = hemisphere.hemisphere_integral(axis, lam, amplitude, normal)
    scale = amplitude * sg.axis_hemisphere_integral(lam)
    assert np.max(np.abs(fast - exact) / np.maximum(scale, 1e-300)) <= 0.002
    # the hemisphere around the axis itself, and the normal reversed
    assert np.allclose(hemisphere.hemisphere_integral_exact(axis, lam, amplitude, axis), scale, rtol=1e-9)
    assert np.allclose(hemisphere.hemisphere_integral(axis, lam, amplitude, axis), scale, rtol=1e-6)


def test_visibility_product_eq31():
    axis = np.array([0.0, 0.6, 0.8])
    lam, mu = np.array([0.5, 20.0, 4000.0]), np.array([1.0, 2.0, 0.5])
    theta = np.array([0.3, -0.1, 0.01])
    out_axis, out_lam, out_mu = hemisphere.visibility_product(axis, lam, mu, theta)
    assert np.all(out_axis == axis) and np.all(out_lam == lam)
    # the product lobe integrates over its axis hemisphere to mu fh(theta_d)
    integral = sg.axis_hemisphere_integral(out_lam, out_mu)
    assert np.allclose(integral, mu * hemisphere.fh(theta, lam), rtol=1e-12)
    assert np.allclose(integral, mu * hemisphere.fh_exact(theta, lam), rtol=0.01)
    saturated = hemisphere.visibility_product(axis, lam, mu, np.array([3.0, -3.0, 2.0]))[2]
    assert np.allclose(saturated, mu * hemisphere.fh_normalized(np.array([1, -1, 1]) * np.pi / 2, lam))


def test_visibility_product_needs_the_final_lobe():
    """eq. 31 on the lobe integrated last (G (x) H) is exact up to fh and to the printed
    normalization's 1 + e^-lambda; applied to G before multiplying by H it is not."""
    p, q, lam_g, lam_h, theta, m = triple_product_case(400, 21)
    axis, lam, mu = sg.product(p, lam_g, 1.0, q, lam_h, 1.0)
    full = sg.inner_product(p, lam_g, 1.0, q, lam_h, 1.0)
    keep = full > 1e-250
    exact = hemisphere.hemisphere_integral_exact(axis, lam, mu, m)[keep]
    theta_final = np.arcsin(np.clip(np.sum(axis * m, -1), -1, 1))
    # integral-preserving eq. 31 on the final lobe: only the fast fh's error remains
    _, lam_v, mu_v = hemisphere.visibility_product_integral_preserving(axis, lam, mu, theta_final)
    preserving = sg.sphere_integral(lam_v, mu_v)[keep]
    assert np.max(np.abs(preserving - exact) / full[keep]) <= 0.002
    # printed eq. 31: over-counts by 1 + e^-lambda
    _, lam_p, mu_p = hemisphere.visibility_product(axis, lam, mu, theta_final)
    printed = sg.sphere_integral(lam_p, mu_p)[keep]
    assert np.allclose(printed, preserving * (1 + np.exp(-lam[keep])), rtol=1e-9)
    # eq. 31 on G alone, then the inner product with H: fine only if H is nearly constant
    _, _, mu_g = hemisphere.visibility_product_integral_preserving(p, lam_g, 1.0, theta)
    early = sg.inner_product(p, lam_g, mu_g, q, lam_h, 1.0)[keep]
    error = np.abs(early - exact) / full[keep]
    broad = lam_h[keep] < 0.01  # H varies by < 2% over the sphere
    assert broad.sum() > 20 and error[broad].max() <= 0.03
    assert error[~broad].max() > 0.5


@pytest.mark.parametrize("lam", [0.05, 2.0, 40.0])
def test_clamped_cosine_identity(lam):
    """An exact link between fh and the SG x clamped-cosine integral I(c) (ours): with
    F(x, lambda) = fh(asin x, lambda), differentiating exp(v.i) along n gives
        I(c) = c (F + dF/dlambda) + (1 - c^2) / lambda dF/dx   at x = c = n.p.
    Checked with finite differences of fh_exact against the cosine-weighted quadrature
    and clamped_cosine's own (ring) quadrature."""
    from sg_prt_addon.spherical import clamped_cosine

    c = np.array([-0.8, -0.2, 0.0, 0.3, 0.9])

    def F(x, sharpness):
        return hemisphere.fh_exact(np.arcsin(x), sharpness)

    dx, dl = 1e-5, 1e-5 * lam
    by_identity = (c * (F(c, lam) + (F(c, lam + dl) - F(c, lam - dl)) / (2 * dl))
                   + (1 - c * c) / lam * (F(c + dx, lam) - F(c - dx, lam)) / (2 * dx))
    weighted = hemisphere._quadrature_array(c, lam, True)
    axis = np.stack([np.sqrt(1 - c * c), 0 * c, c], -1)
    ring = clamped_cosine.sg_clamped_cosine_integral_exact(axis, lam, 1.0, [0, 0, 1.0])
    assert np.allclose(by_identity, weighted, rtol=1e-6)
    assert np.allclose(weighted, ring, rtol=1e-9)
