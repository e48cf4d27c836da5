"""Mip levels of the material textures (spherical/texture_mips.py): their layout in the GPU's atlas, trilinear
sampling at a footprint against the exact average of the texels under it, and the spread of a minified normal
map's normals (techniques.sg.sg_shading.normal_spread) against the von Mises-Fisher distribution it stands for."""
import numpy as np
import pytest

from benchmarks.accuracy import film
from sg_prt_addon.spherical import texture_mips
from sg_prt_addon.spherical.texture_fetch import bilinear
from sg_prt_addon.techniques.sg import sg_shading


def _image(height, width, seed=0):
    return np.random.default_rng(seed).random((height, width, 4)).astype(np.float32)


@pytest.mark.parametrize("width, height", [(1, 1), (5, 3), (16, 16), (7, 1), (1, 9), (300, 200)])
def test_the_atlas_holds_every_level_and_the_header(width, height):
    image = _image(height, width)
    levels = texture_mips.levels(image)
    atlas = texture_mips.atlas(image)
    assert atlas.shape[:2][::-1] == texture_mips.atlas_size(width, height)
    assert len(levels) == texture_mips.level_count(width, height) and levels[-1].shape[:2] == (1, 1)
    for index, level in enumerate(levels):
        (x, y), (w, h) = texture_mips.level_rect((width, height), index)
        assert level.shape[:2] == (h, w)
        np.testing.assert_array_equal(atlas[y:y + h, x:x + w], level)
    np.testing.assert_array_equal(atlas[-1, -1], [width, height, len(levels), 0])
    # even sides: a level's mean is the image's (odd ones repeat an edge texel)
    if width % 2 == 0 and height % 2 == 0:
        np.testing.assert_allclose(levels[1].mean(axis=(0, 1)), image.mean(axis=(0, 1)), rtol=1e-5)


def test_sampling_without_a_footprint_is_bilinear_and_a_wide_one_the_mean():
    image = _image(32, 32)
    uv = np.random.default_rng(1).random((500, 2)).astype(np.float32)
    np.testing.assert_allclose(texture_mips.sample(image, uv), bilinear(image, uv, wrap=True), atol=1e-6)
    np.testing.assert_allclose(texture_mips.sample(image, uv, np.zeros(500)), bilinear(image, uv, wrap=True),
                               atol=1e-6)
    whole = texture_mips.sample(image, uv, np.full(500, 2.0))       # past the last level: the 1 x 1 mean
    np.testing.assert_allclose(whole, np.broadcast_to(image.mean(axis=(0, 1)), whole.shape), rtol=1e-5)


