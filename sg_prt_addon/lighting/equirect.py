"""Equirectangular environment maps in Blender's world mapping.

Blender (Cycles `direction_to_equirectangular`, EEVEE likewise) maps a world
direction d to u = 0.5 - atan2(d.y, d.x) / (2 pi), v = 0.5 + elevation / pi,
with v = 0 at the bottom row of the image.  Our numpy images have row 0 at
the top (ARCHITECTURE.md), so row = (1 - v) * height.
"""
import numpy as np


def direction_to_uv(direction):
    """World directions (..., 3) -> (u, v) in [0, 1], v = 0 at the bottom (Blender)."""
    d = np.asarray(direction)
    u = 0.5 - np.arctan2(d[..., 1], d[..., 0]) / (2 * np.pi)
    v = 0.5 + np.arctan2(d[..., 2], np.hypot(d[..., 0], d[..., 1])) / np.pi
    return u, v


def uv_to_direction(u, v):
    """Inverse of direction_to_uv: unit world directions (..., 3)."""
    u, v = np.broadcast_arrays(np.asarray(u, dtype=float), np.asarray(v, dtype=float))
    azimuth = (0.5 - u) * 2 * np.pi
    elevation = (v - 0.5) * np.pi
    cos_elevation = np.cos(elevation)
    return np.stack([cos_elevation * np.cos(azimuth), cos_elevation * np.sin(azimuth), np.sin(elevation)], axis=-1)


def texel_directions(height, width):
    """Unit direction through the centre of every texel of an (H, W) map, row 0 at the top: (H, W, 3)."""
    v = 1.0 - (np.arange(height) + 0.5) / height
    u = (np.arange(width) + 0.5) / width
    return uv_to_direction(u[None, :], v[:, None])


def texel_solid_angles(height, width):
    """Solid angle of each texel row, (H, 1): (2 pi / W) * (sin(top) - sin(bottom)) of its elevation band."""
    edges = np.pi / 2 - np.arange(height + 1) * np.pi / height
    return ((2 * np.pi / width) * (np.sin(edges[:-1]) - np.sin(edges[1:])))[:, None]


def lookup_nearest(image, direction):
    """Radiance of the texel containing each direction (no filtering): (..., C)."""
    height, width = image.shape[:2]
    u, v = direction_to_uv(direction)
    col = np.clip((u * width).astype(np.int64), 0, width - 1)
    row = np.clip(((1.0 - v) * height).astype(np.int64), 0, height - 1)
    return image[row, col]


def rotated(image, matrix):
    """The map of the world L'(d) = L(normalize(M d)) (a Mapping node's rotation and scale in front of an
    Environment Texture): (H, W, C) float32, each texel centre's direction mapped and the map read bilinearly
    (wrapping in u, clamped in v).  A turn (or mirror) about z that scales x, y and z alike keeps every
    elevation: the rows shift, read along u only."""
    image = np.asarray(image, np.float32)
    matrix = np.asarray(matrix, np.float64)
    height, width = image.shape[:2]
    directions = texel_directions(height, width) @ matrix.T
    u, v = direction_to_uv(directions)
    x = u * width - 0.5
    y = (1.0 - v) * height - 0.5
    planar = matrix[:2, :2]
    if (np.allclose(matrix[2, :2], 0.0) and np.allclose(matrix[:2, 2], 0.0)
            and np.allclose(planar.T @ planar, matrix[2, 2] ** 2 * np.eye(2))):
        y = np.broadcast_to((np.arange(height) + 0.0)[:, None], x.shape)         # the rows stay (no blur in v)
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    xa, xb = x0.astype(np.int64) % width, (x0.astype(np.int64) + 1) % width
    ya, yb = np.clip(y0.astype(np.int64), 0, height - 1), np.clip(y0.astype(np.int64) + 1, 0, height - 1)
    low = image[ya, xa] * (1 - fx) + image[ya, xb] * fx
    high = image[yb, xa] * (1 - fx) + image[yb, xb] * fx
    return (low * (1 - fy) + high * fy).astype(np.float32)
