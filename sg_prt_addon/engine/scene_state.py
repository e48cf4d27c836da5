"""CPU side of the engine: what the scene looks like as numpy data, and what changed.

No `gpu` here, so the update logic runs (and is tested) in background mode.
`SceneState.sync(depsgraph)` builds everything; `SceneState.update(depsgraph)`
applies `depsgraph.updates`: a geometry update re-exports that object's mesh,
a transform update only replaces its matrix, a material edit only re-reads the
material, lights and world are re-read when they changed.  `dirty` tells the
GPU side (renderer.py) what to re-upload.
"""
import dataclasses
import hashlib
from dataclasses import dataclass, field

import numpy as np

from .. import techniques
from ..blender import export
from ..lighting import light_clusters, shadow_maps
from ..lighting import lights as core_lights
from ..lighting.scene_lighting import EnvironmentData, LightData
from ..techniques.shader_sources import MAX_POINT_LIGHTS, MAX_SUNS
from ..visibility import decode, per_vertex
from . import disk_cache

# Prefiltered environments and SG fits by pixel content (prefiltering takes seconds); the most
# recently used few only, since an artist editing the world makes a new one each edit.
_environment_cache = {}
ENVIRONMENT_CACHE_SIZE = 4
ENVIRONMENT_LAYER_SIZE = 128
ENVIRONMENT_FIT_LOBES = 8
# Visible object types the engine has no shading for: named in the render's warnings, not silently dropped.
UNRENDERED_GEOMETRY = {"CURVES": "Curves hair", "POINTCLOUD": "a point cloud", "VOLUME": "a volume",
                       "GPENCIL": "Grease Pencil", "GREASEPENCIL": "Grease Pencil"}

# Tests (and scripts) may set this to a callable(object_eval) -> bake or None, standing in for the
# stored bakes: see visibility_for.
visibility_provider = None


def visibility_for(object_eval):
    """The visibility bake of an evaluated object: blender.visibility_bake.visibility_for_object
    (a StoredBake, or None without one), or what ``visibility_provider`` returns when set (a
    StoredBake, a visibility.pipeline.BakeResult or None).  Whatever comes back goes through ssdf_data,
    which refuses unusable (stale, damaged) bakes and any whose vertex count does not match the
    exported mesh."""
    if visibility_provider is not None:
        return visibility_provider(object_eval)
    try:
        from ..blender import visibility_bake
    except ImportError:
        return None
    return visibility_bake.visibility_for_object(object_eval)


def ssdf_data(bake, mesh):
    """(visibility.per_vertex.PerVertexData of kind "ssdf", or None, message) of a visibility bake (a StoredBake or
    a visibility.pipeline.BakeResult) and the export.MeshExport it should shade."""
    if bake is None:
        return None, "no visibility bake"
    if getattr(bake, "usable", True) is False:
        return None, getattr(bake, "message", "unusable bake")
    packed = getattr(bake, "packed_coefficients", None)
    if packed is None:
        packed = decode.pack_coefficients(bake.coefficients)
    if hasattr(bake, "basis_texture") and callable(bake.basis_texture):
        basis_texture = bake.basis_texture()
    else:
        basis_texture = decode.pack_basis_texture(bake.mean, bake.basis)
    layers = np.shape(packed)[1] // 4 if np.ndim(packed) == 2 else 0
    return per_vertex.check(SSDF, packed, basis_texture, getattr(bake, "terms", 4 * layers - 1),
                            mesh.vertex_count, mesh.corner_vertex, getattr(bake, "domain", "POINT"))


def transfer_for(object_eval):
    """The stored transfer bake (blender.transfer_bake.StoredTransfer) of an evaluated object, or None."""
    try:
        from ..blender import transfer_bake
    except ImportError:
        return None
    return transfer_bake.transfer_for_object(object_eval)


def transfer_data(stored, mesh):
    """(PerVertexData of kind "transfer", or None, message) of a stored transfer bake and the mesh it shades."""
    if stored is None:
        return None, "no transfer bake"
    if not stored.usable:
        return None, stored.message
    return per_vertex.check(TRANSFER, stored.packed_coefficients, stored.basis_texture(), stored.terms,
                            mesh.vertex_count, mesh.corner_vertex, stored.domain)


# Per-vertex kinds the scene state looks up for each mesh: kind -> (source(object_eval), to data(record, mesh))
SSDF = "ssdf"
TRANSFER = "transfer"
PER_VERTEX_KINDS = {SSDF: (visibility_for, ssdf_data), TRANSFER: (transfer_for, transfer_data)}
BAKE_NAMES = {SSDF: "visibility bake", TRANSFER: "transfer bake"}
BAKE_BUTTONS = {SSDF: "Bake Visibility", TRANSFER: "Bake Transfer"}      # in Render Properties