def test_a_minified_checker_comes_close_to_the_texels_it_covers():
    """A 1-texel checker seen 4 texels a pixel: trilinear at the footprint against the mean of the 4 x 4 texels
    under each pixel (0.5 everywhere), beside bilinear in the image (aliased: 0 or 1, the texel under the
    pixel's centre)."""
    size = 256
    checker = (np.add.outer(np.arange(size), np.arange(size)) % 2).astype(np.float32)
    image = np.repeat(checker[..., None], 4, axis=-1)
    pixels = (np.arange(size // 4) * 4 + 1.5) / size          # pixel centres on texel centres
    uv = np.stack(np.meshgrid(pixels, pixels), axis=-1).reshape(-1, 2).astype(np.float32)
    filtered = texture_mips.sample(image, uv, np.full(len(uv), 4.0 / size))[:, 0]
    aliased = texture_mips.sample(image, uv)[:, 0]
    print(f"|error| trilinear {np.abs(filtered - 0.5).max():.3f}, bilinear {np.abs(aliased - 0.5).max():.3f}")
    assert np.abs(filtered - 0.5).max() < 1e-6 and np.abs(aliased - 0.5).max() > 0.4


def test_trilinear_comes_close_to_the_texels_under_a_pixel():
    """Trilinear at footprints of 2, 4 and 8 texels against the mean of the texels under each pixel of white
    noise (docs/ACCURACY.md, film; measured mean 0.052 / 0.036 / 0.019, bilinear in the image 0.088 / 0.145 /
    0.154): the levels approach the average as the footprint grows, the image alone does not."""
    for footprint, bound in ((2, 0.07), (4, 0.045), (8, 0.025)):
        trilinear, bilinear = film.mip_errors(footprint, count=1000)
        print(f"footprint {footprint}: mean |error| trilinear {trilinear.mean():.4f}, bilinear {bilinear.mean():.4f}")
        assert trilinear.mean() < bound and trilinear.mean() < 0.65 * bilinear.mean()


def test_unit_normals_keep_directions():
    pixels = np.full((2, 2, 4), 0.5, np.float32)
    pixels[0, 0, :3] = (0.5, 0.5, 0.9)          # a short normal straight up
    pixels[0, 1, :3] = (0.5, 0.5, 0.5)          # none at all: the surface's
    pixels[1, 0, :3] = (0.9, 0.5, 0.9)
    unit = texture_mips.unit_normals(pixels)
    decoded = 2 * unit[..., :3] - 1
    np.testing.assert_allclose(np.linalg.norm(decoded, axis=-1), 1.0, atol=1e-6)
    np.testing.assert_allclose(decoded[0, 0], [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(decoded[0, 1], [0, 0, 1], atol=1e-6)
    np.testing.assert_allclose(decoded[1, 0], np.array([0.8, 0.0, 0.8]) / np.sqrt(1.28), atol=1e-6)
    np.testing.assert_array_equal(unit[..., 3], pixels[..., 3])


def test_normal_spread_inverts_the_von_mises_fisher_mean_length():
    """normal_spread's 1 / kappa from the mean length r of unit normals drawn from a vMF of concentration kappa
    (r = coth kappa - 1 / kappa): Banerjee et al.'s (3 r - r^3) / (1 - r^2) within 7% of kappa over 1..1000
    (measured 4.9% near kappa = 5); 0 at level 0, where a magnified map's blend of texels is no spread."""
    kappa = np.geomspace(1.0, 1000.0, 200)
    error = film.kappa_errors(kappa)
    print(f"largest relative error of kappa {error.max():.3f} at kappa {kappa[error.argmax()]:.1f}")
    assert error.max() < 0.07
    r = np.array([0.5, 0.9, 0.99])
    mean = np.stack([np.zeros_like(r), np.zeros_like(r), r], axis=-1)
    assert sg_shading.normal_spread(mean[:3], np.zeros(3), 1.0).max() == 0.0
    half = sg_shading.normal_spread(mean[:3], np.full(3, 0.5), 0.5)
    np.testing.assert_allclose(half, 0.125 * sg_shading.normal_spread(mean[:3], np.ones(3), 1.0), rtol=1e-5)


def test_spread_lobes_keep_their_integral():
    """An SG's integral is 2 pi a / lambda (1 - exp(-2 lambda)): the spread keeps it for sharp lobes, and narrows
    sharpness by 1 / (1 + lambda spread), the SG convolution of the NDF with the normals' spread."""
    sharpness = np.array([[10.0, 200.0]], np.float32)
    amplitude = np.array([[1.0, 3.0]], np.float32)
    spread = np.array([0.05], np.float32)
    wide, lower = sg_shading.spread_lobes(sharpness, amplitude, spread)
    np.testing.assert_allclose(wide, sharpness / (1 + sharpness * 0.05), rtol=1e-6)
    np.testing.assert_allclose(lower / wide, amplitude / sharpness, rtol=1e-6)
    assert sg_shading.spread_lobes(sharpness, amplitude, None) == (sharpness, amplitude)


def test_extensions_past_the_edge():
    """An Image Texture's extensions at texel centres past the edge: EXTEND repeats the edge texel, MIRROR reflects
    (texel -1 is texel 0, texel W is texel W - 1), REPEAT wraps, CLIP is black outside [0, 1] and fades to black
    over the half texel inside it."""
    image = np.arange(1.0, 5.0, dtype=np.float32).reshape(1, 4, 1).repeat(2, axis=0)      # texels 1, 2, 3, 4
    centre = lambda k: [(k + 0.5) / 4, 0.5]                                                 # noqa: E731
    uv = np.array([centre(-1), centre(-2), centre(4), centre(5), centre(0)], np.float32)
    for extension, expected in (("EXTEND", [1, 1, 4, 4, 1]), ("MIRROR", [1, 2, 4, 3, 1]), ("REPEAT", [4, 3, 1, 2, 1]),
                                ("CLIP", [0, 0, 0, 0, 1])):
        np.testing.assert_allclose(texture_mips.sample(image, uv, None, extension)[:, 0], expected, atol=1e-6,
                                   err_msg=extension)
    at_edge = texture_mips.sample(image, np.array([[0.0, 0.5], [1.0, 0.5]], np.float32), None, "CLIP")[:, 0]
    np.testing.assert_allclose(at_edge, [0.5, 2.0], atol=1e-6)          # half of texel 1, half of texel 4
