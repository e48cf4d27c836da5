"""Visibility bake operator and its storage: real bpy, real .blend files saved and reopened.

A small Suzanne (507 vertices) floats over a 10 x 10 floor; bakes run at 12 x 12 samples.
"""
import bmesh
import bpy
import numpy as np
import pytest
import recording_layout

from sg_prt_addon.blender import export
from sg_prt_addon.blender import visibility_bake as vb
from sg_prt_addon.visibility import decode, hemisphere_map
from sg_prt_addon.visibility.pipeline import BakeOptions, bake_visibility

SMALL = dict(resolution=12, refinement=3, term_mode="FIXED", terms=6, max_terms=47)


def _scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "SG_PRT"
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=10, y_subdivisions=10, size=4.0)
    floor = bpy.context.active_object
    floor.name = "Floor"
    bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0.0, 0.0, 1.0))
    suzanne = bpy.context.active_object
    suzanne.name = "Suzanne"
    for key, value in SMALL.items():
        setattr(scene.sgprt_bake, key, value)
    return scene, floor, suzanne


def _select(*objects):
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in objects)
    if objects:
        bpy.context.view_layer.objects.active = objects[0]


def _bits(array):
    return np.ascontiguousarray(array, np.float32).view(np.uint32)


def _reopen(path):
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))


@pytest.fixture
def scene(addon):
    yield _scene()
    vb.progress_hook = None