@dataclass
class ObjectEntry:
    name: str
    mesh_key: str                   # name of the mesh datablock (objects sharing a mesh share the export)
    matrix_world: np.ndarray
    material_names: list            # material name (or "") per slot
    holdout: bool = False           # a holdout: occludes, shades nothing, alpha 0 (export.render_roles)
    casts_shadow: bool = True       # Object > Visibility > Ray Visibility > Shadow: drawn into the shadow maps


@dataclass
class Dirty:
    meshes: set = field(default_factory=set)        # mesh keys to (re-)upload
    materials: set = field(default_factory=set)     # material names to rebuild
    images: set = field(default_factory=set)        # image names whose pixels changed
    lights: bool = False
    world: bool = False
    objects: bool = False                          # object list or matrices changed

    def any(self):
        return bool(self.meshes or self.materials or self.images or self.lights or self.world or self.objects)


class SceneState:
    def __init__(self, environment_layer_size=None):
        self.environment_layer_size = environment_layer_size or ENVIRONMENT_LAYER_SIZE
        self.objects = {}           # object name -> ObjectEntry
        self.meshes = {}            # mesh key -> export.MeshExport
        self.per_vertex = {}        # mesh key -> {kind: visibility.per_vertex.PerVertexData} (usable ones only)
        self.per_vertex_status = {}  # mesh key -> {kind: why there is (or is no) data of that kind}
        self.bake_occluders = {}    # mesh key -> {kind: the fingerprints of what its usable bake traced}
        self.materials = {}         # material name ("" = default) -> export.MaterialParams
        self.lights = []            # export.LightExport
        self.area_patches = core_lights.AREA_PATCHES_PER_SIDE   # scene.sgprt.area_light_patches
        self._light_budget = None   # (its key, LightBudget): light_budget()
        self.shadow_map_size = shadow_maps.DEFAULT_SIZE     # the lights' shadow maps' tile side (0: SSDF shadows)
        self.world = export.WorldExport()
        self.environment = EnvironmentData()
        self.dirty = Dirty()
        # bad input met while exporting (NaN texels, degenerate normals...): said once a render/redraw
        self.warnings = []
        self._edited_meshes = None  # names of the meshes the update being applied edited (update())
        self._exported_in_update = set()    # mesh keys exported by the update being applied (update())
        self._roles = export.RenderRoles(set(), set(), set())  # the view layer's, as of the last update()

    # ----------------------------------------------------------------- full sync

    def sync(self, depsgraph):
        """Re-read everything visible in the evaluated scene."""
        # export warnings of this sync and of the upload that follows it (export.collect_warnings)
        self.warnings = export.collect_warnings([])
        self.objects.clear()
        self.meshes.clear()
        self.per_vertex.clear()
        self.per_vertex_status.clear()
        self.bake_occluders.clear()
        self.materials = {"": export.default_surface()}
        self.lights = []
        self.area_patches = _area_patches(depsgraph.scene)
        self.shadow_map_size = _shadow_map_size(depsgraph.scene)
        seen_meshes = set()
        unrendered = set()          # objects named once in the warnings
        roles = export.render_roles(depsgraph.view_layer)
        for instance in depsgraph.object_instances:
            obj = instance.object
            if obj.type == "LIGHT":
                light = export.export_light(obj, instance.matrix_world)
                if light is not None:
                    self.lights.append(light)
                continue
            if obj.type not in ("MESH", "CURVE", "SURFACE", "META", "FONT"):
                if obj.type in UNRENDERED_GEOMETRY and obj.name not in unrendered:
                    unrendered.add(obj.name)
                    export.warn(f"object '{obj.name}': {UNRENDERED_GEOMETRY[obj.type]} is not rendered by SG-PRT "
                                "(left out)")
                continue        # object_instances already lists only what is visible
            if obj.type == "MESH" and obj.name not in unrendered and any(
                    system.settings.type == "HAIR" and system.settings.render_type == "PATH"
                    for system in obj.particle_systems):
                unrendered.add(obj.name)
                export.warn(f"object '{obj.name}': particle hair is not rendered by SG-PRT (its mesh is)")
            if obj.original.name in roles.indirect:
                continue        # not seen by the camera
            name = obj.name if not instance.is_instance else f"{obj.name}#{len(self.objects)}"
            mesh_key = self._mesh_key(obj)
            if mesh_key not in seen_meshes:
                self._export_mesh(obj, mesh_key)
                seen_meshes.add(mesh_key)
            self.objects[name] = ObjectEntry(name, mesh_key, export.matrix_to_numpy(instance.matrix_world),
                                             self._read_materials(obj), obj.original.name in roles.holdout,
                                             _casts_shadow(obj))
        self.world = export.export_world(depsgraph.scene.world)
        self.environment = environment_data(self.world, self.environment_layer_size)
        self._warn_outdated_bakes(depsgraph)
        self.mark_all_dirty()

    def _warn_outdated_bakes(self, depsgraph):
        """A warning for each object whose usable bake traced the scene as it no longer is: what moved, changed
        shape, appeared or went since (blender/occluders.py).  Its shadows are still drawn, as they were baked."""
        if not any(self.bake_occluders.values()):
            return
        from ..blender import modifier_stack, occluders

        geometry = occluders.scene_geometry(depsgraph)
        current = occluders.fingerprints(geometry)
        # a final render evaluates as the bake did; the viewport at its own modifier levels
        counts_may_differ = set() if depsgraph.mode == "RENDER" else {
            name for name, _ in geometry if name in depsgraph.scene.objects
            and modifier_stack.viewport_differences(depsgraph.scene.objects[name])}
        named = set()
        for entry in self.objects.values():
            for kind, baked in self.bake_occluders.get(entry.mesh_key, {}).items():
                changes = occluders.changed_since(baked, current, counts_may_differ)
                if changes and (entry.mesh_key, kind) not in named:
                    named.add((entry.mesh_key, kind))
                    export.warn(f"object '{entry.name.split('#')[0]}': its {BAKE_NAMES[kind]} was made before "
                                f"{'; '.join(changes)}: its shadows are as they were then (re-bake)")

    def _export_mesh(self, obj, mesh_key):
        """Export an evaluated object's mesh and look up its per-vertex data of every kind."""
        mesh = export.export_object_mesh(obj)
        self.meshes[mesh_key] = mesh
        found, status, traced = {}, {}, {}
        for kind, (source, to_data) in PER_VERTEX_KINDS.items():
            try:
                record = source(obj)
            except Exception as error:          # a damaged bake must not stop the render: unshadowed
                record, data, message = None, None, f"bake unreadable: {error}"
            else:
                data, message = to_data(record, mesh)
            if data is not None:
                found[kind] = data
                if getattr(record, "occluders", None):
                    traced[kind] = record.occluders
            status[kind] = message
        if SSDF in found and any(data.domain != found[SSDF].domain for data in found.values()):
            # the corners read every kind's rows by one index (engine/renderer.py): the visibility bake's wins
            def unit(data):
                return "corner" if data.domain == "CORNER" else "vertex"
            for kind in [kind for kind, data in found.items() if data.domain != found[SSDF].domain]:
                status[kind] = (f"made per {unit(found[kind])}, the visibility bake per {unit(found[SSDF])} "
                                f"(one of them older): re-bake it")
                del found[kind]
                traced.pop(kind, None)
        if SSDF in found and found[SSDF].domain == "POINT" and per_vertex.has_split_normals(
                mesh.normals, mesh.vertex_normals, mesh.corner_vertex):
            export.warn(f"object '{obj.name}': its visibility bake is per vertex, made before flat faces and sharp "
                        "edges were baked per corner: re-bake for their shadows")
        self.per_vertex[mesh_key] = found
        self.per_vertex_status[mesh_key] = status
        self.bake_occluders[mesh_key] = traced
        return mesh

    @property
    def visibility(self):
        """mesh key -> the usable SSDF bake (PerVertexData of kind "ssdf") of the meshes that have one."""
        return {key: kinds[SSDF] for key, kinds in self.per_vertex.items() if SSDF in kinds}

    @property
    def visibility_status(self):
        """mesh key -> why its mesh has (or has no) usable SSDF bake."""
        return {key: kinds.get(SSDF, "no visibility bake") for key, kinds in self.per_vertex_status.items()}

    def unshadowed_warnings(self):
        """The render report's lines for objects that render unshadowed: one per object whose bake cannot
        shade it (stale, unusable...) naming it and why, or whose materials' technique reads a kind of bake
        (Technique.shadow_kind) it lacks while it has another; the objects with no bake at all in one line,
        when the scene has bakes (a scene never baked renders unshadowed by design)."""
        lines, unbaked, seen = [], [], set()
        # both read once: each property builds a dict over every mesh (a read per object: quadratic)
        visibility, visibility_status = self.visibility, self.visibility_status
        for entry in self.objects.values():
            if entry.mesh_key in seen:
                continue
            seen.add(entry.mesh_key)
            kinds = self._shadow_kinds(entry)
            found = self.per_vertex.get(entry.mesh_key, {})
            missing = [kind for kind in kinds if kind not in found and found
                       and self.per_vertex_status.get(entry.mesh_key, {}).get(kind) == f"no {BAKE_NAMES[kind]}"]
            for kind in missing:        # baked, but not what this material's technique reads
                others = " and ".join(BAKE_NAMES[other] for other in found)
                lines.append(f"object '{entry.name}' renders unshadowed: material '{kinds[kind] or '(none)'}' is "
                             f"shadowed by a {BAKE_NAMES[kind]} and the object has a {others} only: press "
                             f"{BAKE_BUTTONS[kind]} in Render Properties")
            if entry.mesh_key in visibility or SSDF not in kinds or SSDF in missing:
                continue
            status = visibility_status.get(entry.mesh_key, "no visibility bake")
            if status == "no visibility bake":
                unbaked.append(entry.name)
            else:
                lines.append(f"object '{entry.name}' renders unshadowed: {status}")
        if unbaked and (visibility or lines):
            names = ", ".join(f"'{name}'" for name in unbaked[:5]) + (" ..." if len(unbaked) > 5 else "")
            lines.append(f"{len(unbaked)} object(s) without a visibility bake render unshadowed: {names}")
        seen = set()
        for entry in self.objects.values():      # a transfer bake that no longer fits: shaded without it
            status = self.per_vertex_status.get(entry.mesh_key, {}).get(TRANSFER, "no transfer bake")
            if entry.mesh_key not in seen and status != "no transfer bake" \
                    and TRANSFER not in self.per_vertex.get(entry.mesh_key, {}):
                lines.append(f"object '{entry.name}' renders without its transfer bake: {status}")
            seen.add(entry.mesh_key)
        return lines

    def _shadow_kinds(self, entry):
        """{per-vertex kind: the first material shadowed by it} of an object's material slots (their techniques'
        shadow_kind)."""
        kinds = {}
        for name in entry.material_names or [""]:
            kind = techniques.for_material(self.materials.get(name) or self.materials[""]).shadow_kind
            if kind:
                kinds.setdefault(kind, name)
        return kinds

    @staticmethod
    def _mesh_key(obj):
        """The key of the export an object draws: linked duplicates of a plain mesh (_is_plain_mesh) draw the
        same evaluated mesh and its bakes (stored on the mesh), so they share one export and one GPU copy
        (":mesh name", no object name can be empty); anything else evaluates per object ("object:mesh")."""
        if _is_plain_mesh(obj):
            return f":{obj.original.data.name_full}"
        data = obj.data
        return f"{obj.name}:{data.name if data is not None else ''}"

    def _read_materials(self, obj):
        names = []
        for slot in obj.material_slots:
            material = slot.material
            key = material.name if material is not None else ""
            if key not in self.materials:      # first seen (a new object or slot): upload it too
                self.materials[key] = export.export_material(material)
                self.dirty.materials.add(key)
            names.append(key)
        return names or [""]

    # ----------------------------------------------------------------- incremental

    def update(self, depsgraph):
        """Apply depsgraph.updates; returns the Dirty set (also kept in self.dirty until consumed)."""
        import bpy

        export.collect_warnings(self.warnings)
        dirty = self.dirty
        membership_changed = False
        # meshes whose own data changed (an edit): Blender 5.3 also flags an object's geometry when only its
        # material changed, so a plain mesh object re-exports only when its mesh is among these
        self._edited_meshes = {update.id.name for update in depsgraph.updates
                               if isinstance(update.id, bpy.types.Mesh) and update.is_updated_geometry}
        self._exported_in_update = set()    # a shared mesh edited is exported once, not once per object
        self._roles = export.render_roles(depsgraph.view_layer)
        changed_sources = set()         # datablocks materials are computed from (export.MaterialParams.reads)
        for update in depsgraph.updates:
            datablock = update.id
            if isinstance(datablock, bpy.types.Material):
                self.materials[datablock.name] = export.export_material(datablock)
                dirty.materials.add(datablock.name)
            elif isinstance(datablock, bpy.types.Image):
                dirty.images.add(datablock.name)
                changed_sources.add(("IMAGE", datablock.name))
                if self.world.image_name == datablock.name and depsgraph.scene.world is not None:
                    self.world = export.export_world(depsgraph.scene.world)
                    self.environment = environment_data(self.world, self.environment_layer_size)
                    dirty.world = True
            elif isinstance(datablock, bpy.types.World):
                self.world = export.export_world(datablock)
                self.environment = environment_data(self.world, self.environment_layer_size)
                dirty.world = True
            elif isinstance(datablock, (bpy.types.Scene, bpy.types.Collection)):
                membership_changed = True       # objects may have been added, removed or hidden
                if (_area_patches(depsgraph.scene), _shadow_map_size(depsgraph.scene)) != (
                        self.area_patches, self.shadow_map_size):
                    self.area_patches = _area_patches(depsgraph.scene)
                    self.shadow_map_size = _shadow_map_size(depsgraph.scene)
                    dirty.lights = True
            elif isinstance(datablock, bpy.types.Object):
                self._update_object(depsgraph, datablock.evaluated_get(depsgraph), update, dirty)
                if update.is_updated_geometry:
                    changed_sources.add(("OBJECT", datablock.name))
            elif isinstance(datablock, bpy.types.Light):
                dirty.lights = True
            elif isinstance(datablock, bpy.types.Mesh) and update.is_updated_geometry:
                changed_sources.add(("MESH", datablock.name))
        if changed_sources:
            self._export_readers(changed_sources, dirty)
        if membership_changed:
            self._sync_membership(depsgraph, dirty)
        if dirty.lights:
            self.lights = [export.export_light(obj) for obj in depsgraph.objects if obj.type == "LIGHT"]
            self.lights = [light for light in self.lights if light is not None]
        return dirty

    def _export_readers(self, sources, dirty):
        """Export again, once each, the materials computed from any of `sources` (export.MaterialParams.reads),
        e.g. after their pixels or their mesh changed (a mesh edit updates both the object and its mesh)."""
        import bpy

        for name in [name for name, params in self.materials.items() if sources.intersection(params.reads)]:
            if name in bpy.data.materials:
                self.materials[name] = export.export_material(bpy.data.materials[name])
                dirty.materials.add(name)

    def _sync_membership(self, depsgraph, dirty):
        """Drop objects no longer in the evaluated scene (or now indirect only), export the ones that appeared,
        and follow the holdout collections."""
        roles = self._roles
        present = {obj.name: obj for obj in depsgraph.objects if obj.original.name not in roles.indirect}
        for name, entry in self.objects.items():
            obj = present.get(name.split("#")[0])
            if obj is not None and entry.holdout != (obj.original.name in roles.holdout):
                entry.holdout = not entry.holdout
                dirty.objects = True
        for name in [name for name in self.objects if name.split("#")[0] not in present]:
            del self.objects[name]
            dirty.objects = True
        for name, obj in present.items():
            if obj.type == "LIGHT":
                if not any(light.name == name for light in self.lights):
                    dirty.lights = True
            elif obj.type in ("MESH", "CURVE", "SURFACE", "META", "FONT") and name not in self.objects:
                mesh_key = self._mesh_key(obj)
                if mesh_key not in self._exported_in_update:
                    self._export_mesh(obj, mesh_key)
                    self._exported_in_update.add(mesh_key)
                    dirty.meshes.add(mesh_key)
                self.objects[name] = ObjectEntry(name, mesh_key, export.matrix_to_numpy(obj.matrix_world),
                                                 self._read_materials(obj), obj.original.name in roles.holdout,
                                                 _casts_shadow(obj))
                dirty.objects = True
        if len([obj for obj in present.values() if obj.type == "LIGHT"]) != len(self.lights):
            dirty.lights = True

    def _update_object(self, depsgraph, obj, update, dirty):
        if obj.type == "LIGHT":
            dirty.lights = True
            return
        if obj.type not in ("MESH", "CURVE", "SURFACE", "META", "FONT"):
            return
        entry = self.objects.get(obj.name)
        if not _visible(obj) or obj.original.name in self._roles.indirect:
            if entry is not None:
                del self.objects[obj.name]
                dirty.objects = True
            return
        mesh_key = self._mesh_key(obj)
        if mesh_key not in self._exported_in_update and (entry is None or mesh_key not in self.meshes or (
                update.is_updated_geometry and _geometry_may_differ(obj, self._edited_meshes))):
            self._export_mesh(obj, mesh_key)
            self._exported_in_update.add(mesh_key)
            dirty.meshes.add(mesh_key)
        self.objects[obj.name] = ObjectEntry(obj.name, mesh_key, export.matrix_to_numpy(obj.matrix_world),
                                             self._read_materials(obj), obj.original.name in self._roles.holdout,
                                             _casts_shadow(obj))
        dirty.objects = True

    def mark_all_dirty(self):
        """Everything to upload, as for a renderer that has nothing yet."""
        self.dirty = Dirty(meshes=set(self.meshes), materials=set(self.materials), lights=True, world=True,
                           objects=True)

    def consume_dirty(self):
        dirty, self.dirty = self.dirty, Dirty()
        return dirty

    @staticmethod
    def texture_pixels(value, slot, decode):
        """What the shader samples for a material's texture (an image name in MaterialParams.textures[slot], or one
        image of its Expression): export.slot_pixels, read from Blender's images when the renderer first uploads
        it; None while an image it reads is gone."""
        return export.slot_pixels(value, slot, decode) if export.images_present(value) else None

    # ----------------------------------------------------------------- shader-side data

    def light_data(self):
        return budget_light_data(self.light_budget(MAX_POINT_LIGHTS, MAX_SUNS))

    def light_budget(self, max_points, max_suns):
        """fit_light_budget of the scene's lights, made again only when the lights (sync and update replace the
        list), their patches or the limits change: a frame asks for it per upload and per draw."""
        key = (self.lights, len(self.lights), self.area_patches, max_points, max_suns)
        cached = self._light_budget
        if cached is None or cached[0][0] is not key[0] or cached[0][1:] != key[1:]:
            cached = self._light_budget = (key, fit_light_budget(self.lights, max_points, max_suns,
                                                                 self.area_patches))
        return cached[1]

    def dropped_lights(self, max_points, max_suns):
        """Names of the lights left out to fit the shader's limits (fit_light_budget's last resort)."""
        return self.light_budget(max_points, max_suns).dropped

    def light_budget_warnings(self, max_points, max_suns):
        """The render report's lines for what fitting the shader's limits changed: fewer area light patches,
        merged point lights, lights left out."""
        budget = self.light_budget(max_points, max_suns)
        limits = f"SG-PRT draws at most {max_points} point, spot and area light patches and {max_suns} suns"
        lines = []
        if budget.area_patches < self.area_patches:
            lines.append(f"area lights cut into {budget.area_patches} x {budget.area_patches} patches instead of "
                         f"{self.area_patches} x {self.area_patches} ({limits})")
        if budget.merged:
            count = sum(len(names) for _, names in budget.merged)
            lines.append(f"{count} point lights drawn as {len(budget.merged)} groups of nearby lights, each one "
                         f"light of their summed power ({limits}): "
                         + ", ".join(group.name for group, _ in budget.merged[:3])
                         + (" ..." if len(budget.merged) > 3 else ""))
        if budget.dropped:
            lines.append(f"{len(budget.dropped)} dimmest light(s) left out ({limits}): "
                         + ", ".join(budget.dropped[:5]) + (" ..." if len(budget.dropped) > 5 else ""))
        return lines


