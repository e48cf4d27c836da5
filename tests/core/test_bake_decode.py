"""sg_prt_addon.visibility.decode: GPU-sampler bilinear mirror, packed GPU layout, lookups below the horizon,
and the shadowed lobe integral against ray-traced visibility."""
import numpy as np

from sg_prt_addon.spherical import sg, texture_fetch
from sg_prt_addon.visibility import decode, hemisphere_map, ssdf


def test_bilinear_is_exact_at_texel_centres_linear_between_and_clamped():
    rng = np.random.default_rng(7)
    image = rng.normal(size=(8, 8))
    centres = (np.arange(8) + 0.5) / 8
    t, s = np.meshgrid(centres, centres, indexing="ij")
    assert np.allclose(texture_fetch.bilinear_channels_first(image, np.stack([s, t], -1).reshape(-1, 2)), image.ravel())
    # half-way between two texels in s: their mean
    assert np.isclose(texture_fetch.bilinear_channels_first(image, np.array([[2 / 8, 0.5 / 8]]))[0], 0.5 * (image[0, 1] + image[0, 2]))
    # clamp to edge outside the outer texel centres
    assert np.isclose(texture_fetch.bilinear_channels_first(image, np.array([[0.0, 0.0]]))[0], image[0, 0])
    assert np.isclose(texture_fetch.bilinear_channels_first(image, np.array([[1.0, 0.3 / 8]]))[0], image[0, 7])


def test_packed_layout_decodes_the_same():
    rng = np.random.default_rng(8)
    terms, resolution = 6, 8
    basis = rng.normal(size=(terms, resolution, resolution))
    mean = rng.normal(size=(resolution, resolution))
    coefficients = rng.normal(size=(50, terms))
    direction = rng.normal(size=(50, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    expected = decode.decode(coefficients, basis, mean, direction)
    # one vertex's coefficients broadcast over many directions
    assert np.allclose(decode.decode(coefficients[3], basis, mean, direction)[3], expected[3])
    texture = decode.pack_basis_texture(mean, basis)
    packed = decode.pack_coefficients(coefficients)
    assert texture.shape == (2, resolution, resolution, 4) and packed.shape == (50, 8)
    texcoord, below = decode.texcoord_of(direction, resolution)
    fetched = texture_fetch.bilinear_channels_first(np.moveaxis(texture, -1, 1), texcoord)        # (L, 4, Q)
    value = np.einsum("lcq,qlc->q", fetched, packed.reshape(50, 2, 4)) - below
    assert np.abs(value - expected).max() < 1e-5


def test_below_horizon_subtracts_the_angle():
    image = np.full((8, 8), 0.3)
    d = np.array([[np.cos(0.2), 0.0, -np.sin(0.2)], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    assert np.allclose(decode.decode_image(image, d), [0.3 - 0.2, 0.3 - np.pi / 2, 0.3])


def test_shadowed_integral_against_exact_visibility():
    """A spherical-cap occluder: mu fh(V_d(p)) vs the quadrature of the SG over the true visible set.

    The SSDF's hemisphere is exact for an SG only when the visible boundary is a great circle;
    for a cap of radius 0.5 rad and lobes outside it the error is the cap's curvature: bounded here."""
    resolution, refinement = 32, 5
    fine = hemisphere_map.texel_directions(resolution * refinement)
    cap_centre = np.array([0.0, np.sin(0.5), np.cos(0.5)])
    cap_radius = 0.5
    visible = (fine @ cap_centre < np.cos(cap_radius))[None]
    image = ssdf.ssdf_from_fine(visible, resolution)[0]
    basis = image[None]
    mean = np.zeros_like(image)
    # lobes around the cap's edge
    rng = np.random.default_rng(9)
    axes = rng.normal(size=(40, 3))
    axes[:, 2] = np.abs(axes[:, 2]) + 0.5
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    sharpness = 50.0
    approx = decode.shadowed_integral(axes, sharpness, 1.0, np.ones((40, 1)), basis, mean)
    # reference: SG integrated over the visible set (upper hemisphere minus cap) by a fine Fibonacci sphere
    count = 400000
    k = np.arange(count) + 0.5
    z = 1 - 2 * k / count
    phi = np.pi * (1 + 5 ** 0.5) * k
    points = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    in_visible = (points[:, 2] >= 0) & (points @ cap_centre < np.cos(cap_radius))
    weights = 4 * np.pi / count
    exact = np.array([np.sum(sg.evaluate(points[in_visible], a, sharpness)) * weights for a in axes])
    scale = sg.axis_hemisphere_integral(sharpness)
    error = np.abs(approx - exact) / scale
    assert error.max() < 0.2 and error.mean() < 0.05, (error.max(), error.mean())