def test_operator_bakes_floor_and_suzanne_and_stores_attributes(scene, capfd, tmp_path):
    _, floor, suzanne = scene
    capfd.readouterr()
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    printed = capfd.readouterr().out
    assert "[sg-prt] bake" in printed and "100%" in printed
    # Suzanne's eyes sink into her head: those points take their rows from their neighbours (visibility.buried),
    # split per corner as her flat faces are
    report = next(line for line in printed.splitlines() if "SG-PRT baked" in line)
    suzanne_report = report[report.index("Suzanne"):]
    assert "buried points from their neighbours" in suzanne_report, report
    assert int(suzanne_report.split(" buried points")[0].rsplit(" ", 1)[1]) >= 20, report

    # the flat floor has one normal a vertex: rows per vertex; flat-shaded Suzanne's corners differ: per corner
    for obj, domain, rows in ((floor, "POINT", len(floor.data.vertices)), (suzanne, "CORNER", len(suzanne.data.loops))):
        mesh = obj.data
        layers = -(-(SMALL["terms"] + 1) // 4)
        names = [a.name for a in mesh.attributes if a.name.startswith(vb.ATTRIBUTE_PREFIX)]
        assert names == [vb.attribute_name(k) for k in range(layers)]
        for name in names:
            attribute = mesh.attributes[name]
            assert attribute.data_type == "FLOAT_COLOR" and attribute.domain == domain and len(attribute.data) == rows
        assert vb.load_visibility_bake(mesh).domain == domain
        meta = mesh[vb.PROPERTY]
        assert meta["vertex_count"] == len(mesh.vertices) and meta["terms"] == SMALL["terms"]
        assert meta["resolution"] == SMALL["resolution"] and meta["format_version"] == vb.FORMAT_VERSION
        assert len(meta["basis"]) == SMALL["terms"] * 12 * 12 and len(meta["mean"]) == 144

    stored = vb.load_visibility_bake(floor.data)
    assert stored.usable, stored.message
    assert stored.packed_coefficients.shape == (len(floor.data.vertices), 8)
    assert np.all(stored.packed_coefficients[:, 0] == 1.0)

    # the floor vertex right under Suzanne: occluded straight up, open towards the low sky beside her
    matrix = np.array(floor.matrix_world)
    positions = np.array([matrix[:3, :3] @ v.co + matrix[:3, 3] for v in floor.data.vertices])
    below = int(np.argmin(np.linalg.norm(positions[:, :2], axis=1)))
    frame = hemisphere_map.local_frame(np.array([0.0, 0.0, 1.0]))
    up = decode.decode(stored.coefficients[below], stored.basis, stored.mean, frame @ [0.0, 0.0, 1.0])
    sky = np.array([1.0, 0.3, 0.25]) / np.linalg.norm([1.0, 0.3, 0.25])
    open_sky = decode.decode(stored.coefficients[below], stored.basis, stored.mean, frame @ sky)
    print("SSDF up", up, "sky", open_sky)
    assert up < -0.1 and open_sky > 0.05, (up, open_sky)
    # a floor corner far from Suzanne sees sky straight up
    corner = int(np.argmax(np.linalg.norm(positions[:, :2], axis=1)))
    assert decode.decode(stored.coefficients[corner], stored.basis, stored.mean, frame @ [0.0, 0.0, 1.0]) > 0.5

    before = {obj.name: vb.load_visibility_bake(obj.data) for obj in (floor, suzanne)}
    _reopen(tmp_path / "baked.blend")
    for name, old in before.items():
        new = vb.load_visibility_bake(bpy.data.objects[name].data)
        assert new.usable, new.message
        for field in ("packed_coefficients", "basis", "mean"):
            assert np.array_equal(_bits(getattr(new, field)), _bits(getattr(old, field))), (name, field)
        assert (new.terms, new.rms_error, new.topology_hash, new.date) == (old.terms, old.rms_error,
                                                                           old.topology_hash, old.date)
        assert np.array_equal(new.frame_reference_axis, hemisphere_map.FRAME_REFERENCE_AXIS)


def test_store_is_bit_exact_against_the_bake_result(scene, tmp_path):
    _, floor, suzanne = scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    vertices, normals, triangles, corner_point, _ = vb.receiver_arrays(suzanne, depsgraph)
    assert corner_point is not None and len(corner_point) == len(suzanne.data.loops)       # flat-shaded
    occluder_vertices, occluder_triangles = vb.occluder_arrays(depsgraph)
    assert len(occluder_triangles) == len(floor.data.loop_triangles) + len(suzanne.data.loop_triangles)
    result = bake_visibility(vertices, triangles, normals, occluder_vertices, occluder_triangles,
                             BakeOptions(resolution=8, refinement=1, terms=None, error_target=0.05, max_terms=9))
    vb.store_visibility_bake(suzanne.data, result, corner_point=corner_point)
    assert vb.load_visibility_bake(suzanne.data).topology_hash == vb.mesh_topology_hash(suzanne.data)
    _reopen(tmp_path / "direct.blend")
    stored = vb.load_visibility_bake(bpy.data.objects["Suzanne"].data)
    assert stored.usable and stored.terms == result.terms
    assert np.array_equal(_bits(stored.coefficients), _bits(result.coefficients[corner_point]))
    assert np.array_equal(_bits(stored.basis), _bits(result.basis))
    assert np.array_equal(_bits(stored.mean), _bits(result.mean))
    assert stored.rms_error == pytest.approx(result.rms_error, rel=1e-12)


def test_objects_disabled_in_renders_cast_no_shadow_in_bakes(scene):
    """Disable in Renders, on an object or on a collection holding it, takes it out of the occluders and of
    an ALL bake's receivers (it cast its shadow into bakes while the render left it out)."""
    _, floor, suzanne = scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    both = len(vb.occluder_arrays(depsgraph)[1])
    suzanne.hide_render = True
    try:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        assert len(vb.occluder_arrays(depsgraph)[1]) == both - len(suzanne.data.loop_triangles)
        assert [obj.name for obj in vb.mesh_objects(bpy.context, "ALL")] == [floor.name]
    finally:
        suzanne.hide_render = False
    hidden = bpy.data.collections.new("hidden_in_renders")
    child = bpy.data.collections.new("inside_it")
    bpy.context.scene.collection.children.link(hidden)
    hidden.children.link(child)
    owners = list(suzanne.users_collection)
    child.objects.link(suzanne)
    hidden.hide_render = True
    try:
        # still linked where it renders
        assert suzanne.name not in export.render_roles(bpy.context.view_layer).hidden
        for owner in owners:
            owner.objects.unlink(suzanne)
        assert suzanne.name in export.render_roles(bpy.context.view_layer).hidden
        depsgraph = bpy.context.evaluated_depsgraph_get()
        assert len(vb.occluder_arrays(depsgraph)[1]) == both - len(suzanne.data.loop_triangles)
    finally:
        for owner in owners:
            if suzanne.name not in owner.objects:
                owner.objects.link(suzanne)
        child.objects.unlink(suzanne)
        bpy.data.collections.remove(child)
        bpy.data.collections.remove(hidden)
    assert suzanne.name not in export.render_roles(bpy.context.view_layer).hidden


def test_cancelled_rebake_keeps_the_previous_bake(scene, tmp_path):
    _, floor, suzanne = scene
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    previous = vb.load_visibility_bake(suzanne.data)
    calls = []

    def cancel_midway(fraction, message):
        calls.append(fraction)
        return fraction > 0.2

    vb.progress_hook = cancel_midway
    # a different setting: had anything been written, the data would differ
    assert bpy.ops.sgprt.bake_visibility(resolution=8, terms=3) == {"CANCELLED"}
    vb.progress_hook = None
    assert calls and max(calls) < 1.0
    _reopen(tmp_path / "cancelled.blend")
    kept = vb.load_visibility_bake(bpy.data.objects["Suzanne"].data)
    assert kept.usable and kept.resolution == 12 and kept.terms == SMALL["terms"]
    for field in ("packed_coefficients", "basis", "mean"):
        assert np.array_equal(_bits(getattr(kept, field)), _bits(getattr(previous, field))), field
    assert kept.date == previous.date
    assert vb.load_visibility_bake(bpy.data.objects["Floor"].data) is None


def test_threaded_job_cancels_and_writes_nothing(scene):
    _, floor, suzanne = scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    receiver = vb.Receiver("Floor", "Floor", *vb.receiver_arrays(floor, depsgraph))
    assert receiver.corner_point is None                # a flat grid: one normal a vertex
    job = vb.BakeJob([receiver], *vb.occluder_arrays(depsgraph), BakeOptions(resolution=8, refinement=1, terms=2),
                     hook=lambda f, m: f > 0.0)
    job.start()
    job.join(30)
    assert not job.running and job.cancelled and job.results == {} and job.error is None
    done = vb.BakeJob([receiver], *vb.occluder_arrays(depsgraph), BakeOptions(resolution=8, refinement=1, terms=2))
    done.start()
    done.join(30)
    assert not done.cancelled and done.results["Floor"].coefficients.shape == (len(receiver.points), 2)
    assert done.fraction == 1.0


def test_topology_edits_make_the_bake_stale(scene, tmp_path, capfd):
    _, floor, suzanne = scene
    _select(floor)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    assert vb.load_visibility_bake(floor.data).usable
    obj_eval = floor.evaluated_get(bpy.context.evaluated_depsgraph_get())
    assert vb.visibility_for_object(obj_eval).usable

    # same vertex count, one face fewer: the topology hash catches it
    bm = bmesh.new()
    bm.from_mesh(floor.data)
    bm.faces.ensure_lookup_table()
    bmesh.ops.delete(bm, geom=[bm.faces[0]], context="FACES_ONLY")
    bm.to_mesh(floor.data)
    bm.free()
    floor.data.update()
    stale = vb.load_visibility_bake(floor.data)
    assert stale.status == "STALE" and "topology" in stale.message
    assert stale.packed_coefficients is None and not stale.usable
    with pytest.raises(ValueError):
        stale.corner_coefficients([0, 1, 2])

    # the next bake (of another object) warns about the stale one
    _select(suzanne)
    capfd.readouterr()
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    warned = capfd.readouterr()
    assert "'Floor' renders unshadowed" in warned.out + warned.err
    assert [name for name, _ in vb.unusable_bakes(bpy.context.scene, bpy.context.evaluated_depsgraph_get())] \
        == ["Floor"]

    # one vertex more
    floor.data.vertices.add(1)
    floor.data.update()
    _reopen(tmp_path / "stale.blend")
    stale = vb.load_visibility_bake(bpy.data.objects["Floor"].data)
    assert stale.status == "STALE" and "vertices" in stale.message and stale.coefficients is None

    # a topology-changing modifier added after the bake: the engine's evaluated mesh is stale
    bpy.ops.wm.read_factory_settings(use_empty=True)
    _, floor, suzanne = _scene()
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    suzanne.modifiers.new("Subdivision", "SUBSURF").levels = 1
    obj_eval = suzanne.evaluated_get(bpy.context.evaluated_depsgraph_get())
    assert vb.visibility_for_object(obj_eval).status == "STALE"
    assert vb.load_visibility_bake(suzanne.data).usable          # the datablock itself is intact

    assert bpy.ops.sgprt.clear_visibility() == {"FINISHED"}
    assert vb.load_visibility_bake(suzanne.data) is None
    assert not any(a.name.startswith(vb.ATTRIBUTE_PREFIX) for a in suzanne.data.attributes)


def test_bad_input_reports_instead_of_raising_tracebacks(scene, capfd):
    _, floor, suzanne = scene
    _select()
    with pytest.raises(RuntimeError, match="no mesh object selected"):
        bpy.ops.sgprt.bake_visibility()
    points = bpy.data.objects.new("Points", bpy.data.meshes.new("Points"))
    points.data.vertices.add(3)
    bpy.context.scene.collection.objects.link(points)
    _select(points)
    capfd.readouterr()
    with pytest.raises(RuntimeError, match="none of the objects can be baked"):
        bpy.ops.sgprt.bake_visibility()
    assert "has no faces" in capfd.readouterr().out + capfd.readouterr().err
    assert vb.load_visibility_bake(points.data) is None
    # a mesh in Edit Mode would lose the attributes when Edit Mode writes the mesh back: refused
    _select(suzanne)
    bpy.ops.object.mode_set(mode="EDIT")
    capfd.readouterr()
    with pytest.raises(RuntimeError, match="none of the objects can be baked"):
        bpy.ops.sgprt.bake_visibility()
    assert "leave it before baking" in "".join(capfd.readouterr())
    bpy.ops.object.mode_set(mode="OBJECT")
    # a faceless object among good ones is skipped, the others are baked
    _select(points, suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    assert vb.load_visibility_bake(suzanne.data).usable and vb.load_visibility_bake(points.data) is None


@pytest.mark.parametrize("bad_value", [float("nan"), float("inf"), 1e30])
def test_a_bad_vertex_refuses_its_object_alone(scene, capfd, bad_value):
    """One NaN, Inf or huge vertex in one object: that object is refused, named; every other object bakes as it
    would without the bad vertex (its good faces still cast shadows)."""
    _, floor, suzanne = scene
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(1.5, 1.5, 0.5))
    broken = bpy.context.active_object
    broken.name = "Broken"
    broken.data.vertices[0].co = (bad_value, 0.0, 0.0)
    _select(floor, suzanne, broken)
    capfd.readouterr()
    assert bpy.ops.sgprt.bake_visibility(target="SELECTED") == {"FINISHED"}
    printed = "".join(capfd.readouterr())
    assert "skips 'Broken': 1 of its vertices are NaN, Inf or beyond 1e+10 m" in printed, printed
    assert "'Broken' has 1 vertices that are NaN, Inf or beyond 1e+10 m: its faces there cast no shadow" in printed
    assert vb.load_visibility_bake(broken.data) is None
    with_bad = {obj.name: vb.load_visibility_bake(obj.data) for obj in (floor, suzanne)}
    assert all(bake.usable and bake.terms == SMALL["terms"] for bake in with_bad.values())
    # the cube's five good faces (of six) still occlude: the floor under it is darker than without the cube
    broken.data.vertices[0].co = (0.25, 0.25, 0.25)
    bpy.data.objects.remove(broken)
    _select(floor)
    assert bpy.ops.sgprt.bake_visibility(target="SELECTED") == {"FINISHED"}
    without = vb.load_visibility_bake(floor.data)
    below = np.linalg.norm(np.array([v.co for v in floor.data.vertices])[:, :2] - 1.5, axis=1) < 0.3
    assert below.any()

    def mean_ssdf(bake):        # the SSDF (radians to the nearest boundary, negative where occluded) under the cube
        return (bake.coefficients[below] @ bake.basis.reshape(bake.terms, -1) + bake.mean.ravel()).mean()
    assert mean_ssdf(with_bad["Floor"]) < mean_ssdf(without) - 0.05


def test_damaged_storage_is_invalid_not_out_of_bounds(scene):
    _, floor, suzanne = scene
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    stored = vb.load_visibility_bake(suzanne.data)
    with pytest.raises(IndexError):
        stored.corner_coefficients([0, len(suzanne.data.vertices)])
    suzanne.data.attributes.remove(suzanne.data.attributes[vb.attribute_name(1)])
    damaged = vb.load_visibility_bake(suzanne.data)
    assert damaged.status == "INVALID" and damaged.packed_coefficients is None
    suzanne.data[vb.PROPERTY]["format_version"] = 99
    assert "format" in vb.load_visibility_bake(suzanne.data).message


def test_invoke_runs_synchronously_headless_and_the_panel_is_registered(scene):
    _, floor, suzanne = scene
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility("INVOKE_DEFAULT", resolution=8, terms=2) == {"FINISHED"}
    stored = vb.load_visibility_bake(suzanne.data)
    assert stored.usable and stored.resolution == 8 and stored.terms == 2
    # what the panel reads: status only, from the view layer's depsgraph, no arrays
    status = vb.visibility_for_object(suzanne.evaluated_get(bpy.context.view_layer.depsgraph), read_arrays=False)
    assert status.usable and status.packed_coefficients is None and "2 terms" in status.message
    panel = bpy.types.SGPRT_PT_visibility_bake
    assert panel.bl_context == "render" and panel.COMPAT_ENGINES == {"SG_PRT"}
    assert bpy.context.scene.sgprt_bake.resolution == SMALL["resolution"]   # operator options do not leak


def test_example_scene_floor_under_suzanne_is_shadowed(addon):
    """examples/build_scenes.build_suzanne_courtyard (Suzanne 8k vertices, floor 4k) baked coarsely."""
    from examples.build_scenes import build_suzanne_courtyard
    scene = build_suzanne_courtyard(resolution=64)
    for key, value in dict(resolution=8, refinement=1, term_mode="FIXED", terms=4).items():
        setattr(scene.sgprt_bake, key, value)
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    floor = bpy.data.objects["Floor"]
    stored = vb.load_visibility_bake(floor.data)
    assert stored.usable and stored.vertex_count == len(floor.data.vertices) > 4000
    matrix = np.array(floor.matrix_world)
    co = np.empty(len(floor.data.vertices) * 3, np.float32)
    floor.data.vertices.foreach_get("co", co)
    positions = co.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
    below = int(np.argmin(np.linalg.norm(positions[:, :2], axis=1)))
    frame = hemisphere_map.local_frame(np.array([0.0, 0.0, 1.0]))
    coefficients = stored.coefficients[below]
    up = float(decode.decode(coefficients, stored.basis, stored.mean, frame @ [0.0, 0.0, 1.0]))
    # a ring of directions 8.6 degrees above the horizon: open sky beside Suzanne (measured: 15 of 16
    # azimuths positive, median 0.05 rad, the lowest -0.013); straight up -0.55 rad
    ring = np.array([[np.cos(a), np.sin(a), 0.15] for a in np.linspace(0, 2 * np.pi, 16, endpoint=False)])
    ring /= np.linalg.norm(ring, axis=1, keepdims=True)
    low = decode.decode(coefficients, stored.basis, stored.mean, ring @ frame.T)
    assert up < -0.3 and np.median(low) > 0.03 and np.sum(low > 0) >= 12, (up, low)
    suzanne = vb.load_visibility_bake(bpy.data.objects["Suzanne"].data)
    assert suzanne.usable and suzanne.vertex_count == len(bpy.data.objects["Suzanne"].data.vertices) > 7000


BAKE_IN_OTHER_BLENDER = """
import sys
import bpy
import numpy as np
import sg_prt_addon
sg_prt_addon.register()
from sg_prt_addon.blender import visibility_bake as vb
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_grid_add(x_subdivisions=6, y_subdivisions=6, size=4.0)
bpy.ops.mesh.primitive_monkey_add(size=1.0, location=(0, 0, 1))
bpy.ops.mesh.primitive_cylinder_add(location=(2, 0, 1))     # 32-gon caps: polyfill triangulation
assert bpy.ops.sgprt.bake_visibility(target="ALL", resolution=6, refinement=1, term_mode="FIXED",
                                     terms=5) == {"FINISHED"}
bpy.ops.wm.save_as_mainfile(filepath=sys.argv[-1] + "/old.blend")
np.savez(sys.argv[-1] + "/old.npz", **{m.name: vb.load_visibility_bake(m).packed_coefficients
                                        for m in bpy.data.meshes})
sys.stdout.flush()
import os
os._exit(0)     # pip bpy 4.2.23 segfaults at interpreter exit once any Operator or Panel class is registered
"""


def test_a_bake_from_blender_4_2_loads_bit_exactly_in_this_blender(addon, tmp_path):
    """Users upgrade: a .blend baked by Blender 4.2 LTS (the second venv) opens here with the bake
    valid (same topology hash, n-gons included) and bit-identical coefficients."""
    import os
    import pathlib
    import subprocess
    root = pathlib.Path(__file__).resolve().parents[2]
    python = root / ".venv-bpy42" / "bin" / "python"
    if not python.exists() or bpy.app.version < (4, 3, 0):
        pytest.skip("needs the bpy 4.2 venv, and a newer Blender running the test")
    script = tmp_path / "bake_old.py"
    script.write_text(BAKE_IN_OTHER_BLENDER)
    done = subprocess.run([str(python), str(script), str(tmp_path)], cwd=root, capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": str(root)})
    assert done.returncode == 0, done.stderr[-2000:]
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "old.blend"))
    expected = np.load(tmp_path / "old.npz")
    assert sorted(expected.files) == sorted(m.name for m in bpy.data.meshes) and len(expected.files) == 3
    for mesh in bpy.data.meshes:
        stored = vb.load_visibility_bake(mesh)
        assert stored.usable, (mesh.name, stored.message)
        assert np.array_equal(_bits(stored.packed_coefficients), _bits(expected[mesh.name])), mesh.name