def _visible(obj):
    """Visibility in the view layer (asked of the original: evaluated copies report False)."""
    original = getattr(obj, "original", obj)
    try:
        return original.visible_get()
    except RuntimeError:
        return True


def _casts_shadow(obj):
    """Whether an object casts shadows (its Shadow ray visibility, as Cycles and EEVEE read it)."""
    return bool(getattr(obj, "visible_shadow", True))


def _area_patches(scene):
    """The scene's patches a side of an area light (its SG-PRT render setting)."""
    settings = getattr(scene, "sgprt", None)
    return int(getattr(settings, "area_light_patches", core_lights.AREA_PATCHES_PER_SIDE))


def _shadow_map_size(scene):
    """The tile side of the lights' shadow maps (the scene's Light Shadows settings), 0 for the SSDF's."""
    settings = getattr(scene, "sgprt", None)
    if getattr(settings, "light_shadows", "SHADOW_MAPS") != "SHADOW_MAPS":
        return 0
    return int(getattr(settings, "shadow_map_size", shadow_maps.DEFAULT_SIZE))


def _point_count(light, area_patches):
    """How many of the shader's point lights a light takes: an area light's patches, else one."""
    if light.kind != "AREA":
        return 1
    n_u, n_v = core_lights.area_grid(np.linalg.norm(light.edge_u), np.linalg.norm(light.edge_v), area_patches)
    return n_u * n_v


