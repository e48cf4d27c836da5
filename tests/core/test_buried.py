"""visibility.buried: points inside other geometry found by their back-face hits and given their neighbours'
rows, measured against rays at the visible points of the triangles they share (validation.visibility_cases)."""
import numpy as np
import pytest

from benchmarks.bake_speed import grid
from sg_prt_addon.visibility import BakeOptions, bake_visibility, buried, hemisphere_map
from sg_prt_addon.visibility.raytrace import RayTracer
from validation import visibility_cases

DOME_RADIUS = visibility_cases.SPHERE_RADIUS


@pytest.fixture(scope="module")
def sunk_sphere():
    """validation.visibility_cases.floor_through_sphere: the floor's vertices inside the sphere are buried."""
    return visibility_cases.floor_through_sphere()


def _share(points, normals, vertices, triangles):
    tracer = RayTracer(vertices, triangles, threads=1)
    try:
        origins = points + tracer.offset * normals
        return buried.backface_share(tracer, origins, hemisphere_map.local_frame(normals))
    finally:
        tracer.close()


def test_backface_share_finds_points_inside_a_closed_mesh(sunk_sphere):
    floor_v, _, vertices, triangles = sunk_sphere
    share = _share(floor_v, np.tile([0.0, 0.0, 1.0], (len(floor_v), 1)), vertices, triangles)
    radius = np.linalg.norm(floor_v, axis=1)
    inside, outside = radius < DOME_RADIUS - 0.02, radius > DOME_RADIUS + 0.02
    assert inside.sum() >= 30 and share[inside].min() == 1.0          # every ray leaves through the sphere
    assert share[outside].max() == 0.0                                # the sphere's outside faces them


def test_a_wrongly_wound_plane_overhead_does_not_bury():
    """A single-sided square facing away (a ceiling wound the wrong way) over a third of the hemisphere:
    back faces, but not the whole hemisphere's."""
    square_v, square_t = grid(2, 1.0)
    square_v = square_v + [0.0, 0.0, 1.0]                             # its normal +z: seen from below, a back face
    points = np.zeros((1, 3))
    share = _share(points, np.array([[0.0, 0.0, 1.0]]), square_v, square_t)
    assert 0.2 < share[0] < buried.BURIED_SHARE                       # the square's solid angle: 1/3 of 2 pi


def test_fill_buried_goes_ring_by_ring_and_keeps_unreachable_rows():
    """A strip of 2 x 6 vertices (columns 0..5) whose columns 3..5 are buried, and a lone buried triangle."""
    strip_v, strip_t = grid(6, 1.0)
    strip_t = strip_t[np.all(strip_v[strip_t][..., 1] <= -0.5, axis=1)]       # the first two rows of 6
    used = np.unique(strip_t)
    column = np.round((strip_v[:, 0] + 1.0) / 0.4).astype(int)
    lone = np.array([[36, 37, 38]])
    triangles = np.concatenate([strip_t, lone])
    samples = np.zeros((39, 2), np.float32)
    samples[:36, 0] = column
    samples[36:] = 7.0
    buried_mask = np.zeros(39, bool)
    buried_mask[used[column[used] >= 3]] = True
    buried_mask[36:] = True
    filled = buried.fill_buried(samples, buried_mask, buried.adjacency(triangles, 39))
    assert np.array_equal(filled, buried_mask & (np.arange(39) < 36))
    assert np.all(samples[36:] == 7.0)                                  # no unburied point in reach
    # column 3 takes the mean of its column-2 neighbours (2.0), and so on outwards
    for index in used[column[used] >= 3]:
        assert samples[index, 0] == pytest.approx(2.0)


def test_filled_rows_give_the_visible_side_of_a_seam_its_visibility():
    """At points of the floor's triangles that leave the sphere (buried and unburied corners, the point itself
    outside it), the cosine-weighted open share of the SSDF interpolated from the corners against rays cast
    from the point: the buried corners' rows ("no sky at all") darken the visible side; filled, they do not."""
    errors = visibility_cases.seam_open_share_errors()
    assert len(errors["baked"]) >= 50
    mean = {name: float(value.mean()) for name, value in errors.items()}
    print("mean |open share error| at the seam's visible points:", mean)
    assert mean["filled"] <= 0.07                                     # measured 0.048 (the sphere's wall near them)
    assert mean["baked"] >= 5 * mean["filled"]                        # measured 0.50: ten times


def test_the_bake_fills_buried_points_when_given_their_triangles(sunk_sphere):
    floor_v, floor_t, vertices, triangles = sunk_sphere
    normals = np.tile([0.0, 0.0, 1.0], (len(floor_v), 1))
    options = BakeOptions(resolution=8, refinement=1, terms=4)
    plain = bake_visibility(floor_v, floor_t, normals, vertices, triangles, options)
    filled = bake_visibility(floor_v, floor_t, normals, vertices, triangles, options, point_triangles=floor_t)
    inside = np.linalg.norm(floor_v, axis=1) < DOME_RADIUS - 0.02
    assert plain.buried_points == 0 and filled.buried_points >= inside.sum()
    # buried rows: "occluded everywhere" (the SSDF's mean below zero) before, the open floor's after
    assert plain.ssdf(np.flatnonzero(inside)).mean() < 0 < filled.ssdf(np.flatnonzero(inside)).mean()


def test_the_transfer_bake_fills_buried_points_too(sunk_sphere):
    """The SH transfer bake (kautz2002) finds the same points, their candidates by the visible solid angle its
    glossy matrix holds, and gives them their neighbours' vectors."""
    from sg_prt_addon.visibility import transfer

    floor_v, floor_t, vertices, triangles = sunk_sphere
    normals = np.tile([0.0, 0.0, 1.0], (len(floor_v), 1))
    options = transfer.TransferOptions(order=3, directions=256, terms=4)
    plain = transfer.bake_transfer(floor_v, floor_t, normals, vertices, triangles, options)
    filled = transfer.bake_transfer(floor_v, floor_t, normals, vertices, triangles, options, point_triangles=floor_t)
    inside = np.linalg.norm(floor_v, axis=1) < DOME_RADIUS - 0.02
    assert plain.buried_points == 0 and filled.buried_points >= inside.sum()
    # their diffuse transfer's band-0 term: none of the sky before, the open floor's after
    def band0(result):
        return (result.coefficients @ result.basis + result.mean)[np.flatnonzero(inside), 0]
    assert np.abs(band0(plain)).max() < 0.05 * transfer.open_sky(3)[0][0]
    assert band0(filled).mean() > 0.5 * transfer.open_sky(3)[0][0]