def test_moved_vertices_keep_the_faces_and_the_bake(scene):
    """Moving vertices keeps the faces, so the bake stays usable, though Blender cuts some quads along their
    other diagonal (the loop triangles' hash, which bakes before face_hash compare, changes); a Displace
    modifier that keeps the faces can be baked through."""
    from sg_prt_addon.blender import per_vertex_store

    _, floor, suzanne = scene
    _select(floor)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    triangles_before = per_vertex_store.mesh_topology_hash(floor.data)
    rng = np.random.default_rng(3)
    for vertex in floor.data.vertices:
        vertex.co.z += rng.uniform(-0.4, 0.4)
    floor.data.update()
    assert per_vertex_store.mesh_topology_hash(floor.data) != triangles_before      # quads cut the other way
    assert vb.load_visibility_bake(floor.data).usable
    group = floor.data[vb.PROPERTY]
    del group["face_hash"]                      # a bake made before face_hash: the triangles decide, as then
    assert vb.load_visibility_bake(floor.data).status == "STALE"

    displace = floor.modifiers.new("Displace", "DISPLACE")
    displace.strength = 0.3
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    obj_eval = floor.evaluated_get(bpy.context.evaluated_depsgraph_get())
    assert vb.visibility_for_object(obj_eval).usable
    # a deform modifier keeps the faces: the rows stay on the mesh, no companion
    assert vb.load_visibility_bake(floor.data).usable and per_vertex_store.companion_mesh(floor, vb.KIND) is None