def _power(light):
    """A light's brightness for the budget: its intensity, an area light's power over 4 pi (a point light's)."""
    scale = 1.0 / (4 * np.pi) if light.kind == "AREA" else 1.0
    return float(np.sum(light.colour_intensity)) * scale


@dataclass
class LightBudget:
    """The scene's lights as the shader takes them (fit_light_budget): `lights` drawn (merged groups as new
    LightExports), area lights cut into `area_patches` a side, and what was given up for the report."""
    lights: list
    area_patches: int
    merged: list = field(default_factory=list)      # [(the LightExport drawn, [names of the lights it stands for])]
    dropped: list = field(default_factory=list)     # names of the lights left out


def fit_light_budget(light_exports, max_points, max_suns, area_patches=core_lights.AREA_PATCHES_PER_SIDE):
    """The LightBudget of max_points point lights (an area light counts its patches) and max_suns suns.  Where the
    lights are more: area lights first get fewer patches (down to one), then nearby omni point lights are merged
    into one light a group (lighting.light_clusters); only where spot and area lights alone pass the limit are the
    dimmest left out, as are the dimmest suns past max_suns."""
    suns = sorted((light for light in light_exports if light.kind == "SUN"), key=_power, reverse=True)
    points = sorted((light for light in light_exports if light.kind in ("POINT", "AREA")), key=_power, reverse=True)
    dropped = [light.name for light in suns[max_suns:]]
    suns = suns[:max_suns]

    def used(lights, patches):
        return sum(_point_count(light, patches) for light in lights)
    patches = area_patches
    while patches > 1 and used(points, patches) > max_points:
        patches -= 1
    if used(points, patches) <= max_points:
        return LightBudget(points + suns, patches, dropped=dropped)
    omni = [light for light in points if light.kind == "POINT" and not light.is_spot]
    fixed = [light for light in points if light.kind == "AREA" or light.is_spot]
    slots = max_points - used(fixed, patches)
    if slots < 1 or not omni:          # the last resort: the dimmest left out
        kept, count = [], 0
        for light in points:
            if count + _point_count(light, patches) <= max_points:
                kept.append(light)
                count += _point_count(light, patches)
            else:
                dropped.append(light.name)
        return LightBudget(kept + suns, patches, dropped=dropped)
    clusters = light_clusters.cluster_point_lights([light.position for light in omni], [light.radius for light in omni],
                                                   [light.colour_intensity for light in omni], slots)
    drawn, merged = list(fixed), []
    for k in range(len(clusters.radius)):
        members = [light for light, label in zip(omni, clusters.labels) if label == k]
        if len(members) == 1:
            drawn.append(members[0])
            continue
        group = export.LightExport(f"{len(members)} lights about '{members[0].name}'", "POINT",
                                   tuple(clusters.position[k]), (0.0, 0.0, -1.0), tuple(clusters.intensity[k]),
                                   radius=float(clusters.radius[k]),
                                   soft_falloff=all(light.soft_falloff for light in members))
        drawn.append(group)
        merged.append((group, [light.name for light in members]))
    return LightBudget(drawn + suns, patches, merged, dropped)


