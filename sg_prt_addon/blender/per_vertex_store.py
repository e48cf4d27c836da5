"""Per-vertex precomputations stored on a mesh datablock: one storage path for every kind (visibility.per_vertex).

A record of kind K (an SSDF bake is kind "ssdf"; blender/visibility_bake.py documents its fields):

- ``sgprt_K_00`` .. ``sgprt_K_{L-1}``: FLOAT_COLOR attributes (4 float32 a vertex, or a corner where the
  record's ``domain`` is CORNER: visibility.per_vertex; saved, reloaded and propagated through modifiers by 4.2
  and 5.x alike), together the rows, L <= MAX_ROWS;
- ``mesh["sgprt_K"]``: an ID property group.  ``format_version``, ``layers`` L, ``vertex_count``,
  ``topology_hash`` (visibility.pipeline.topology_hash of the vertex count and the loop triangles' vertex
  indices: mesh_topology_hash), ``face_hash`` (of its faces' corners: mesh_face_hash), ``domain`` (POINT, or
  CORNER; records made before it are POINT) and ``occluders`` (the
  fingerprints of what the bake traced, blender/occluders.py, as JSON; optional) are this module's; the kind
  adds its own fields.

A record whose vertex count or faces no longer match the mesh is STALE (records made before ``face_hash``
compare the loop triangles, which re-triangulated quads change); missing or inconsistent data is INVALID; both
are unusable.  load_record() reads and checks any kind the same way.

Objects whose modifiers change the topology (Subdivision Surface, Mirror, Array, Geometry Nodes...)
-------------------------------------------------------------------------------------------------------
Their rows index the evaluated mesh's vertices or corners, which the mesh datablock does not have, so their
record lives on a companion mesh: a Mesh datablock of the evaluated mesh's faces and positions (nothing else)
that the object points at with the ID property ``sgprt_K_evaluated_mesh`` (a user of it: it is saved with the
object, renamed with it, and goes when the object goes).  The mesh datablock is left as it is.  Besides the
store's fields such a record holds ``modifiers`` (modifier_stack.fingerprint as JSON: what the render evaluates),
``base_face_hash`` (the mesh datablock's faces) and ``viewport_face_hash`` (the viewport's evaluated faces at the
bake, which the bake made at the render's settings: blender/modifier_stack.py).  record_for_object() picks an
object's record: the one on its mesh where it fits what the object evaluates to (bakes without such modifiers,
as always), else its companion's, STALE, with the reason, when the mesh, the modifiers or the evaluated faces
changed since the bake, or when the viewport evaluates the modifiers otherwise than renders.
write_companion() replaces a companion only once the new record is written.
"""
import hashlib
import json
from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np

from ..visibility.per_vertex import MAX_ROWS
from ..visibility.pipeline import topology_hash
from . import modifier_stack


def property_name(kind):
    return f"sgprt_{kind}"


def attribute_name(kind, layer):
    return f"sgprt_{kind}_{layer:02d}"


def mesh_triangles(mesh):
    """(T, 3) int64 vertex indices of the loop triangles of a bpy Mesh."""
    triangles = mesh.loop_triangles
    if len(triangles) == 0 and len(mesh.polygons):
        mesh.calc_loop_triangles()
        triangles = mesh.loop_triangles
    flat = np.empty(len(triangles) * 3, np.int64)
    triangles.foreach_get("vertices", flat)
    return flat.reshape(-1, 3)


def mesh_triangle_corners(mesh):
    """(T, 3) int64 corner (loop) indices of the loop triangles of a bpy Mesh (after mesh_triangles)."""
    flat = np.empty(len(mesh.loop_triangles) * 3, np.int64)
    mesh.loop_triangles.foreach_get("loops", flat)
    return flat.reshape(-1, 3)


def mesh_topology_hash(mesh):
    """``visibility.pipeline.topology_hash`` of a bpy Mesh: its vertex count and loop triangles' vertices."""
    return topology_hash(len(mesh.vertices), mesh_triangles(mesh))


def mesh_face_hash(mesh):
    """Digest of a bpy Mesh's topology as faces: its vertex count, each face's corner count and the corners'
    vertices.  Moving vertices (a Displace modifier applied) keeps it, though Blender may then cut quads into
    other triangles."""
    sizes = np.empty(len(mesh.polygons), np.int32)
    mesh.polygons.foreach_get("loop_total", sizes)
    corners = np.empty(len(mesh.loops), np.int32)
    mesh.loops.foreach_get("vertex_index", corners)
    digest = hashlib.blake2b(np.int64(len(mesh.vertices)).tobytes(), digest_size=16)
    digest.update(sizes.tobytes())
    digest.update(corners.tobytes())
    return digest.hexdigest()