def _render_warnings():
    from sg_prt_addon.engine import scene_state

    state = scene_state.SceneState()
    state.sync(bpy.context.evaluated_depsgraph_get())
    return [warning for warning in state.warnings if "was made before" in warning]


def test_render_names_what_moved_since_the_bake(scene):
    """A bake keeps the fingerprints of what it traced: the render names each object whose bake saw the scene
    otherwise (moved, changed shape, appeared), and says nothing once the scene is as baked again."""
    _, floor, suzanne = scene
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    assert _render_warnings() == []

    suzanne.location.z += 0.5
    warnings = _render_warnings()
    assert len(warnings) == 2 and all("'Suzanne' moved" in warning for warning in warnings), warnings
    assert any(warning.startswith("object 'Floor'") for warning in warnings)
    suzanne.location.z -= 0.5
    assert _render_warnings() == []

    baked_co = suzanne.data.vertices[0].co.copy()
    suzanne.data.vertices[0].co.x += 0.2
    suzanne.data.update()
    assert all("'Suzanne' changed shape" in warning for warning in _render_warnings())
    suzanne.data.vertices[0].co = baked_co
    suzanne.data.update()

    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(1.0, 1.0, 0.5))
    warnings = _render_warnings()
    assert len(warnings) == 2 and all("'Cube' appeared" in warning for warning in warnings), warnings
    bpy.context.active_object.hide_render = True            # left out of renders: it shadows nothing
    assert _render_warnings() == []


