"""Visibility bake operators and its storage in the .blend (wang2009 section 5; numerics in ../visibility).

Which points are baked
----------------------
Where every vertex has one corner normal (smooth meshes, flat planes), the Blender
mesh vertices (``mesh.vertices``, one SSDF per vertex), in world space, with
their vertex normals (``MeshVertex.normal``); where a vertex has corners of
several normals (flat-shaded faces, sharp edges), one point per vertex and
normal (``visibility.per_vertex.split_points``), moved a little into its faces
(``inset_points``), with that normal: its rows are stored per corner (domain
CORNER), so a flat face's corners read its own hemisphere.  The local frame is
``visibility.hemisphere_map.local_frame`` of the normal (no tangents).  The
geometry is the evaluated object's, as a final render evaluates it
(modifier_stack.as_rendered: the render's subdivision levels, the modifiers
shown in renders).  Where the modifiers keep the faces (deform only, or none)
the rows live on the mesh datablock, as they always did; where they change
them (Subdivision Surface, Mirror, Array, Geometry Nodes...) on a companion
mesh of the evaluated faces, with the modifier stack's fingerprint
(per_vertex_store's module docstring: the mesh datablock stays as it is; a
render whose modifiers changed since, or the viewport where it evaluates them
otherwise, draws the object unshadowed and says why).

The engine exports one vertex per face corner (blender/export/meshes.py).  To upload
per-corner data it maps corner -> vertex with the loop's ``vertex_index``::

    stored = visibility_for_object(object_eval)        # or load_visibility_bake(mesh, evaluated_mesh)
    if stored is not None and stored.usable:
        vertex_index = np.empty(len(mesh.loops), np.int64)
        mesh.loops.foreach_get("vertex_index", vertex_index)   # the mesh the corners came from
        per_corner = stored.corner_coefficients(vertex_index)  # (corners, 4 L) float32, L = stored.layers
        texture = stored.basis_texture()                       # (L, R, R, 4): decode.pack_basis_texture
    else:
        ...render this object unshadowed (no bake, stale or damaged: stored.message says why)

``corner_coefficients`` checks the indices against the stored vertex count,
so a stale bake is never read out of bounds.

Storage, per mesh datablock (format version 1)
----------------------------------------------
The per-vertex record of kind ``ssdf`` (blender/per_vertex_store.py, the one storage path of every
per-vertex kind):

- ``sgprt_ssdf_00`` .. ``sgprt_ssdf_{L-1}``: POINT-domain FLOAT_COLOR attributes
  (4 float32 a vertex; saved, reloaded and propagated through modifiers by 4.2
  and 5.x alike), together the rows of ``decode.pack_coefficients``:
  [1, w_0, w_1, ...] zero-padded to 4 L floats, L = ceil((terms + 1) / 4) <= 12
  (visibility.per_vertex.MAX_ROWS);
- ``mesh["sgprt_ssdf"]``, an ID property group: the store's ``format_version``,
  ``layers`` L, ``vertex_count``, ``topology_hash`` (``visibility.pipeline.topology_hash`` of the
  vertex count and the loop triangles' vertex indices: ``mesh_topology_hash``), ``face_hash``,
  ``occluders`` (per_vertex_store's; on a companion mesh also ``modifiers``,
  ``base_face_hash`` and ``viewport_face_hash``), and the bake's
  ``resolution`` R, ``terms`` N, ``rms_error`` (radians),
  ``frame_reference_axis`` (3), ``date`` (ISO 8601 UTC), ``seconds``,
  ``refinement``, ``error_target`` (-1 for fixed terms), ``rays_traced``, and the
  basis ``basis`` (N R R) and ``mean`` (R R) as float arrays (stored as double:
  the float32 values round-trip bit-exactly through save and reopen).

A bake whose vertex count or faces no longer match the mesh is STALE; missing
or inconsistent data is INVALID; both are unusable.  Moving vertices keeps the
faces (and the bake usable) but makes the shadows wrong, as does moving an
occluder: the bake keeps the fingerprints of what it traced
(blender/occluders.py) and the render names what moved or changed since.
Occluders are all visible objects with geometry (evaluated, world space), the
receivers included; a hidden receiver does not shadow itself.

Operators: ``sgprt.bake_visibility`` (execute: synchronous with printed
progress, for ``blender -b`` and tests; invoke: a background thread polled by
a timer, window-manager progress, Esc cancels) and ``sgprt.clear_visibility``.
Results are written only after every receiver finished: a cancelled or failed
bake leaves the previous bakes untouched.  The bake thread never touches bpy.
"""
import datetime
from dataclasses import dataclass
from typing import NamedTuple, Optional

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty

from ..visibility import decode, pca, per_vertex, raytrace
from ..visibility.per_vertex import MAX_ROWS, MAX_TERMS
from ..visibility.pipeline import BakeCancelled, BakeOptions, bake_visibility
from . import export, modifier_stack, occluders, per_vertex_store
from .background_job import BackgroundJob, SceneJobOperator
from .occluders import occluder_arrays
from .panels import RenderPanel
from .per_vertex_store import mesh_face_hash, mesh_topology_hash, mesh_triangle_corners, mesh_triangles

FORMAT_VERSION = 1
KIND = "ssdf"           # the bake's per-vertex kind (visibility.per_vertex; stored by per_vertex_store)
PROPERTY = per_vertex_store.property_name(KIND)
ATTRIBUTE_PREFIX = per_vertex_store.attribute_name(KIND, 0)[:-2]
MAX_LAYERS = MAX_ROWS

# Tests (and scripts) may set this to a callable(fraction, message) -> bool: True cancels the bake.
progress_hook = None


def attribute_name(layer):
    return per_vertex_store.attribute_name(KIND, layer)


# --------------------------------------------------------------------------- mesh arrays (main thread)

def _vertex_array(mesh, name):
    out = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get(name, out)
    return out.reshape(-1, 3).astype(np.float64)


def _matrix(matrix):
    return np.array([list(row) for row in matrix], np.float64)