def _point_rows(light, area_patches):
    """(position, radius, intensity, direction, spot size, spot blend, emitter, soft falloff) rows of one
    point-like light: one for a point or spot, a patch each for an area light (a sphere of its patch's size)."""
    if light.kind != "AREA":
        return [(light.position, light.radius, light.colour_intensity, light.direction,
                 light.spot_size if light.is_spot else -1.0, light.spot_blend if light.is_spot else 0.0,
                 (0.0, 0.0, 0.0), light.soft_falloff)]
    patches = core_lights.area_light_patches(light.position, light.edge_u, light.edge_v, light.direction,
                                             light.shape, light.colour_intensity, area_patches, light.spread)
    emitter = (1.0, patches.tan_half_spread, patches.spread_normalization)
    return [(position, radius, intensity, patches.normal, -1.0, 0.0, emitter, False)
            for position, radius, intensity in zip(patches.position, patches.radius, patches.intensity)]


def light_data(light_exports, area_patches=core_lights.AREA_PATCHES_PER_SIDE):
    """LightData (float32) from export.LightExport records, an area light cut into about area_patches^2
    patches, within the shader's limits (fit_light_budget)."""
    return budget_light_data(fit_light_budget(light_exports, MAX_POINT_LIGHTS, MAX_SUNS, area_patches))


