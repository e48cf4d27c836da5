"""Transfer bake: precomputed radiance transfer for the SH technique (kautz2002 section 5; numerics in
../visibility/transfer.py), its operators, panel and storage in the .blend.

The same vertices, geometry rules, occluders and safety as the visibility bake (blender/visibility_bake.py:
geometry evaluated as final renders evaluate it, the rows of objects whose modifiers change the topology on a
companion mesh, a cancelled or failed bake leaves the previous ones, the bake thread never touches bpy), stored
through the one per-vertex path (per_vertex_store), kind ``transfer`` (format version 1):

- ``sgprt_transfer_00`` .. : the rows [1, w_0, ..., w_{K-1}] (visibility.decode.pack_coefficients);
- ``mesh["sgprt_transfer"]``: the store's fields and ``order`` N, ``terms`` K, ``relative_error``,
  ``directions``, ``rays_traced``, ``error_target`` (-1: fixed terms), ``date``, ``seconds``, and
  ``mean`` (D) and ``basis`` (K D) as float arrays (double: float32 values round-trip bit-exactly),
  D = visibility.transfer.vector_size(N).

A stale bake (the topology changed) or a damaged one renders without transfer (unshadowed SH), with the
reason in the panel and the render report.
"""
import datetime
from dataclasses import dataclass
from typing import Optional

import bpy
import numpy as np
from bpy.props import EnumProperty, FloatProperty, IntProperty, PointerProperty

from ..visibility import decode, transfer
from ..visibility.per_vertex import MAX_ROWS, MAX_TERMS
from ..visibility.pipeline import BakeCancelled
from . import per_vertex_store
from .background_job import BackgroundJob, SceneJobOperator
from .panels import RenderPanel
from .visibility_bake import (
    TARGETS,
    TERM_MODES,
    active_mesh_record,
    bake_inputs,
    clear_bakes,
    draw_bake_controls,
    float_array,
    mesh_objects,
    store_results,
)

FORMAT_VERSION = 1
KIND = "transfer"
PROPERTY = per_vertex_store.property_name(KIND)

# Tests (and scripts) may set this to a callable(fraction, message) -> bool: True cancels the bake.
progress_hook = None


@dataclass
class StoredTransfer:
    """A transfer bake read back from a mesh.  Arrays are None unless ``usable`` (and read_arrays)."""
    status: str
    message: str
    order: int = 0
    terms: int = 0
    layers: int = 0
    relative_error: float = 0.0
    vertex_count: int = 0
    date: str = ""
    packed_coefficients: Optional[np.ndarray] = None   # (V, 4 L) rows [1, w_0, ...]
    mean: Optional[np.ndarray] = None                  # (D,) float32
    basis: Optional[np.ndarray] = None                 # (K, D) float32
    occluders: Optional[dict] = None                   # what it traced (blender/occluders.py fingerprints)
    domain: str = "POINT"                              # rows per vertex, or per corner (CORNER)

    @property
    def usable(self):
        return self.status == "VALID"

    def basis_texture(self):
        """(L, 1, D, 4) float32: visibility.transfer.basis_texture(mean, basis)."""
        return transfer.basis_texture(self.mean, self.basis)


def has_transfer_bake(mesh):
    return per_vertex_store.has_record(mesh, KIND)


def clear_transfer_bake(mesh):
    return per_vertex_store.clear_record(mesh, KIND)


def store_transfer_bake(mesh, result, options, occluder_fingerprints=None, corner_point=None, evaluation=None):
    """Write a finished visibility.transfer.TransferResult to a mesh datablock, replacing any previous one
    (occluder_fingerprints, corner_point, evaluation: see visibility_bake.store_visibility_bake)."""
    packed = per_vertex_store.rows_for_mesh(mesh, decode.pack_coefficients(result.coefficients), corner_point,
                                            "transfer")
    per_vertex_store.store_record(mesh, KIND, packed, FORMAT_VERSION, {
        "order": int(result.order), "terms": int(result.terms), "relative_error": float(result.relative_error),
        "directions": int(options.directions), "rays_traced": int(result.rays_traced),
        "error_target": float(options.error_target) if options.terms is None else -1.0,
        "date": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "seconds": float(result.seconds),
        "mean": np.asarray(result.mean, np.float32).astype(np.float64).tolist(),
        "basis": np.asarray(result.basis, np.float32).ravel().astype(np.float64).tolist(),
    }, occluder_fingerprints, per_vertex_store.domain_of(corner_point), evaluation)


