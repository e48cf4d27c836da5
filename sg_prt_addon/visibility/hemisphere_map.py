"""Square <-> upper hemisphere map of the SSDF textures (wang2009 section 5.2).

Shirley & Chiu's concentric map takes the square [-1, 1]^2 to the unit disc
without folding, then the disc lifts to the hemisphere with equal area
(z = 1 - r^2, (x, y) scaled by sqrt(2 - r^2)): every texel covers the same
solid angle (2 pi / R^2) and texels stay nearly square.

Conventions (shared by the bake, ``decode`` and shaders/lib/ssdf.glsl):

- local frame: the vertex normal along z+; x+ along the ``local_frame`` tangent;
- square coordinates (a, b) in [-1, 1]^2, a along local x, b along local y;
- grids are indexed [row, column] = [b index, a index];
- ray grids (``texel_directions``): R x R texels, texel k centred at
  -1 + (2 k + 1) / R;
- stored SSDF images (``sample_directions``): R x R samples on the lattice
  -1 + 2 k / (R - 1), whose outer rows lie ON the horizon, so that bilinear
  interpolation covers the whole hemisphere with no clamp-to-edge band (with
  texel centres, the outer half texel, 3.5 degrees at R = 32, would repeat
  the edge value).  A GPU texture of these samples is read at texture
  coordinates ``sample_texcoord`` = ((a + 1) / 2 (R - 1) + 1 / 2) / R, so that
  sample k sits at texel centre k; texture row t = 0 is numpy row 0;
- the square's edge is the horizon (z = 0).

Directions below the horizon (a lobe centre can be, e.g. for the diffuse
product of eq. 39) have no texel.  Below the horizon the surface itself
occludes, so the SSDF there is negative and its distance to the visible set
grows by the angle below the horizon: ``horizon_lookup`` maps such a direction
to the horizon point of the same azimuth and returns that angle, which the
decoder subtracts from the value looked up there.
"""
import numpy as np

from ..spherical.concentric_map import disc_to_square, square_to_disc

# Reference axis of the default tangent: an oblique world direction that mesh normals
# (floors, walls, axis-aligned faces) practically never equal, so that the frame varies
# smoothly between the vertices of a triangle (any tangent field has a singular normal).
FRAME_REFERENCE_AXIS = np.array([0.2672612419124244, 0.5345224838248488, 0.8017837257372732])
FRAME_FALLBACK_AXIS = np.array([0.8017837257372732, -0.2672612419124244, -0.5345224838248488])


def square_to_hemisphere(square):
    """(..., 2) square points -> (..., 3) unit directions with z >= 0 (equal-area lift of the disc)."""
    disc = square_to_disc(square)
    radius2 = np.sum(disc * disc, axis=-1)
    scale = np.sqrt(np.maximum(2.0 - radius2, 0.0))
    return np.concatenate([disc * scale[..., None], (1.0 - radius2)[..., None]], axis=-1)


def hemisphere_to_square(direction):
    """(..., 3) unit directions with z >= 0 -> (..., 2) square points (inverse of square_to_hemisphere).

    The disc point is (x, y) / sqrt(1 + z): no cancellation near the pole or the horizon.
    """
    direction = np.asarray(direction, np.float64)
    z = np.clip(direction[..., 2], 0.0, 1.0)
    disc = direction[..., :2] / np.sqrt(1.0 + z)[..., None]
    return disc_to_square(disc)


def texel_centres(resolution):
    """(R,) square coordinates of the texel centres along one axis: -1 + (2 k + 1) / R."""
    return -1.0 + (2.0 * np.arange(resolution) + 1.0) / resolution


def texel_directions(resolution):
    """(R, R, 3) local directions of the texel centres, indexed [b index, a index]."""
    centres = texel_centres(resolution)
    b, a = np.meshgrid(centres, centres, indexing="ij")
    return square_to_hemisphere(np.stack([a, b], axis=-1))


def sample_points(resolution):
    """(R,) square coordinates of the stored SSDF samples along one axis: -1 + 2 k / (R - 1)."""
    return np.linspace(-1.0, 1.0, resolution)


def sample_directions(resolution):
    """(R, R, 3) local directions of the stored SSDF samples, indexed [b index, a index]."""
    points = sample_points(resolution)
    b, a = np.meshgrid(points, points, indexing="ij")
    return square_to_hemisphere(np.stack([a, b], axis=-1))


def sample_texcoord(square, resolution):
    """Texture coordinates (..., 2) of square points in an R x R texture of stored samples."""
    return ((np.asarray(square, np.float64) + 1.0) * (0.5 * (resolution - 1)) + 0.5) / resolution


def elevation(direction):
    """Signed angle of unit directions above the horizon, asin(z) in the well-conditioned atan2 form."""
    direction = np.asarray(direction, np.float64)
    return np.arctan2(direction[..., 2], np.hypot(direction[..., 0], direction[..., 1]))


def horizon_lookup(direction):
    """Where to look up the SSDF for any local direction: (square (..., 2), angle below horizon (...)).

    Upper hemisphere: the direction's own square point and 0.  Below: the horizon
    point of the same azimuth (straight down: azimuth 0) and the angle below the
    horizon, which the caller subtracts from the SSDF value found there.
    """
    direction = np.asarray(direction, np.float64)
    horizontal = np.hypot(direction[..., 0], direction[..., 1])
    below = direction[..., 2] < 0
    straight_down = below & (horizontal == 0)
    clamped = np.where(below[..., None], np.concatenate(
        [direction[..., :2] / np.where(horizontal == 0, 1.0, horizontal)[..., None],
         np.zeros(direction.shape[:-1] + (1,))], axis=-1), direction)
    clamped = np.where(straight_down[..., None], np.array([1.0, 0.0, 0.0]), clamped)
    angle_below = np.where(below, np.arctan2(-direction[..., 2], horizontal), 0.0)
    return hemisphere_to_square(clamped), angle_below


def local_frame(normals, tangents=None):
    """(..., 3, 3) rotations world -> local: rows (tangent, bitangent, normal).

    Without tangents, the tangent is FRAME_REFERENCE_AXIS projected on the tangent
    plane (FRAME_FALLBACK_AXIS when the normal is within ~0.6 degrees of it).  Zero or
    non-finite normals become +z; tangents parallel to their normal fall back to the default.
    local = frame @ world; world = local @ frame.
    """
    n = np.asarray(normals, np.float64)
    length = np.linalg.norm(n, axis=-1, keepdims=True)
    # zero or non-finite normals (degenerate vertices) get +z rather than NaN rays
    usable = np.isfinite(length) & (length > 1e-30)
    n = np.where(usable, n / np.where(usable, length, 1.0), np.array([0.0, 0.0, 1.0]))
    if tangents is None:
        parallel = np.abs(np.sum(n * FRAME_REFERENCE_AXIS, axis=-1, keepdims=True)) > 0.99995
        reference = np.where(parallel, FRAME_FALLBACK_AXIS, FRAME_REFERENCE_AXIS)
    else:
        reference = np.asarray(tangents, np.float64)
    t = reference - np.sum(reference * n, axis=-1, keepdims=True) * n
    t_length = np.linalg.norm(t, axis=-1, keepdims=True)
    if tangents is not None:
        # a given tangent parallel to the normal (or zero): fall back to the default frame's tangent
        bad = ~(t_length > 1e-9)
        if np.any(bad):
            default = local_frame(n)[..., 0, :]
            t = np.where(bad, default, t)
            t_length = np.where(bad, 1.0, t_length)
    t = t / t_length
    b = np.cross(n, t)
    return np.stack([t, b, n], axis=-2)