def budget_light_data(budget):
    """LightData (float32) of a LightBudget's lights."""
    rows = [row for light in budget.lights if light.kind != "SUN" for row in _point_rows(light, budget.area_patches)]
    suns = [light for light in budget.lights if light.kind == "SUN"]
    data = LightData()
    f = np.float32
    if rows:
        columns = list(zip(*rows))
        (data.point_position, data.point_radius, data.point_intensity, data.spot_direction, data.spot_size,
         data.spot_blend, data.point_emitter) = (np.array(column, f) for column in columns[:7])
        data.point_soft_falloff = np.array(columns[7], bool)
    if suns:
        axis, sharpness, amplitude = core_lights.directional_light_sg(
            -np.array([light.direction for light in suns], np.float64),
            0.5 * np.array([light.angle for light in suns]), np.array([light.colour_intensity for light in suns]))
        data.sun_axis, data.sun_sharpness, data.sun_amplitude = (
            np.asarray(axis, f), np.asarray(sharpness, f), np.asarray(amplitude, f))
        data.sun_radius = 0.5 * np.array([light.angle for light in suns], f)
    return data


def _is_plain_mesh(obj):
    """Whether an (evaluated) object draws its mesh as stored: a mesh object without modifiers or shape keys
    (those, and other object types, evaluate from more than the mesh)."""
    original = obj.original
    return (original.type == "MESH" and not len(original.modifiers) and original.data is not None
            and getattr(original.data, "shape_keys", None) is None)