def _to_world(points, matrix):
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def _corner_face_centres(mesh):
    """(C, 3) the centre of each corner's face, object space."""
    centres = np.empty(len(mesh.polygons) * 3, np.float32)
    mesh.polygons.foreach_get("center", centres)
    sizes = np.empty(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_total", sizes)
    return np.repeat(centres.reshape(-1, 3).astype(np.float64), sizes, axis=0)


def _evaluated_mesh(obj, depsgraph):
    """The evaluated mesh of an object a bake can take; ValueError with a message for the user if none."""
    if obj.type != "MESH":
        raise ValueError(f"'{obj.name}' is not a mesh")
    if obj.mode == "EDIT":
        raise ValueError(f"'{obj.name}' is in Edit Mode: leave it before baking")
    mesh = obj.evaluated_get(depsgraph).data
    if len(mesh.polygons) == 0:
        if any(modifier.type == "NODES" and modifier.show_render for modifier in obj.modifiers):
            raise ValueError(f"'{obj.name}' has no faces of its own: its Geometry Nodes output is instances (a "
                             "Realize Instances node makes them its faces, to bake; they cast shadows as they are)")
        raise ValueError(f"'{obj.name}' has no faces: nothing to bake")
    return mesh


def receiver_arrays(obj, depsgraph):
    """World-space (points, normals, triangles, corner_point, point_triangles) where a mesh object is baked, from
    its evaluated geometry: its vertices (corner_point None) where every corner has its vertex's normal, else one
    point a vertex and normal (visibility.per_vertex.split_points: flat faces and sharp edges get their faces'
    hemispheres) and the point each corner reads; triangles over the mesh's vertices (hashed) and over the
    points (which points neighbour which); ValueError with a message for the user when it cannot be baked."""
    mesh = _evaluated_mesh(obj, depsgraph)
    matrix = _matrix(obj.evaluated_get(depsgraph).matrix_world)
    vertices = _vertex_array(mesh, "co")
    bad = int(np.count_nonzero(~raytrace.traceable(_to_world(vertices, matrix))))
    if bad:
        raise ValueError(f"'{obj.name}': {bad} of its vertices are NaN, Inf or beyond "
                         f"{raytrace.COORDINATE_LIMIT:.0e} m")
    normals = _vertex_array(mesh, "normal")
    corner_vertex = np.empty(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    corner_normals = export.mesh_corner_normals(mesh, corner_vertex, obj.name)
    # the render asks the same question of the exported mesh (scene_state): a bake per vertex must not look stale
    triangles = mesh_triangles(mesh)
    if not per_vertex.has_split_normals(corner_normals, normals, corner_vertex):
        corner_point = None                  # one normal a vertex: rows per vertex, as smooth meshes always had
        point_triangles = triangles
    else:
        corner_point, point_vertex, normals = per_vertex.split_points(corner_vertex, corner_normals)
        vertices = per_vertex.inset_points(vertices[point_vertex], corner_point, _corner_face_centres(mesh))
        point_triangles = corner_point[mesh_triangle_corners(mesh)]
    normals = normals @ np.linalg.inv(matrix[:3, :3])   # inverse transpose
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    return _to_world(vertices, matrix), normals, triangles, corner_point, point_triangles


class Receiver(NamedTuple):
    """One mesh a per-vertex bake writes to (bake_inputs), world space (receiver_arrays)."""
    key: str                        # the BakeTarget's key
    label: str                      # the object's name, for progress and messages
    points: np.ndarray              # (P, 3) where the rows are baked
    normals: np.ndarray             # (P, 3)
    triangles: np.ndarray           # (T, 3) over the mesh's vertices (the topology hash)
    corner_point: Optional[np.ndarray]      # (C,) the point each corner reads; None: the points are the vertices
    point_triangles: Optional[np.ndarray] = None    # (T, 3) over the points: neighbours (visibility.buried)


@dataclass
class BakeTarget:
    """Where a receiver's rows are stored: on its mesh datablock (`evaluated` None: its modifiers keep the faces),
    or on a companion mesh of its evaluated faces (per_vertex_store), with what the bake saw of the object."""
    key: tuple                          # ("MESH", mesh name) or ("OBJECT", object name): one bake each
    object_name: str
    mesh_name: str
    topology_hash: str                  # the mesh datablock's at the bake: an edit during the bake is not stored
    evaluated: Optional[per_vertex_store.EvaluatedTopology] = None
    modifiers: Optional[list] = None    # modifier_stack.fingerprint at the bake (companions)
    evaluation: Optional[dict] = None   # per_vertex_store.evaluation_fields (companions)

    def changed_since(self):
        """Why the object can no longer take what was baked (gone, its mesh or modifiers edited), or None."""
        obj = bpy.data.objects.get(self.object_name)
        mesh = bpy.data.meshes.get(self.mesh_name)
        if obj is None or mesh is None or obj.data != mesh:
            return "went or changed its mesh"
        if mesh_topology_hash(mesh) != self.topology_hash:
            return "had its mesh edited"
        if self.evaluated is not None and modifier_stack.changes(self.modifiers, modifier_stack.fingerprint(obj)):
            return "had its modifiers changed"
        return None

    def write(self, kind, store):
        """store(mesh, evaluation) writes the record of `kind` to `mesh`: here the mesh datablock (and the
        object's older companion goes), or a new companion replacing the object's (per_vertex_store.write_companion).
        Returns what store returned."""
        obj = bpy.data.objects[self.object_name]
        if self.evaluated is None:
            written = store(obj.data, None)
            obj.data.update()
            per_vertex_store.remove_companion(obj, kind)
        else:
            written = per_vertex_store.write_companion(obj, kind, self.evaluated,
                                                       lambda mesh: store(mesh, self.evaluation))
        obj.update_tag(refresh={"DATA"})        # the viewport re-reads the object's bake
        return written


def bake_target(obj, depsgraph, viewport_face_hash):
    """The BakeTarget of a mesh object evaluated as a render does (`depsgraph`, inside modifier_stack.as_rendered);
    viewport_face_hash: of its viewport evaluation.  ValueError with a message for the user when it cannot be
    baked."""
    mesh = _evaluated_mesh(obj, depsgraph)
    base_face_hash = mesh_face_hash(obj.data)
    if len(mesh.vertices) == len(obj.data.vertices) and mesh_face_hash(mesh) == base_face_hash:
        if obj.data.library is not None or getattr(obj.data, "override_library", None) is not None:
            raise ValueError(f"'{obj.name}' uses a linked mesh, which cannot store a bake")
        return BakeTarget(("MESH", obj.data.name), obj.name, obj.data.name, mesh_topology_hash(obj.data))
    if obj.library is not None:
        raise ValueError(f"'{obj.name}' is linked from a library, which cannot store a bake of its modifiers' mesh")
    modifiers = modifier_stack.fingerprint(obj)
    return BakeTarget(("OBJECT", obj.name), obj.name, obj.data.name, mesh_topology_hash(obj.data),
                      per_vertex_store.EvaluatedTopology.of(mesh), modifiers,
                      per_vertex_store.evaluation_fields(modifiers, base_face_hash, viewport_face_hash))


# --------------------------------------------------------------------------- storage

@dataclass
class StoredBake:
    """A bake read back from a mesh.  Arrays are None unless ``usable`` (and read_arrays)."""
    status: str                         # 'VALID', 'STALE' (topology changed) or 'INVALID' (damaged, old format)
    message: str
    format_version: int = 0
    resolution: int = 0
    terms: int = 0
    layers: int = 0
    rms_error: float = 0.0
    vertex_count: int = 0
    topology_hash: str = ""
    frame_reference_axis: Optional[np.ndarray] = None
    date: str = ""
    seconds: float = 0.0
    packed_coefficients: Optional[np.ndarray] = None   # (V, 4 L) float32 rows [1, w_0, ...]
    basis: Optional[np.ndarray] = None                 # (N, R, R) float32
    mean: Optional[np.ndarray] = None                  # (R, R) float32
    occluders: Optional[dict] = None                   # what it traced (blender/occluders.py fingerprints)
    domain: str = "POINT"                              # rows per vertex, or per corner (CORNER)
    renders_only: bool = False                         # stale here, for the viewport only (per_vertex_store)

    @property
    def usable(self):
        return self.status == "VALID"

    @property
    def coefficients(self):
        """(V, N) float32 PCA weights, as ``BakeResult.coefficients``."""
        return None if self.packed_coefficients is None else self.packed_coefficients[:, 1:self.terms + 1]

    def basis_texture(self):
        """(L, R, R, 4) float32: ``decode.pack_basis_texture(mean, basis)``."""
        return decode.pack_basis_texture(self.mean, self.basis)

    def corner_coefficients(self, vertex_index):
        """Per-corner (C, 4 L) rows from the loops' vertex indices; IndexError if any is out of range (or,
        for a bake per corner, if there are not as many corners as were baked)."""
        vertex_index = np.asarray(vertex_index, np.int64)
        if self.packed_coefficients is None:
            raise ValueError(f"no usable bake: {self.message}")
        if self.domain == "CORNER":
            if len(vertex_index) != len(self.packed_coefficients):
                raise IndexError(f"{len(vertex_index)} corners, the bake has {len(self.packed_coefficients)}")
            return self.packed_coefficients
        if vertex_index.size and (vertex_index.min() < 0 or vertex_index.max() >= self.vertex_count):
            raise IndexError(f"vertex index out of the baked range 0..{self.vertex_count - 1}")
        return self.packed_coefficients[vertex_index]


def has_visibility_bake(mesh):
    return per_vertex_store.has_record(mesh, KIND)


def clear_visibility_bake(mesh):
    """Remove a stored bake (metadata first, then the attributes). True if there was anything."""
    return per_vertex_store.clear_record(mesh, KIND)


def store_visibility_bake(mesh, result, options=None, occluder_fingerprints=None, corner_point=None,
                          evaluation=None):
    """Write a finished ``BakeResult`` to a mesh datablock, replacing any previous bake; with the fingerprints
    of the occluders it traced (occluders.fingerprints), a render can name what moved since.  corner_point:
    the point of each corner where the bake is per point (receiver_arrays), None where per vertex;
    evaluation: per_vertex_store.evaluation_fields on a companion mesh (BakeTarget), else None."""
    packed = per_vertex_store.rows_for_mesh(mesh, decode.pack_coefficients(result.coefficients), corner_point,
                                            "bake")
    layers = packed.shape[1] // 4
    if layers > MAX_LAYERS:
        raise ValueError(f"{result.terms} terms need {layers} attributes, more than {MAX_LAYERS}")
    options = options or BakeOptions(resolution=result.resolution)
    per_vertex_store.store_record(mesh, KIND, packed, FORMAT_VERSION, {
        "resolution": int(result.resolution),
        "terms": int(result.terms),
        "rms_error": float(result.rms_error),
        "frame_reference_axis": [float(x) for x in np.asarray(result.frame_reference_axis).ravel()],
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "seconds": float(result.seconds),
        "refinement": int(options.refinement),
        "error_target": float(options.error_target) if options.terms is None else -1.0,
        "rays_traced": int(result.rays_traced),
        "basis": np.asarray(result.basis, np.float32).ravel().astype(np.float64).tolist(),
        "mean": np.asarray(result.mean, np.float32).ravel().astype(np.float64).tolist(),
    }, occluder_fingerprints, per_vertex_store.domain_of(corner_point), evaluation)


def float_array(value):
    try:
        return np.array(value, np.float64).ravel()          # IDPropertyArray: buffer protocol, no list
    except (TypeError, ValueError):
        return np.asarray(value.to_list() if hasattr(value, "to_list") else list(value), np.float64).ravel()


def _terms_fill_layers(group, layers):
    """per_vertex_store's check of the SSDF's own fields: the mean and the terms fill the layers."""
    if layers != -(-(int(group["terms"]) + 1) // 4):
        return "bake metadata inconsistent (terms vs layers): re-bake"
    return None


def load_visibility_bake(mesh, evaluated_mesh=None, read_arrays=True, obj=None):
    """The bake stored on a mesh datablock, or None if it has none.

    evaluated_mesh: the mesh the engine draws (an object's evaluated data), checked for staleness
    instead of ``mesh`` itself.  read_arrays=False skips the arrays (cheap status for panels).  obj: the object
    whose companion ``mesh`` is (per_vertex_store.load_record).
    """
    try:
        record = per_vertex_store.load_record(mesh, KIND, FORMAT_VERSION, evaluated_mesh, read_arrays,
                                              check_layers=_terms_fill_layers, obj=obj)
    except (KeyError, TypeError, ValueError) as error:
        return StoredBake("INVALID", f"bake metadata damaged ({error}): re-bake")
    if record is None:
        return None
    group = record.metadata
    try:
        stored = StoredBake(
            status=record.status, message=record.message, format_version=record.format_version,
            resolution=int(group["resolution"]), terms=int(group["terms"]), layers=record.layers,
            rms_error=float(group["rms_error"]), vertex_count=record.vertex_count,
            topology_hash=record.topology_hash, frame_reference_axis=float_array(group["frame_reference_axis"]),
            date=str(group.get("date", "")), seconds=float(group.get("seconds", 0.0)), occluders=record.occluders,
            domain=record.domain, renders_only=record.renders_only)
    except (KeyError, TypeError, ValueError) as error:
        return StoredBake("INVALID", f"bake metadata damaged ({error}): re-bake")
    if not stored.usable:
        return stored
    stored.message = (f"{stored.terms} terms, RMS error {np.degrees(stored.rms_error):.2f} deg, "
                      f"{stored.vertex_count} vertices{' (per corner)' if stored.domain == 'CORNER' else ''}"
                      f"{' with its modifiers' if record.evaluated else ''}, baked {stored.date}")
    if not read_arrays:
        return stored
    resolution = stored.resolution
    basis = float_array(group["basis"]) if stored.terms else np.zeros(0)
    mean = float_array(group["mean"])
    if basis.size != stored.terms * resolution * resolution or mean.size != resolution * resolution:
        stored.status, stored.message = "INVALID", "stored basis has the wrong size: re-bake"
        return stored
    stored.basis = basis.astype(np.float32).reshape(stored.terms, resolution, resolution)
    stored.mean = mean.astype(np.float32).reshape(resolution, resolution)
    stored.packed_coefficients = record.rows
    return stored


def visibility_for_object(object_eval, read_arrays=True):
    """The engine's entry: the bake of an (evaluated) object's mesh, checked against the geometry it
    draws; None without a bake or for non-mesh objects."""
    if object_eval.type != "MESH":
        return None
    return per_vertex_store.record_for_object(object_eval, KIND, lambda mesh, obj: load_visibility_bake(
        mesh, evaluated_mesh=object_eval.data, read_arrays=read_arrays, obj=obj))


def unusable_bakes(scene, depsgraph):
    """[(object name, message)] of the scene's visible mesh objects whose stored bake is stale or damaged
    (they render unshadowed): what the operator and the panel warn about."""
    found = []
    for obj in scene.objects:
        if obj.type == "MESH" and obj.visible_get() and per_vertex_store.object_has_record(obj, KIND):
            stored = visibility_for_object(obj.evaluated_get(depsgraph), read_arrays=False)
            if stored is not None and not stored.usable:
                found.append((obj.name, stored.message))
    return found


# --------------------------------------------------------------------------- the bake job (no bpy)

class BakeJob(BackgroundJob):
    """Bakes receivers one after another; run() synchronously or start() a thread.  Never touches bpy.

    receivers: [Receiver] (bake_inputs), world space.
    results: {key: BakeResult} (a row a point)
    once every receiver finished; cancelled / error otherwise (results then empty).
    """

    verb = "bake"
    thread_name = "sgprt-visibility-bake"

    def __init__(self, receivers, occluder_vertices, occluder_triangles, options, verbose=False, hook=None):
        super().__init__(verbose, hook)
        self.receivers = receivers
        self.occluder_vertices = occluder_vertices
        self.occluder_triangles = occluder_triangles
        self.options = options
        self.results = {}

    def _progress_for(self, index, label):
        count = len(self.receivers)

        def progress(fraction, message):
            overall = (index + min(max(fraction, 0.0), 1.0)) / count
            return self.record_progress(overall, f"{label}: {message}", always_print=fraction >= 1.0)
        return progress

    def run(self):
        results = {}
        try:
            for index, receiver in enumerate(self.receivers):
                results[receiver.key] = bake_visibility(
                    receiver.points, receiver.triangles, receiver.normals, self.occluder_vertices,
                    self.occluder_triangles, self.options, progress=self._progress_for(index, receiver.label),
                    point_triangles=receiver.point_triangles)
                if self.cancelling:
                    raise BakeCancelled("cancelled after a receiver finished")
        except BakeCancelled:
            self.cancelled = True
            if self.verbose:
                print("[sg-prt] bake cancelled: nothing written", flush=True)
            return
        except Exception as error:       # reported to the user by the operator, nothing written
            self.error = error
            if self.verbose:
                print(f"[sg-prt] bake failed: {error}", flush=True)
            return
        self.results = results


# --------------------------------------------------------------------------- settings, operators, panel

TERM_MODES = (("ERROR_TARGET", "Error Target", "The fewest PCA terms reaching the RMS error target"),
              ("FIXED", "Fixed Terms", "A fixed number of PCA terms"))
TARGETS = (("SELECTED", "Selected", "Bake the selected mesh objects"),
           ("ALL", "All Visible", "Bake every visible mesh object"))
OPTION_NAMES = ("target", "resolution", "refinement", "term_mode", "error_target", "terms", "max_terms")


def _option_properties():
    return dict(
        target=EnumProperty(name="Target", items=TARGETS, default="SELECTED",
                            description="Which mesh objects receive a bake (all visible objects cast shadows)"),
        resolution=IntProperty(name="Resolution", default=32, min=4, max=64,
                               description="SSDF samples per side of each vertex's hemisphere map"),
        refinement=IntProperty(name="Refinement", default=5, min=1, max=9, step=2,
                               description="Odd supersampling factor of hemisphere cells that mix visible "
                                           "and occluded rays"),
        term_mode=EnumProperty(name="Terms", items=TERM_MODES, default="ERROR_TARGET",
                               description="How many PCA terms to keep"),
        error_target=FloatProperty(name="Error Target", default=pca.DEFAULT_ERROR_TARGET, min=0.001, max=0.5, subtype="ANGLE",
                                   description="RMS angular error of the compressed SSDFs"),
        terms=IntProperty(name="Fixed Terms", default=24, min=0, max=MAX_TERMS,
                          description="PCA terms when the number is fixed"),
        max_terms=IntProperty(name="Max Terms", default=MAX_TERMS, min=1, max=MAX_TERMS,
                              description=f"Most PCA terms ({MAX_TERMS} + the mean fill {MAX_ROWS} vec4 a vertex)"),
    )


SGPRT_PG_bake = type("SGPRT_PG_bake", (bpy.types.PropertyGroup,),
                     {"__annotations__": _option_properties(),
                      "__doc__": "Scene settings of the visibility bake: scene.sgprt_bake"})


def _bake_options(settings):
    fixed = settings.term_mode == "FIXED"
    refinement = settings.refinement if settings.refinement % 2 else settings.refinement + 1
    return BakeOptions(resolution=settings.resolution, refinement=refinement,
                       terms=min(settings.terms, settings.max_terms) if fixed else None,
                       error_target=settings.error_target, max_terms=settings.max_terms)


def mesh_objects(context, target):
    if target == "ALL":
        hidden = export.render_roles(context.view_layer).hidden
        return [obj for obj in context.scene.objects if obj.type == "MESH" and obj.visible_get()
                and obj.name not in hidden]
    return [obj for obj in context.selected_objects if obj.type == "MESH"]


def collection_instancers(context):
    """The visible objects that instance a collection (an Empty's Instancing > Collection)."""
    hidden = export.render_roles(context.view_layer).hidden
    return [obj for obj in context.scene.objects if obj.instance_type == "COLLECTION"
            and obj.instance_collection is not None and obj.visible_get() and obj.name not in hidden]


def bake_inputs(operator, context, objects, what):
    """(receivers [Receiver] (receiver_arrays),
    occluder vertices, occluder triangles, {target key: BakeTarget}, the occluders' fingerprints
    (occluders.fingerprints, stored with the bake)) of the objects a per-vertex bake writes to, world space, as
    a final render evaluates the scene (modifier_stack.as_rendered); None after the operator reported why not.
    what: the bake's name in messages ("bake", "transfer bake")."""
    if operator.target == "ALL":
        for instancer in collection_instancers(context):
            operator.report({"WARNING"}, f"SG-PRT {what}: collection instance '{instancer.name}' is not baked: its "
                                         f"instances share the meshes of '{instancer.instance_collection.name}' and "
                                         "so would share one bake (Make Instances Real to bake each); they cast "
                                         "shadows on what is baked")
    if not objects:
        operator.report({"ERROR"}, f"SG-PRT {what}: no mesh object selected" if operator.target == "SELECTED"
                        else f"SG-PRT {what}: no visible mesh object")
        return None
    depsgraph = context.evaluated_depsgraph_get()
    viewport_faces = {obj.name: mesh_face_hash(obj.evaluated_get(depsgraph).data) for obj in objects
                      if obj.type == "MESH"}
    receivers, targets = [], {}
    with modifier_stack.as_rendered(context.scene):
        depsgraph = context.evaluated_depsgraph_get()
        for obj in objects:
            try:
                target = bake_target(obj, depsgraph, viewport_faces.get(obj.name))
                if target.key in targets:
                    operator.report({"WARNING"}, f"'{obj.name}' shares its mesh with an object baked already; "
                                                 f"the {what} is stored once per mesh")
                    continue
                arrays = receiver_arrays(obj, depsgraph)
            except ValueError as error:
                operator.report({"WARNING"}, f"SG-PRT {what} skips {error}")
                continue
            targets[target.key] = target
            receivers.append(Receiver(target.key, obj.name, *arrays))
        if not receivers:
            operator.report({"ERROR"}, f"SG-PRT {what}: none of the objects can be baked (see the warnings)")
            return None
        geometry = occluders.scene_geometry(depsgraph)
        for name, bad in occluders.untraceable(geometry).items():
            operator.report({"WARNING"}, f"SG-PRT {what}: '{name}' has {bad} vertices that are NaN, Inf or beyond "
                                         f"{raytrace.COORDINATE_LIMIT:.0e} m: its faces there cast no shadow")
        occluder_vertices, occluder_triangles = occluder_arrays(depsgraph, geometry)
    return receivers, occluder_vertices, occluder_triangles, targets, occluders.fingerprints(geometry)


def store_results(operator, job, targets, kind, store, what, done):
    """The operator's outcome of a finished per-vertex bake job: nothing written when it was cancelled or
    failed; else store(mesh, result, corner_point, evaluation) -> a summary, for every target (BakeTarget) of
    `kind` whose object is as it was baked, reported after `done`."""
    if job.cancelled:
        operator.report({"WARNING"}, f"SG-PRT {what} cancelled: nothing written, previous bakes kept")
        return {"CANCELLED"}
    if job.error is not None:
        operator.report({"ERROR"}, f"SG-PRT {what} failed, nothing written: {job.error}")
        return {"CANCELLED"}
    written = []
    for key, result in job.results.items():
        target = targets[key]
        problem = target.changed_since()
        if problem is not None:
            operator.report({"WARNING"}, f"'{target.object_name}' {problem} during the {what}: not stored")
            continue
        corner_point = next(receiver.corner_point for receiver in job.receivers if receiver.key == key)
        summary = target.write(kind, lambda mesh, evaluation: store(mesh, result, corner_point, evaluation))
        written.append(f"{target.object_name} ({summary})")
    if not written:
        return {"CANCELLED"}
    operator.report({"INFO"}, f"{done} " + ", ".join(written))
    return {"FINISHED"}


class SGPRT_OT_bake_visibility(SceneJobOperator, bpy.types.Operator):
    """Bake all-frequency visibility (PCA-compressed SSDFs) at the vertices of mesh objects"""
    bl_idname = "sgprt.bake_visibility"
    bl_label = "Bake Visibility"
    bl_options = {"REGISTER", "UNDO"}
    __annotations__ = _option_properties()

    job_label = "SG-PRT bake"
    _running = False       # one bake at a time

    @classmethod
    def poll(cls, context):
        return not SGPRT_OT_bake_visibility._running and context.scene is not None

    def _resolve_options(self, context):
        settings = getattr(context.scene, "sgprt_bake", None)
        for name in OPTION_NAMES:
            if settings is not None and not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))

    def _prepare(self, context):
        """The BakeJob, or None after reporting why not."""
        self._resolve_options(context)
        inputs = bake_inputs(self, context, mesh_objects(context, self.target), "bake")
        if inputs is None:
            return None
        receivers, occluder_vertices, occluder_triangles, self._targets, self._occluders = inputs
        return BakeJob(receivers, occluder_vertices, occluder_triangles, _bake_options(self),
                       hook=progress_hook)

    def _finish(self, context, job):
        def store(mesh, result, corner_point, evaluation):
            store_visibility_bake(mesh, result, job.options, self._occluders, corner_point, evaluation)
            buried = f", {result.buried_points} buried points from their neighbours" if result.buried_points else ""
            return f"{result.terms} terms, {np.degrees(result.rms_error):.2f} deg, {result.seconds:.1f} s{buried}"

        outcome = store_results(self, job, self._targets, KIND, store, "bake", "SG-PRT baked")
        if not job.cancelled and job.error is None:
            with modifier_stack.as_rendered(context.scene):     # what final renders say, as the bake was made
                unusable = unusable_bakes(context.scene, context.evaluated_depsgraph_get())
            for name, message in unusable:
                self.report({"WARNING"}, f"SG-PRT: '{name}' renders unshadowed, its bake is {message}")
        return outcome


def clear_bakes(operator, context, kind, what):
    """A clear operator's execute: the records of `kind` of the target's mesh objects (else the active one), on
    their meshes and companions (per_vertex_store.clear_object_record)."""
    objects = mesh_objects(context, operator.target)
    if not objects and context.active_object is not None and context.active_object.type == "MESH":
        objects = [context.active_object]
    if not objects:
        operator.report({"ERROR"}, "SG-PRT: no mesh object selected")
        return {"CANCELLED"}
    cleared = [obj for obj in objects if per_vertex_store.clear_object_record(obj, kind)]
    for obj in cleared:
        obj.data.update()
        obj.update_tag(refresh={"DATA"})
    operator.report({"INFO"}, f"SG-PRT cleared {len(cleared)} {what}")
    return {"FINISHED"}


class SGPRT_OT_clear_visibility(bpy.types.Operator):
    """Remove the stored visibility bake of the selected mesh objects"""
    bl_idname = "sgprt.clear_visibility"
    bl_label = "Clear Visibility Bake"
    bl_options = {"REGISTER", "UNDO"}

    target: EnumProperty(name="Target", items=TARGETS, default="SELECTED")

    def execute(self, context):
        return clear_bakes(self, context, KIND, "bake(s)")


def draw_bake_controls(layout, settings, option_names, bake_idname, clear_idname):
    """A bake panel's settings (option_names, then its PCA terms: fixed, or by an error target, at most
    max_terms) and its Bake and Clear buttons."""
    layout.use_property_split = True
    for name in option_names + ("term_mode",):
        layout.prop(settings, name)
    layout.prop(settings, "terms" if settings.term_mode == "FIXED" else "error_target")
    layout.prop(settings, "max_terms")
    row = layout.row(align=True)
    row.operator(bake_idname, icon="RENDER_STILL")
    row.operator(clear_idname, text="", icon="X")


def active_mesh_record(layout, context, load, what):
    """(the active object, load(its evaluated object, read_arrays=False)) for a bake panel's status line, or
    (None, None) after drawing why there is none: no active mesh, or `what` could not be read."""
    obj = context.active_object
    if obj is None or obj.type != "MESH":
        layout.label(text="Active object: not a mesh", icon="INFO")
        return None, None
    try:
        # the view layer's depsgraph as last evaluated: drawing must not trigger an evaluation
        return obj, load(obj.evaluated_get(context.view_layer.depsgraph), read_arrays=False)
    except Exception as error:      # a panel must draw whatever the data
        layout.label(text=f"{obj.name}: cannot read {what} ({error})", icon="ERROR")
        return None, None


class SGPRT_PT_visibility_bake(RenderPanel, bpy.types.Panel):
    bl_label = "SG-PRT Visibility Bake"

    def draw(self, context):
        layout = self.layout
        draw_bake_controls(layout, context.scene.sgprt_bake, ("target", "resolution", "refinement"),
                           SGPRT_OT_bake_visibility.bl_idname, SGPRT_OT_clear_visibility.bl_idname)
        obj, stored = active_mesh_record(layout, context, visibility_for_object, "the bake")
        if obj is None:
            return
        column = layout.column(align=True)
        if stored is None:
            column.label(text=f"{obj.name}: not baked (renders unshadowed)", icon="INFO")
        elif stored.usable:
            column.label(text=f"{obj.name}: {stored.terms} terms, {stored.resolution}x{stored.resolution}",
                         icon="CHECKMARK")
            column.label(text=f"RMS error {np.degrees(stored.rms_error):.2f} deg, {stored.vertex_count} vertices")
            column.label(text=f"Baked {stored.date}")
        else:
            column.alert = True
            column.label(text=f"{obj.name}: {stored.message}", icon="ERROR")
            if not stored.renders_only:         # else its message says final renders are shadowed
                column.label(text="Renders unshadowed until re-baked")


classes = (SGPRT_PG_bake, SGPRT_OT_bake_visibility, SGPRT_OT_clear_visibility, SGPRT_PT_visibility_bake)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sgprt_bake = PointerProperty(type=SGPRT_PG_bake, name="SG-PRT Bake",
                                                 description="SG-PRT visibility bake settings")


def unregister():
    del bpy.types.Scene.sgprt_bake
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
