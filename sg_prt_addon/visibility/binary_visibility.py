"""Binary visibility of the upper hemisphere at mesh vertices, through the square map.

wang2009 section 5.2 casts 512 x 512 rays a vertex and downsamples to 128 x 128:
far too many rays for 20k vertices on a CPU.  ``adaptive_visibility`` casts a
coarse C x C grid of texel-centre rays (C = the stored resolution) and supersamples it ``refinement`` times
(odd, so a coarse centre is also a fine centre) only where the boundary can pass: a fine texel is traced when
the coarse centres around it (its cell's and its side's neighbours') disagree, and copies its cell otherwise
(``_texels_to_trace``; refining every cell of a mixed 3 x 3 neighbourhood whole, as before, cast 1.45x the
rays for the same error).  Along the horizon, where a visible wedge between an occluder and the horizon thins
to nothing (a tilted plane, an object on a floor), the cells of the square's edge are also probed at their
outermost fine row (refinement rays a cell, ~4 C refinement in all) and traced whole when a probe disagrees.
It matches the dense fine grid except where a feature fits between coarse samples (thinner than a coarse
cell, 0.078 rad = 4.5 degrees across at 32 x 32); tests/core/test_bake_pipeline.py and
benchmarks/accuracy/ssdf.py measure the mismatch (34 texels of 7.68 million at 300 vertices of the
sphere-over-floor scene, at ~2.6k rays a vertex; 6 with whole cells at ~3.7k).

Grids are (B, F, F) bool, True = visible, indexed [vertex, b index, a index]
as in ``hemisphere_map``.
"""
import functools

import numpy as np

from . import hemisphere_map


def world_directions(local_directions, frames):
    """local (..., K, 3) with frames (..., 3, 3) (rows t, b, n) -> world (..., K, 3)."""
    return np.matmul(local_directions, frames)


@functools.lru_cache(maxsize=8)
def _local_directions32(resolution):
    """hemisphere_map.texel_directions as float32 (what the tracer takes), read-only, made once."""
    directions = hemisphere_map.texel_directions(resolution).astype(np.float32)
    directions.flags.writeable = False
    return directions


def _occluded(tracer, origins, local, frames):
    """(B, K) occlusion of rays from origins (B, 3) along local directions (K, 3), or (B, K, 3) a vertex, in
    frames (B, 3, 3).  Built in float32, the tracer's precision, so no float64 copy is made and converted."""
    directions = world_directions(local, np.asarray(frames, np.float32))
    count, per_vertex = directions.shape[:2]
    ray_origins = np.repeat(np.asarray(origins, np.float32), per_vertex, axis=0)
    return tracer.occluded(ray_origins, directions.reshape(-1, 3)).reshape(count, per_vertex)


def dense_visibility(tracer, origins, frames, resolution):
    """(B, R, R) visibility from one ray per texel centre (the reference for the adaptive scheme)."""
    occluded = _occluded(tracer, origins, _local_directions32(resolution).reshape(-1, 3), frames)
    return ~occluded.reshape(len(occluded), resolution, resolution)


def _horizon_probe(tracer, origins, frames, coarse, refinement):
    """(B, C, C) bool: edge cells whose outermost fine row (towards the horizon) holds a sample
    of the other visibility than the cell's centre."""
    count, resolution, _ = coarse.shape
    fine_resolution = resolution * refinement
    last = fine_resolution - 1
    offsets = np.arange(refinement)
    cells, rows, cols = [], [], []
    edge = np.arange(resolution - 1)
    # walk the border once (corners belong to one side each): bottom, right, top, left
    for cell_row, cell_col, fine_row, fine_col in (
            (np.zeros_like(edge), edge, np.zeros((len(edge), refinement), int), edge[:, None] * refinement + offsets),
            (edge, np.full_like(edge, resolution - 1), edge[:, None] * refinement + offsets, np.full((len(edge), refinement), last)),
            (np.full_like(edge, resolution - 1), edge + 1, np.full((len(edge), refinement), last), (edge + 1)[:, None] * refinement + offsets),
            (edge + 1, np.zeros_like(edge), (edge + 1)[:, None] * refinement + offsets, np.zeros((len(edge), refinement), int))):
        cells.append(np.stack([cell_row, cell_col], 1))
        rows.append(fine_row)
        cols.append(fine_col)
    cells, rows, cols = np.concatenate(cells), np.concatenate(rows), np.concatenate(cols)   # (E, 2), (E, f)
    local = _local_directions32(fine_resolution)[rows, cols].reshape(-1, 3)
    visible = ~_occluded(tracer, origins, local, frames).reshape(count, len(cells), refinement)
    centre = coarse[:, cells[:, 0], cells[:, 1]]
    disagree = np.any(visible != centre[:, :, None], axis=2)
    flagged = np.zeros_like(coarse)
    flagged[:, cells[:, 0], cells[:, 1]] = disagree
    return flagged


