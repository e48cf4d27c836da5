"""Baked points buried inside other geometry, and their rows taken from their neighbours.

A mesh that passes through another (Suzanne's eyes sink into her head, a rock into the ground) has
vertices inside the other's volume.  Their hemispheres see nothing but the inside of that volume, so
their SSDF says "occluded everywhere", and the renderer's interpolation of per-vertex rows carries that
darkness across every triangle they share with visible vertices: a dark rim where the surfaces meet,
one to two triangles wide, which no resolution of the SSDF removes.  Light-map bakers answer the same
problem by treating such samples as invalid and filling them from valid neighbours; this does the same
for the bake's points.

A point is buried when its hemisphere's rays nearly all leave through back faces (a triangle seen from
the side its winding turns away from): from inside a closed, consistently wound volume every ray does.
The test asks for BURIED_SHARE of the hemisphere, not a majority, so a single-sided plane facing the
wrong way (a common floor) or a canopy of back-facing leaves does not mark the points above it as
buried.  Buried points then take the mean row of their unburied neighbours along the mesh's edges,
ring by ring, so the interpolation across a triangle that leaves the volume is the visible vertices'.
A point with no unburied point in reach keeps its own row.
"""
from concurrent.futures import ThreadPoolExecutor

import numpy as np
from scipy import sparse

from . import hemisphere_map

BURIED_SHARE = 0.9       # share of the hemisphere's probe rays that must hit back faces
PROBE_RAYS = 64          # probe directions a point (spiral points, equal solid angle)
MAX_RINGS = 64           # edge rings a fill may cross; beyond, points keep their own rows
# Points that saw more of their hemisphere open than this in the bake are not probed: twice what a buried point
# can see (1 - BURIED_SHARE), a margin for the bake's directions differing from the probe's
CANDIDATE_OPEN_SHARE = 2.0 * (1.0 - BURIED_SHARE)

_GOLDEN_ANGLE = np.pi * (3.0 - np.sqrt(5.0))


def probe_directions(count=PROBE_RAYS):
    """(count, 3) local directions of the upper hemisphere, one a cell of equal solid angle."""
    j = np.arange(count)
    z = (j + 0.5) / count
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(j * _GOLDEN_ANGLE), r * np.sin(j * _GOLDEN_ANGLE), z], axis=-1)


def backface_share(tracer, origins, frames, rays=PROBE_RAYS, batch=4096, threads=1):
    """(P,) share of each point's probe rays whose first hit is a back face.

    origins (P, 3): ray origins already off the surface; frames (P, 3, 3): rows x, y, z (z the normal);
    tracer: a visibility.raytrace.RayTracer over every occluder."""
    origins = np.asarray(origins, np.float64).reshape(-1, 3)
    local = probe_directions(rays)
    share = np.zeros(len(origins))

    def probe(part):
        directions = np.einsum("kj,pjc->pkc", local, frames[part]).reshape(-1, 3)
        hits = tracer.intersect(np.repeat(origins[part], rays, axis=0), directions)
        facing = np.einsum("ij,ij->i", tracer.geometric_normals(hits.triangle), directions)
        share[part] = (hits.hit & (facing > 0.0)).reshape(-1, rays).mean(axis=1)

    parts = [slice(start, min(start + batch, len(origins))) for start in range(0, len(origins), batch)]
    with ThreadPoolExecutor(max(1, threads)) as pool:
        list(pool.map(probe, parts))
    return share


def adjacency(point_triangles, count):
    """(count, count) CSR matrix, 1 where two points share a triangle's edge (no diagonal)."""
    triangles = np.asarray(point_triangles, np.int64).reshape(-1, 3)
    first = triangles.ravel()
    second = np.roll(triangles, -1, axis=1).ravel()
    rows = np.concatenate([first, second])
    cols = np.concatenate([second, first])
    keep = rows != cols
    matrix = sparse.csr_matrix((np.ones(keep.sum(), np.float32), (rows[keep], cols[keep])), shape=(count, count))
    matrix.data[:] = 1.0                                   # duplicates summed: back to one
    return matrix


def fill_buried(samples, buried, neighbours, max_rings=MAX_RINGS):
    """Rows of ``buried`` points replaced, in place, by the mean of their filled or unburied neighbours',
    ring by ring outwards from the unburied points; returns the (P,) mask of the points filled.

    samples (P, N) any float dtype; buried (P,) bool; neighbours: adjacency()'s matrix."""
    known = ~np.asarray(buried, bool)
    filled = np.zeros(len(known), bool)
    for _ in range(max_rings):
        waiting = ~known
        if not waiting.any():
            break
        reach = neighbours[waiting][:, known]               # waiting points x known points
        counts = np.asarray(reach.sum(axis=1)).ravel()
        ready = counts > 0
        if not ready.any():
            break
        rows = reach[ready]
        means = (rows @ samples[known].astype(np.float32)) / counts[ready, None]
        index = np.flatnonzero(waiting)[ready]
        samples[index] = means.astype(samples.dtype)
        known[index] = True
        filled[index] = True
    return filled


def fill_buried_points(samples, tracer, points, normals, point_triangles, open_share=None, threads=1):
    """The bakes' step: rows (P, N) of the baked points (world points and normals (P, 3)) whose hemispheres
    are buried (backface_share against ``tracer``'s occluders) replaced in place by their neighbours' along
    point_triangles (T, 3); returns how many were filled.  open_share (P,): the share of each hemisphere the
    bake found open, when it knows it: only points that saw at most CANDIDATE_OPEN_SHARE of theirs are probed
    (a buried point sees at most 1 - BURIED_SHARE), which spares the probe's rays on meshes that pass through
    nothing."""
    frames = hemisphere_map.local_frame(np.asarray(normals, np.float64).reshape(-1, 3))
    origins = np.asarray(points, np.float64).reshape(-1, 3) + tracer.offset * frames[:, 2]
    candidates = np.ones(len(origins), bool) if open_share is None else \
        np.asarray(open_share) <= CANDIDATE_OPEN_SHARE
    is_buried = np.zeros(len(origins), bool)
    if candidates.any():
        share = backface_share(tracer, origins[candidates], frames[candidates], threads=threads)
        is_buried[candidates] = share >= BURIED_SHARE
    if not is_buried.any():
        return 0
    filled = fill_buried(samples, is_buried, adjacency(point_triangles, len(origins)))
    return int(filled.sum())
