"""reflectance.ggx_albedo: GGX's directional albedo by half-vector quadrature against a dense solid-angle
quadrature of brdf.GGX itself, and the table the shader fetches."""
import numpy as np
import pytest

from sg_prt_addon.reflectance import brdf, ggx_albedo
from sg_prt_addon.techniques.sg.sg_shading import sample_texture


def _solid_angle_albedo(cos_o, roughness, nodes=700):
    """Gauss-Legendre in cos theta_i x uniform phi over the hemisphere of wi: a slow, independent reference."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    cos_i, weight = 0.5 * (x + 1), 0.5 * w
    phi = (np.arange(2 * nodes) + 0.5) * np.pi / nodes
    sin_i = np.sqrt(1 - cos_i ** 2)
    wi = np.stack(np.broadcast_arrays(sin_i[:, None] * np.cos(phi), sin_i[:, None] * np.sin(phi), cos_i[:, None]),
                  -1).reshape(-1, 3)
    wo = np.array([np.sqrt(1 - cos_o ** 2), 0.0, cos_o])
    value = brdf.GGX(roughness=roughness).specular(np.broadcast_to(wo, wi.shape), wi) * wi[:, 2]
    return float(value.reshape(nodes, 2 * nodes).sum(1) @ weight * (np.pi / nodes))


@pytest.mark.parametrize("cos_o, roughness", [(1.0, 0.5), (0.5, 0.3), (0.2, 0.8), (0.05, 0.6), (0.3, 1.0), (0.9, 0.2)])
def test_albedo_matches_a_solid_angle_quadrature(cos_o, roughness):
    # measured: within 1.5e-4 (default nodes 64 x 32)
    assert abs(ggx_albedo.directional_albedo(cos_o, roughness) - _solid_angle_albedo(cos_o, roughness)) < 2e-3


@pytest.mark.slow_maths
def test_table_is_bounded_and_close_to_a_finer_quadrature():
    table = ggx_albedo.albedo_table()
    assert table.shape == (ggx_albedo.TABLE_SIZE, ggx_albedo.TABLE_SIZE) and np.all(np.isfinite(table))
    assert table.min() > 0.2 and table.max() <= 1.0 + 1e-6        # no Fresnel: at most all the light
    grid = ggx_albedo.texel_centres()
    finer = ggx_albedo.directional_albedo(grid[None, :], grid[:, None], 192, 128)
    assert np.abs(table - finer).max() < 6e-3      # measured 4.9e-3, at the grazing and smoothest corners


def test_bilinear_fetch_lands_on_the_texel_centres():
    table = ggx_albedo.albedo_table()
    grid = ggx_albedo.texel_centres()
    s, t = ggx_albedo.table_coordinates(grid[[3, 17, 31]], grid[[0, 9, 30]])
    fetched = sample_texture(table[..., None], np.stack([s, t], -1))[:, 0]
    np.testing.assert_allclose(fetched, table[[0, 9, 30], [3, 17, 31]], rtol=1e-5)
