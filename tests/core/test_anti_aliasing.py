"""Render Samples' maths (engine/anti_aliasing.py): Edges Only's edge test, its tiles and their projection, the
dithered coverage's thresholds."""
import numpy as np

from benchmarks.accuracy import film
from sg_prt_addon.engine import anti_aliasing


def _frame(height, width, value=0.5):
    frame = np.zeros((height, width, 4), np.float32)
    frame[..., :3] = value
    frame[..., 3] = 1.0
    return frame


def test_edge_pixels_marks_both_sides_of_a_step_and_nothing_flat():
    frame = _frame(6, 8)
    assert not anti_aliasing.edge_pixels(frame, 0.2).any()
    frame[:, 4:, :3] = 1.0                          # a vertical step: columns 3 and 4 differ
    edges = anti_aliasing.edge_pixels(frame, 0.2)
    assert edges[:, 3:5].all() and edges.sum() == 12
    # a difference under the threshold, relative to the brighter pixel plus the floor, is no edge
    frame = _frame(4, 4)
    frame[:, 2:, :3] = 0.5 * (1.0 + 0.15)
    assert not anti_aliasing.edge_pixels(frame, 0.2).any()
    assert anti_aliasing.edge_pixels(frame, 0.1).any()
    # a diagonal neighbour counts: one bright pixel marks its 8 neighbours and itself
    frame = _frame(5, 5, 0.0)
    frame[2, 2, :3] = 1.0
    assert anti_aliasing.edge_pixels(frame, 0.2).sum() == 9


def test_edge_pixels_floor_keeps_dark_noise_out_and_alpha_counts():
    frame = _frame(4, 4, 0.001)
    frame[:, 2:, :3] = 0.003                        # 3x brighter, but 0.002 of the display's white
    assert not anti_aliasing.edge_pixels(frame, 0.2).any()
    assert anti_aliasing.edge_pixels(frame, 0.2, floor=0.0).any()
    frame = _frame(4, 4)
    frame[:, 2:, 3] = 0.0                            # same colour, a transparent film's silhouette
    assert anti_aliasing.edge_pixels(frame, 0.2)[:, 1:3].all()


def test_edge_pixels_non_finite_are_edges_and_compared_as_black():
    frame = _frame(5, 5)
    frame[2, 2, 0] = np.nan
    frame[0, 0, 1] = np.inf
    edges = anti_aliasing.edge_pixels(frame, 0.2)
    assert edges[2, 2] and edges[0, 0] and edges[1:4, 1:4].all()
    assert not edges[4, 4]
    assert not anti_aliasing.edge_pixels(np.zeros((0, 0, 4), np.float32), 0.2).size


def test_grid_side_and_footprint_limit():
    assert [anti_aliasing.grid_side(n) for n in (1, 2, 4, 5, 9, 16, 17, 64)] == [1, 2, 2, 3, 3, 4, 5, 8]
    assert [anti_aliasing.footprint_grid_limit(s) for s in (1, 2, 3, 4, 8)] == [4, 4, 3, 2, 1]
    # a grid's cell centres are pixel_jitter's square pattern
    side = anti_aliasing.grid_side(16)
    cells = (np.arange(side) + 0.5) / side - 0.5
    expected = sorted((x, y) for x in cells for y in cells)
    np.testing.assert_allclose(sorted(map(tuple, anti_aliasing.pixel_jitter(16))), expected)


def test_edge_tiles_cover_every_edge_once():
    edges = np.zeros((70, 100), bool)
    edges[0, 0] = edges[69, 99] = edges[33, 40] = True
    tiles = anti_aliasing.edge_tiles(edges, 32)
    assert sorted(tiles) == [(0, 0), (32, 32), (96, 64)]
    covered = np.zeros_like(edges)
    for x0, y0 in tiles:
        covered[y0:y0 + 32, x0:x0 + 32] = True
    assert covered[edges].all()
    assert anti_aliasing.edge_tiles(np.zeros((8, 8), bool), 4) == []


def _pixel(projection, point, width, height):
    clip = projection @ np.append(point, 1.0)
    return (clip[:2] / clip[3] + 1.0) * 0.5 * np.array([width, height])


def test_tile_projection_maps_the_tile_onto_the_whole_target():
    """A point at image pixel p lands at (p - origin) * side in a target side times the tile's size: the
    target's pixel centres are the centres of each image pixel's grid cells."""
    near, far, width, height = 0.1, 50.0, 160, 90
    projection = np.array([[1.8, 0.0, 0.1, 0.0], [0.0, 3.2, -0.05, 0.0],
                           [0.0, 0.0, -(far + near) / (far - near), -2 * far * near / (far - near)],
                           [0.0, 0.0, -1.0, 0.0]])
    rng = np.random.default_rng(3)
    origin, tile, side = (64, 32), 32, 4
    cropped = anti_aliasing.tile_projection(projection, origin, tile, width, height)
    for _ in range(20):
        point = rng.uniform([-2, -1, -9], [2, 1, -1])
        image = _pixel(projection, point, width, height)
        in_tile = _pixel(cropped, point, tile * side, tile * side)
        np.testing.assert_allclose(in_tile, (image - origin) * side, atol=1e-9)
        # depth is untouched
        np.testing.assert_allclose((cropped @ np.append(point, 1))[2:], (projection @ np.append(point, 1))[2:])


def test_coverage_offsets_spread_a_pixels_kept_frames_over_the_grid():
    """16 frames: a pixel's filtered coverage is its alpha within 0.035 RMS (0.12 at most; measured 0.029 and
    0.090), where plain k / 16 offsets, whose kept frames are adjacent rows of the jitter grid, give 0.047;
    Cycles' 16 random samples give sqrt(alpha (1 - alpha) / 16), 0.10 RMS over uniform alphas."""
    offsets = anti_aliasing.coverage_offsets(16)
    assert len(set(offsets)) == 16 and offsets.min() >= 0.0 and offsets.max() < 1.0
    errors = film.coverage_errors(offsets)
    rms = np.sqrt(np.mean(errors ** 2))
    assert rms < 0.035 and np.abs(errors).max() < 0.12, (rms, np.abs(errors).max())
    plain = np.sqrt(np.mean(film.coverage_errors(np.arange(16) / 16.0) ** 2))
    assert plain > 1.3 * rms