def test_render_names_an_occluder_whose_vertex_count_changed(scene):
    """An occluder's Array count 5 -> 3 after the floor's bake: the floor's shadows of the two copies gone stay
    in its bake, and the render names the occluder; back at 5, nothing."""
    _, floor, suzanne = scene
    array = suzanne.modifiers.new("Array", "ARRAY")
    array.count = 5
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    assert _render_warnings() == []
    array.count = 3
    warnings = _render_warnings()
    assert any(warning.startswith("object 'Floor'") and "'Suzanne' changed shape" in warning
               for warning in warnings), warnings
    array.count = 5
    assert not any("changed shape" in warning for warning in _render_warnings())


def test_a_bake_per_vertex_of_a_flat_mesh_asks_for_a_rebake(scene):
    """A visibility bake made per vertex before flat faces were baked per corner still renders, and the render
    says to re-bake; a smooth mesh's bake per vertex says nothing."""
    from sg_prt_addon.engine import scene_state

    _, floor, suzanne = scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    matrix = np.array(suzanne.matrix_world)
    vertices = np.array([matrix[:3, :3] @ v.co + matrix[:3, 3] for v in suzanne.data.vertices])
    normals = np.array([matrix[:3, :3] @ v.normal for v in suzanne.data.vertices])      # as bakes were made
    result = bake_visibility(vertices, vb.mesh_triangles(suzanne.data), normals, *vb.occluder_arrays(depsgraph),
                             BakeOptions(resolution=8, refinement=1, terms=3))
    vb.store_visibility_bake(suzanne.data, result)
    _select(floor)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    state = scene_state.SceneState()
    state.sync(bpy.context.evaluated_depsgraph_get())
    asked = [warning for warning in state.warnings if "made before flat faces" in warning]
    assert len(asked) == 1 and "'Suzanne'" in asked[0], state.warnings
    assert len(state.visibility) == 2                           # it still shades