@dataclass
class StoredRecord:
    """A record read back from a mesh.  rows is None unless ``status`` is VALID (and rows were read)."""
    status: str                         # 'VALID', 'STALE' or 'INVALID'
    message: str
    metadata: object = None             # the ID property group, as read
    format_version: int = 0
    layers: int = 0
    vertex_count: int = 0
    topology_hash: str = ""
    rows: Optional[np.ndarray] = None   # (V, 4 L) float32, or (C, 4 L) with domain CORNER
    occluders: Optional[dict] = None    # the fingerprints of what the bake traced (blender/occluders.py)
    domain: str = "POINT"
    evaluated: bool = False             # on a companion mesh: of the object's evaluated mesh (module docstring)
    renders_only: bool = False          # STALE only because the viewport evaluates the modifiers otherwise


def has_record(mesh, kind):
    return property_name(kind) in mesh.keys()


def clear_record(mesh, kind):
    """Remove a stored record (metadata first, then the attributes).  True if there was anything."""
    found = False
    if property_name(kind) in mesh.keys():
        del mesh[property_name(kind)]
        found = True
    prefix = attribute_name(kind, 0)[:-2]
    for name in [a.name for a in mesh.attributes if a.name.startswith(prefix)]:
        mesh.attributes.remove(mesh.attributes[name])
        found = True
    return found


def domain_of(corner_point):
    """The attribute domain of a bake's rows: CORNER where it was made per point (corner_point), else POINT."""
    return "POINT" if corner_point is None else "CORNER"


def _domain_size(mesh, domain):
    return len(mesh.loops) if domain == "CORNER" else len(mesh.vertices)


def rows_for_mesh(mesh, rows, corner_point, what):
    """A bake's rows as stored: per vertex as baked (corner_point None), or a point's row for each of its
    corners; ValueError where they do not fit the mesh."""
    rows = np.asarray(rows, np.float32)
    if corner_point is None:
        if rows.shape[0] != len(mesh.vertices):
            raise ValueError(f"{what} of {rows.shape[0]} vertices does not fit '{mesh.name}' "
                             f"({len(mesh.vertices)} vertices)")
        return rows
    corner_point = np.asarray(corner_point, np.int64)
    if len(corner_point) != len(mesh.loops) or (len(corner_point) and corner_point.max() >= rows.shape[0]):
        raise ValueError(f"{what} of {rows.shape[0]} points does not fit the {len(mesh.loops)} corners of "
                         f"'{mesh.name}'")
    return rows[corner_point]


def store_record(mesh, kind, rows, format_version, metadata, occluders=None, domain="POINT", evaluation=None):
    """Write rows (V, 4 L), or (C, 4 L) for domain CORNER, and the kind's metadata to a mesh datablock,
    replacing any record of that kind; occluders: the fingerprints of what the bake traced
    (blender/occluders.py), or None; evaluation: evaluation_fields() of a record on a companion mesh, else None."""
    rows = np.asarray(rows, np.float32)
    layers = rows.shape[1] // 4
    if rows.shape[0] != _domain_size(mesh, domain):
        raise ValueError(f"{rows.shape[0]} rows do not fit the {_domain_size(mesh, domain)} "
                         f"{'corners' if domain == 'CORNER' else 'vertices'} of '{mesh.name}'")
    if rows.shape[1] != 4 * layers or not 0 < layers <= MAX_ROWS:
        raise ValueError(f"{rows.shape[1]} values a vertex need {-(-rows.shape[1] // 4)} attributes, at most {MAX_ROWS}")
    clear_record(mesh, kind)
    for layer in range(layers):
        attribute = mesh.attributes.new(attribute_name(kind, layer), "FLOAT_COLOR", domain)
        attribute.data.foreach_set("color", np.ascontiguousarray(rows[:, 4 * layer:4 * layer + 4]).ravel())
    mesh[property_name(kind)] = {"format_version": int(format_version), "layers": int(layers),
                                 "vertex_count": len(mesh.vertices), "topology_hash": mesh_topology_hash(mesh),
                                 "face_hash": mesh_face_hash(mesh), "domain": domain, **metadata,
                                 **({"occluders": json.dumps(occluders)} if occluders is not None else {}),
                                 **(evaluation or {})}


def evaluation_fields(modifiers, base_face_hash, viewport_face_hash):
    """A companion record's own fields (module docstring): the modifier stack's fingerprint
    (modifier_stack.fingerprint), the mesh datablock's face hash and the viewport's evaluated face hash, at the bake."""
    return {"modifiers": json.dumps(modifiers), "base_face_hash": str(base_face_hash),
            "viewport_face_hash": str(viewport_face_hash)}


