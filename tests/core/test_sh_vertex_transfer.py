"""The SH technique's transfer summed at the vertices (techniques/sh/spherical_harmonics.py vertex_transfer_rows,
vertex_transfer_values; shaders/techniques/sh/sh_shading.glsl VERTEX_TRANSFER): which variants the varyings
hold, the packed layout, and that interpolating the vertices' sums is the sum of the interpolated weights."""
import numpy as np
import pytest

from sg_prt_addon.lighting import env_prefilter
from sg_prt_addon.lighting.scene_lighting import EnvironmentData
from sg_prt_addon.techniques import shader_sources
from sg_prt_addon.techniques.sh import sh_shading, spherical_harmonics
from sg_prt_addon.visibility import transfer
from sg_prt_addon.visibility.per_vertex import PerVertexData


def test_the_sums_go_to_the_vertices_up_to_order_5_and_within_the_varyings(monkeypatch):
    """Order 5 with lights is the largest: 26 vec4 (T L 75, t . L 3, t 25 floats), 31 with the surface's own."""
    for order in range(2, 9):
        for has_lights in (False, True):
            rows = spherical_harmonics.vertex_transfer_rows(order, has_lights)
            assert (rows > 0) == (order <= 5)
            floats = 3 * (order * order + 1) + (order * order if has_lights else 0)
            if rows:
                assert 4 * rows >= floats > 4 * rows - 4
                assert rows + shader_sources.SURFACE_VARYINGS <= shader_sources.MAX_VARYINGS
    assert spherical_harmonics.vertex_transfer_rows(5, True) == 26
    # a driver with fewer varyings (Metal's 124 floats less Blender's own, some GL drivers' 64) keeps the larger
    # orders summed per pixel: 16 vec4 hold order 3 with lights (10 rows and the surface's 5), not order 4
    monkeypatch.setattr(shader_sources, "_driver_varyings", [16])
    assert spherical_harmonics.vertex_transfer_rows(3, True) == 10
    assert spherical_harmonics.vertex_transfer_rows(4, False) == 0
    monkeypatch.setattr(spherical_harmonics, "VERTEX_TRANSFER", False)
    assert spherical_harmonics.vertex_transfer_rows(3, False) == 0


@pytest.fixture(scope="module")
def baked():
    """A transfer bake's PerVertexData of 12 vertices, order 5 and 6 terms, under a random environment map."""
    rng = np.random.default_rng(4)
    order, terms = 5, 6
    size = transfer.vector_size(order)
    weights = np.c_[np.ones(12), rng.normal(size=(12, terms)), np.zeros(12)].astype(np.float32)   # [1, w_0, ...]
    texture = transfer.basis_texture(rng.normal(size=size) * 0.3, rng.normal(size=(terms, size)) * 0.1)
    data = PerVertexData("transfer", weights, texture, 2, terms, 1)
    image = rng.uniform(0.1, 2.0, (16, 32, 3)).astype(np.float32)
    environment = EnvironmentData(colour=np.ones(3, np.float32), radiance=image,
                                  prefiltered=env_prefilter.prefilter_environment(image, size=8))
    return data, environment, order


@pytest.mark.parametrize("has_lights", [False, True])
def test_packed_as_the_shader_reads_them(baked, has_lights):
    data, environment, order = baked
    count = order * order
    rows = spherical_harmonics.vertex_transfer_rows(order, has_lights)
    values = spherical_harmonics.vertex_transfer_values(data, environment, order, "none", rows)
    assert values.shape == (12, 4 * rows) and values.dtype == np.float32
    lit, irradiance, diffuse_transfer = sh_shading.transfer_sums(
        data.rows, spherical_harmonics.transfer_radiance_texture(data, environment, order, "none"),
        transfer.basis_terms(data.basis_texture), count)
    np.testing.assert_array_equal(values[:, :3 * count].reshape(12, count, 3), lit)          # coefficient i: 3 i ..
    np.testing.assert_array_equal(values[:, 3 * count:3 * count + 3], irradiance)
    tail = values[:, 3 * count + 3:]
    if has_lights:
        np.testing.assert_array_equal(tail[:, :count], diffuse_transfer)
        tail = tail[:, count:]
    assert np.all(tail == 0)


def test_interpolating_the_vertex_sums_is_the_sum_of_the_interpolated_weights(baked):
    """Linear in the weights, so exact but for float32 rounding: measured 1.3e-7 of the largest value."""
    data, environment, order = baked
    count = order * order
    rng = np.random.default_rng(5)
    corners = rng.integers(0, 12, (200, 3))
    barycentric = rng.dirichlet(np.ones(3), 200)
    products = spherical_harmonics.transfer_radiance_texture(data, environment, order, "none")
    terms = transfer.basis_terms(data.basis_texture)
    rows = spherical_harmonics.vertex_transfer_rows(order, True)
    at_vertices = spherical_harmonics.vertex_transfer_values(data, environment, order, "none", rows)
    interpolated = np.einsum("nk,nkc->nc", barycentric, at_vertices[corners].astype(np.float64))
    per_pixel = sh_shading.transfer_sums(np.einsum("nk,nkc->nc", barycentric, data.rows[corners]), products, terms,
                                         count)
    expected = np.concatenate([per_pixel[0].reshape(200, -1), per_pixel[1], per_pixel[2]], axis=1)
    error = np.abs(interpolated[:, :expected.shape[1]] - expected).max() / np.abs(expected).max()
    print("relative difference", error)
    assert error < 2e-6
