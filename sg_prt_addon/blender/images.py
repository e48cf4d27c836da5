"""Pixels of Blender images as numpy arrays: what export, the bi-scale tiles and the tests read."""
import numpy as np


def image_pixels(image):
    """(H, W, 4) float32 pixels of a bpy Image, Blender's orientation (row 0 at the bottom).
    Colour images come as Blender stores them in float (linear for float buffers, else the
    byte values / 255: data textures such as normal maps stay as authored)."""
    width, height = image.size
    pixels = np.empty(width * height * image.channels, np.float32)
    image.pixels.foreach_get(pixels)
    pixels = pixels.reshape(height, width, image.channels)
    if image.channels == 4:
        return pixels
    out = np.ones((height, width, 4), np.float32)
    out[..., :min(3, image.channels)] = pixels[..., :3]
    if image.channels == 1:
        out[..., 1] = out[..., 2] = pixels[..., 0]
    return out


def image_has_pixels(image):
    """False for an image Blender could not load (a missing or unreadable file: size 0 x 0)."""
    return image.size[0] > 0 and image.size[1] > 0 and image.channels > 0
