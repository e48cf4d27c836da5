"""sg_prt_addon.visibility: adaptive visibility vs the dense fine grid, the bake API, cancellation."""
import numpy as np
import pytest

from benchmarks.bake_speed import grid, icosphere, sphere_over_floor
from sg_prt_addon.visibility import (
    BakeCancelled,
    BakeOptions,
    bake_visibility,
    binary_visibility,
    hemisphere_map,
    topology_hash,
)
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer


@pytest.fixture(scope="module")
def scene():
    return sphere_over_floor(700)


def _adaptive_and_dense(vertices, triangles, points, normals):
    tracer = RayTracer(vertices, triangles, threads=2)
    frames = hemisphere_map.local_frame(normals)
    origins = points + tracer.offset * normals
    adaptive, rays = binary_visibility.adaptive_visibility(tracer, origins, frames, 32, 5)
    dense = binary_visibility.dense_visibility(tracer, origins, frames, 160)
    tracer.close()
    return adaptive, dense, rays


def test_adaptive_matches_dense_on_smooth_features(scene):
    vertices, triangles, normals = scene
    pick = np.random.default_rng(0).choice(len(vertices), 40, replace=False)
    adaptive, dense, rays = _adaptive_and_dense(vertices, triangles, vertices[pick], normals[pick])
    mismatch = np.mean(adaptive != dense)
    assert mismatch <= 1e-4, mismatch                     # measured 0
    assert rays / len(pick) < 0.25 * 160 * 160            # measured ~3.9k rays a vertex vs 25.6k dense


def test_adaptive_misses_only_features_thinner_than_a_coarse_cell():
    """A thin rod (about 2 degrees wide, a coarse cell is 4.5) near a floor point: the adaptive grid
    may miss it, and every mismatch is a missed occluded texel of the rod (measured: 10 and 32 of
    25600 texels at the two points)."""
    floor_v, floor_t = grid(3, 1.0)
    rod_v, rod_t = icosphere(2)
    rod_v = rod_v * [0.005, 0.005, 2.0] + [0.3, 0.0, 1.0]       # thin vertical rod, 0.005 radius
    sphere_v, sphere_t = icosphere(2)
    sphere_v = sphere_v * 0.3 + [-0.5, 0.2, 0.6]                # and a big smooth occluder
    vertices = np.concatenate([floor_v, rod_v, sphere_v])
    triangles = np.concatenate([floor_t, rod_t + len(floor_v), sphere_t + len(floor_v) + len(rod_v)])
    points = np.array([[0.0, 0.0, 0.0], [0.1, -0.1, 0.0]])
    normals = np.array([[0.0, 0.0, 1.0]] * 2)
    adaptive, dense, _ = _adaptive_and_dense(vertices, triangles, points, normals)
    mismatch = adaptive != dense
    # the rod subtends about 0.005 / 0.3 rad across: at most a sliver of the 160 x 160 texels
    assert mismatch.mean() < 0.01
    assert np.all(adaptive[mismatch]) and not np.any(dense[mismatch])  # only missed occluders


def test_bake_result_shapes_and_metadata(scene):
    vertices, triangles, normals = scene
    options = BakeOptions(resolution=16, refinement=3, terms=8, batch_vertices=128)
    calls = []
    result = bake_visibility(vertices, triangles, normals, vertices, triangles, options,
                             progress=lambda fraction, message: calls.append(fraction))
    count = len(vertices)
    assert result.coefficients.shape == (count, 8) and result.coefficients.dtype == np.float32
    assert result.basis.shape == (8, 16, 16) and result.basis.dtype == np.float32
    assert result.mean.shape == (16, 16) and result.mean.dtype == np.float32
    assert (result.resolution, result.terms, result.vertex_count) == (16, 8, count)
    assert result.topology_hash == topology_hash(count, triangles)
    assert result.topology_hash != topology_hash(count, triangles[::-1])
    assert calls[0] == 0.0 and calls[-1] == 1.0 and np.all(np.diff(calls) >= 0)
    # the stored data reconstruct the uncompressed SSDFs with the reported RMS error
    tracer = RayTracer(vertices, triangles)
    raw = bake_ssdf(vertices, normals, tracer, options).astype(np.float64)
    tracer.close()
    rms = np.sqrt(np.mean((result.ssdf().reshape(count, -1) - raw) ** 2))
    assert abs(rms - result.rms_error) < 1e-3 * max(result.rms_error, 1e-3) + 1e-5
    # visible values never exceed the elevation (the horizon is a boundary)
    elevation = np.arcsin(hemisphere_map.sample_directions(16)[..., 2]).ravel()
    assert np.all(raw <= elevation + 1e-3)


@pytest.mark.parametrize("cancel_at_call", [1, 2])
def test_cancelled_bake_raises_and_returns_nothing(scene, cancel_at_call):
    vertices, triangles, normals = scene
    calls = []

    def progress(fraction, message):
        calls.append(fraction)
        return len(calls) >= cancel_at_call

    with pytest.raises(BakeCancelled):
        bake_visibility(vertices, triangles, normals, vertices, triangles,
                        BakeOptions(resolution=8, refinement=3, batch_vertices=64), progress=progress)
    assert len(calls) == cancel_at_call


def test_bad_options_are_refused(scene):
    vertices, triangles, normals = scene
    with pytest.raises(ValueError):
        bake_visibility(vertices, triangles, normals, vertices, triangles, BakeOptions(refinement=4))
    with pytest.raises(ValueError):
        bake_visibility(vertices, triangles, normals[:5], vertices, triangles)


def test_no_occluders_gives_the_open_plane():
    points = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 3.0]])
    normals = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    result = bake_visibility(points, np.zeros((0, 3), int), normals, np.zeros((0, 3)), np.zeros((0, 3), int),
                             BakeOptions(resolution=8, refinement=3, terms=2))
    elevation = np.arcsin(hemisphere_map.sample_directions(8)[..., 2])
    assert np.abs(result.ssdf() - elevation).max() < 1e-3


@pytest.mark.parametrize("visible_fraction", [0.02, 0.5, 0.98])
def test_mixed_cells_are_those_of_a_3x3_max_and_min_filter(visible_fraction):
    """cells_to_refine's ORs and ANDs against scipy's max/min filters with the edge clamped (what it replaced)."""
    from scipy import ndimage

    coarse = np.random.default_rng(1).random((40, 32, 32)) < visible_fraction
    footprint = np.ones((1, 3, 3), bool)
    expected = (ndimage.maximum_filter(coarse, footprint=footprint, mode="nearest")
                != ndimage.minimum_filter(coarse, footprint=footprint, mode="nearest"))
    np.testing.assert_array_equal(binary_visibility.cells_to_refine(coarse), expected)
