"""SG fits of NDFs (reflectance.ndf_fit and the models' ndf_lobes) against the exact NDFs."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import approx_fprime

from sg_prt_addon.reflectance import brdf, ndf_fit
from sg_prt_addon.spherical import sg
from validation import ndf_mappings


@pytest.mark.parametrize("roughness, bound", [(0.045, 3e-4), (0.2, 5e-3), (0.5, 0.03), (0.8, 0.07)])
def test_cook_torrance_eq12_single_lobe(roughness, bound):
    """wang2009 eq. 12: G(h; n, 2/m^2, 1) against exp(-(theta/m)^2), relative L2 over the hemisphere."""
    model = brdf.CookTorrance(roughness=roughness)
    axis, sharpness, amplitude = model.ndf_lobes()
    assert sharpness[0] == pytest.approx(2 / roughness ** 2) and amplitude[0] == 1
    assert ndf_fit.ndf_l2_error(model, (axis, sharpness, amplitude)) < bound


@pytest.mark.parametrize("kind", sorted(ndf_fit.ISOTROPIC_MAPPINGS))
def test_isotropic_mappings_are_near_l2_optimal(kind):
    low, high = ndf_fit.ISOTROPIC_MAPPINGS[kind]["width_range"]
    widths = np.r_[np.linspace(0.01, high, 7), 0.99 * high]
    mapping_error, optimal_error = ndf_mappings.isotropic_mapping_errors(kind, widths)
    allowed = 0.006 if kind == "GGX" else 0.002  # GGX: 0.0055 at alpha = 1 (a constant NDF)
    assert np.all(mapping_error <= optimal_error + allowed), (mapping_error - optimal_error)


@pytest.mark.parametrize("roughness", [0.05, 0.2, 0.45, 0.7, 0.9, 1.0])
def test_ggx_one_and_two_lobes(roughness):
    model = brdf.GGX(roughness=roughness)
    one = ndf_fit.ndf_l2_error(model, model.ndf_lobes(1))
    two = ndf_fit.ndf_l2_error(model, model.ndf_lobes(2))
    assert one < 0.21 and two < 0.05
    assert two <= 0.7 * one + 1e-5


@pytest.mark.parametrize("model, bound", [
    (brdf.CookTorranceBeckmann(roughness=0.1), 0.005), (brdf.CookTorranceBeckmann(roughness=0.3), 0.045),
    (brdf.CookTorranceBeckmann(roughness=0.6), 0.2), (brdf.BlinnPhong(exponent=300.0), 0.0011),
    (brdf.BlinnPhong(exponent=30.0), 0.01), (brdf.BlinnPhong(exponent=3.0), 0.09),
    (brdf.WardIsotropic(alpha_x=0.1), 0.0045), (brdf.WardIsotropic(alpha_x=0.3), 0.035),
    (brdf.WardIsotropic(alpha_x=0.6), 0.1)], ids=str)
def test_models_single_lobe_errors(model, bound):
    """Measured 1-lobe errors of the other isotropic models (the bounds are the measured values + ~20%)."""
    assert ndf_fit.ndf_l2_error(model, model.ndf_lobes()) < bound


@settings(max_examples=8, deadline=None)
@given(st.floats(5.0, 500.0), st.floats(0.1, 0.9), st.floats(1.5, 8.0))
def test_fit_isotropic_recovers_a_two_lobe_mixture(sharpness, share, ratio):
    theta, weights = ndf_fit.polar_quadrature([1 / np.sqrt(sharpness)])
    truth_sharpness = np.array([sharpness, sharpness * ratio])
    truth_amplitude = np.array([share, 1 - share]) * 3.0
    values = np.sum(truth_amplitude[:, None] * np.exp(truth_sharpness[:, None] * (np.cos(theta) - 1)), 0)
    fitted_sharpness, fitted_amplitude, error = ndf_fit.fit_isotropic(values, theta, weights, 2)
    assert error < 1e-3
    assert np.all(np.diff(fitted_sharpness) >= 0)  # sorted for texture interpolation


def test_fit_isotropic_batched():
    theta, weights = ndf_fit.polar_quadrature([0.1])
    values = np.stack([np.exp(s * (np.cos(theta) - 1)) for s in (50.0, 200.0)])
    sharpness, amplitude, error = ndf_fit.fit_isotropic(values, theta, weights, 1)
    np.testing.assert_allclose(sharpness[:, 0], [50, 200], rtol=1e-6)
    np.testing.assert_allclose(amplitude[:, 0], 1, rtol=1e-6)
    assert np.all(error < 1e-8)


def test_fit_anisotropic_recovers_free_axes():
    axes = sg.normalize(np.array([[0.2, 0.0, 1.0], [-0.1, 0.15, 1.0]]))
    sharpness, amplitude = np.array([80.0, 300.0]), np.array([1.0, 2.0])
    directions, weights = ndf_fit.hemisphere_quadrature([0.05, 0.2], 20, 128)
    values = sg.mixture_evaluate(directions, axes, sharpness, amplitude)
    fitted_axes, fitted_sharpness, fitted_amplitude, error = ndf_fit.fit_anisotropic(values, directions, weights, 2)
    assert error < 1e-3
    np.testing.assert_allclose(fitted_sharpness, sharpness, rtol=1e-2)
    np.testing.assert_allclose(np.abs(np.sum(fitted_axes * axes, -1)), 1, atol=1e-4)


TARGETS = {"gaussian": ndf_fit.gaussian_target(0.2), "ggx": ndf_fit.ggx_composed_target(0.2, 0.3)}


@pytest.mark.parametrize("target", sorted(TARGETS))
@pytest.mark.parametrize("weighting", [ndf_fit.PLANE_L2, ndf_fit.LIGHT_WEIGHTED])
def test_plane_fit_gradient_is_exact(weighting, target):
    rng = np.random.default_rng(0)
    for lobe_count in (1, 2, 5, 8):
        pairs, unique, _, _ = ndf_fit._row_layout(lobe_count)
        params = np.concatenate([rng.uniform(0.1, 1, pairs), rng.uniform(0, 3, unique)])
        analytic = ndf_fit._plane_fit(params, TARGETS[target], lobe_count, weighting)[1]
        numeric = approx_fprime(params, lambda x: ndf_fit._plane_fit(x, TARGETS[target], lobe_count, weighting)[0],
                                1e-7)
        np.testing.assert_allclose(analytic, numeric, atol=1e-5)


@pytest.mark.parametrize("target", sorted(TARGETS))
def test_blurred_plane_fit_matches_a_grid(target):
    """The closed-form blurred error of _plane_fit against the same on a fine grid: T (Ward's Gaussian, or GGX's
    two sphere-fitted lobes stretched) and the row (its amplitudes as the fit solved them) sampled, each term's
    residual and T blurred by a Gaussian of that variance (scipy.ndimage), squared and summed."""
    from scipy.ndimage import gaussian_filter

    ratio, lobe_count = 0.25, 4
    weights, x_precision, y_precision = (ndf_fit.gaussian_target(ratio) if target == "gaussian"
                                         else ndf_fit.ggx_composed_target(ratio, 0.3))
    params = np.array([0.6, 0.2, np.log(12.0), np.log(30.0)])
    error, _, p, b, mu = ndf_fit._plane_fit(params, (weights, x_precision, y_precision), lobe_count,
                                            ndf_fit.LIGHT_WEIGHTED)
    step = 0.01
    x, y = np.meshgrid(np.arange(-6, 6, step), np.arange(-4, 4, step), indexing="ij")
    target_values = sum(w * np.exp(-(a * x ** 2 + c * y ** 2)) for w, a, c in zip(weights, x_precision, y_precision))
    row = sum(m * np.exp(-bb * ((x - pp) ** 2 + y ** 2)) for pp, bb, m in zip(p, b, mu))
    total = 0.0
    for variance, weight in ndf_fit.LIGHT_WEIGHTED:
        def blur(field):
            return gaussian_filter(field, np.sqrt(variance) / step, mode="constant") if variance else field
        total += weight * np.sum(blur(target_values - row) ** 2) / np.sum(blur(target_values) ** 2)
    grid_error = total / sum(weight for _, weight in ndf_fit.LIGHT_WEIGHTED)
    assert error == pytest.approx(grid_error, rel=2e-3), (error, grid_error)


def test_ggx_composed_target_is_ggx_two_lobes():
    """Isotropic, anisotropic GGX's target is GGX's two-lobe sphere fit: the same lobes in normalized slopes."""
    for alpha in (0.03, 0.2, 0.6):
        weights, x_precision, y_precision = ndf_fit.ggx_composed_target(1.0, alpha)
        _, sharpness, amplitude = ndf_fit.ggx_two_lobes(np.float64(alpha))
        # ggx_two_lobes returns float32
        np.testing.assert_allclose(2 * x_precision, sharpness * alpha ** 2, rtol=1e-6)
        np.testing.assert_allclose(weights, amplitude * np.pi * alpha ** 2, rtol=1e-6)
        np.testing.assert_allclose(x_precision, y_precision)


@pytest.mark.parametrize("alphas, lobe_count, bound", [
    # relative L2 of D, measured 0.045 (before the joint table 0.044), 0.029 (0.020), 0.047 (0.044), 0.334 (0.364);
    # the plain small-angle GGX as the target gave 0.128, 0.359 at the first two
    ((0.35, 0.35), 4, 0.05), ((0.6, 0.6), 8, 0.035), ((0.3, 0.29), 8, 0.055), ((0.6, 0.2), 4, 0.35),
])
def test_ggx_anisotropic_lobes_broad_and_near_isotropy(alphas, lobe_count, bound):
    """Anisotropic GGX's lobes against its exact D on the sphere where a small-angle table fails: broad lobes,
    between the table's alphas, and near isotropy, where the table's pairs must not be paired crosswise
    (ndf_fit._order_pairs: (0.3, 0.29) at 8 lobes was 0.18 before it).  test_models.py has the anisotropic
    cases."""
    model = brdf.GGXAnisotropic(alpha_x=alphas[0], alpha_y=alphas[1])
    lobes = ndf_fit.ggx_anisotropic_lobes(np.float64(alphas[0]), np.float64(alphas[1]), lobe_count)
    assert len(lobes[1]) == lobe_count
    assert ndf_fit.ndf_l2_error(model, lobes, 16, 128) < bound


@pytest.mark.slow_maths
def test_ggx_anisotropy_table_interpolates_smoothly():
    """Between any two neighbouring rows the interpolated lobes are nearly as close to GGX as the rows
    themselves: the relative L2 of D at the midpoint ratio at most 1.12x the worse of the two rows' (alpha_x
    0.2, 4 lobes, every row pair; measured 1.07x, and 1.26x with half the rows)."""
    model_error = {}
    _, ratios, _ = ndf_fit.ggx_anisotropy_table(4)
    alpha_x = 0.2
    worst = 0.0
    for low, high in zip(ratios[:-1], ratios[1:]):
        errors = []
        for ratio in (low, np.sqrt(low * high), high):
            if ratio not in model_error:
                model = brdf.GGXAnisotropic(alpha_x=alpha_x, alpha_y=alpha_x * ratio)
                lobes = ndf_fit.ggx_anisotropic_lobes(np.float64(alpha_x), np.float64(alpha_x * ratio), 4)
                model_error[ratio] = ndf_fit.ndf_l2_error(model, lobes, 8, 64)
            errors.append(model_error[ratio])
        worst = max(worst, errors[1] / max(errors[0], errors[2]))
    assert worst < 1.12, worst


def test_anisotropic_table_errors_fall_with_lobe_count():
    """Table path at real parameters: A-S (75, 1200) as in wang2009 Fig. 2, and Ward (0.3, 0.05)."""
    ashikhmin = brdf.AshikhminShirley(nu=75.0, nv=1200.0)
    ward = brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.05)
    errors = {}
    for name, model in (("as", ashikhmin), ("ward", ward)):
        errors[name] = [ndf_fit.ndf_l2_error(model, model.ndf_lobes(k), 16, 128) for k in (1, 2, 4)]
        assert np.all(np.diff(errors[name]) < 0), errors
    # measured: A-S 0.60, 0.40, 0.18; Ward 0.71, 0.53, 0.30
    assert errors["as"][2] < 0.19 and errors["ward"][2] < 0.32, errors


def test_table_is_close_to_a_direct_fit():
    """The normalized table loses little against L-BFGS-B on the exact sphere NDF."""
    model = brdf.AshikhminShirley(nu=75.0, nv=1200.0)
    lobes = model.ndf_lobes(2)
    directions, weights = ndf_fit.hemisphere_quadrature(model.ndf_widths(), 16, 128)
    table_error = ndf_fit.relative_l2(model.ndf(directions), sg.mixture_evaluate(directions, *lobes), weights)
    *_, direct_error = ndf_fit.fit_anisotropic(model.ndf(directions), directions, weights, 2, initial=lobes,
                                               max_iterations=100)
    assert direct_error <= table_error + 1e-9 and table_error - direct_error < 0.01


def test_anisotropic_lobes_swap_axes_and_broadcast():
    across = brdf.WardAnisotropic(alpha_x=0.05, alpha_y=0.3).ndf_lobes(4)
    along = brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.05).ndf_lobes(4)
    np.testing.assert_allclose(across[0][..., [1, 0, 2]], along[0], atol=1e-12)
    np.testing.assert_allclose(across[1], along[1])
    alpha_x = np.array([0.1, 0.3, 0.02], np.float32)
    batch = brdf.WardAnisotropic(alpha_x=alpha_x, alpha_y=np.float32(0.05)).ndf_lobes(4)
    assert batch[0].dtype == np.float32 and batch[0].shape == (3, 4, 3)
    for i in range(3):
        single = brdf.WardAnisotropic(alpha_x=float(alpha_x[i]), alpha_y=0.05).ndf_lobes(4)
        np.testing.assert_allclose(batch[1][i], single[1], rtol=1e-5)
        np.testing.assert_allclose(batch[2][i], single[2], rtol=1e-5)
    table = ndf_fit.anisotropy_table_array(4)
    assert table.dtype == np.float32 and table.shape == (ndf_fit.ANISOTROPY_RATIO_COUNT, 4, 4)
    assert table.flags.c_contiguous and np.all(np.isfinite(table))


def test_brdf_rmse_of_cook_torrance_eq12():
    model = brdf.CookTorrance(roughness=0.2)
    assert ndf_fit.brdf_relative_rmse(model, model.ndf_lobes(), count=40_000) < 0.005


def test_batched_fit_matches_scipy_levenberg_marquardt():
    theta, weights = ndf_fit.polar_quadrature([0.05, 0.3], 16)
    alphas = np.array([0.05, 0.1, 0.25, 0.4, 0.6])
    values = np.stack([1 / ((np.sin(theta) / a) ** 2 + np.cos(theta) ** 2) ** 2 for a in alphas])  # GGX / D(n)
    for lobe_count in (1, 2):
        batch = ndf_fit.fit_isotropic_batch(values, theta, weights, lobe_count)
        single = ndf_fit.fit_isotropic(values, theta, weights, lobe_count)
        np.testing.assert_allclose(batch[2], single[2], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(batch[0], single[0], rtol=1e-4)


@pytest.mark.parametrize("model, corrected_bound", [
    (brdf.WardAnisotropic(alpha_x=0.5, alpha_y=0.5), 0.07), (brdf.WardAnisotropic(alpha_x=0.8, alpha_y=0.4), 0.16),
    (brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.05), 0.31), (brdf.AshikhminShirley(nu=3.0, nv=30.0), 0.12),
    (brdf.AshikhminShirley(nu=75.0, nv=1200.0), 0.18)], ids=str)
def test_broad_lobe_correction(model, corrected_bound):
    """The geometric-mean-width isotropic mapping fixes the small-angle scaling of broad lobes
    (measured 0.066, 0.147, 0.303, 0.113, 0.178 with 4 lobes) and never makes it worse."""
    plain = ndf_fit.ndf_l2_error(model, model.ndf_lobes(4), 16, 128)
    corrected = ndf_fit.ndf_l2_error(model, model.ndf_lobes(4, broad_lobe_correction=True), 16, 128)
    assert corrected < corrected_bound and corrected <= plain + 1e-3


def test_fit_ndf_front_end():
    """Callable and tabulated inputs reach the same fits as the model's own numbers."""
    model = brdf.GGX(roughness=0.4)
    alpha = 0.16
    axis, sharpness, amplitude, error = ndf_fit.fit_ndf(model.ndf, 2, alpha, isotropic=True)
    assert error < 0.05 and np.all(axis[:, 2] == 1)
    table_theta = np.linspace(0, np.pi / 2, 4000)
    table = model.ndf(np.stack([np.sin(table_theta), 0 * table_theta, np.cos(table_theta)], -1))
    _, table_sharpness, _, table_error = ndf_fit.fit_ndf((table_theta, table), 2, alpha)
    np.testing.assert_allclose(table_sharpness, sharpness, rtol=1e-3)
    ward = brdf.WardAnisotropic(alpha_x=0.2, alpha_y=0.1)
    *_, anisotropic_error = ndf_fit.fit_ndf(ward.ndf, 2, [0.2, 0.1])
    assert anisotropic_error < ndf_fit.ndf_l2_error(ward, ward.ndf_lobes(1)) - 0.05


def test_refined_lobes_for_uniform_materials():
    """refine=True fits the exact D on the sphere from the table (uniform parameters)."""
    model = brdf.WardAnisotropic(alpha_x=0.8, alpha_y=0.4)
    refined = model.ndf_lobes(4, broad_lobe_correction=True, refine=True)
    assert ndf_fit.ndf_l2_error(model, refined, 16, 128) < 0.045  # measured 0.035; table alone 0.28
    again = brdf.WardAnisotropic(alpha_x=0.8, alpha_y=0.4).ndf_lobes(4, broad_lobe_correction=True, refine=True)
    np.testing.assert_array_equal(again[1], refined[1])  # cached by value
    ashikhmin = brdf.AshikhminShirley(nu=3.0, nv=30.0)
    assert (ndf_fit.ndf_l2_error(ashikhmin, ashikhmin.ndf_lobes(4, refine=True), 16, 128)
            <= ndf_fit.ndf_l2_error(ashikhmin, ashikhmin.ndf_lobes(4), 16, 128))
