"""reflectance.texture_expression: the arithmetic of textured node values and their evaluation, against the
same formula applied to the pixels."""
import numpy as np
import pytest

from sg_prt_addon.reflectance import principled
from sg_prt_addon.reflectance.texture_expression import Expression

RNG = np.random.default_rng(4)
BASE = RNG.uniform(0, 1, (8, 8, 4)).astype(np.float32)
METAL = np.repeat(RNG.uniform(0, 1, (4, 4, 1)), 4, axis=-1).astype(np.float32)


def test_constants_fold_and_plain_images_stay_plain():
    assert (Expression.constant(0.25) * 2 + 0.5).as_constant() == (1.0, 1.0, 1.0)
    scaled = Expression.image("base") * (0.5, 0.25, 1.0)
    assert scaled.as_factor_times_image() == ((0.5, 0.25, 1.0), "base")
    assert (Expression.image("base") * 0.0).as_constant() == (0.0, 0.0, 0.0)
    assert (1.0 - Expression.image("metal")).as_factor_times_image() is None


def test_principled_textured_metallic_evaluates_to_its_formula():
    base, metal = Expression.image("base"), Expression.image("metal")
    values = principled.principled(base_color=base, metallic=metal, roughness=0.4, ior=1.5)
    from sg_prt_addon.spherical import texture_mips
    centres = (np.arange(8) + 0.5) / 8
    uv = np.stack(np.broadcast_arrays(centres[None, :], centres[:, None]), -1).reshape(-1, 2).astype(np.float32)
    bound = values["diffuse_color"].bound({"base": BASE, "metal": METAL})
    diffuse = bound.sample(uv).reshape(8, 8, 4)
    specular = values["specular_color"].bound({"base": BASE, "metal": METAL}).sample(uv).reshape(8, 8, 4)
    assert np.all(diffuse[..., 3] == 1)
    metal_up = texture_mips.sample(METAL, uv)[:, :3].reshape(8, 8, 3)   # each image read at the pixel
    np.testing.assert_allclose(diffuse[..., :3], BASE[..., :3] * (1 - metal_up), atol=1e-6)
    np.testing.assert_allclose(specular[..., :3], metal_up * BASE[..., :3] + (1 - metal_up) * 0.04, atol=1e-6)
    assert values["layered_f0"] == np.float32(0.04) or abs(values["layered_f0"] - 0.04) < 1e-9


def test_mean_value():
    expression = 0.5 * Expression.image("a") + Expression.image("a") * Expression.image("b")
    assert np.allclose(expression.mean_value({"a": (0.2, 0.4, 0.6), "b": (1.0, 0.5, 0.0)}), (0.3, 0.4, 0.3))


def test_material_textures_repeat_and_the_uv_transform():
    """sg_shading.sample_material_texture wraps (GL_REPEAT) where the tables' fetch clamps; material_uv applies
    the material's affine UV transform."""
    from types import SimpleNamespace

    from sg_prt_addon.techniques.sg import sg_shading

    image = RNG.uniform(0, 1, (4, 8, 3)).astype(np.float32)
    uv = np.array([[0.3, 0.6], [1.3, -0.4], [0.01, 0.99]], np.float32)
    wrapped = sg_shading.sample_material_texture(image, uv)
    np.testing.assert_allclose(wrapped[0], wrapped[1], atol=1e-5)           # one period apart
    corner = 0.25 * (image[3, 0] + image[3, 7] + image[0, 0] + image[0, 7])   # between the four corner texels
    np.testing.assert_allclose(sg_shading.sample_material_texture(image, [[0.0, 0.0]])[0], corner, atol=1e-6)
    assert not np.allclose(sg_shading.sample_texture(image, [[0.0, 0.0]])[0], corner)     # clamped: texel (0, 0)
    material = SimpleNamespace(uv_transform=(2.0, 0.0, 0.5, 0.0, 3.0, -1.0))
    np.testing.assert_allclose(sg_shading.material_uv(material, uv[:1]), [[1.1, 0.8]], atol=1e-6)


def test_channels_of_products_and_their_recombination():
    """channel(k) of a sum of products is each product's channel k (Separate Color); the channels put back
    with unit colours (Combine Color) give the expression back, swizzled where asked."""
    base, metal = Expression.image("base"), Expression.image("metal")
    expression = (0.2, 0.5, 1.0) * base * (1.0 - 0.5 * metal) + (0.1, 0.0, 0.3)
    images = {"base": BASE[..., :3], "metal": METAL[:2, :2, :3].repeat(4, 0).repeat(4, 1)}
    value = expression.values(images)
    for k in range(3):
        channel = expression.channel(k)
        np.testing.assert_allclose(channel.values(images), np.repeat(value[..., k:k + 1], 3, -1), atol=1e-6)
        assert channel.channel(0) == channel            # a channel's channel is itself
        assert channel.as_factor_times_image() is None
    swizzled = sum((expression.channel(source) * tuple(np.eye(3)[target]) for target, source in enumerate((2, 0, 1))),
                   Expression.constant(0.0))
    np.testing.assert_allclose(swizzled.values(images), value[..., [2, 0, 1]], atol=1e-6)
    means = {"base": (0.2, 0.4, 0.6), "metal": (0.5, 0.5, 0.5)}
    assert expression.channel(1).mean_value(means) == pytest.approx((expression.mean_value(means)[1],) * 3)