def _geometry_may_differ(obj, edited_meshes):
    """Whether an object whose update flags its geometry can shade differently: anything but a plain mesh
    object does; a plain mesh only when its mesh itself was edited (edited_meshes; None: not known, so it may)."""
    if edited_meshes is None or not _is_plain_mesh(obj):
        return True
    return obj.original.data.name in edited_meshes


def environment_data(world, layer_size=None):
    """EnvironmentData of an export.WorldExport (cached per image and pixels)."""
    colour = np.asarray(world.colour[:3], np.float32)
    if world.equirect is None:
        return EnvironmentData(colour=colour)
    layer_size = layer_size or ENVIRONMENT_LAYER_SIZE
    image = world.equirect
    # keyed by the pixels themselves: a renamed or reloaded image with the same content hits the cache
    key = (image.shape, str(image.dtype), hashlib.blake2b(np.ascontiguousarray(image).data, digest_size=16).digest(),
           layer_size)
    cached = _environment_cache.pop(key, None)
    if cached is None:
        arrays = disk_cache.load_or_build("environment", key, lambda: _prefilter_and_fit(image, layer_size))
        cached = EnvironmentData(colour=colour, prefiltered=_prefiltered_of(arrays), lobe_axis=arrays["lobe_axis"],
                                 lobe_sharpness=arrays["lobe_sharpness"], lobe_amplitude=arrays["lobe_amplitude"],
                                 radiance=image)
    _environment_cache[key] = cached                 # (re)inserted last: the most recent
    while len(_environment_cache) > ENVIRONMENT_CACHE_SIZE:
        del _environment_cache[next(iter(_environment_cache))]
    return cached


