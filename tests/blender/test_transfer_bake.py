"""Transfer bake operator (sgprt.bake_transfer, blender/transfer_bake.py) and its storage: real bpy, real
.blend files saved and reopened; a small Suzanne over a floor, 256 directions a vertex."""
import bmesh
import bpy
import numpy as np
import pytest
import recording_layout

from sg_prt_addon.blender import transfer_bake as tb
from sg_prt_addon.engine import scene_state
from sg_prt_addon.visibility import transfer

SMALL = dict(order=4, directions=256, term_mode="FIXED", terms=6)


@pytest.fixture
def scene(addon):
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
        setattr(scene.sgprt_transfer, key, value)
    yield scene, floor, suzanne
    tb.progress_hook = None


def _snapshot(mesh):
    stored = tb.load_transfer_bake(mesh)
    return (stored.status, stored.order, stored.terms, np.asarray(stored.packed_coefficients).view(np.uint32).copy(),
            stored.mean.view(np.uint32).copy(), stored.basis.view(np.uint32).copy())


def _same(a, b):
    return a[:3] == b[:3] and all(np.array_equal(x, y) for x, y in zip(a[3:], b[3:]))


def test_bake_stores_and_survives_save_and_reopen(scene, tmp_path):
    _, floor, suzanne = scene
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    stored = tb.load_transfer_bake(suzanne.data)
    assert stored.usable and (stored.order, stored.terms, stored.layers) == (4, 6, 2)
    assert stored.basis.shape == (6, transfer.vector_size(4))
    # flat-shaded Suzanne: a row per corner (its corners' normals differ), as the visibility bake's
    assert stored.domain == "CORNER" and stored.packed_coefficients.shape == (len(suzanne.data.loops), 8)
    assert 0 < stored.relative_error < 0.5
    # the record reconstructs what the bake computed: the rows' weights times the basis, plus the mean
    vectors = stored.mean + stored.packed_coefficients[:, 1:7] @ stored.basis
    diffuse, _ = transfer.unpack(vectors, 4)
    assert np.all(diffuse[:, 0] > -0.05)               # t_00: the visible cosine-weighted solid angle, >= 0
    before = {mesh.name: _snapshot(mesh) for mesh in (floor.data, suzanne.data)}
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "transfer.blend"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "transfer.blend"))
    for name, snapshot in before.items():
        assert _same(snapshot, _snapshot(bpy.data.meshes[name])), name


def test_the_floor_under_suzanne_is_shadowed(scene):
    """t_00 (the visible cosine-weighted solid angle over sqrt(4 pi)) of the floor's centre vertex, under
    Suzanne, against 20,000 cosine-weighted rays traced from it; a far corner sees the whole sky
    (pi / sqrt(4 pi) = 0.886)."""
    from sg_prt_addon.blender import visibility_bake
    from sg_prt_addon.visibility.raytrace import RayTracer

    _, floor, _ = scene
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    stored = tb.load_transfer_bake(floor.data)
    vectors = stored.mean + stored.packed_coefficients[:, 1:7] @ stored.basis
    positions = np.array([v.co for v in floor.data.vertices])
    centre = np.argmin(np.linalg.norm(positions[:, :2], axis=1))
    corner = np.argmax(np.linalg.norm(positions[:, :2], axis=1))
    assert vectors[corner, 0] == pytest.approx(np.pi / np.sqrt(4 * np.pi), rel=0.05)   # Suzanne: a little of its sky
    rng = np.random.default_rng(0)
    u = rng.random((20000, 2))
    rays = np.stack([np.sqrt(u[:, 0]) * np.cos(2 * np.pi * u[:, 1]), np.sqrt(u[:, 0]) * np.sin(2 * np.pi * u[:, 1]),
                     np.sqrt(1 - u[:, 0])], -1)
    tracer = RayTracer(*visibility_bake.occluder_arrays(bpy.context.evaluated_depsgraph_get()))
    try:
        visible = ~tracer.occluded(np.tile(positions[centre] + [0, 0, tracer.offset], (len(rays), 1)), rays)
    finally:
        tracer.close()
    expected = visible.mean() * np.pi / np.sqrt(4 * np.pi)
    print(vectors[centre, 0], expected)
    assert expected < 0.9 * vectors[corner, 0]
    assert vectors[centre, 0] == pytest.approx(expected, abs=0.02)     # measured 0.733 against 0.732


def test_cancelled_and_failed_bakes_keep_the_previous_one(scene, monkeypatch):
    _, floor, suzanne = scene
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    before = _snapshot(suzanne.data)
    tb.progress_hook = lambda fraction, message: fraction > 0.3
    assert bpy.ops.sgprt.bake_transfer(target="ALL", terms=3) == {"CANCELLED"}
    assert _same(before, _snapshot(suzanne.data))
    tb.progress_hook = None

    def fails(*args, **kwargs):            # the second receiver's bake fails: nothing of the first is written
        if fails.calls:
            raise MemoryError("out of memory")
        fails.calls += 1
        return real(*args, **kwargs)
    real, fails.calls = transfer.bake_transfer, 0
    monkeypatch.setattr(transfer, "bake_transfer", fails)
    with pytest.raises(RuntimeError, match="transfer bake failed, nothing written: out of memory"):
        bpy.ops.sgprt.bake_transfer(target="ALL", terms=3)
    assert _same(before, _snapshot(suzanne.data))


