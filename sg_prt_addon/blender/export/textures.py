"""A material's textures as the shader samples them: image pixels decoded as Blender decodes them, missing
images and NaN texels replaced, with a warning."""

import numpy as np

from ..images import image_has_pixels, image_pixels
from .messages import finite_texels, warn

COLOUR_SLOTS = ("diffuse_color", "specular_color", "emission")
# What a texture whose image has no pixels (a missing or unreadable file) samples, and what the warning calls it:
# Blender's magenta for colours (what its own engines show), a flat normal for the normal map, 1 for scalars.
MISSING_TEXEL = {"colour": ((1.0, 0.0, 1.0, 1.0), "magenta"), "normal_map": ((0.5, 0.5, 1.0, 1.0), "a flat normal"),
                 "scalar": ((1.0, 1.0, 1.0, 1.0), "the factor alone")}


def no_pixels_reason(image):
    return f"file '{image.filepath}' missing or unreadable" if image.filepath else "no pixels"


def srgb_to_linear(values):
    """The sRGB transfer function inverted (IEC 61966-2-1), elementwise."""
    values = np.asarray(values, np.float32)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4).astype(np.float32)


def texture_pixels(image, slot, decode=None):
    """What the shader samples for `slot`: image_pixels, with the RGB of colour slots made
    scene-linear when the image holds sRGB-encoded bytes (float images are linear already;
    data slots such as roughness or the normal map are used as stored, like Non-Color, unless
    `decode`: a node tree's data slot, decoded as Blender decodes it).  NaN/Inf texels become 0,
    with a warning (finite_texels): the upload reads each image once."""
    if not image_has_pixels(image):
        texel, what = MISSING_TEXEL["colour" if slot in COLOUR_SLOTS else "normal_map" if slot == "normal_map"
                                    else "scalar"]
        warn(f"image '{image.name}': {no_pixels_reason(image)}: {what} used for {slot}")
        return np.array(texel, np.float32).reshape(1, 1, 4)
    if image.source == "TILED" and len(image.tiles) > 1:
        warn(f"image '{image.name}': a UDIM set of {len(image.tiles)} tiles, of which SG-PRT reads tile "
             f"{image.tiles[0].number} alone over every UV (Cycles reads each tile where the UVs reach it)")
    pixels = finite_texels(image_pixels(image), f"image '{image.name}'")
    if decode is None:
        decode = slot in COLOUR_SLOTS
    if decode and not image.is_float and image.colorspace_settings.name == "sRGB":
        pixels = pixels.copy()
        pixels[..., :3] = srgb_to_linear(pixels[..., :3])
    return pixels


def texture_sources(value):
    """The image names a slot's texture reads: its image, or an Expression's (reflectance.texture_expression)."""
    return (value,) if isinstance(value, str) else value.images


def images_present(value):
    """Whether every image a slot's texture reads is in bpy.data."""
    import bpy

    return all(name in bpy.data.images for name in texture_sources(value))


def slot_pixels(value, slot, decode=None):
    """What the shader samples for a slot's texture (MaterialParams.textures[slot]): an image's texture_pixels,
    or (an Expression) the expression bound to its images' pixels, each decoded as Blender decodes it, which the
    mirrors sample per pixel (texture_expression.BoundExpression)."""
    import bpy

    if isinstance(value, str):
        return texture_pixels(bpy.data.images[value], slot, decode)
    return value.bound({name: texture_pixels(bpy.data.images[name], slot, decode=True) for name in value.images})
