"""SG-prefiltered environment (wang2009 eq. 34-35): layout, GPU-mirror lookup, and error against exact
SG-mixture convolutions (the inner product of two SGs is closed form)."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from sg_prt_addon.lighting import env_prefilter as ep
from sg_prt_addon.lighting import equirect
from sg_prt_addon.spherical import sg
from validation import exact_references

# an environment made of SG lobes: its SG convolution is exact (sg.inner_product)
ENV_AXES = sg.normalize(np.array([[0.3, 0.2, 0.9], [-0.8, 0.1, -0.2], [0.1, -0.9, 0.3], [0.0, 0.0, -1.0]]))
ENV_SHARPNESS = np.array([30.0, 6.0, 60.0, 2.0])
ENV_AMPLITUDE = np.array([[4.0, 3.0, 2.0], [1.0, 1.5, 2.0], [6.0, 5.0, 1.0], [0.3, 0.3, 0.3]])
CONSTANT = np.array([0.2, 0.25, 0.3])


def _render(height):
    directions = equirect.texel_directions(height, 2 * height)
    weights = sg.evaluate(directions[..., None, :], ENV_AXES, ENV_SHARPNESS)
    return weights @ ENV_AMPLITUDE + CONSTANT


def _exact_normalized(axis, sharpness):
    """Gamma_L(p, lambda) / integral G for the SG-mixture environment, closed form."""
    inner = sg.inner_product(axis[:, None, :], sharpness[:, None], 1.0, ENV_AXES, ENV_SHARPNESS, 1.0)
    gamma = inner @ ENV_AMPLITUDE + CONSTANT * sg.sphere_integral(sharpness)[:, None]
    return gamma / sg.sphere_integral(sharpness)[:, None]


@pytest.fixture(scope="module")
def environment():
    return _render(256)


@pytest.fixture(scope="module")
def prefiltered(environment):
    return ep.prefilter_environment(environment, size=128)


def _random_axes(count, seed):
    return sg.normalize(np.random.default_rng(seed).normal(size=(count, 3)))


def test_octahedral_roundtrip_and_gutter_continuation():
    axes = _random_axes(500, 0)
    np.testing.assert_allclose(ep.oct_decode(ep.oct_encode(axes)), axes, atol=1e-12)
    coords = ep.oct_encode(axes)
    assert np.all(np.abs(coords) <= 1)
    # a point just outside an edge continues to the mirrored point inside: same direction
    np.testing.assert_allclose(ep.oct_decode([1.02, 0.3]), ep.oct_decode([0.98, -0.3]), atol=1e-12)
    np.testing.assert_allclose(ep.oct_decode([-0.3, -1.01]), ep.oct_decode([0.3, -0.99]), atol=1e-12)
    # texel solid angles du dv / |p|^3 of the octahedron point sum to 4 pi
    n = 64
    c = ep.content_texel_coords(n + 2)[1:-1, 1:-1]
    d = ep.oct_decode(c)
    p = d / np.sum(np.abs(d), axis=-1, keepdims=True)
    assert np.sum((2 / n) ** 2 / np.linalg.norm(p, axis=-1) ** 3) == pytest.approx(4 * np.pi, rel=1e-3)


def test_layout(prefiltered):
    layers = prefiltered.layers
    assert layers.dtype == np.float32 and layers.shape[1:3] == (128, 128)
    assert layers.shape[0] == prefiltered.sharpness.size
    ratios = np.diff(np.log2(prefiltered.sharpness)) * prefiltered.levels_per_octave
    np.testing.assert_allclose(ratios, 1.0)
    assert np.all(np.isfinite(layers)) and np.all(layers >= 0)
    # texture coordinates of the octahedron's corners land on the first and last interior texel edges
    for k, n in enumerate(prefiltered.content_size):
        low = -1 * prefiltered.texcoord_scale[k] + prefiltered.texcoord_offset[k]
        high = 1 * prefiltered.texcoord_scale[k] + prefiltered.texcoord_offset[k]
        assert low * 128 == pytest.approx(1.0, abs=1e-4) and high * 128 == pytest.approx(n - 1, abs=1e-4)


def test_constant_environment_is_reproduced_exactly():
    pre = ep.prefilter_environment(np.full((32, 64, 3), 0.7), size=64)
    axes = _random_axes(200, 1)
    sharpness = np.exp(np.random.default_rng(2).uniform(-4, 12, 200))
    np.testing.assert_allclose(ep.lookup(pre, axes, sharpness), 0.7, rtol=1e-5)


def test_lookup_at_texel_centres_returns_the_texel(prefiltered):
    k = 9
    n = prefiltered.content_size[k]
    rows, cols = np.meshgrid(np.arange(1, n - 1, 5), np.arange(1, n - 1, 7), indexing="ij")
    directions = ep.oct_decode(ep.content_texel_coords(n)[rows, cols])
    got = ep.lookup(prefiltered, directions, np.full(rows.shape, prefiltered.sharpness[k]))
    np.testing.assert_allclose(got, prefiltered.layers[k, rows, cols], rtol=2e-5)


def test_brute_force_reference_matches_closed_form(environment):
    axes = _random_axes(40, 3)
    sharpness = np.array([0.5, 5.0, 50.0, 300.0] * 10)
    np.testing.assert_allclose(exact_references.brute_force_convolution(environment, axes, sharpness),
                               _exact_normalized(axes, sharpness), rtol=2e-3)


@pytest.mark.parametrize("band, bound", [((0.125, 8.0), 0.005), ((8.0, 64.0), 0.018), ((64.0, 256.0), 0.02)])
def test_lookup_error_against_exact_sg_convolution(prefiltered, band, bound):
    """Random axes, sharpness log-uniform in the band (mostly between levels); error relative to the
    local value.  Measured at size 128: 0.0031, 0.0126, 0.0149 (bilinear interpolation across the
    octahedral creases dominates once the layer size caps the content; 256 halves it)."""
    count = 400
    axes = _random_axes(count, 4)
    sharpness = np.exp(np.random.default_rng(5).uniform(np.log(band[0]), np.log(band[1]), count))
    exact = _exact_normalized(axes, sharpness)
    got = ep.lookup(prefiltered, axes, sharpness)
    assert np.max(np.abs(got - exact) / exact) < bound


def test_sharpness_beyond_the_levels_degenerates_to_radiance(prefiltered, environment):
    axes = _random_axes(100, 6)
    top = prefiltered.sharpness[-1]
    beyond = ep.lookup(prefiltered, axes, np.full(100, 1e7))
    np.testing.assert_array_equal(beyond, ep.lookup(prefiltered, axes, np.full(100, top)))
    # the top level (645 at size 128) approaches the radiance: it still blurs the lambda = 60 lobe's
    # peak by 1 - 645 / (645 + 60) = 8.5% (measured 9.6%)
    exact_radiance = (sg.evaluate(axes[:, None, :], ENV_AXES, ENV_SHARPNESS) @ ENV_AMPLITUDE) + CONSTANT
    assert np.max(np.abs(beyond - exact_radiance) / exact_radiance) < 0.11
    # below the broadest level the broadest layer is used; lookup_integral scales by the SG integral
    integral = ep.lookup_integral(prefiltered, axes, np.full(100, 1e-9))
    assert np.all(np.isfinite(integral))


@settings(max_examples=10, deadline=None)
@given(st.floats(0.2, 100.0))
def test_lookup_integral_is_the_inner_product(prefiltered, sharpness):
    axes = _random_axes(50, 7)
    lam = np.full(50, sharpness)
    exact = _exact_normalized(axes, lam) * sg.sphere_integral(lam)[:, None]
    got = ep.lookup_integral(prefiltered, axes, lam)
    assert np.max(np.abs(got - exact) / exact) < 0.018  # measured 0.0133 at lambda 100


def test_prefilter_is_fast_and_float32_in_float32_out():
    import time

    image = np.random.default_rng(8).random((128, 256, 3)).astype(np.float32)
    start = time.perf_counter()
    pre = ep.prefilter_environment(image, size=64)
    assert time.perf_counter() - start < 5.0
    out = ep.lookup(pre, np.float32([[0, 0, 1]]), np.float32([10.0]))
    assert out.dtype == np.float32


def test_equirect_mapping_matches_cycles():
    """Cycles direction_to_equirectangular: u = (atan2(y, x) - pi) / (-2 pi), v = (acos(z) - pi) / (-pi),
    v = 0 at the image's bottom row (our row = (1 - v) * height)."""
    directions = _random_axes(200, 9)
    u, v = equirect.direction_to_uv(directions)
    cycles_u = (np.arctan2(directions[:, 1], directions[:, 0]) - np.pi) / (-2 * np.pi)
    cycles_v = (np.arccos(directions[:, 2]) - np.pi) / (-np.pi)
    np.testing.assert_allclose(u, cycles_u, atol=1e-12)
    np.testing.assert_allclose(v, cycles_v, atol=1e-12)
    # +x is the image centre, +y a quarter from the left, +z the top row
    assert equirect.direction_to_uv(np.array([1.0, 0, 0]))[0] == pytest.approx(0.5)
    assert equirect.direction_to_uv(np.array([0, 1.0, 0]))[0] == pytest.approx(0.25)
    image = np.zeros((8, 16, 3))
    image[0] = 1.0
    assert equirect.lookup_nearest(image, np.array([0, 0, 1.0]))[0] == 1.0


