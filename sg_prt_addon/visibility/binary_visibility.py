"""Binary visibility of the upper hemisphere at mesh vertices, through the square map.

wang2009 section 5.2 casts 512 x 512 rays a vertex and downsamples to 128 x 128:
far too many rays for 20k vertices on a CPU.  ``adaptive_visibility`` casts a
coarse C x C grid of texel-centre rays (C = the stored resolution) and supersamples, at ``refinement``^2
rays (odd, so a coarse centre is also a fine centre), only the coarse cells
whose 3 x 3 neighbourhood holds both visible and occluded samples.  Along the
horizon, where a visible wedge between an occluder and the horizon thins to
nothing (a tilted plane, an object on a floor), the cells of the square's edge
are also probed at their outermost fine row (refinement rays a cell, ~4 C
refinement in all) and refined when a probe disagrees.  It matches
the dense fine grid except where a feature fits between coarse samples
(thinner than a coarse cell, 0.078 rad = 4.5 degrees across at 32 x 32);
tests/core/test_bake_pipeline.py and benchmarks/accuracy/ssdf.py measure the
mismatch (0 texels of 25600 on the sphere-over-floor scene, at ~3.7k rays a vertex).

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


def cells_to_refine(coarse_visible):
    """(B, C, C) bool: cells whose 3 x 3 neighbourhood (clamped at the square's edge) is mixed."""
    padded = np.pad(coarse_visible, ((0, 0), (1, 1), (1, 1)), mode="edge")
    # separable: OR and AND over the three rows, then over the three columns
    rows_any = padded[:, :-2] | padded[:, 1:-1] | padded[:, 2:]
    rows_all = padded[:, :-2] & padded[:, 1:-1] & padded[:, 2:]
    any_visible = rows_any[:, :, :-2] | rows_any[:, :, 1:-1] | rows_any[:, :, 2:]
    all_visible = rows_all[:, :, :-2] & rows_all[:, :, 1:-1] & rows_all[:, :, 2:]
    return any_visible != all_visible


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


def adaptive_visibility(tracer, origins, frames, coarse_resolution, refinement):
    """(B, F, F) visibility with F = coarse_resolution * refinement, and the number of rays cast.

    Coarse rays at the coarse texel centres; in mixed cells (``cells_to_refine``)
    the other refinement^2 - 1 fine texels are traced; elsewhere fine texels copy
    their coarse cell.
    """
    if refinement % 2 != 1:
        raise ValueError("refinement must be odd (coarse texel centres must be fine texel centres)")
    coarse = dense_visibility(tracer, origins, frames, coarse_resolution)
    rays = coarse.size
    fine = np.repeat(np.repeat(coarse, refinement, axis=1), refinement, axis=2)
    if refinement == 1:
        return fine, rays
    refine = cells_to_refine(coarse) | _horizon_probe(tracer, origins, frames, coarse, refinement)
    rays += len(origins) * 4 * (coarse_resolution - 1) * refinement
    cell_vertex, cell_row, cell_col = np.nonzero(refine)
    if len(cell_vertex) == 0:
        return fine, rays
    fine_resolution = coarse_resolution * refinement
    offset_row, offset_col = np.divmod(np.arange(refinement * refinement), refinement)
    not_centre = (offset_row != refinement // 2) | (offset_col != refinement // 2)
    offset_row, offset_col = offset_row[not_centre], offset_col[not_centre]
    rows = cell_row[:, None] * refinement + offset_row            # (M, f^2 - 1)
    cols = cell_col[:, None] * refinement + offset_col
    local = _local_directions32(fine_resolution)[rows, cols]       # (M, f^2 - 1, 3): a cell's own directions
    occluded = _occluded(tracer, np.asarray(origins)[cell_vertex], local, np.asarray(frames)[cell_vertex])
    fine[cell_vertex[:, None], rows, cols] = ~occluded
    return fine, rays + occluded.size