def _check_layers(group, layers):
    if layers != -(-(int(group["terms"]) + 1) // 4):
        return "transfer metadata inconsistent (terms vs layers): re-bake"
    if not 2 <= int(group["order"]) <= transfer.MAX_ORDER:
        return f"transfer order {int(group['order'])} unsupported: re-bake"
    return None


def load_transfer_bake(mesh, evaluated_mesh=None, read_arrays=True, obj=None):
    """The transfer bake stored on a mesh datablock, or None without one (see load_visibility_bake)."""
    try:
        record = per_vertex_store.load_record(mesh, KIND, FORMAT_VERSION, evaluated_mesh, read_arrays,
                                              check_layers=_check_layers, obj=obj)
    except (KeyError, TypeError, ValueError) as error:
        return StoredTransfer("INVALID", f"transfer metadata damaged ({error}): re-bake")
    if record is None:
        return None
    group = record.metadata
    try:
        stored = StoredTransfer(record.status, record.message, order=int(group["order"]), terms=int(group["terms"]),
                                layers=record.layers, relative_error=float(group["relative_error"]),
                                vertex_count=record.vertex_count, date=str(group.get("date", "")),
                                occluders=record.occluders, domain=record.domain)
    except (KeyError, TypeError, ValueError) as error:
        return StoredTransfer("INVALID", f"transfer metadata damaged ({error}): re-bake")
    if not stored.usable:
        return stored
    stored.message = (f"order {stored.order}, {stored.terms} terms, error {stored.relative_error:.3f}, "
                      f"{stored.vertex_count} vertices{' with its modifiers' if record.evaluated else ''}, "
                      f"baked {stored.date}")
    if not read_arrays:
        return stored
    size = transfer.vector_size(stored.order)
    mean = float_array(group["mean"])
    basis = float_array(group["basis"]) if stored.terms else np.zeros(0)
    if mean.size != size or basis.size != stored.terms * size:
        stored.status, stored.message = "INVALID", "stored transfer basis has the wrong size: re-bake"
        return stored
    stored.mean = mean.astype(np.float32)
    stored.basis = basis.astype(np.float32).reshape(stored.terms, size)
    stored.packed_coefficients = record.rows
    return stored


def transfer_for_object(object_eval, read_arrays=True):
    """The engine's entry: the transfer bake of an evaluated object's mesh, checked against what it draws."""
    if object_eval.type != "MESH":
        return None
    return per_vertex_store.record_for_object(object_eval, KIND, lambda mesh, obj: load_transfer_bake(
        mesh, evaluated_mesh=object_eval.data, read_arrays=read_arrays, obj=obj))


# --------------------------------------------------------------------------- the job (no bpy)

class TransferJob(BackgroundJob):
    """Bakes the transfer of receivers one after another (see visibility_bake.BakeJob)."""

    verb = "transfer bake"
    thread_name = "sgprt-transfer-bake"

    def __init__(self, receivers, occluder_vertices, occluder_triangles, options, verbose=False, hook=None):
        super().__init__(verbose, hook)
        self.receivers = receivers
        self.occluder_vertices, self.occluder_triangles = occluder_vertices, occluder_triangles
        self.options = options
        self.results = {}

    def run(self):
        results = {}
        count = len(self.receivers)
        try:
            for index, receiver in enumerate(self.receivers):
                def progress(fraction, message, index=index, label=receiver.label):
                    overall = (index + min(max(fraction, 0.0), 1.0)) / count
                    return self.record_progress(overall, f"{label}: {message}", always_print=fraction >= 1.0)

                results[receiver.key] = transfer.bake_transfer(
                    receiver.points, receiver.triangles, receiver.normals, self.occluder_vertices,
                    self.occluder_triangles, self.options, progress, point_triangles=receiver.point_triangles)
                if self.cancelling:
                    raise BakeCancelled("cancelled after a receiver finished")
        except BakeCancelled:
            self.cancelled = True
            if self.verbose:
                print("[sg-prt] transfer bake cancelled: nothing written", flush=True)
            return
        except Exception as error:       # reported by the operator, nothing written
            self.error = error
            if self.verbose:
                print(f"[sg-prt] transfer bake failed: {error}", flush=True)
            return
        self.results = results


# --------------------------------------------------------------------------- settings, operators, panel

OPTION_NAMES = ("target", "order", "directions", "term_mode", "error_target", "terms", "max_terms")


def _option_properties():
    return dict(
        target=EnumProperty(name="Target", items=TARGETS, default="SELECTED",
                            description="Which mesh objects receive a transfer bake (all visible objects cast "
                                        "shadows)"),
        order=IntProperty(name="Order", default=5, min=2, max=transfer.MAX_ORDER,
                          description="SH order of the transfer (materials of a higher order shade at this one)"),
        directions=IntProperty(name="Directions", default=1024, min=64, max=16384,
                               description="Sphere directions a vertex (about half are traced)"),
        term_mode=EnumProperty(name="Terms", items=TERM_MODES, default="ERROR_TARGET",
                               description="How many PCA terms to keep"),
        error_target=FloatProperty(name="Error Target", default=0.02, min=0.001, max=0.5,
                                   description="Relative RMS error of the compressed transfer"),
        terms=IntProperty(name="Fixed Terms", default=16, min=0, max=MAX_TERMS,
                          description="PCA terms when the number is fixed"),
        max_terms=IntProperty(name="Max Terms", default=MAX_TERMS, min=1, max=MAX_TERMS,
                              description=f"Most PCA terms ({MAX_TERMS} + the mean fill {MAX_ROWS} vec4 a vertex)"),
    )


SGPRT_PG_transfer_bake = type("SGPRT_PG_transfer_bake", (bpy.types.PropertyGroup,),
                              {"__annotations__": _option_properties(),
                               "__doc__": "Scene settings of the transfer bake: scene.sgprt_transfer"})


def _transfer_options(settings):
    fixed = settings.term_mode == "FIXED"
    return transfer.TransferOptions(order=settings.order, directions=settings.directions,
                                    terms=min(settings.terms, settings.max_terms) if fixed else None,
                                    error_target=settings.error_target, max_terms=settings.max_terms)


class SGPRT_OT_bake_transfer(SceneJobOperator, bpy.types.Operator):
    """Bake precomputed radiance transfer (shadows of distant SH lighting) at the vertices of mesh objects, for the SH technique"""
    bl_idname = "sgprt.bake_transfer"
    bl_label = "Bake Transfer"
    bl_options = {"REGISTER", "UNDO"}
    __annotations__ = _option_properties()

    job_label = "SG-PRT transfer bake"
    _running = False

    @classmethod
    def poll(cls, context):
        return not SGPRT_OT_bake_transfer._running and context.scene is not None

    def _prepare(self, context):
        settings = getattr(context.scene, "sgprt_transfer", None)
        for name in OPTION_NAMES:
            if settings is not None and not self.properties.is_property_set(name):
                setattr(self, name, getattr(settings, name))
        inputs = bake_inputs(self, context, mesh_objects(context, self.target), "transfer bake")
        if inputs is None:
            return None
        receivers, occluder_vertices, occluder_triangles, self._targets, self._occluders = inputs
        return TransferJob(receivers, occluder_vertices, occluder_triangles, _transfer_options(self),
                           hook=progress_hook)

    def _finish(self, context, job):
        def store(mesh, result, corner_point, evaluation):
            store_transfer_bake(mesh, result, job.options, self._occluders, corner_point, evaluation)
            buried = f", {result.buried_points} buried points from their neighbours" if result.buried_points else ""
            return (f"order {result.order}, {result.terms} terms, error {result.relative_error:.3f}, "
                    f"{result.seconds:.1f} s{buried}")

        return store_results(self, job, self._targets, KIND, store, "transfer bake",
                             "SG-PRT baked the transfer of")


class SGPRT_OT_clear_transfer(bpy.types.Operator):
    """Remove the stored transfer bake of the selected mesh objects"""
    bl_idname = "sgprt.clear_transfer"
    bl_label = "Clear Transfer Bake"
    bl_options = {"REGISTER", "UNDO"}

    target: EnumProperty(name="Target", items=TARGETS, default="SELECTED")

    def execute(self, context):
        return clear_bakes(self, context, KIND, "transfer bake(s)")


class SGPRT_PT_transfer_bake(RenderPanel, bpy.types.Panel):
    bl_label = "SG-PRT Transfer Bake (SH)"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        draw_bake_controls(layout, context.scene.sgprt_transfer, ("target", "order", "directions"),
                           SGPRT_OT_bake_transfer.bl_idname, SGPRT_OT_clear_transfer.bl_idname)
        obj, stored = active_mesh_record(layout, context, transfer_for_object, "the transfer")
        if obj is None:
            return
        column = layout.column(align=True)
        if stored is None:
            column.label(text=f"{obj.name}: no transfer (SH renders unshadowed)", icon="INFO")
        elif stored.usable:
            column.label(text=f"{obj.name}: {stored.message}", icon="CHECKMARK")
        else:
            column.alert = True
            column.label(text=f"{obj.name}: {stored.message}", icon="ERROR")


classes = (SGPRT_PG_transfer_bake, SGPRT_OT_bake_transfer, SGPRT_OT_clear_transfer, SGPRT_PT_transfer_bake)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sgprt_transfer = PointerProperty(type=SGPRT_PG_transfer_bake, name="SG-PRT Transfer Bake",
                                                     description="SG-PRT transfer bake settings")


def unregister():
    del bpy.types.Scene.sgprt_transfer
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
