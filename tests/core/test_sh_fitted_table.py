"""The SH tables of a stored lobe fit (harmonics/fitted_table.py): each texel's entries against a dense
lattice's projection of the fitted BRDF x cosine, the very BRDF the SG_FITTED mirror evaluates
(validation/fitted_sh_reference.py), per order; the view interpolation; the GPU layout; the cache."""
import numpy as np
import pytest

from sg_prt_addon.harmonics import basis, fitted_table
from sg_prt_addon.measured import microfacet_fit
from sg_prt_addon.reflectance import brdf
from validation import brdf_generators, fitted_sh_reference

ORDERS = (3, 4, 5, 6)
VIEWS = 16                             # table nodes; the engine's tables have fitted_table.DEFAULT_VIEWS
CHECKED_VIEWS = (1, 8, 13, 15)         # theta_v 0.15, 0.83, 1.28, 1.52 rad


@pytest.fixture(scope="module")
def fit():
    """A 2-lobe fit (lobes about the normal) of a generated 8 x 8 SVBRDF table: sharpness 3 to 15,000."""
    table, _ = brdf_generators.generate_svbrdf_table(size=8, seed=5)
    return fitted_sh_reference.fit_arrays(microfacet_fit.fit_lobes(table, 2, shadowing_components=5))


def _texels(fit):
    """The sharpest, the broadest and a middle texel."""
    sharpness = fit["sharpness"]
    return np.unique([int(np.argmax(sharpness.max(1))), int(np.argmin(sharpness.min(1))),
                      int(np.argsort(sharpness.max(1))[len(sharpness) // 2])])


@pytest.mark.slow_maths
def test_entries_against_a_dense_lattice_per_order(fit):
    """Orders 3-6 at view nodes from the normal to 87 degrees: measured max 1.15e-3 of the texel's largest
    coefficient at every order (a coefficient's quadrature is the same at any order: the kinks of the
    piecewise linear S, which the nodes do not follow, limit it); the dense projection's m < 0 coefficients
    vanish (an isotropic product in the view-plane frame: 2.5e-7, the lattice's asymmetry), which the table
    leaves out."""
    texels = _texels(fit)
    reference = {view: fitted_sh_reference.dense_product(fit, texels, fitted_table.view_thetas(VIEWS)[view],
                                                         max(ORDERS)) for view in CHECKED_VIEWS}
    _, m = basis.band_of(max(ORDERS) ** 2)
    for values in reference.values():
        assert np.max(np.abs(values[:, m < 0])) < 1e-5 * np.max(np.abs(values))
    errors = {}
    for order in ORDERS:
        table = fitted_table.table_for(fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], (8, 8), order,
                                       views=VIEWS)
        scale = np.max(np.abs(np.stack(list(reference.values()))[:, :, :order * order]), axis=(0, 2, 3))
        errors[order] = max(float(np.max(np.abs(fitted_sh_reference.table_product(fit, table, texels, view)
                                                - reference[view][:, :order * order]) / scale[:, None, None]))
                            for view in CHECKED_VIEWS)
    print("max error / largest coefficient per order", errors)
    assert max(errors.values()) < 3e-3


def test_views_between_nodes_interpolate_linearly(fit):
    """The shader's linear interpolation between the 64 view nodes against the projection at the view itself:
    measured max 8.3e-4 of the texel's largest coefficient below 70 degrees, 1.1e-2 nearer grazing (where
    the broad lobes' part above the horizon changes fastest)."""
    texels = _texels(fit)
    args = (fit["sharpness"][texels], fit["eta"][texels], fit["shadowing"][texels], fit["theta"], 5)
    nodes = fitted_table.project_texels(*args, fitted_table.view_thetas())
    table = fitted_table.FittedTable(5, (1, len(texels)), nodes)
    middles = (np.arange(fitted_table.DEFAULT_VIEWS - 1) + 1.0) / fitted_table.DEFAULT_VIEWS * (np.pi / 2)
    looked_up = np.stack([fitted_table.lookup(table, np.arange(len(texels)), np.full(len(texels), theta))
                          for theta in middles], 2)[..., fitted_table.positive_m_indices(5)]
    direct = fitted_table.project_texels(*args, middles)
    error = np.abs(looked_up - direct) / np.max(np.abs(nodes), axis=(1, 2, 3))[:, None, None, None]
    below = middles < np.radians(70)
    print("interpolation error", error[:, :, below].max(), error[:, :, ~below].max())
    assert error[:, :, below].max() < 5e-3 and error.max() < 3e-2


def test_texture_layout_is_what_the_shader_fetches(fit):
    """texture_layers: lobe k's stored coefficient p of texel (x, y) at view node j is component p % 4 of layer
    k ceil(M / 4) + p // 4, column x V + j, row y."""
    table = fitted_table.table_for(fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], (8, 8), 4, views=VIEWS)
    layers = fitted_table.texture_layers(table)
    stored = len(fitted_table.positive_m_indices(4))
    per_lobe = fitted_table.layers_per_lobe(4)
    assert layers.shape == (2 * per_lobe, 8, 8 * VIEWS, 4) and layers.dtype == np.float32
    assert layers.nbytes == fitted_table.table_bytes(64, 2, 4, VIEWS)
    rng = np.random.default_rng(1)
    for _ in range(20):
        x, y, k, j, p = (int(rng.integers(n)) for n in (8, 8, 2, VIEWS, stored))
        assert layers[k * per_lobe + p // 4, y, x * VIEWS + j, p % 4] == table.coefficients[y * 8 + x, k, j, p]


def test_tables_are_cached_by_content_and_equal_texels_share_rows(fit):
    args = (fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], (8, 8), 3)
    first = fitted_table.table_for(*args, views=8)
    assert fitted_table.table_for(*(np.copy(a) if isinstance(a, np.ndarray) else a for a in args), views=8) is first
    changed = fit["eta"].copy()
    changed[0] += 0.1
    assert fitted_table.table_for(args[0], changed, *args[2:], views=8) is not first
    repeated = [np.repeat(a[:2], 3, axis=0) for a in (fit["sharpness"], fit["eta"], fit["shadowing"])]
    table = fitted_table.table_for(*repeated, fit["theta"], (2, 3), 3, views=8)
    np.testing.assert_array_equal(table.coefficients[0], table.coefficients[2])
    np.testing.assert_array_equal(table.coefficients[3], table.coefficients[5])
    np.testing.assert_allclose(table.coefficients[[0, 3]], first.coefficients[:2], rtol=1e-6, atol=1e-12)


def test_fused_fresnel_is_the_dielectric_fresnel():
    """Against brdf.fresnel_dielectric in float64 (total internal reflection included): within 1e-4 (eta 1.0001:
    eta^2 - 1 in float32; the library's own float32 is off by 4e-4 there), else 1.4e-6."""
    cosine = np.linspace(1e-4, 1.0, 500).astype(np.float32)
    for eta in (np.array([[1.0001], [1.33], [1.5], [3.0]], np.float32), np.array([[0.7], [1.5]], np.float32)):
        exact = brdf.fresnel_dielectric(np.broadcast_to(cosine.astype(np.float64), (len(eta), 500)),
                                        eta.astype(np.float64))
        np.testing.assert_allclose(fitted_table._fresnel(cosine, eta), exact, rtol=1.5e-4)


def test_the_memory_bound():
    """64 x 64 texels of 2 lobes: 34 MB at order 5, 75 MB at order 8, both under MAX_TABLE_BYTES."""
    assert fitted_table.table_bytes(4096, 2, 5) == 4096 * 2 * 64 * 4 * 16
    assert fitted_table.table_bytes(4096, 2, 8) < fitted_table.MAX_TABLE_BYTES < fitted_table.table_bytes(16384, 2, 6)
