"""The GPU's bilinear texture fetch in numpy, for every mirror of a shader's texture read.

GL_LINEAR with clamp-to-edge: texel k of a side of `size` texels has its centre at (k + 0.5) / size,
and a coordinate between two centres mixes them linearly.  The tables (clamped cosine, GGX albedo),
the prefiltered environment's layers, the SSDF basis and the material textures are all read this way.
"""
import numpy as np


def _texel_index(index, size, extension):
    """Texel indices past the edge as an Image Texture's extension takes them: REPEAT wraps, EXTEND and CLIP
    clamp to the edge (CLIP's texels past it are black: _inside), MIRROR reflects every other period."""
    if extension in ("EXTEND", "CLIP"):
        return np.clip(index, 0, size - 1)
    if extension == "MIRROR":
        folded = index % (2 * size)
        return np.where(folded < size, folded, 2 * size - 1 - folded)
    return index % size


def bilinear(image, uv, layer=None, wrap=False, extension=None):
    """Samples of `image` at texture coordinates uv (..., 2) in [0, 1]^2 (u along a row, v across rows).

    image: (H, W, ...) indexed [row, column], row 0 at v = 0 (the GPU's and Blender's order); with `layer`,
    (L, H, W, ...) and layer (...) integer indices, as a texture array.  Returns (...) + image's trailing
    dimensions.  The arithmetic is in uv's precision (float32 coordinates: the shader's, float64: a
    reference's).  wrap: the texel indices repeat (GL_REPEAT: the material textures' manual fetch in
    shaders/techniques/common/material_textures.glsl), else they clamp to the edge; extension (an Image
    Texture's: REPEAT, EXTEND, CLIP, MIRROR) in wrap's place where given."""
    uv = np.asarray(uv)
    dtype = np.result_type(uv.dtype, np.float32).type
    first = 0 if layer is None else 1
    height, width = image.shape[first], image.shape[first + 1]
    x = uv[..., 0].astype(dtype) * dtype(width) - dtype(0.5)
    y = uv[..., 1].astype(dtype) * dtype(height) - dtype(0.5)
    x0, y0 = np.floor(x), np.floor(y)
    trailing = (Ellipsis,) + (None,) * (image.ndim - 2 - first)
    fx, fy = (x - x0)[trailing], (y - y0)[trailing]
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    extension = extension or ("REPEAT" if wrap else "EXTEND")
    xa, xb = _texel_index(x0, width, extension), _texel_index(x0 + 1, width, extension)
    ya, yb = _texel_index(y0, height, extension), _texel_index(y0 + 1, height, extension)
    wx0, wx1, wy0, wy1 = 1 - fx, fx, 1 - fy, fy
    if extension == "CLIP":             # texels past the edge are black: their weights count nothing
        def inside(index, size):
            return ((index >= 0) & (index < size))[trailing].astype(dtype)
        wx0, wx1 = wx0 * inside(x0, width), wx1 * inside(x0 + 1, width)
        wy0, wy1 = wy0 * inside(y0, height), wy1 * inside(y0 + 1, height)
    index = () if layer is None else (layer,)
    low = image[index + (ya, xa)] * wx0 + image[index + (ya, xb)] * wx1
    high = image[index + (yb, xa)] * wx0 + image[index + (yb, xb)] * wx1
    return low * wy0 + high * wy1


def bilinear_channels_first(images, uv):
    """bilinear of images laid out (..., H, W) (a stack of single-channel maps): (..., Q) at uv (Q, 2)."""
    images = np.asarray(images)
    moved = np.moveaxis(images.reshape((-1,) + images.shape[-2:]), 0, -1)          # (H, W, C)
    samples = bilinear(moved, uv)                                                   # (Q, C)
    return np.moveaxis(samples, -1, 0).reshape(images.shape[:-2] + samples.shape[:1])
