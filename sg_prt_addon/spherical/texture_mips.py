"""Mip levels of the material textures, so a texture seen smaller than its texels is filtered, not aliased (moire,
and the bias of a normal map's bumps sampled at a few of its texels).

Level 0 is the image; each next level half the last a side (rounded up, at least 1), each texel the mean of the
2 x 2 texels below it (past an odd side the edge texel counts twice).  The GPU holds them in one atlas: level 0 at
the origin, levels 1.. stacked upwards in a column at its right, and a header texel in the atlas's last texel
(W, H, level count, 0), which common/surface_io.glsl's material_texture reads to find the levels.  A fragment's
level is log2 of its footprint in texels (the larger screen derivative of the texture coordinates, times the
image's larger side), between 0 and the last; trilinear between the two levels around it.  sample() is the numpy
mirror.  Texture coordinates: u along a row, v across rows, row 0 at v = 0."""
import numpy as np

from . import texture_fetch


def levels(image):
    """[level 0 (the image), 1, ...] down to 1 x 1, as float32 (h, w, C) arrays."""
    current = np.asarray(image, np.float32)
    out = [current]
    while current.shape[0] > 1 or current.shape[1] > 1:
        height, width = current.shape[:2]
        padded = np.pad(current, ((0, height % 2), (0, width % 2), (0, 0)), mode="edge")
        rows, columns = padded.shape[0] // 2, padded.shape[1] // 2
        current = padded.reshape(rows, 2, columns, 2, -1).mean(axis=(1, 3), dtype=np.float64).astype(np.float32)
        out.append(current)
    return out


def level_rect(size, level):
    """((x, y) origin, (w, h) size) of a level in the atlas of an image of size (W, H): level 0 at the origin, the
    others stacked in the column at its right."""
    sizes = _sizes(*size)
    if level == 0:
        return (0, 0), sizes[0]
    return (sizes[0][0], sum(h for _, h in sizes[1:level])), sizes[level]


def atlas_size(width, height):
    """(A, B): the atlas of a W x H image: level 0 and at its right a column as wide as level 1, as high as level 0
    or as the levels stacked in it and the header texel above them."""
    sizes = _sizes(width, height)
    stacked = sum(size[1] for size in sizes[1:])
    return int(width) + max((int(width) + 1) // 2, 1), max(int(height), stacked + 1)


def _sizes(width, height):
    sizes = [(int(width), int(height))]
    while sizes[-1] != (1, 1):
        w, h = sizes[-1]
        sizes.append((max((w + 1) // 2, 1), max((h + 1) // 2, 1)))
    return sizes


def level_count(width, height):
    """Levels of a W x H image, down to 1 x 1."""
    return len(_sizes(width, height))


def unit_normals(pixels):
    """A normal map's texels (H, W, 4) with their decoded normals 2 rgb - 1 made unit (a zero one: the surface's,
    (0, 0, 1)): a level's mean normal is then shorter only where the texels below it disagree (the spread that
    techniques.sg.sg_shading.normal_spread reads), not where the map was stored a little off unit."""
    pixels = np.array(pixels, np.float32)
    normal = 2.0 * pixels[..., :3].astype(np.float64) - 1.0
    length = np.linalg.norm(normal, axis=-1, keepdims=True)
    unit = np.where(length > 1e-12, normal / np.maximum(length, 1e-12), [0.0, 0.0, 1.0])
    pixels[..., :3] = 0.5 + 0.5 * unit
    return pixels


def atlas(image):
    """(B, A, C) float32: the image's levels laid out as level_rect says, the header texel (W, H, levels, 0) last."""
    pyramid = levels(image)
    height, width, channels = pyramid[0].shape
    atlas_width, atlas_height = atlas_size(width, height)
    out = np.zeros((atlas_height, atlas_width, channels), np.float32)
    for index, level in enumerate(pyramid):
        (x, y), (w, h) = level_rect((width, height), index)
        out[y:y + h, x:x + w] = level
    out[-1, -1, :4] = (width, height, len(pyramid), 0.0)[:channels]
    return out


def level_of(footprint, width, height, count):
    """The fractional level (N,) of footprints (N,) in texture coordinates: log2 of footprint x the larger side,
    between 0 and count - 1."""
    texels = np.asarray(footprint, np.float32) * np.float32(max(width, height))
    with np.errstate(divide="ignore"):
        level = np.log2(np.maximum(texels, np.float32(1e-30)))
    return np.clip(level, np.float32(0.0), np.float32(count - 1))


def sample(image, uv, footprint=None, extension="REPEAT"):
    """The image at texture coordinates uv (N, 2), past its edges as the Image Texture's extension says (REPEAT,
    EXTEND, MIRROR, CLIP: 0 outside [0, 1]): bilinear in level 0 where footprint is None, else trilinear at
    level_of(footprint) (the mirror of material_texture and material_texture_at)."""
    uv = np.asarray(uv)
    fetch = extension
    if footprint is None:
        out = texture_fetch.bilinear(np.asarray(image), uv, extension=fetch)
        return _clipped(out, uv) if extension == "CLIP" else out
    pyramid = levels(image)
    height, width = pyramid[0].shape[:2]
    level = level_of(footprint, width, height, len(pyramid))
    low = np.floor(level).astype(np.int64)
    fraction = (level - low)[:, None]
    out = np.zeros((len(uv), pyramid[0].shape[2]), np.float32)
    for index in np.unique(low):
        rows = low == index
        value = texture_fetch.bilinear(pyramid[index], uv[rows], extension=fetch)
        if index + 1 < len(pyramid):
            upper = texture_fetch.bilinear(pyramid[index + 1], uv[rows], extension=fetch)
            value = value + (upper - value) * fraction[rows]
        out[rows] = value
    return _clipped(out, uv) if extension == "CLIP" else out


def _clipped(values, uv):
    """CLIP's transparent black outside [0, 1]^2 (within it, the texels past the edge are black: texture_fetch)."""
    inside = np.all((uv >= 0.0) & (uv <= 1.0), axis=-1)
    return np.where(inside[..., None], values, np.float32(0.0)).astype(np.float32)