# --------------------------------------------------------------------------- objects whose modifiers change the faces

def _mesh_snapshot(mesh):
    """A mesh datablock's positions, faces and attribute names: what a bake through modifiers must not touch."""
    from sg_prt_addon.blender import per_vertex_store

    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    return _bits(co).tobytes(), per_vertex_store.mesh_face_hash(mesh), sorted(a.name for a in mesh.attributes)


def _as_rendered(obj, load=vb.visibility_for_object):
    """An object's record as a final render reads it: its modifiers evaluated at their render settings."""
    from sg_prt_addon.blender import modifier_stack

    with modifier_stack.as_rendered(bpy.context.scene):
        return load(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()))


def _in_viewport(obj, load=vb.visibility_for_object):
    return load(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()))


def test_a_subdivided_object_bakes_its_evaluated_mesh_on_a_companion(scene, tmp_path, capfd):
    """Suzanne under a Subdivision Surface (levels 1 in the viewport, 2 in renders: Blender's defaults) bakes the
    mesh a render evaluates, onto a companion mesh; her mesh datablock stays as it was.  The viewport, at another
    level, says why it shows no shadows; another render level makes the bake stale, naming the change; the bake
    survives save and reopen; Clear removes the companion."""
    from sg_prt_addon.blender import per_vertex_store
    from sg_prt_addon.engine import scene_state

    _, floor, suzanne = scene
    subdivision = suzanne.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels, subdivision.render_levels = 1, 2
    untouched = _mesh_snapshot(suzanne.data)
    _select(suzanne)
    viewport_state = scene_state.SceneState()               # a viewport's, fed its updates as view_update does
    bpy.context.view_layer.update()
    viewport_state.sync(bpy.context.view_layer.depsgraph)

    def on_update(updated_scene, depsgraph):
        viewport_state.update(depsgraph)
    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        capfd.readouterr()
        assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
        assert "renders unshadowed" not in "".join(capfd.readouterr())     # the operator asks as renders do
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    assert _mesh_snapshot(suzanne.data) == untouched and not vb.has_visibility_bake(suzanne.data)
    companion = per_vertex_store.companion_mesh(suzanne, vb.KIND)
    stored = _as_rendered(suzanne)
    assert stored.usable and "with its modifiers" in stored.message, stored.message
    with per_vertex_store.modifier_stack.as_rendered(bpy.context.scene):
        evaluated = suzanne.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
        assert stored.vertex_count == len(evaluated.vertices) == len(companion.vertices) > 8 * len(suzanne.data.vertices)
        assert stored.domain == "CORNER" and stored.packed_coefficients.shape[0] == len(evaluated.loops)
    rows = stored.packed_coefficients.copy()

    # the viewport evaluates level 1: no shadows there, and why (the operator's update reached its state)
    viewport = _in_viewport(suzanne)
    assert viewport.status == "STALE" and viewport.packed_coefficients is None
    assert "'Subdivision' levels 1 in the viewport, 2 in renders" in viewport.message, viewport.message
    assert "final renders are shadowed" in viewport.message
    key = next(entry.mesh_key for entry in viewport_state.objects.values() if entry.name == "Suzanne")
    assert viewport_state.visibility_status[key] == viewport.message
    assert f"object 'Suzanne' renders unshadowed: {viewport.message}" in viewport_state.unshadowed_warnings()
    drawn = recording_layout.draw(vb.SGPRT_PT_visibility_bake, bpy.context)          # the panel's status line
    assert ("label", f"Suzanne: {viewport.message}") in drawn
    assert ("label", "Renders unshadowed until re-baked") not in drawn

    subdivision.render_levels = 3
    stale = _as_rendered(suzanne)
    assert stale.status == "STALE" and stale.packed_coefficients is None
    assert "its modifiers changed since the bake ('Subdivision' render levels 2 -> 3): re-bake" in stale.message
    subdivision.render_levels = 2
    assert _as_rendered(suzanne).usable                     # as baked again
    subdivision.levels = 2                                  # the viewport at the render's level: shadowed there too
    assert _in_viewport(suzanne).usable

    _reopen(tmp_path / "subdivided.blend")
    suzanne = bpy.data.objects["Suzanne"]
    reopened = _as_rendered(suzanne)
    assert reopened.usable and np.array_equal(_bits(reopened.packed_coefficients), _bits(rows))
    assert _mesh_snapshot(suzanne.data) == untouched

    assert bpy.ops.sgprt.clear_visibility(target="ALL") == {"FINISHED"}
    assert per_vertex_store.companion_mesh(suzanne, vb.KIND) is None and _as_rendered(suzanne) is None
    assert not [mesh.name for mesh in bpy.data.meshes if mesh.name.startswith("SG-PRT")]
    assert _mesh_snapshot(suzanne.data) == untouched