def _texels_to_trace(coarse, probe_flagged, refinement):
    """(vertex, fine row, fine col) of the fine texels to trace.  A fine texel lies between its cell's centre
    and the centres of the neighbours on its side (the row's, the column's and the diagonal one; its cell's
    own for an offset of 0, clamped at the square's edge): it is traced when those disagree, since the boundary
    then passes between them, and copies its cell otherwise.  A cell the horizon probe flagged is traced whole.
    Against refining every cell of a mixed 3 x 3 neighbourhood whole, a straight boundary costs about 2 / 5 of
    the rays, and a texel is copied only where the coarse centres around it agree (as before, a feature
    thinner than a cell can pass between them)."""
    count, resolution, _ = coarse.shape
    padded = np.pad(coarse, ((0, 0), (1, 1), (1, 1)), mode="edge")

    def shifted(row, col):
        return padded[:, 1 + row:resolution + 1 + row, 1 + col:resolution + 1 + col]

    half = refinement // 2
    mixed_by_side = {}          # (side_row, side_col) -> (B, C, C): the texels of one side share their corners
    vertex, fine_row, fine_col = [], [], []
    for offset_row in range(refinement):
        for offset_col in range(refinement):
            if offset_row == half and offset_col == half:
                continue                                    # the coarse ray itself
            side = (int(np.sign(offset_row - half)), int(np.sign(offset_col - half)))
            if side not in mixed_by_side:
                a, b, c, d = coarse, shifted(side[0], 0), shifted(0, side[1]), shifted(*side)
                mixed_by_side[side] = ((a | b | c | d) != (a & b & c & d)) | probe_flagged
            mixed = mixed_by_side[side]
            cell_vertex, cell_row, cell_col = np.unravel_index(np.flatnonzero(mixed), mixed.shape)
            vertex.append(cell_vertex)
            fine_row.append(cell_row * refinement + offset_row)
            fine_col.append(cell_col * refinement + offset_col)
    return np.concatenate(vertex), np.concatenate(fine_row), np.concatenate(fine_col)


def adaptive_visibility(tracer, origins, frames, coarse_resolution, refinement):
    """(B, F, F) visibility with F = coarse_resolution * refinement, and the number of rays cast.

    Coarse rays at the coarse texel centres; fine texels whose surrounding coarse centres disagree
    (``_texels_to_trace``), and every fine texel of edge cells the horizon probe flags, are traced; the others
    copy their coarse cell.
    """
    if refinement % 2 != 1:
        raise ValueError("refinement must be odd (coarse texel centres must be fine texel centres)")
    coarse = dense_visibility(tracer, origins, frames, coarse_resolution)
    rays = coarse.size
    count = len(coarse)
    fine_resolution = coarse_resolution * refinement
    fine = np.broadcast_to(coarse[:, :, None, :, None], (count, coarse_resolution, refinement, coarse_resolution,
                                                         refinement)).reshape(count, fine_resolution, fine_resolution)
    if refinement == 1:
        return fine, rays
    probe_flagged = _horizon_probe(tracer, origins, frames, coarse, refinement)
    rays += count * 4 * (coarse_resolution - 1) * refinement
    vertex, rows, cols = _texels_to_trace(coarse, probe_flagged, refinement)
    if len(vertex) == 0:
        return fine, rays
    local = _local_directions32(fine_resolution)[rows, cols]                   # (M, 3): one ray a texel
    frames32 = np.asarray(frames, np.float32)[vertex]                           # (M, 3, 3), rows t, b, n
    # t x + b y + n z: einsum's one loop is 1.6x faster than writing the sum out (a stack of M (1 x 3) @ (3 x 3)
    # matmuls is slower still) and gives the same bits
    directions = np.einsum("mk,mkc->mc", local, frames32)
    occluded = tracer.occluded(np.asarray(origins, np.float32)[vertex], directions)
    fine[vertex, rows, cols] = ~occluded
    return fine, rays + len(vertex)