def test_texture_and_uniform_data(prefiltered):
    data = prefiltered.texture_data()
    assert data.shape == prefiltered.layers.shape[:3] + (4,) and data.dtype == np.float32 and data.flags.c_contiguous
    np.testing.assert_array_equal(data[..., :3], prefiltered.layers)
    uniforms = prefiltered.level_uniforms()
    assert uniforms.shape == (prefiltered.sharpness.size, 4) and uniforms.dtype == np.float32
    np.testing.assert_array_equal(uniforms[:, 0], prefiltered.texcoord_scale)


def test_lookup_integral_amplitude_shapes(prefiltered):
    axes = _random_axes(5, 10)
    lam = np.full(5, 20.0)
    base = ep.lookup_integral(prefiltered, axes, lam)
    np.testing.assert_allclose(ep.lookup_integral(prefiltered, axes, lam, 2.0), 2 * base, rtol=1e-6)
    per_lobe = np.arange(1.0, 6.0)
    np.testing.assert_allclose(ep.lookup_integral(prefiltered, axes, lam, per_lobe), base * per_lobe[:, None], rtol=1e-6)
    colour = np.tile([1.0, 2.0, 3.0], (5, 1))
    np.testing.assert_allclose(ep.lookup_integral(prefiltered, axes, lam, colour), base * colour, rtol=1e-6)
    # a scalar sharpness broadcasts over the axes
    np.testing.assert_allclose(ep.lookup_integral(prefiltered, axes, 20.0), base, rtol=1e-6)


def test_sharpness_below_the_broadest_level(prefiltered):
    """Affine in lambda towards the mean radiance: measured 0.00046 max at size 128 (clamping to the
    broadest layer instead gave 0.028 at lambda -> 0)."""
    axes = _random_axes(200, 11)
    for lam in (0.0, 1e-3, 0.01, 0.05, 0.1):
        sharpness = np.full(200, lam)
        exact = _exact_normalized(axes, np.maximum(sharpness, 1e-9))
        assert np.max(np.abs(ep.lookup(prefiltered, axes, sharpness) - exact) / exact) < 0.002
