"""What per-vertex bakes trace and what they remember of it: every object with geometry a render shows, as one
world-space triangle soup (the occluders), and a fingerprint of each, stored with a bake so that a render can
name the objects that moved or changed since (SceneState.outdated_bake_warnings).

A fingerprint is (placement, vertex count, shape): a digest of the world matrices of the object's instances,
the evaluated vertex count, and a digest of its evaluated local vertex positions.  A bake traces the scene as a
final render evaluates it, and so does a final render's check; the viewport evaluates modifiers at their
viewport levels, so there an object whose modifiers differ between the two (modifier_stack.viewport_differences)
is compared by shape only where the vertex counts agree: its higher render level is no change.
"""
import hashlib
from dataclasses import dataclass

import numpy as np

from ..visibility import raytrace
from . import export
from .per_vertex_store import mesh_triangles

GEOMETRY_TYPES = ("MESH", "CURVE", "SURFACE", "META", "FONT")


@dataclass
class OccluderObject:
    """One evaluated geometry of an object: local vertices (P, 3), triangles (T, 3), its instances' world matrices.
    An object may have several: its own mesh and the geometry it instances (Geometry Nodes' Instance on Points)."""
    vertices: np.ndarray
    triangles: np.ndarray
    matrices: list


def scene_geometry(depsgraph):
    """{(object name, geometry key): OccluderObject} of every object with geometry a render shows (visible and not
    disabled in renders: export.render_roles), its instances included: each geometry an object draws is keyed
    apart (an object's own, often empty, mesh and what its Geometry Nodes instance share its name)."""
    objects = {}
    hidden = export.render_roles(depsgraph.view_layer).hidden
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type not in GEOMETRY_TYPES or obj.name in hidden:
            continue
        key = (obj.name, obj.data.as_pointer() if obj.data is not None else 0)
        if key not in objects:
            mesh = obj.to_mesh()
            try:
                count = len(mesh.vertices)
                local = np.empty(count * 3, np.float32)
                mesh.vertices.foreach_get("co", local)
                objects[key] = OccluderObject(local.reshape(-1, 3), mesh_triangles(mesh), [])
            finally:
                obj.to_mesh_clear()
        objects[key].matrices.append(np.array([list(row) for row in instance.matrix_world], np.float64))
    return objects


def _in_world(occluder, matrix):
    """(P, 3) float64: an occluder's local vertices placed by one instance's world matrix."""
    return occluder.vertices.astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]


def occluder_arrays(depsgraph, geometry=None):
    """(vertices (P, 3) float32, triangles (T, 3) int32) of scene_geometry, world space."""
    geometry = scene_geometry(depsgraph) if geometry is None else geometry
    vertices, triangles, offset = [], [], 0
    for occluder in geometry.values():
        if len(occluder.triangles) == 0:
            continue
        for matrix in occluder.matrices:
            vertices.append(_in_world(occluder, matrix))
            triangles.append(occluder.triangles + offset)
            offset += len(occluder.vertices)
    if not vertices:
        return np.zeros((0, 3), np.float32), np.zeros((0, 3), np.int32)
    return (np.ascontiguousarray(np.concatenate(vertices), np.float32),
            np.ascontiguousarray(np.concatenate(triangles), np.int32))


def untraceable(geometry):
    """{object name: vertices (summed over its instances) that are NaN, Inf or beyond raytrace.COORDINATE_LIMIT in
    world space} of scene_geometry's objects that have any: their triangles there cast no shadow."""
    counts = {}
    for (name, _), occluder in geometry.items():
        bad = sum(int(np.count_nonzero(~raytrace.traceable(_in_world(occluder, matrix))))
                  for matrix in occluder.matrices)
        if bad:
            counts[name] = counts.get(name, 0) + bad
    return counts


def _digest(data):
    return hashlib.blake2b(data, digest_size=8).hexdigest()


def fingerprints(geometry):
    """{object name: [placement digest, vertex count, shape digest]} of scene_geometry (JSON-ready), an object's
    geometries together: the digest of all their instances' matrices, their vertices summed, the digest of their
    shapes' digests (an object of one geometry: the digest of its vertices)."""
    parts = {}
    for (name, _), occluder in geometry.items():
        parts.setdefault(name, []).append(occluder)
    prints = {}
    for name, occluders in parts.items():
        placement = _digest(b"".join(sorted(np.asarray(m, np.float32).tobytes()
                                            for occluder in occluders for m in occluder.matrices)))
        shapes = [_digest(np.ascontiguousarray(occluder.vertices).tobytes()) for occluder in occluders]
        shape = shapes[0] if len(shapes) == 1 else _digest("".join(sorted(shapes)).encode())
        prints[name] = [placement, int(sum(len(occluder.vertices) for occluder in occluders)), shape]
    return prints


def changed_since(baked, current, counts_may_differ=()):
    """Sentences naming the objects whose fingerprints differ between a bake's (`baked`) and the scene's now
    (`current`): moved, changed shape (its vertices moved, or their count changed), added, or gone; [] when the
    scene is as it was baked.  counts_may_differ: names whose vertex count is evaluated otherwise now than at
    the bake (the viewport's levels): a count change alone is no change for them."""
    moved, reshaped, added, gone = [], [], [], []
    for name in sorted(set(baked) | set(current)):
        then, now = baked.get(name), current.get(name)
        if then is None:
            added.append(name)
        elif now is None:
            gone.append(name)
        elif then[0] != now[0]:
            moved.append(name)
        elif then[1] != now[1] and name not in counts_may_differ or then[1] == now[1] and then[2] != now[2]:
            reshaped.append(name)

    def names(items):
        return ", ".join(f"'{name}'" for name in items[:4]) + (f" and {len(items) - 4} more" if len(items) > 4 else "")
    return [f"{names(items)} {verb}" for items, verb in
            ((moved, "moved"), (reshaped, "changed shape"), (added, "appeared"), (gone, "went"))
            if items]
