"""sg_prt_addon.visibility: adaptive visibility vs the dense fine grid, the bake API, cancellation."""
import numpy as np
import pytest
import threadpoolctl

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


def _blas_threads():
    return {info["filepath"]: info["num_threads"] for info in threadpoolctl.threadpool_info()
            if info["user_api"] == "blas"}


def test_the_batches_run_blas_on_one_thread_and_the_bake_gives_its_threads_back(scene):
    """The bake's own threads fill the cores; BLAS threads inside them only fight for them
    (visibility.pipeline.one_blas_thread).  A cancel gives them back too."""
    vertices, triangles, normals = scene
    before = _blas_threads()
    if max(before.values(), default=1) == 1:
        pytest.skip("BLAS runs on one thread here already: nothing to limit")
    during = []

    def progress(fraction, message):
        during.append(_blas_threads())
        return len(during) == 7          # the first bake: 4 batches; cancel the second at its third

    tracer = RayTracer(vertices, triangles, threads=1)
    try:
        bake_ssdf(vertices[:256], normals[:256], tracer, BakeOptions(resolution=8, refinement=3, batch_vertices=64),
                  progress=progress)
        with pytest.raises(BakeCancelled):
            bake_ssdf(vertices[:256], normals[:256], tracer,
                      BakeOptions(resolution=8, refinement=3, batch_vertices=64), progress=progress)
    finally:
        tracer.close()
    assert len(during) == 7 and all(set(threads.values()) == {1} for threads in during)
    assert _blas_threads() == before


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


@pytest.mark.parametrize("visible_fraction", [0.05, 0.5, 0.95])
def test_a_fine_texel_is_traced_exactly_when_the_coarse_centres_around_it_disagree(visible_fraction):
    """_texels_to_trace against a plain loop over every fine texel: traced where its cell's centre and its
    side's neighbouring centres (edge clamped) disagree or the horizon probe flagged the cell, else copied."""
    rng = np.random.default_rng(2)
    count, resolution, refinement = 3, 8, 5
    coarse = rng.random((count, resolution, resolution)) < visible_fraction
    flagged = rng.random(coarse.shape) < 0.05
    traced = set(zip(*(axis.tolist() for axis in binary_visibility._texels_to_trace(coarse, flagged, refinement))))
    expected, half = set(), refinement // 2
    for vertex in range(count):
        for row in range(resolution * refinement):
            for col in range(resolution * refinement):
                cell_row, offset_row = divmod(row, refinement)
                cell_col, offset_col = divmod(col, refinement)
                if offset_row == half and offset_col == half:
                    continue
                rows = {cell_row, min(max(cell_row + int(np.sign(offset_row - half)), 0), resolution - 1)}
                cols = {cell_col, min(max(cell_col + int(np.sign(offset_col - half)), 0), resolution - 1)}
                values = {bool(coarse[vertex, r, c]) for r in rows for c in cols}
                if len(values) > 1 or flagged[vertex, cell_row, cell_col]:
                    expected.add((vertex, row, col))
    assert traced == expected


def test_a_straight_boundary_traces_two_fifths_of_the_cells_it_crosses():
    coarse = np.zeros((1, 8, 8), bool)
    coarse[:, :, 4:] = True                   # a boundary between columns 3 and 4
    vertex, _, _ = binary_visibility._texels_to_trace(coarse, np.zeros_like(coarse), 5)
    assert len(vertex) == 8 * 2 * 10          # 10 of the 24 other texels of each cell on either side