def _evaluation_problem(group, obj):
    """(status, message) of why a companion record no longer fits the object `obj` (original) whose evaluated
    mesh it was baked on: its mesh datablock's faces or its modifiers changed; None if neither."""
    if str(group.get("base_face_hash")) != mesh_face_hash(obj.data):
        return "STALE", "stale: its mesh's faces were edited since the bake: re-bake"
    try:
        baked = json.loads(group["modifiers"])
    except (TypeError, ValueError):
        return "INVALID", "bake metadata damaged (modifiers): re-bake"
    phrases = modifier_stack.changes(baked, modifier_stack.fingerprint(obj))
    if phrases:
        return "STALE", f"stale: its modifiers changed since the bake ({'; '.join(phrases)}): re-bake"
    return None


def _evaluated_faces_problem(group, current, obj):
    """(message, renders_only) of a companion record whose object and modifiers are as baked but which does not
    fit the evaluated mesh `current`: the viewport's evaluation, as it was at the bake (the bake is of the render's:
    modifier_stack.as_rendered; renders_only), or other faces."""
    differences = "; ".join(modifier_stack.viewport_differences(obj))
    if differences and str(group.get("viewport_face_hash")) == mesh_face_hash(current):
        return ("the bake is of its modifiers as final renders evaluate them, the viewport evaluates them otherwise "
                f"({differences}): final renders are shadowed"), True
    hint = (f" (unless this is the viewport, which evaluates them otherwise than final renders: {differences})"
            if differences else "")
    return f"stale: its modifiers evaluate to other faces than the bake's: re-bake{hint}", False


def _topology_problem(group, record, current, obj):
    """(status, message) of why a record does not fit the evaluated mesh `current` (its vertex count or faces;
    a companion's checked against its object `obj` first, setting record.renders_only), or None."""
    if obj is not None and record.evaluated:
        problem = _evaluation_problem(group, obj)
        if problem is None and (len(current.vertices) != record.vertex_count
                                or mesh_face_hash(current) != str(group.get("face_hash"))):
            message, record.renders_only = _evaluated_faces_problem(group, current, obj)
            problem = "STALE", message
        return problem
    if len(current.vertices) != record.vertex_count:
        return "STALE", f"stale: the mesh has {len(current.vertices)} vertices, the bake {record.vertex_count}: re-bake"
    face_hash = group.get("face_hash")
    if (mesh_face_hash(current) != str(face_hash) if face_hash is not None
            else mesh_topology_hash(current) != record.topology_hash):
        return "STALE", "stale: the mesh topology changed since the bake: re-bake"
    return None


def load_record(mesh, kind, format_version, evaluated_mesh=None, read_rows=True, check_layers=None, obj=None):
    """The record of `kind` on a mesh datablock, or None without one.

    evaluated_mesh: the mesh the engine draws (an object's evaluated data), checked for staleness instead
    of `mesh`; read_rows=False skips the attributes' values (a cheap status for panels); check_layers:
    callable(metadata, layers) -> None or the message of an inconsistency of the kind's own fields; obj: the
    (original) object whose companion `mesh` is, whose mesh datablock and modifiers a companion record is checked
    against (module docstring)."""
    group = mesh.get(property_name(kind))
    if group is None:
        return None
    current = evaluated_mesh if evaluated_mesh is not None else mesh
    try:
        record = StoredRecord("VALID", "", group, format_version=int(group.get("format_version", 0)),
                              layers=int(group["layers"]), vertex_count=int(group["vertex_count"]),
                              topology_hash=str(group["topology_hash"]), domain=str(group.get("domain", "POINT")),
                              evaluated="modifiers" in group)
    except (KeyError, TypeError, ValueError) as error:
        return StoredRecord("INVALID", f"bake metadata damaged ({error}): re-bake")
    if record.domain not in ("POINT", "CORNER"):
        record.status, record.message = "INVALID", f"bake metadata damaged (domain {record.domain!r}): re-bake"
        return record
    if record.format_version != format_version:
        record.status, record.message = "INVALID", (f"bake format {record.format_version}, this add-on reads "
                                                    f"{format_version}: re-bake")
        return record
    problem = check_layers(group, record.layers) if check_layers is not None else None
    if problem is None and not 0 < record.layers <= MAX_ROWS:
        problem = f"bake metadata inconsistent ({record.layers} layers): re-bake"
    if problem is not None:
        record.status, record.message = "INVALID", problem
        return record
    problem = _topology_problem(group, record, current, obj)
    if problem is not None:
        record.status, record.message = problem
        return record
    try:
        record.occluders = json.loads(group["occluders"]) if "occluders" in group else None
    except (TypeError, ValueError):
        record.occluders = None             # unreadable: the render cannot say what moved, the bake still shades
    row_count = _domain_size(mesh, record.domain)
    for layer in range(record.layers):
        attribute = mesh.attributes.get(attribute_name(kind, layer))
        if (attribute is None or attribute.data_type != "FLOAT_COLOR" or attribute.domain != record.domain
                or len(attribute.data) != row_count):
            record.status = "INVALID"
            record.message = f"attribute {attribute_name(kind, layer)} missing or damaged: re-bake"
            return record
    if read_rows:
        rows = np.empty((row_count, 4 * record.layers), np.float32)
        column = np.empty(row_count * 4, np.float32)
        for layer in range(record.layers):
            mesh.attributes[attribute_name(kind, layer)].data.foreach_get("color", column)
            rows[:, 4 * layer:4 * layer + 4] = column.reshape(-1, 4)
        record.rows = rows
    return record


