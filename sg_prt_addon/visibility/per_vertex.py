"""Per-vertex precomputations as the engine takes them: rows of vec4 a Blender mesh vertex and a basis.

An SSDF bake (kind "ssdf": PCA coefficient rows [1, w_0, ...] and the mean + basis maps) is one kind;
a precomputed radiance transfer is another.  Every kind is stored, checked against the mesh it shades,
uploaded and fetched by the vertex stage the same way; only what the rows mean is the technique's.

Rows belong to the mesh's vertices (domain "POINT"), or, where a vertex has corners of several normals (flat
faces, sharp edges), to its corners (domain "CORNER"): each corner then has the row of its own normal's
hemisphere, baked once for the corners that share it (split_points), and the local frame is the corner's
normal instead of the vertex's.
"""
from dataclasses import dataclass

import numpy as np

# vec4 rows a vertex of one kind: each becomes a varying of the surface shader (llvmpipe and desktop GL
# give 32 vec4; the surface uses 5 of its own and the diffuse pass's rows, at most 4, may follow: 25).
# 16 rather than 12: a Suzanne's SSDF takes 63 terms at the bake's error target (visibility.pca).
MAX_ROWS = 16
# PCA terms of an SSDF bake that fit them: the rows hold [1, w_0, ..., w_{N-1}] (the mean's weight first)
MAX_TERMS = 4 * MAX_ROWS - 1
# One layout for every per-vertex texture and target of a mesh: a vertex takes at most TEXELS_PER_VERTEX_LIMIT
# vec4 texels of a row (a kind's rows, at most MAX_ROWS; a per-object pass's, 8 for the SSDF quadrature's
# coverage; values summed at the vertices, no more than the 32 vec4 varyings of llvmpipe and desktop GL), so a
# row of vertices_per_row(side) vertices fits a texture `side` texels wide whatever it holds.
TEXELS_PER_VERTEX_LIMIT = 32