def test_a_changed_mesh_makes_the_bake_stale_and_the_render_says_so(scene):
    _, floor, suzanne = scene
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    mesh = bmesh.new()
    mesh.from_mesh(suzanne.data)
    bmesh.ops.subdivide_edges(mesh, edges=mesh.edges[:3], cuts=1)
    mesh.to_mesh(suzanne.data)
    mesh.free()
    stored = tb.transfer_for_object(suzanne.evaluated_get(bpy.context.evaluated_depsgraph_get()))
    assert stored.status == "STALE" and "re-bake" in stored.message
    state = scene_state.SceneState()
    state.sync(bpy.context.evaluated_depsgraph_get())
    warnings = state.unshadowed_warnings()
    assert any("'Suzanne' renders without its transfer bake: stale" in line for line in warnings), warnings
    assert any(data.get("transfer") is not None for data in state.per_vertex.values())    # the floor's is kept


def test_a_subdivided_object_bakes_its_transfer_on_a_companion(scene):
    """The transfer of Suzanne under a Subdivision Surface is baked on her evaluated mesh, as renders evaluate it
    (per_vertex_store's companion, as the visibility bake's), and shades the render; another render level makes it
    stale and the render says why.  Her mesh datablock keeps no transfer."""
    from sg_prt_addon.blender import modifier_stack, per_vertex_store

    _, floor, suzanne = scene
    subdivision = suzanne.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels, subdivision.render_levels = 0, 1
    bpy.ops.object.select_all(action="DESELECT")
    suzanne.select_set(True)
    assert bpy.ops.sgprt.bake_transfer(target="SELECTED") == {"FINISHED"}
    assert not tb.has_transfer_bake(suzanne.data) and per_vertex_store.companion_mesh(suzanne, tb.KIND) is not None

    def render_state():
        with modifier_stack.as_rendered(bpy.context.scene):
            state = scene_state.SceneState()
            state.sync(bpy.context.evaluated_depsgraph_get())
        key = next(entry.mesh_key for entry in state.objects.values() if entry.name == "Suzanne")
        return state, key

    state, key = render_state()
    data = state.per_vertex[key].get(scene_state.TRANSFER)
    assert data is not None and data.rows.shape[0] == len(state.meshes[key].corner_vertex) == 4 * len(suzanne.data.loops)
    subdivision.render_levels = 2
    state, key = render_state()
    assert scene_state.TRANSFER not in state.per_vertex[key]
    assert any(line.startswith("object 'Suzanne' renders without its transfer bake: stale: its modifiers changed "
                               "since the bake ('Subdivision' render levels 1 -> 2)") for line in
               state.unshadowed_warnings()), state.unshadowed_warnings()


def test_both_bake_panels_draw_their_settings_buttons_and_status(scene):
    """The visibility and transfer panels' draw() (shared controls and status reader) against the real scene
    settings and the real active object: before and after a transfer bake."""
    from sg_prt_addon.blender import visibility_bake

    _, floor, suzanne = scene
    bpy.context.view_layer.objects.active = suzanne
    drawn = {}
    for name, panel in (("visibility", visibility_bake.SGPRT_PT_visibility_bake), ("transfer", tb.SGPRT_PT_transfer_bake)):
        drawn[name] = recording_layout.draw(panel, bpy.context)
    assert ("prop", "resolution") in drawn["visibility"] and ("prop", "order") in drawn["transfer"]
    assert ("operator", "sgprt.bake_transfer") in drawn["transfer"]
    assert ("label", "Suzanne: not baked (renders unshadowed)") in drawn["visibility"]
    assert ("label", "Suzanne: no transfer (SH renders unshadowed)") in drawn["transfer"]
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    calls = recording_layout.draw(tb.SGPRT_PT_transfer_bake, bpy.context)
    assert any(call[0] == "label" and call[1].startswith("Suzanne: order 4, 6 terms") for call in calls)


def test_a_transfer_bake_per_vertex_beside_a_visibility_bake_per_corner_is_named(scene):
    """The corners read every kind's rows by one index: a transfer bake made per vertex (an older bake of a
    flat mesh) beside a visibility bake made per corner is left out of the render, and named with why."""
    from sg_prt_addon.blender import per_vertex_store
    from sg_prt_addon.blender import visibility_bake as vb

    _, floor, suzanne = scene
    scene[0].sgprt_bake.resolution, scene[0].sgprt_bake.terms, scene[0].sgprt_bake.term_mode = 8, 3, "FIXED"
    assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    assert bpy.ops.sgprt.bake_transfer(target="ALL") == {"FINISHED"}
    stored = tb.load_transfer_bake(suzanne.data)
    group = suzanne.data[per_vertex_store.property_name(tb.KIND)].to_dict()
    rows = np.zeros((len(suzanne.data.vertices), stored.packed_coefficients.shape[1]), np.float32)
    rows[:, 0] = 1.0
    metadata = {key: value for key, value in group.items() if key not in (
        "format_version", "layers", "vertex_count", "topology_hash", "face_hash", "domain", "occluders")}
    per_vertex_store.store_record(suzanne.data, tb.KIND, rows, tb.FORMAT_VERSION, metadata)    # per vertex
    assert tb.load_transfer_bake(suzanne.data).usable and vb.load_visibility_bake(suzanne.data).domain == "CORNER"
    state = scene_state.SceneState()
    state.sync(bpy.context.evaluated_depsgraph_get())
    key = next(entry.mesh_key for entry in state.objects.values() if entry.name == "Suzanne")
    assert set(state.per_vertex[key]) == {scene_state.SSDF}
    assert any("Suzanne" in line and "made per vertex, the visibility bake per corner" in line
               for line in state.unshadowed_warnings())