def test_a_bake_on_the_mesh_and_one_on_a_companion_take_turns(scene):
    """A bake made on the mesh (no modifiers) still shades where the object's modifiers keep its faces, beside the
    object's bake through a Subdivision; a companion whose modifier went says so; a bake on the mesh again drops
    the companion."""
    from sg_prt_addon.blender import per_vertex_store

    _, floor, suzanne = scene
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    on_mesh = vb.load_visibility_bake(suzanne.data)
    subdivision = suzanne.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels = subdivision.render_levels = 1
    assert _in_viewport(suzanne).status == "STALE"
    assert bpy.ops.sgprt.bake_visibility(resolution=8) == {"FINISHED"}
    assert _in_viewport(suzanne).usable and _in_viewport(suzanne).resolution == 8
    assert vb.load_visibility_bake(suzanne.data).date == on_mesh.date          # kept for the mesh's other users

    subdivision.show_viewport = subdivision.show_render = False               # the faces are the mesh's again
    assert _in_viewport(suzanne).usable and _in_viewport(suzanne).resolution == SMALL["resolution"]
    subdivision.show_viewport = subdivision.show_render = True
    vb.clear_visibility_bake(suzanne.data)
    suzanne.modifiers.remove(subdivision)
    gone = _in_viewport(suzanne)
    assert gone.status == "STALE" and "its modifiers changed since the bake ('Subdivision' removed)" in gone.message

    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    assert per_vertex_store.companion_mesh(suzanne, vb.KIND) is None
    assert not [mesh.name for mesh in bpy.data.meshes if mesh.name.startswith("SG-PRT")]
    assert _in_viewport(suzanne).usable and vb.load_visibility_bake(suzanne.data).usable


def _subdivide_nodes():
    """A Geometry Nodes group subdividing its geometry by its input "Level"."""
    group = bpy.data.node_groups.new("Subdivide", "GeometryNodeTree")
    group.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    level = group.interface.new_socket("Level", in_out="INPUT", socket_type="NodeSocketInt")
    group.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    inputs, outputs = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    subdivide = group.nodes.new("GeometryNodeSubdivideMesh")
    group.links.new(inputs.outputs["Geometry"], subdivide.inputs["Mesh"])
    group.links.new(inputs.outputs["Level"], subdivide.inputs["Level"])
    group.links.new(subdivide.outputs["Mesh"], outputs.inputs["Geometry"])
    return group, level.identifier


def _set_node_input(modifier, identifier, value):
    """A Geometry Nodes modifier's input: an RNA struct's value from Blender 5.2, an ID property before."""
    if hasattr(modifier, "properties"):
        getattr(modifier.properties.inputs, identifier).value = value
    else:
        modifier[identifier] = value


def test_mirror_array_and_geometry_nodes_bake_their_evaluated_meshes(scene):
    """Cubes under a Mirror (about the floor's origin), an Array and a Geometry Nodes subdivision bake their
    evaluated meshes; a changed setting, node input or node group makes the bake stale and says which; moving a
    node in the editor does not."""
    from sg_prt_addon.blender import per_vertex_store

    _, floor, suzanne = scene
    cubes = {}
    for name, location in (("Mirrored", (1.4, 0.0, 0.4)), ("Arrayed", (-1.8, 1.2, 0.4)), ("Noded", (0.0, -1.6, 0.4))):
        bpy.ops.mesh.primitive_cube_add(size=0.5, location=location)
        cubes[name] = bpy.context.active_object
        cubes[name].name = name
    mirror = cubes["Mirrored"].modifiers.new("Mirror", "MIRROR")
    mirror.mirror_object = floor
    array = cubes["Arrayed"].modifiers.new("Array", "ARRAY")
    array.count = 3
    nodes = cubes["Noded"].modifiers.new("GeometryNodes", "NODES")
    group, level = _subdivide_nodes()
    nodes.node_group = group
    _set_node_input(nodes, level, 1)
    _select(*cubes.values())
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    for name, vertex_count in (("Mirrored", 16), ("Arrayed", 24), ("Noded", 26)):
        stored = _as_rendered(cubes[name])
        assert stored.usable and stored.vertex_count == vertex_count, (name, stored.message)
        assert per_vertex_store.companion_mesh(cubes[name], vb.KIND) is not None
        assert len(cubes[name].data.vertices) == 8 and not vb.has_visibility_bake(cubes[name].data)

    array.count = 4
    assert "('Array' count 3 -> 4)" in _as_rendered(cubes["Arrayed"]).message
    _set_node_input(nodes, level, 2)
    cubes["Noded"].update_tag()
    assert "('GeometryNodes' inputs changed)" in _as_rendered(cubes["Noded"]).message
    _set_node_input(nodes, level, 1)
    cubes["Noded"].update_tag()
    group.nodes["Group Output"].location.x += 100.0
    assert _as_rendered(cubes["Noded"]).usable
    group.nodes.new("GeometryNodeSetShadeSmooth")            # the group's content changed (unlinked: same faces)
    assert "('GeometryNodes' node group 'Subdivide' edited)" in _as_rendered(cubes["Noded"]).message


