"""BRDF product tables (harmonics/brdf_table.py, kautz2002 section 3): the MIS quadrature against a dense
one, the isotropic layout's symmetries, interpolation along the parameter axis, and the paper's eq. 1:
for a band-limited lighting the dot product equals the shading integral."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from sg_prt_addon.harmonics import basis, brdf_table, rotation
from sg_prt_addon.reflectance import brdf
from sg_prt_addon.spherical.lattice import hemisphere_points

DENSE = hemisphere_points(300000)
MODELS = [("GGX 0.5", brdf.GGX(roughness=0.5)), ("GGX 0.2", brdf.GGX(roughness=0.2)),
          ("Cook-Torrance 0.3", brdf.CookTorrance(roughness=0.3)), ("Blinn-Phong 50", brdf.BlinnPhong(exponent=50.0)),
          ("Ward 0.3 x 0.1", brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.1)),
          ("Ashikhmin-Shirley 50 x 500", brdf.AshikhminShirley(nu=50, nv=500))]


def _dense_projection(model, views, order):
    y = basis.evaluate(DENSE, order)
    return np.stack([(model.specular(np.broadcast_to(v, DENSE.shape), DENSE) * DENSE[:, 2]) @ y
                     * (2 * np.pi / len(DENSE)) for v in views])


@pytest.mark.parametrize("label, model", MODELS, ids=[m[0] for m in MODELS])
def test_mis_quadrature_against_a_dense_lattice(label, model):
    """1024 + 1024 MIS samples against 300,000 uniform ones (itself good to about 1e-4 on the sharpest):
    measured 4e-5 to 1.2e-3 of the largest coefficient."""
    views = np.array([[np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)] for t, p in ((0.1, 0.3), (0.7, 2.0),
                                                                                             (1.3, -1.0))])
    table = brdf_table.project_product(model, views, 6)
    reference = _dense_projection(model, views, 6)
    error = np.max(np.abs(table - reference)) / np.max(np.abs(reference))
    print(label, error)
    assert error < 3e-3


def test_isotropic_products_are_even_in_y_and_turn_with_the_view():
    """An isotropic BRDF's product at view azimuth phi is the phi = 0 product turned by phi about z; at
    phi = 0 its m < 0 coefficients vanish (it is even in y: the lattice leaves 3e-5 of the largest, the
    tables store zero)."""
    model = brdf.GGX(roughness=0.4)
    theta, phi = 0.8, 1.1
    aligned = brdf_table.project_product(model, [[np.sin(theta), 0, np.cos(theta)]], 5, samples=4096)[0]
    turned = brdf_table.project_product(model, [[np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                                                 np.cos(theta)]], 5, samples=4096)[0]
    _, m = basis.band_of(25)
    assert np.max(np.abs(aligned[m < 0])) < 1e-3 * np.max(np.abs(aligned))
    assert np.all(brdf_table.table_for("GGX", order=5).coefficients[..., m < 0] == 0)
    np.testing.assert_allclose(rotation.rotate_z(aligned, phi), turned, atol=2e-3 * np.abs(aligned).max())


def test_parameter_axis_interpolation():
    """GGX's table over roughness (16 nodes on [0.02, 1]) read between nodes, against the product at that
    roughness: within 3% of the largest coefficient at roughness >= 0.2 (linear interpolation of a
    function that sharpens as roughness falls; measured 0.65%)."""
    table = brdf_table.table_for("GGX", order=5)
    views = brdf_table.theta_directions(64)[::9]
    worst = 0.0
    for roughness in (0.2, 0.37, 0.55, 0.81):
        looked_up = brdf_table.lookup(table, views, roughness)
        direct = brdf_table.project_product(brdf.GGX(roughness=roughness), views, 5)
        worst = max(worst, np.max(np.abs(looked_up - direct)) / np.max(np.abs(direct)))
    print(worst)
    assert worst < 0.03


@pytest.mark.parametrize("label, model", [MODELS[0], MODELS[2], MODELS[5]], ids=[MODELS[i][0] for i in (0, 2, 5)])
def test_dot_product_is_the_shading_integral_for_band_limited_light(label, model):
    """kautz2002 eq. 1: with L of order 5, sum L_i c_i(v) = integral L f cos, to the quadrature's error."""
    order = 5
    rng = np.random.default_rng(3)
    light = rng.normal(size=order * order)
    light[0] = 4.0                                   # mostly positive, as radiance is
    views = Rotation.random(4, random_state=1).apply([0, 0, 1])
    views[:, 2] = np.abs(views[:, 2]) + 0.05
    views /= np.linalg.norm(views, axis=-1, keepdims=True)
    c = brdf_table.project_product(model, views, order, samples=4096)
    radiance = basis.reconstruct(light, DENSE)
    direct = np.array([np.sum(model.specular(np.broadcast_to(v, DENSE.shape), DENSE) * DENSE[:, 2] * radiance)
                       * (2 * np.pi / len(DENSE)) for v in views])
    error = np.max(np.abs(c @ light - direct)) / np.max(np.abs(direct))
    print(label, error)
    assert error < 2e-3


def test_tables_are_cached_and_built_in_seconds():
    first = brdf_table.table_for("BLINN_PHONG", order=4, parameter_count=8)
    again = brdf_table.table_for("BLINN_PHONG", order=4, parameter_count=8)
    assert again is first and first.coefficients.shape == (8, 64, 16) and first.seconds < 10
    anisotropic = brdf_table.table_for("ASHIKHMIN_SHIRLEY", order=4, resolution=16, nu=20.0, nv=200.0)
    assert anisotropic.layout == "parabolic" and anisotropic.coefficients.shape == (1, 256, 16)
    assert anisotropic is not brdf_table.table_for("ASHIKHMIN_SHIRLEY", order=4, resolution=16, nu=20.0, nv=100.0)
