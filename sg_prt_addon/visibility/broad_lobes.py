"""The visible fraction of a broad lobe by a quadrature of the SSDF over the hemisphere.

eq. 30 reads one SSDF value, at the lobe's axis, as the distance to a straight boundary with everything
beyond it occluded.  For a narrow lobe the boundary is straight on the lobe's scale; a broad one (the
environment's lobes times the cosine, at a vertex of a diffuse surface) reaches past a small or distant
occluder, which the half-space reading takes for a half of the sky: a floor under a sphere in a uniform
sky came out 5% too dark on average (tests/gpu/test_shadows_reference.py), and the half-space's error of
a lobe's visible fraction reaches 0.1-0.2 on baked vertices (docs/ACCURACY.md, ssdf: broad lobes).

Here the SSDF is decoded at a fixed set of equal-area points of the hemisphere (a Fibonacci spiral in the
SSDF's local frame), each point's cell taken as a disc whose covered part by a straight boundary at the
decoded distance is its visible share, and a lobe's visible fraction is the lobe- and cosine-weighted sum
of those shares over the same sum without occluders (the horizon alone, as eq. 30's ratio has it).  The
points' spacing limits it to broad lobes: sharper ones blend to eq. 30's reading (`quadrature_weight`).

Mirrored by shaders/lib/ssdf_quadrature.glsl; the per-vertex pass of the broad diffuse lobes
(shaders/techniques/sg/vertex_visibility.frag.glsl) uses it.
"""
import numpy as np

from ..spherical import hemisphere

QUADRATURE_POINTS = 32
GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))
# Lobe sharpness (of the lobe before its product with the cosine) from which the quadrature hands over to
# eq. 30's reading, and where the hand-over ends (linear in between): chosen on the sphere-over-floor bake
# against dense rays (benchmarks/accuracy/ssdf.py, "broad lobes").
QUADRATURE_SHARPNESS_START = 8.0
QUADRATURE_SHARPNESS_END = 32.0


def quadrature_points(count=QUADRATURE_POINTS):
    """(count, 3) local directions, z the SSDF's normal: equal-area cells of the upper hemisphere (z at
    their centres' heights, turning by the golden angle)."""
    index = np.arange(count, dtype=np.float64)
    z = (index + 0.5) / count
    phi = index * GOLDEN_ANGLE
    radius = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    return np.stack([radius * np.cos(phi), radius * np.sin(phi), z], axis=-1)


def cell_radius(count=QUADRATURE_POINTS):
    """Angular radius of a disc of one cell's solid angle, 2 pi / count (small-angle)."""
    return np.sqrt(2.0 / count)


def cell_coverage(signed_distance, radius):
    """Visible share of a cell (a disc of ``radius``) whose centre lies ``signed_distance`` (+ visible) from a
    straight boundary."""
    return hemisphere.disc_coverage(signed_distance, radius)


def open_coverage(count=QUADRATURE_POINTS):
    """Each point's share without occluders: its cell above the horizon (the SSDF is the elevation)."""
    points = quadrature_points(count)
    return cell_coverage(np.arcsin(points[:, 2]), cell_radius(count))


def quadrature_visible_fraction(coverage, local_axis, sharpness, count=QUADRATURE_POINTS):
    """Visible fraction of the lobes G(i; axis, sharpness) max(0, i.z) at each vertex: coverage (N, count)
    (cell_coverage of the SSDF decoded at quadrature_points), local_axis (N, E, 3) in the SSDF's frame,
    sharpness (N, E) -> (N, E) in [0, 1]."""
    points = quadrature_points(count)
    axis = np.asarray(local_axis, np.float64)
    lam = np.asarray(sharpness, np.float64)[..., None]
    weight = np.exp(lam * (np.einsum("nex,px->nep", axis, points) - 1.0)) * points[:, 2]      # (N, E, P)
    visible = np.einsum("nep,np->ne", weight, np.asarray(coverage, np.float64))
    unoccluded = weight @ open_coverage(count)
    return np.clip(visible / np.maximum(unoccluded, 1e-30), 0.0, 1.0)


def quadrature_weight(sharpness):
    """Weight of the quadrature against eq. 30's reading of a lobe of this sharpness: 1 for broad lobes,
    0 for those the points are too sparse for."""
    s = (np.asarray(sharpness, np.float64) - QUADRATURE_SHARPNESS_START) / (
        QUADRATURE_SHARPNESS_END - QUADRATURE_SHARPNESS_START)
    return 1.0 - np.clip(s, 0.0, 1.0)
