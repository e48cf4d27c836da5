"""Meshes: one vertex per face corner, object space, the world transform beside (see the package's docstring)."""
from dataclasses import dataclass

import numpy as np

from ...reflectance import models
from .. import uv_maps
from ..colour_attributes import default_color_attribute
from .materials import TEXTURED_PARAMETERS
from .messages import warn

# Mesh exports since import; tests read it to check what an update re-exported.
export_counter = {"meshes": 0}


@dataclass
class MeshExport:
    """Triangles over face corners, object space, float32/uint32 arrays."""
    positions: np.ndarray          # (V, 3) corner positions
    normals: np.ndarray            # (V, 3) split (corner) normals, unit
    tangents: np.ndarray           # (V, 4) unit tangent xyz, bitangent sign w (+-1)
    uvs: np.ndarray                # (V, 2) the UV map renders use (zeros without one: blender/uv_maps.py)
    triangles: np.ndarray          # (T, 3) uint32 corner indices, sorted by material index
    material_ranges: list          # [(material_index, first_triangle, triangle_count)]
    has_uv: bool = False
    # corner (loop) -> Blender mesh vertex (mesh.vertices index): corners of a vertex share its
    # per-vertex data (the visibility bake's coefficients); vertex_normals (vertex_count, 3) are the
    # smooth vertex normals (MeshVertex.normal, object space), the bake's local frames
    corner_vertex: np.ndarray = None   # (V,) uint32
    vertex_count: int = 0
    vertex_normals: np.ndarray = None  # (vertex_count, 3) float32
    # the mesh's default colour attribute (what a node tree's Color Attribute reads), linear RGBA a corner
    colors: np.ndarray = None          # (V, 4) float32, or None without one
    # the mesh's second UV map (blender/uv_maps.py) at every corner, or None without one
    second_uvs: np.ndarray = None      # (V, 2) float32
    # the mesh's texture space (location, size): what Generated coordinates span ([0, 1] over location +- size)
    texture_space: tuple = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0))


# --------------------------------------------------------------------------- meshes

def _tangents_from_uv(positions, normals, uvs, triangles):
    """Per-corner tangents by accumulating each triangle's UV gradient at the vertices it shares
    position with; for meshes calc_tangents refuses (n-gons).  Sign from the UV handedness."""
    p = positions[triangles]                       # (T, 3, 3)
    t = uvs[triangles]
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    d1, d2 = t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    safe = np.where(np.abs(det) > 1e-20, det, 1.0)
    tangent = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) / safe[:, None]
    bitangent = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) / safe[:, None]
    per_corner = np.zeros_like(positions)
    per_corner_b = np.zeros_like(positions)
    for k in range(3):
        np.add.at(per_corner, triangles[:, k], tangent)
        np.add.at(per_corner_b, triangles[:, k], bitangent)
    tangent = per_corner - normals * np.sum(per_corner * normals, axis=1, keepdims=True)
    length = np.linalg.norm(tangent, axis=1, keepdims=True)
    fallback = _any_perpendicular(normals)
    tangent = np.where(length > 1e-12, tangent / np.maximum(length, 1e-30), fallback)
    sign = np.where(np.sum(np.cross(normals, tangent) * per_corner_b, axis=1) < 0, -1.0, 1.0)
    return np.concatenate([tangent, sign[:, None]], axis=1)


