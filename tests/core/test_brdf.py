"""Exact BRDF models of reflectance.brdf against independent textbook formulas, reciprocity,
energy, normalization, Fresnel limits and the samplers' densities."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, stats

from sg_prt_addon.reflectance import brdf, models

RNG_SEED = 1234


def random_upper(rng, n, min_z=0.05):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:, 2] = np.maximum(np.abs(v[:, 2]), min_z)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def all_models():
    return [
        brdf.CookTorrance(roughness=0.25, ior=1.5),
        brdf.CookTorranceBeckmann(roughness=0.25, ior=1.8),
        brdf.BlinnPhong(exponent=40.0),
        brdf.WardIsotropic(alpha_x=0.2),
        brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.08),
        brdf.AshikhminShirley(nu=20.0, nv=300.0, rf0=0.1),
        brdf.GGX(roughness=0.5),
        brdf.Beckmann(roughness=0.5),
        brdf.Lambert(kd=0.8),
    ]


# ----------------------------------------------------------------------------- independent references

def fresnel_polarized(cos_i, eta):
    """Average of the s and p Fresnel equations (no total internal reflection cases)."""
    sin_t = np.sqrt(1 - cos_i ** 2) / eta
    cos_t = np.sqrt(1 - sin_t ** 2)
    rs = ((cos_i - eta * cos_t) / (cos_i + eta * cos_t)) ** 2
    rp = ((eta * cos_i - cos_t) / (eta * cos_i + cos_t)) ** 2
    return 0.5 * (rs + rp)


def angles(h):
    theta = np.arccos(np.clip(h[..., 2], -1, 1))
    phi = np.arctan2(h[..., 1], h[..., 0])
    return theta, phi


def reference(model, wo, wi):
    h = (wo + wi) / np.linalg.norm(wo + wi, axis=-1, keepdims=True)
    no, ni, nh, ih = wo[:, 2], wi[:, 2], h[:, 2], np.sum(wi * h, -1)
    theta, phi = angles(h)
    g_ct = np.minimum(1, np.minimum(2 * nh * no / ih, 2 * nh * ni / ih))
    if type(model) is brdf.CookTorrance:
        return fresnel_polarized(ih, model.ior) * g_ct / (np.pi * ni * no) * np.exp(-(theta / model.roughness) ** 2)
    if type(model) is brdf.CookTorranceBeckmann:
        m = model.roughness
        d = np.exp(-np.tan(theta) ** 2 / m ** 2) / (np.pi * m ** 2 * np.cos(theta) ** 4)
        return fresnel_polarized(ih, model.ior) * g_ct * d / (4 * ni * no)
    if type(model) is brdf.BlinnPhong:
        n = model.exponent
        return (n + 2) / (8 * np.pi) * nh ** n * g_ct / (ni * no)
    if isinstance(model, brdf.WardAnisotropic):
        ax = model.alpha_x
        ay = ax if type(model) is brdf.WardIsotropic else model.alpha_y
        exponent = -np.tan(theta) ** 2 * (np.cos(phi) ** 2 / ax ** 2 + np.sin(phi) ** 2 / ay ** 2)
        return np.exp(exponent) / (4 * np.pi * ax * ay * np.sqrt(ni * no))
    if type(model) is brdf.AshikhminShirley:
        nu, nv = model.nu, model.nv
        fresnel = model.rf0 + (1 - model.rf0) * (1 - ih) ** 5
        power = nh ** (nu * np.cos(phi) ** 2 + nv * np.sin(phi) ** 2)
        return np.sqrt((nu + 1) * (nv + 1)) / (8 * np.pi) * power / (ih * np.maximum(ni, no)) * fresnel
    if type(model) is brdf.GGX:
        a = model.roughness ** 2
        d = a ** 2 / (np.pi * (nh ** 2 * (a ** 2 - 1) + 1) ** 2)

        def smith_lambda(z):
            return (-1 + np.sqrt(1 + a ** 2 * (1 - z ** 2) / z ** 2)) / 2
        return d / (1 + smith_lambda(ni) + smith_lambda(no)) / (4 * ni * no)
    if type(model) is brdf.Beckmann:
        a = model.roughness ** 2
        d = np.exp(-np.tan(theta) ** 2 / a ** 2) / (np.pi * a ** 2 * np.cos(theta) ** 4)

        def walter_lambda(z):
            inverse = z / (a * np.sqrt(1 - z ** 2))
            return np.where(inverse < 1.6, np.maximum((1 - 1.259 * inverse + 0.396 * inverse ** 2)
                                                      / (3.535 * inverse + 2.181 * inverse ** 2), 0), 0)
        return d / (1 + walter_lambda(ni) + walter_lambda(no)) / (4 * ni * no)
    if type(model) is brdf.Lambert:
        return np.full(len(wo), model.kd / np.pi)
    raise AssertionError(model)


def test_beckmann_shadowing_is_walters_form_of_the_exact_lambda():
    """Beckmann's Lambda by Walter et al. 2007's rational form (Cycles'), against the exact
    (erf(a) - 1)/2 + exp(-a^2) / (2 a sqrt(pi)), a = 1 / (alpha tan theta): what G1 = 1 / (1 + Lambda) takes of
    it, |Lambda - exact| / (1 + exact), within 0.4% at every angle (measured 0.31% near a = 1.3; the rational
    form is cut to 0 at a = 1.6)."""
    from benchmarks.accuracy import microfacet_shadowing

    error = microfacet_shadowing.beckmann_lambda_errors()
    print(f"largest |Lambda - exact| / (1 + exact) {error.max():.5f}")
    assert error.max() < 0.004


@pytest.mark.parametrize("model", all_models(), ids=lambda m: type(m).__name__)
def test_specular_matches_textbook_formula_and_factorization(model):
    rng = np.random.default_rng(RNG_SEED)
    wo, wi = random_upper(rng, 500), random_upper(rng, 500)
    value = model.specular(wo, wi)
    np.testing.assert_allclose(value, reference(model, wo, wi), rtol=1e-9, atol=1e-300)
    h = brdf.half_vector(wo, wi)
    np.testing.assert_allclose(value, model.m_factor(wo, wi) * model.ndf(h), rtol=1e-12)


@pytest.mark.parametrize("model", all_models(), ids=lambda m: type(m).__name__)
def test_reciprocity_and_horizon(model):
    rng = np.random.default_rng(RNG_SEED + 1)
    wo, wi = random_upper(rng, 1000), random_upper(rng, 1000)
    np.testing.assert_allclose(model.specular(wo, wi), model.specular(wi, wo), rtol=1e-10)
    below = wi * np.array([1, 1, -1])
    assert np.all(model.specular(wo, below) == 0) and np.all(model.specular(below, wo) == 0)


def furnace_albedo(model, wo, count=40_000, seed=0):
    """Directional albedo by the model's own importance sampling, with its standard error."""
    wi, pdf = model.sample(wo, np.random.default_rng(seed).random((count, 2)))
    weight = np.where(pdf > 0, model.specular(wo, wi) * np.maximum(wi[:, 2], 0) / np.where(pdf > 0, pdf, 1), 0)
    return weight.mean(), weight.std() / np.sqrt(count)


@pytest.mark.parametrize("model", [brdf.GGX(roughness=0.05), brdf.GGX(roughness=0.5), brdf.GGX(roughness=1.0),
                                   brdf.BlinnPhong(exponent=10.0), brdf.BlinnPhong(exponent=1000.0),
                                   brdf.CookTorranceBeckmann(roughness=0.3, ior=1e6),
                                   brdf.WardIsotropic(alpha_x=0.2), brdf.Lambert(kd=1.0)],
                         ids=lambda m: f"{type(m).__name__}")
@pytest.mark.parametrize("view_degrees", [0.0, 60.0])
def test_white_furnace(model, view_degrees):
    t = np.radians(view_degrees)
    albedo, error = furnace_albedo(model, np.array([np.sin(t), 0, np.cos(t)]))
    assert albedo <= 1 + 4 * error + 1e-12
    if isinstance(model, (brdf.GGX, brdf.Lambert)) and view_degrees == 0 and model.__dict__.get("roughness", 0) <= 0.05:
        assert albedo > 0.99  # smooth GGX at normal incidence loses almost nothing
    if isinstance(model, brdf.Lambert):
        assert abs(albedo - 1) < 1e-9


def polar_integral(function, theta_max=np.pi / 2, n_theta=4000, n_phi=64):
    """Integral over the cap theta < theta_max of function(direction) d omega (midpoint rule)."""
    theta = (np.arange(n_theta) + 0.5) * theta_max / n_theta
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    return np.sum(function(d) * np.sin(t)) * (theta_max / n_theta) * (2 * np.pi / n_phi)


@pytest.mark.parametrize("roughness", [0.01, 0.03, 0.2, 0.6, 1.0])
def test_ggx_ndf_normalization(roughness):
    model = brdf.GGX(roughness=roughness)
    alpha = roughness ** 2

    def integrand(theta):
        h = np.array([np.sin(theta), 0, np.cos(theta)])
        return 2 * np.pi * model.ndf(h) * np.cos(theta) * np.sin(theta)
    total, _ = integrate.quad(integrand, 0, np.pi / 2, points=[alpha, 10 * alpha], limit=200, epsabs=1e-12)
    assert abs(total - 1) < 1e-7


def test_other_ndf_normalizations():
    beckmann = brdf.CookTorranceBeckmann(roughness=0.3)
    assert abs(polar_integral(lambda h: beckmann.ndf(h) * h[..., 2]) - 1) < 2e-4
    phong = brdf.BlinnPhong(exponent=50.0)
    assert abs(polar_integral(lambda h: phong.ndf(h) * h[..., 2]) - 1) < 2e-4
    ashikhmin = brdf.AshikhminShirley(nu=30.0, nv=200.0)  # A-S normalize D itself, not D (n.h)
    assert abs(polar_integral(ashikhmin.ndf, n_phi=256) - 1) < 2e-3


def test_fresnel_limits_and_polarized_reference():
    cos = np.linspace(0.01, 1, 200)
    for eta in (1.33, 1.5, 2.5):
        np.testing.assert_allclose(brdf.fresnel_dielectric(cos, eta), fresnel_polarized(cos, eta), rtol=1e-10)
        assert abs(brdf.fresnel_dielectric(1.0, eta) - ((eta - 1) / (eta + 1)) ** 2) < 1e-14
        assert brdf.fresnel_dielectric(0.0, eta) == 1
        assert np.all(np.diff(brdf.fresnel_dielectric(cos, eta)) < 0)  # rises towards grazing
    assert np.all(brdf.fresnel_dielectric(cos, 1.0) == 0)
    assert brdf.fresnel_dielectric(0.1, 0.8) == 1  # total internal reflection
    near_one = brdf.fresnel_dielectric(np.float32(0.7), np.float32(1.0 + 1e-6))
    assert near_one.dtype == np.float32 and 0 <= near_one < 1e-12


@settings(max_examples=30, deadline=None)
@given(st.floats(0.0, 1.0), st.floats(1.0, 4.0))
def test_fresnel_range(cos, eta):
    value = brdf.fresnel_dielectric(cos, eta)
    assert 0 <= value <= 1 and np.isfinite(value)


def sphere_grid(n_theta=300, n_phi=360):
    theta = (np.arange(n_theta) + 0.5) * np.pi / n_theta
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    d = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    return t, p, d, np.sin(t) * (np.pi / n_theta) * (2 * np.pi / n_phi)


SAMPLED = [brdf.CookTorrance(roughness=0.4), brdf.BlinnPhong(exponent=12.0), brdf.WardAnisotropic(0.45, 0.2),
           brdf.AshikhminShirley(nu=8.0, nv=40.0), brdf.GGX(roughness=0.6), brdf.Lambert()]


@pytest.mark.parametrize("model", SAMPLED, ids=lambda m: type(m).__name__)
def test_sampling_density(model):
    wo = np.array([0.5, 0.2, 0.84])
    wo /= np.linalg.norm(wo)
    theta, phi, directions, solid_angle = sphere_grid()
    density = model.pdf(wo, directions)
    assert abs(np.sum(density * solid_angle) - 1) < 5e-3
    count = 60_000
    wi, pdf = model.sample(wo, np.random.default_rng(7).random((count, 2)))
    np.testing.assert_allclose(pdf, model.pdf(wo, wi), rtol=1e-9)
    # chi-square of a coarse (theta, phi) histogram against the pdf integrated per bin
    theta_bins, phi_bins = 15, 12
    grid_bin = (np.minimum((theta / np.pi * theta_bins).astype(int), theta_bins - 1) * phi_bins
                + np.minimum((phi / (2 * np.pi) * phi_bins).astype(int), phi_bins - 1))
    expected = np.bincount(grid_bin.ravel(), (density * solid_angle).ravel(), theta_bins * phi_bins)
    sample_theta = np.arccos(np.clip(wi[:, 2], -1, 1))
    sample_phi = np.mod(np.arctan2(wi[:, 1], wi[:, 0]), 2 * np.pi)
    observed = np.bincount(np.minimum((sample_theta / np.pi * theta_bins).astype(int), theta_bins - 1) * phi_bins
                           + np.minimum((sample_phi / (2 * np.pi) * phi_bins).astype(int), phi_bins - 1),
                           minlength=theta_bins * phi_bins)
    keep = expected * count > 20
    statistic = np.sum((observed[keep] - count * expected[keep]) ** 2 / (count * expected[keep]))
    p_value = stats.chi2.sf(statistic, keep.sum() - 1)
    assert p_value > 1e-4, (statistic, keep.sum())


def test_spatially_varying_parameters_and_dtype():
    rng = np.random.default_rng(3)
    wo = random_upper(rng, 64).astype(np.float32)
    wi = random_upper(rng, 64).astype(np.float32)
    roughness = rng.uniform(0.05, 1, 64)
    model = brdf.GGX(roughness=roughness)
    value = model.specular(wo, wi)
    assert value.dtype == np.float32 and value.shape == (64,)
    for i in (0, 17, 63):
        single = brdf.GGX(roughness=roughness[i]).specular(wo[i].astype(np.float64), wi[i].astype(np.float64))
        assert abs(value[i] - single) <= 1e-4 * abs(single) + 1e-6
    axis, sharpness, amplitude = model.ndf_lobes()
    assert axis.shape == (64, 1, 3) and sharpness.shape == (64, 1) and amplitude.shape == (64, 1)
    axis, sharpness, amplitude = brdf.WardAnisotropic(alpha_x=roughness, alpha_y=0.1).ndf_lobes(4)
    assert axis.shape == (64, 4, 3) and sharpness.shape == (64, 4)


def test_model_from_name():
    model = brdf.model_from_name("COOK_TORRANCE", roughness=0.1, ior=1.4, exponent=5.0, nu=3.0)
    assert type(model) is brdf.CookTorrance and model.roughness == 0.1 and model.ior == 1.4
    assert type(brdf.model_from_name("WARD_ISO", alpha_x=0.2, alpha_y=0.9)) is brdf.WardIsotropic
    for name in models.NAMES:
        assert brdf.model_from_name(name) is not None
    with pytest.raises(ValueError):
        brdf.model_from_name("PHONG")


@settings(max_examples=15, deadline=None)
@given(st.sampled_from(["COOK_TORRANCE", "BLINN_PHONG", "WARD_ISO", "WARD_ANISO", "ASHIKHMIN_SHIRLEY", "GGX",
                        "BECKMANN"]),
       st.floats(0.01, 1.0), st.floats(0.01, 1.0), st.floats(1.0, 1e4), st.integers(0, 2 ** 31))
def test_reciprocity_and_positivity_for_random_parameters(name, roughness, alpha_y, exponent, seed):
    model = brdf.model_from_name(name, roughness=roughness, ior=1.0 + roughness, exponent=exponent,
                                 alpha_x=roughness, alpha_y=alpha_y, nu=exponent, nv=exponent * alpha_y)
    rng = np.random.default_rng(seed)
    wo, wi = random_upper(rng, 200, 1e-3), random_upper(rng, 200, 1e-3)
    forward, backward = model.specular(wo, wi), model.specular(wi, wo)
    assert np.all(np.isfinite(forward)) and np.all(forward >= 0)
    np.testing.assert_allclose(forward, backward, rtol=1e-9)


def grid_around(axis, n_polar=200, n_phi=360):
    """Gauss-Legendre in the polar angle around ``axis`` x uniform phi: directions, solid angles."""
    x, w = np.polynomial.legendre.leggauss(n_polar)
    polar, polar_weight = 0.5 * np.pi * (x + 1), 0.5 * np.pi * w
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    b, p = np.meshgrid(polar, phi, indexing="ij")
    z = axis / np.linalg.norm(axis)
    t = np.cross(z, [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t)
    local = [np.sin(b) * np.cos(p), np.sin(b) * np.sin(p), np.cos(b)]
    directions = local[0][..., None] * t + local[1][..., None] * np.cross(z, t) + local[2][..., None] * z
    return directions, np.sin(b) * polar_weight[:, None] * (2 * np.pi / n_phi)


@pytest.mark.parametrize("model", [brdf.GGX(roughness=0.5), brdf.WardAnisotropic(0.4, 0.2), brdf.BlinnPhong(10.0),
                                   brdf.AshikhminShirley(nu=10.0, nv=40.0)], ids=lambda m: type(m).__name__)
def test_pdf_normalized_at_grazing_view(model):
    """At 80 degrees many NDF-sampled half vectors face away from the view (o.h < 0); their
    wi crowd towards -wo, where p_h / (4 |o.h|) has an integrable 1/angle singularity.
    A grid polar around -wo resolves it: pdf() integrates to 1 over the sphere."""
    t = np.radians(80.0)
    wo = np.array([np.sin(t), 0.0, np.cos(t)])
    directions, solid_angle = grid_around(-wo)
    assert abs(np.sum(model.pdf(wo, directions) * solid_angle) - 1) < 1e-4