def vertices_per_row(max_side):
    """Vertices a row of a mesh's per-vertex textures, each at most `max_side` texels wide (the GPU's limit)."""
    return max(1, int(max_side) // TEXELS_PER_VERTEX_LIMIT)


def rows_needed(count, per_row):
    """Texture rows of `count` vertices at `per_row` vertices a row."""
    return max(1, -(-int(count) // int(per_row)))


def texture_of(values, texels_per_vertex, per_row):
    """(rows, per_row * texels_per_vertex, 4) float32 texture of per-vertex values (V, 4 * texels_per_vertex):
    vertex v's texel k at (column (v % per_row) * texels_per_vertex + k, row v // per_row)
    (techniques/shader_sources.py per_vertex_fetch_source reads it back with texelFetch)."""
    count = values.shape[0]
    rows = rows_needed(count, per_row)
    out = np.zeros((rows * per_row, texels_per_vertex, 4), np.float32)
    out[:count] = np.asarray(values, np.float32).reshape(count, texels_per_vertex, 4)
    return out.reshape(rows, per_row * texels_per_vertex, 4)


def texture_refusal(count, max_side, what="vertices"):
    """Why `count` vertices' per-vertex textures cannot be made on a GPU of `max_side` texels a side, or None."""
    rows = rows_needed(count, vertices_per_row(max_side))
    if rows <= max_side:
        return None
    return (f"its {count:,} {what} need per-vertex textures of {rows:,} rows, over this GPU's limit of "
            f"{max_side:,} texels a side (at most {vertices_per_row(max_side) * max_side:,})")


@dataclass
class PerVertexData:
    """A usable precomputation of one exported mesh.

    rows: (vertex_count, 4 layers) float32, one row per Blender mesh vertex (the engine reads row
    corner_vertex[corner] for each corner, export.MeshExport), or with domain "CORNER" one per corner (row
    corner); basis_texture: the kind's (layers, R, R, 4) float32 decode basis; terms: values a vertex that
    mean something; resolution: R."""
    kind: str
    rows: np.ndarray
    basis_texture: np.ndarray
    layers: int
    terms: int
    resolution: int
    domain: str = "POINT"

    def corner_rows(self, corner_vertex):
        """(C,) the row each corner reads."""
        if self.domain == "CORNER":
            return np.arange(len(corner_vertex), dtype=np.int64)
        return np.asarray(corner_vertex, np.int64)

    @property
    def packed(self):           # the SSDF bake's name for its rows (decode.pack_coefficients)
        return self.rows


def split_points(corner_vertex, corner_normals, tolerance=1e-5):
    """Where a per-vertex precomputation is evaluated: (corner_point (C,), point_vertex (P,), point_normal
    (P, 3)), corners of a vertex sharing one point where their normals agree to `tolerance`, so that a flat
    face's corners see their face's hemisphere.  One point a used vertex where every vertex has one normal."""
    corner_vertex = np.asarray(corner_vertex, np.int64)
    corner_normals = np.asarray(corner_normals, np.float64).reshape(-1, 3)
    key = np.concatenate([corner_vertex[:, None], np.round(corner_normals / tolerance).astype(np.int64)], axis=1)
    _, first, corner_point = np.unique(key, axis=0, return_index=True, return_inverse=True)
    return corner_point.ravel(), corner_vertex[first], corner_normals[first]


def has_split_normals(corner_normals, vertex_normals, corner_vertex, tolerance=1e-3):
    """Whether any corner's normal differs from its vertex's (flat faces, sharp edges): where split_points
    makes more points than vertices."""
    if vertex_normals is None or not len(corner_vertex):
        return False
    difference = np.asarray(corner_normals, np.float64) - np.asarray(vertex_normals, np.float64)[corner_vertex]
    return bool(np.any(np.einsum("ij,ij->i", difference, difference) > tolerance * tolerance))


# How far a point baked for its corners moves toward their faces' centres: a corner on a contact edge (a box's
# bottom corner on a floor) lies on the other surface's plane, where rays along that plane hit it at t = 0
CORNER_INSET = 1e-3


def inset_points(positions, corner_point, corner_face_centres):
    """Positions (P, 3) of split_points' points moved CORNER_INSET of the way to the mean centre of the faces
    of their corners (corner_face_centres (C, 3)): inside their own faces, off any surface they touch."""
    counts = np.bincount(corner_point, minlength=len(positions))[:, None]
    sums = np.zeros((len(positions), 3))
    np.add.at(sums, corner_point, corner_face_centres)
    target = np.where(counts > 0, sums / np.maximum(counts, 1), positions)
    return positions + CORNER_INSET * (target - positions)


def check(kind, rows, basis_texture, terms, vertex_count, corner_vertex, domain="POINT"):
    """(PerVertexData or None, message): None, with why, when the rows cannot shade the mesh of
    `vertex_count` vertices whose corners index them with `corner_vertex` (rows per vertex), or of those
    corners (domain "CORNER") (a stale or damaged record must never be read past its rows)."""
    rows = np.ascontiguousarray(rows, np.float32)
    basis_texture = np.ascontiguousarray(basis_texture, np.float32)
    layers = rows.shape[1] // 4 if rows.ndim == 2 else 0
    if rows.ndim != 2 or rows.shape[1] != 4 * layers or basis_texture.shape[0] != layers \
            or not 0 < layers <= MAX_ROWS:
        return None, f"{kind} data layout inconsistent ({rows.shape}, basis {basis_texture.shape})"
    if corner_vertex is None:
        return None, "stale bake: the mesh has no corner vertices"
    if domain == "CORNER":
        if rows.shape[0] != len(corner_vertex):
            return None, f"stale bake: {rows.shape[0]} corners baked, the mesh has {len(corner_vertex)}"
    elif rows.shape[0] != vertex_count:
        return None, f"stale bake: {rows.shape[0]} vertices baked, the mesh has {vertex_count}"
    elif len(corner_vertex) and int(np.max(corner_vertex)) >= rows.shape[0]:
        return None, "stale bake: corner vertex index beyond the baked vertices"
    if not np.all(np.isfinite(rows)) or not np.all(np.isfinite(basis_texture)):
        return None, "bake holds non-finite values"
    return PerVertexData(kind, rows, basis_texture, layers, int(terms), int(basis_texture.shape[1]),
                         "CORNER" if domain == "CORNER" else "POINT"), "ok"