def _any_perpendicular(normals):
    helper = np.where(np.abs(normals[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t = np.cross(normals, helper)
    return t / np.maximum(np.linalg.norm(t, axis=1, keepdims=True), 1e-30)


# Vertex coordinates beyond this (object space) are treated as NaN/Inf: float32 transforms overflow.
MAX_COORDINATE = 1e30


def mesh_corner_normals(mesh, vertex_index, name=None):
    """(C, 3) float32 unit corner (split) normals of a bpy Mesh, object space, degenerate ones repaired (the
    shading's normals, and the local frames of per-corner bakes); vertex_index: the corners' vertices."""
    normals = np.empty(len(mesh.loops) * 3, np.float32)
    if hasattr(mesh, "corner_normals"):            # Blender 4.1+
        mesh.corner_normals.foreach_get("vector", normals)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", normals)
    return _usable_normals(normals.reshape(-1, 3), vertex_index, mesh, name or mesh.name)


def export_mesh_data(mesh, name=None):
    """MeshExport of a bpy Mesh (already evaluated), object space; `name` (the object's) in warnings."""
    export_counter["meshes"] += 1
    mesh.calc_loop_triangles()
    loop_count = len(mesh.loops)
    triangle_count = len(mesh.loop_triangles)
    vertex_co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", vertex_co)
    vertex_index = np.empty(loop_count, np.int64)
    mesh.loops.foreach_get("vertex_index", vertex_index)
    positions = vertex_co.reshape(-1, 3)[vertex_index] if loop_count else np.zeros((0, 3), np.float32)

    normals = mesh_corner_normals(mesh, vertex_index, name)

    triangles = np.empty(triangle_count * 3, np.int64)
    mesh.loop_triangles.foreach_get("loops", triangles)
    triangles = triangles.reshape(-1, 3)
    material_index = np.empty(triangle_count, np.int64)
    mesh.loop_triangles.foreach_get("material_index", material_index)
    finite = (np.abs(positions) <= MAX_COORDINATE).all(axis=1)          # (False with a NaN)
    if not finite.all():
        # NaN/Inf coordinates (scripts, broken modifiers; Blender stores Inf as 3.4e38): leave their
        # triangles out (the vertex transform would overflow), zero the positions
        keep = finite[triangles].all(axis=1)
        triangles, material_index = triangles[keep], material_index[keep]
        triangle_count = len(triangles)
        positions = np.where(finite[:, None], positions, np.float32(0.0))
        warn(f"object '{name or mesh.name}': {len(np.unique(vertex_index[~finite]))} vertices with NaN/Inf "
             f"coordinates (or beyond {MAX_COORDINATE:g}): their {int((~keep).sum())} triangle(s) left out")

    uv_layer = uv_maps.render_layer(mesh)
    uvs = np.zeros((loop_count, 2), np.float32)
    tangents = None
    if uv_layer is not None and loop_count:
        flat = np.empty(loop_count * 2, np.float32)
        uv_layer.data.foreach_get("uv", flat)
        uvs = flat.reshape(-1, 2)
        try:
            mesh.calc_tangents(uvmap=uv_layer.name)
            tangent = np.empty(loop_count * 3, np.float32)
            sign = np.empty(loop_count, np.float32)
            mesh.loops.foreach_get("tangent", tangent)
            mesh.loops.foreach_get("bitangent_sign", sign)
            tangents = np.concatenate([tangent.reshape(-1, 3), sign[:, None]], axis=1)
            mesh.free_tangents()
        except RuntimeError:                        # n-gons: compute our own
            tangents = None
        if tangents is None:
            tangents = _tangents_from_uv(positions.astype(np.float64), normals.astype(np.float64),
                                         uvs.astype(np.float64), triangles)
    if tangents is None:
        tangents = np.concatenate([_any_perpendicular(normals.astype(np.float64)),
                                   np.ones((loop_count, 1))], axis=1)
    else:
        tangents = _usable_tangents(tangents, normals)

    order = np.argsort(material_index, kind="stable")
    triangles = triangles[order]
    material_index = material_index[order]
    ranges = []
    if triangle_count:
        starts = np.flatnonzero(np.diff(material_index, prepend=-1))
        ends = np.append(starts[1:], triangle_count)
        ranges = [(int(material_index[s]), int(s), int(e - s)) for s, e in zip(starts, ends)]
    return MeshExport(
        positions=np.ascontiguousarray(positions, np.float32),
        normals=np.ascontiguousarray(normals, np.float32),
        tangents=np.ascontiguousarray(tangents, np.float32),
        uvs=np.ascontiguousarray(uvs, np.float32),
        triangles=np.ascontiguousarray(triangles, np.uint32),
        material_ranges=ranges,
        has_uv=uv_layer is not None,
        corner_vertex=np.ascontiguousarray(vertex_index, np.uint32),
        vertex_count=len(mesh.vertices),
        vertex_normals=_vertex_normals(mesh),
        texture_space=(tuple(mesh.texspace_location), tuple(mesh.texspace_size)),
        **_corner_colors(mesh, vertex_index, name),
        **_second_uvs(mesh, loop_count),
    )


def _second_uvs(mesh, loop_count):
    """MeshExport's second_uvs: the mesh's second UV map (uv_maps.second_layer) at every corner."""
    layer = uv_maps.second_layer(mesh)
    if layer is None or not loop_count:
        return {}
    flat = np.empty(loop_count * 2, np.float32)
    layer.data.foreach_get("uv", flat)
    return {"second_uvs": np.ascontiguousarray(flat.reshape(-1, 2), np.float32)}


def _corner_colors(mesh, vertex_index, name):
    """MeshExport's colors: the default colour attribute's linear RGBA at every corner (a point attribute taken
    at the corner's vertex), non-finite values made 0 (warned)."""
    attribute = default_color_attribute(mesh)
    if attribute is None or attribute.domain not in ("POINT", "CORNER"):
        return {}
    values = np.empty(len(attribute.data) * 4, np.float32)
    attribute.data.foreach_get("color", values)
    values = values.reshape(-1, 4)
    if attribute.domain == "POINT":
        values = values[vertex_index]
    if not np.isfinite(values).all():
        warn(f"object '{name or mesh.name}': colour attribute '{attribute.name}' has non-finite values: 0 used")
        values = np.where(np.isfinite(values), values, np.float32(0.0))
    return {"colors": np.ascontiguousarray(values, np.float32)}


def _usable_normals(normals, vertex_index, mesh, name):
    """Corner normals with the zero-length or non-finite ones (degenerate faces: Blender gives them
    (0, 0, 0)) replaced by their vertex's normal, else object +Z; warns with the count."""
    length = np.linalg.norm(normals, axis=1)
    bad = ~(length > 1e-12)                       # zero, NaN
    bad |= ~np.isfinite(length)
    if not bad.any():
        return normals
    normals = normals.copy()
    vertex_normals = _vertex_normals(mesh)[vertex_index[bad]] if len(mesh.vertices) else np.zeros((0, 3))
    vertex_length = np.linalg.norm(vertex_normals, axis=1)
    usable = np.isfinite(vertex_length) & (vertex_length > 1e-12)
    replacement = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (int(bad.sum()), 1))
    replacement[usable] = vertex_normals[usable] / vertex_length[usable, None]
    normals[bad] = replacement
    warn(f"object '{name}': {int(bad.sum())} corner normal(s) of zero length or not finite (degenerate "
         f"faces) replaced by the vertex normal ({int(usable.sum())}) or object +Z ({int((~usable).sum())})")
    return normals


def _usable_tangents(tangents, normals):
    """UV tangents (calc_tangents) with the zero-length or non-finite ones (degenerate UVs or faces)
    replaced by a unit vector perpendicular to the normal, sign +1."""
    tangents = np.asarray(tangents)
    length = np.linalg.norm(tangents[:, :3], axis=1)
    bad = ~(np.isfinite(length) & (length > 1e-12)) | ~np.isfinite(tangents[:, 3])
    if not bad.any():
        return tangents
    tangents = np.array(tangents, np.float64)
    tangents[bad, :3] = _any_perpendicular(np.asarray(normals, np.float64)[bad])
    tangents[bad, 3] = 1.0
    return tangents


def _vertex_normals(mesh):
    normals = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("normal", normals)
    if not np.isfinite(normals).all():             # vertices at NaN/Inf: zero (the shaders' fallback: +Z)
        normals = np.where(np.isfinite(normals), normals, np.float32(0.0))
    return normals.reshape(-1, 3)


def to_world(mesh, matrix_world):
    """The MeshExport in world space (positions, normals by the inverse transpose, tangents with
    the bitangent sign flipped by mirroring transforms), e.g. for ray tracing the scene."""
    matrix = np.asarray(matrix_world, np.float64)
    linear = matrix[:3, :3]
    normal_matrix = np.linalg.inv(linear).T
    handedness = -1.0 if np.linalg.det(linear) < 0 else 1.0

    def unit(v):
        return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-30)

    tangents = np.concatenate([unit(mesh.tangents[:, :3] @ linear.T), mesh.tangents[:, 3:] * handedness], axis=1)
    return MeshExport(
        positions=np.ascontiguousarray(mesh.positions @ linear.T + matrix[:3, 3], np.float32),
        normals=np.ascontiguousarray(unit(mesh.normals @ normal_matrix.T), np.float32),
        tangents=np.ascontiguousarray(tangents, np.float32),
        uvs=mesh.uvs, triangles=mesh.triangles, material_ranges=list(mesh.material_ranges), has_uv=mesh.has_uv,
        corner_vertex=mesh.corner_vertex, vertex_count=mesh.vertex_count,
        vertex_normals=None if mesh.vertex_normals is None else np.ascontiguousarray(
            unit(mesh.vertex_normals @ normal_matrix.T), np.float32))


def export_object_mesh(object_eval):
    """MeshExport of an evaluated object (mesh, curve, text... anything with to_mesh)."""
    mesh = object_eval.to_mesh()
    try:
        exported = export_mesh_data(mesh, object_eval.name)
    finally:
        object_eval.to_mesh_clear()
    if not exported.has_uv and len(exported.triangles):
        _warn_missing_uvs(object_eval)
    return exported


def _warn_missing_uvs(object_eval):
    """A mesh without a UV map whose materials sample textures (they read texel (0, 0) everywhere)
    or take anisotropy tangents from the UV map (they get tangents from the object's axes)."""
    for slot in getattr(object_eval, "material_slots", ()):
        material = slot.material
        settings = getattr(material, "sgprt", None) if material is not None else None
        if settings is None:
            continue
        textures = [name for name in TEXTURED_PARAMETERS if getattr(settings, name + "_texture", None) is not None]
        if settings.normal_map is not None:
            textures.append("normal_map")
        if textures:
            warn(f"object '{object_eval.name}' has no UV map: material '{material.name}' samples its textures "
                 f"({', '.join(textures)}) at UV (0, 0)")
        if settings.model in models.ANISOTROPIC and settings.tangent_source == "UV_MAP":
            warn(f"object '{object_eval.name}' has no UV map: material '{material.name}' (anisotropic, tangent "
                 f"source UV Map) gets tangents from the object's axes instead")


def matrix_to_numpy(matrix):
    return np.array([list(row) for row in matrix], np.float64)