def _prefilter_and_fit(image, layer_size):
    """The environment's prefiltered layers and diffuse SG fit as named arrays (what the disk cache stores)."""
    from ..lighting import env_prefilter
    prefiltered = env_prefilter.prefilter_environment(image, size=layer_size)
    arrays = dataclasses.asdict(prefiltered)
    arrays["lobe_axis"], arrays["lobe_sharpness"], arrays["lobe_amplitude"] = _fit_environment(image)
    return arrays


def _prefiltered_of(arrays):
    from ..lighting import env_prefilter
    fields = {item.name: arrays[item.name] for item in dataclasses.fields(env_prefilter.PrefilteredEnvironment)}
    fields["levels_per_octave"] = float(fields["levels_per_octave"])          # stored as a 0-d array
    return env_prefilter.PrefilteredEnvironment(**fields)


def _fit_environment(image):
    """Diffuse SG mixture of the environment (wang2009 eq. 39): lighting.env_fit when present,
    else a fixed-axis least-squares mixture (_fit_environment_fixed_axes)."""
    try:
        from ..lighting import env_fit
    except ImportError:
        return _fit_environment_fixed_axes(image)
    fit = env_fit.fit_environment_sg(image, lobes=ENVIRONMENT_FIT_LOBES)
    if isinstance(fit, tuple):          # (fit, report)
        fit = fit[0]
    return (np.asarray(fit.axis, np.float32), np.asarray(fit.sharpness, np.float32),
            np.asarray(fit.amplitude, np.float32).reshape(len(fit.sharpness), -1)[:, :3])


def _fit_environment_fixed_axes(image, lobe_count=12, sharpness=3.0, rows=32):
    """SG mixture with Fibonacci-sphere axes and one sharpness; non-negative amplitudes per
    channel by least squares, weighted by texel solid angle, on a downsampled map."""
    from scipy.optimize import nnls

    from ..lighting import equirect

    height, width = image.shape[:2]
    row_index = (np.arange(rows) + 0.5) * height / rows
    col_index = (np.arange(2 * rows) + 0.5) * width / (2 * rows)
    small = image[row_index.astype(int)][:, col_index.astype(int), :3].reshape(-1, 3)
    directions = equirect.texel_directions(rows, 2 * rows).reshape(-1, 3)
    weights = np.sqrt(np.broadcast_to(equirect.texel_solid_angles(rows, 2 * rows), (rows, 2 * rows)).ravel())
    k = np.arange(lobe_count) + 0.5
    z = 1 - 2 * k / lobe_count
    phi = np.pi * (1 + 5 ** 0.5) * k
    axes = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], axis=1)
    basis = np.exp(sharpness * (directions @ axes.T - 1)) * weights[:, None]
    amplitude = np.stack([nnls(basis, small[:, c] * weights)[0] for c in range(3)], axis=1)
    return (axes.astype(np.float32), np.full(lobe_count, sharpness, np.float32), amplitude.astype(np.float32))