# --------------------------------------------------------------------------- companion meshes (module docstring)

def companion_property(kind):
    """The object ID property pointing at its companion mesh of `kind`."""
    return f"sgprt_{kind}_evaluated_mesh"


def companion_mesh(obj, kind):
    """The companion mesh holding an (original) object's record of `kind`, or None."""
    mesh = obj.get(companion_property(kind))
    return mesh if isinstance(mesh, bpy.types.Mesh) else None


def object_has_record(obj, kind):
    """Whether a mesh object has a record of `kind`, on its mesh datablock or on its companion."""
    return has_record(obj.data, kind) or companion_mesh(obj, kind) is not None


@dataclass
class EvaluatedTopology:
    """What a companion mesh is built of: an evaluated mesh's vertex positions (V, 3) float32, its faces' sizes
    (F,) and its corners' vertices (C,), read at the bake (the evaluated mesh is gone by the time it is stored)."""
    positions: np.ndarray
    face_sizes: np.ndarray
    corner_vertex: np.ndarray

    @classmethod
    def of(cls, mesh):
        positions = np.empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertices.foreach_get("co", positions)
        sizes = np.empty(len(mesh.polygons), np.int32)
        mesh.polygons.foreach_get("loop_total", sizes)
        corners = np.empty(len(mesh.loops), np.int32)
        mesh.loops.foreach_get("vertex_index", corners)
        return cls(positions.reshape(-1, 3), sizes, corners)


def _new_companion(topology, name):
    """A Mesh datablock of `topology`'s faces and positions, nothing else (no materials, UVs or attributes)."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(topology.positions))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(topology.positions, np.float32).ravel())
    mesh.loops.add(len(topology.corner_vertex))
    mesh.loops.foreach_set("vertex_index", np.ascontiguousarray(topology.corner_vertex, np.int32))
    mesh.polygons.add(len(topology.face_sizes))
    starts = np.concatenate([[0], np.cumsum(topology.face_sizes)[:-1]]).astype(np.int32)
    mesh.polygons.foreach_set("loop_start", starts)
    mesh.update(calc_edges=True)
    return mesh


def write_companion(obj, kind, topology, write):
    """Store an object's record of `kind` on a new companion mesh of `topology` (write(mesh) writes it, e.g.
    through store_record), then point the object at it, dropping the previous companion: an error while writing
    leaves the previous one as it was.  Returns what write returned."""
    companion = _new_companion(topology, f"SG-PRT {kind} of {obj.name}")
    try:
        written = write(companion)
    except BaseException:
        bpy.data.meshes.remove(companion)
        raise
    previous = companion_mesh(obj, kind)
    obj[companion_property(kind)] = companion
    if previous is not None and previous.users == 0:        # another object (a duplicate) may point at it too
        bpy.data.meshes.remove(previous)
    return written


def remove_companion(obj, kind):
    """Drop an object's companion of `kind` (the mesh goes with its last user).  True if it had one."""
    if companion_property(kind) not in obj.keys():
        return False
    previous = companion_mesh(obj, kind)
    del obj[companion_property(kind)]
    if previous is not None and previous.users == 0:
        bpy.data.meshes.remove(previous)
    return True


def clear_object_record(obj, kind):
    """Remove a mesh object's records of `kind`: on its mesh datablock and on its companion.  True if there was
    anything."""
    on_mesh = clear_record(obj.data, kind)
    return remove_companion(obj, kind) or on_mesh


def record_for_object(object_eval, kind, load):
    """The record of `kind` that shades an evaluated mesh object: the one on its mesh datablock where it fits the
    evaluated mesh (as always), else its companion's (module docstring), else the mesh datablock's (None, stale...).
    load(mesh, obj) -> the kind's record on `mesh` checked against the evaluated mesh, and against the original
    object `obj` (None for the mesh datablock's record) as load_record does."""
    original = getattr(object_eval, "original", None) or object_eval
    record = load(original.data, None)
    companion = companion_mesh(original, kind)
    if companion is None or (record is not None and record.status == "VALID"):
        return record
    return load(companion, original)
