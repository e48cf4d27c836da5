"""Per-vertex precomputations as the engine takes them: rows of vec4 a Blender mesh vertex and a basis.

An SSDF bake (kind "ssdf": PCA coefficient rows [1, w_0, ...] and the mean + basis maps) is one kind;
a precomputed radiance transfer is another.  Every kind is stored, checked against the mesh it shades,
uploaded and fetched by the vertex stage the same way; only what the rows mean is the technique's.
"""
from dataclasses import dataclass

import numpy as np

# vec4 rows a vertex of one kind: each becomes a varying of the surface shader (llvmpipe and the GL
# minimum give 32 vec4; the surface uses 5 of its own and a pass's rows may follow: 12 leaves room)
MAX_ROWS = 12
# PCA terms of an SSDF bake that fit them: the rows hold [1, w_0, ..., w_{N-1}] (the mean's weight first)
MAX_TERMS = 4 * MAX_ROWS - 1


@dataclass
class PerVertexData:
    """A usable precomputation of one exported mesh.

    rows: (vertex_count, 4 layers) float32, one row per Blender mesh vertex (the engine reads row
    corner_vertex[corner] for each corner, export.MeshExport); basis_texture: the kind's (layers, R, R, 4)
    float32 decode basis; terms: values a vertex that mean something; resolution: R."""
    kind: str
    rows: np.ndarray
    basis_texture: np.ndarray
    layers: int
    terms: int
    resolution: int

    @property
    def packed(self):           # the SSDF bake's name for its rows (decode.pack_coefficients)
        return self.rows


def check(kind, rows, basis_texture, terms, vertex_count, corner_vertex):
    """(PerVertexData or None, message): None, with why, when the rows cannot shade the mesh of
    `vertex_count` vertices whose corners index them with `corner_vertex` (a stale or damaged record
    must never be read past its rows)."""
    rows = np.ascontiguousarray(rows, np.float32)
    basis_texture = np.ascontiguousarray(basis_texture, np.float32)
    layers = rows.shape[1] // 4 if rows.ndim == 2 else 0
    if rows.ndim != 2 or rows.shape[1] != 4 * layers or basis_texture.shape[0] != layers \
            or not 0 < layers <= MAX_ROWS:
        return None, f"{kind} data layout inconsistent ({rows.shape}, basis {basis_texture.shape})"
    if corner_vertex is None or rows.shape[0] != vertex_count:
        return None, f"stale bake: {rows.shape[0]} vertices baked, the mesh has {vertex_count}"
    if len(corner_vertex) and int(np.max(corner_vertex)) >= rows.shape[0]:
        return None, "stale bake: corner vertex index beyond the baked vertices"
    if not np.all(np.isfinite(rows)) or not np.all(np.isfinite(basis_texture)):
        return None, "bake holds non-finite values"
    return PerVertexData(kind, rows, basis_texture, layers, int(terms), int(basis_texture.shape[1])), "ok"