def test_a_cancelled_or_failed_rebake_keeps_the_previous_companion(scene):
    from sg_prt_addon.blender import per_vertex_store

    _, floor, suzanne = scene
    suzanne.modifiers.new("Subdivision", "SUBSURF").render_levels = 1
    _select(suzanne)
    assert bpy.ops.sgprt.bake_visibility() == {"FINISHED"}
    companion = per_vertex_store.companion_mesh(suzanne, vb.KIND)
    previous = _as_rendered(suzanne)
    vb.progress_hook = lambda fraction, message: fraction > 0.2
    assert bpy.ops.sgprt.bake_visibility(resolution=8, terms=3) == {"CANCELLED"}
    vb.progress_hook = None
    meshes = sorted(bpy.data.meshes.keys())

    def fails(mesh):
        raise ValueError("disk full")
    with pytest.raises(ValueError, match="disk full"):
        per_vertex_store.write_companion(suzanne, vb.KIND, per_vertex_store.EvaluatedTopology.of(suzanne.data), fails)
    assert sorted(bpy.data.meshes.keys()) == meshes                 # the half-made companion went
    assert per_vertex_store.companion_mesh(suzanne, vb.KIND) == companion
    kept = _as_rendered(suzanne)
    assert kept.usable and kept.resolution == SMALL["resolution"] and kept.date == previous.date
    for field in ("packed_coefficients", "basis", "mean"):
        assert np.array_equal(_bits(getattr(kept, field)), _bits(getattr(previous, field))), field


def _instance_on_grid(obj, size, cube_size, z):
    """A Geometry Nodes modifier on obj whose output is only instances: cubes on a 3 x 3 grid, not realized."""
    modifier = obj.modifiers.new("Scatter", "NODES")
    tree = bpy.data.node_groups.new("Scatter", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes = tree.nodes
    grid = nodes.new("GeometryNodeMeshGrid")
    grid.inputs["Size X"].default_value = grid.inputs["Size Y"].default_value = size
    grid.inputs["Vertices X"].default_value = grid.inputs["Vertices Y"].default_value = 3
    cube = nodes.new("GeometryNodeMeshCube")
    cube.inputs["Size"].default_value = (cube_size, cube_size, cube_size)
    place = nodes.new("GeometryNodeInstanceOnPoints")
    lift = nodes.new("GeometryNodeTranslateInstances")
    lift.inputs["Translation"].default_value = (0.0, 0.0, z)
    output = nodes.new("NodeGroupOutput")
    tree.links.new(grid.outputs["Mesh"], place.inputs["Points"])
    tree.links.new(cube.outputs["Mesh"], place.inputs["Instance"])
    tree.links.new(place.outputs["Instances"], lift.inputs["Instances"])
    tree.links.new(lift.outputs["Instances"], output.inputs[0])
    modifier.node_group = tree


def test_instances_cast_shadows_and_instancers_say_why_they_are_not_baked(scene, capfd):
    """Geometry Nodes instances that are not realized shadow the floor baked under them; their object is refused
    with what to do; a collection instance is named as not baked, its instances casting shadows too."""
    _, floor, suzanne = scene
    bpy.data.objects.remove(suzanne)
    bpy.ops.mesh.primitive_plane_add(size=0.1, location=(0.0, 0.0, 0.0))
    scatter = bpy.context.active_object
    scatter.name = "Scatter"
    _instance_on_grid(scatter, 2.0, 0.4, 0.5)

    def mean_ssdf(bake, near):
        points = np.array([v.co for v in floor.data.vertices])
        chosen = np.min(np.linalg.norm(points[:, None, :2] - np.asarray(near)[None, :, :2], axis=2), axis=1) < 0.25
        return (bake.coefficients[chosen] @ bake.basis.reshape(bake.terms, -1) + bake.mean.ravel()).mean()

    under = [(x, y) for x in (-1.0, 0.0, 1.0) for y in (-1.0, 0.0, 1.0)]
    capfd.readouterr()
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    assert "'Scatter' has no faces of its own: its Geometry Nodes output is instances" in "".join(capfd.readouterr())
    shadowed = mean_ssdf(vb.load_visibility_bake(floor.data), under)
    scatter.modifiers["Scatter"].show_render = scatter.modifiers["Scatter"].show_viewport = False
    _select(floor)
    assert bpy.ops.sgprt.bake_visibility(target="SELECTED") == {"FINISHED"}
    open_sky = mean_ssdf(vb.load_visibility_bake(floor.data), under)
    assert shadowed < open_sky - 0.1, (shadowed, open_sky)

    # the same cubes as a collection instance: named, and casting shadows
    bpy.data.objects.remove(scatter)
    source = bpy.data.collections.new("Crates")
    bpy.ops.mesh.primitive_cube_add(size=0.4, location=(0.0, 0.0, 0.5))
    crate = bpy.context.active_object
    for collection in crate.users_collection:
        collection.objects.unlink(crate)
    source.objects.link(crate)
    instancer = bpy.data.objects.new("Crates Instance", None)
    instancer.instance_type, instancer.instance_collection = "COLLECTION", source
    bpy.context.scene.collection.objects.link(instancer)
    capfd.readouterr()
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    assert "collection instance 'Crates Instance' is not baked" in "".join(capfd.readouterr())
    assert mean_ssdf(vb.load_visibility_bake(floor.data), [(0.0, 0.0)]) < open_sky - 0.1
