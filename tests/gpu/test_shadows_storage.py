"""Bakes stored in the .blend reach the engine (blender.visibility_bake.visibility_for_object, the
default of engine.scene_state.visibility_for); stale bakes and bakes of another vertex count
render unshadowed, never read out of bounds."""
import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _scene(name):
    scene = fx.new_scene(name, 64, 64)
    scene.camera.location = (0.0, -5.5, 4.0)
    scene.camera.rotation_euler = (np.radians(52.0), 0.0, 0.0)
    fx.world_colour(scene, (0.02, 0.02, 0.02))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 0.9), radius=0.8, segments=16, rings=8)
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=6.0, segments=16)
    fx.point_light(scene, name + "_light", (1.2, -0.6, 3.6), 600.0, radius=0.05)
    return scene, sphere, floor


def test_stored_bakes_shadow_and_stale_bakes_do_not(engine):
    import bmesh

    from sg_prt_addon.blender import visibility_bake

    scene, sphere, floor = _scene("stored_bakes")
    unshadowed = fx.render(scene)["passes"]["Combined"]
    try:
        bakes = fx.bake_objects(scene, [sphere, floor], resolution=8)
    finally:
        fx.clear_bakes()
    for obj in (sphere, floor):
        visibility_bake.store_visibility_bake(obj.data, bakes[obj.name])
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    state = result["state"]
    assert len(state.visibility) == 2, state.visibility_status
    shadowed = result["passes"]["Combined"]
    darker = shadowed[..., 0] < 0.5 * unshadowed[..., 0]
    assert darker.mean() > 0.03             # the sphere's shadow on the floor (and its own dark side)
    assert np.all(shadowed[..., :3] <= unshadowed[..., :3] * 1.001 + 1e-6)

    # the floor gains a vertex: its bake is stale, the floor renders exactly as without a bake
    bm = bmesh.new()
    bm.from_mesh(floor.data)
    bm.verts.new((10.0, 10.0, 0.0))
    bm.to_mesh(floor.data)
    bm.free()
    floor.data.update()
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    state = result["state"]
    floor_key = state.objects[floor.name].mesh_key
    assert floor_key not in state.visibility
    assert "stale" in state.visibility_status[floor_key]
    assert len(state.visibility) == 1                      # the sphere keeps its shadows
    # and the render says so, naming the object and why
    warnings = state.unshadowed_warnings()
    assert len(warnings) == 1 and warnings[0].startswith(f"object '{floor.name}' renders unshadowed: stale")
    # without its bake at all it is named in the one line of unbaked objects (the sphere is baked)
    visibility_bake.clear_visibility_bake(floor.data)
    floor.data.update()
    warnings = fx.render(scene)["state"].unshadowed_warnings()
    assert warnings == [f"1 object(s) without a visibility bake render unshadowed: '{floor.name}'"]


def test_a_bake_of_another_vertex_count_is_refused(engine):
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.visibility.pipeline import BakeResult

    scene, sphere, floor = _scene("mismatched_bake")
    vertex_count = len(floor.data.vertices)
    resolution, terms = 8, 3
    rng = np.random.default_rng(0)

    def fake(count):
        return BakeResult(coefficients=rng.normal(size=(count, terms)).astype(np.float32),
                          basis=rng.normal(size=(terms, resolution, resolution)).astype(np.float32),
                          mean=np.ones((resolution, resolution), np.float32), resolution=resolution, terms=terms,
                          rms_error=0.0, rms_error_by_terms=np.zeros(terms + 1), vertex_count=count,
                          topology_hash="")
    bakes = {floor.name: fake(vertex_count - 1), sphere.name: fake(vertex_count * 10)}
    scene_state.visibility_provider = lambda object_eval: bakes.get(object_eval.name)
    try:
        result = fx.render(scene)
    finally:
        fx.clear_bakes()
    assert "error" not in result, result.get("error")
    state = result["state"]
    assert state.visibility == {}
    assert all("stale" in message for message in state.visibility_status.values()), state.visibility_status


def test_viewport_update_picks_up_a_new_bake_and_its_removal(blender):
    """SceneState.update (view_update's logic) after the bake operator's mesh.update(): the object is
    re-exported with its new bake; clearing the bake drops it again."""
    from sg_prt_addon.blender import visibility_bake

    fx.ensure_registered()
    bpy = blender
    scene = bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    fx.uv_sphere(scene, "viewport_bake_sphere", (0.0, 0.0, 1.0), segments=12, rings=6)
    floor = fx.grid(scene, "viewport_bake_floor", (0.0, 0.0, 0.0), size=4.0, segments=8)
    view_layer = bpy.context.view_layer
    try:
        with fx.tracked_state(scene, view_layer) as state:
            assert state.visibility == {}
            try:
                bakes = fx.bake_objects(scene, [floor], resolution=8)
            finally:
                fx.clear_bakes()
            visibility_bake.store_visibility_bake(floor.data, bakes[floor.name])
            floor.data.update()                 # as the operator does after storing
            view_layer.update()
            floor_key = state.objects[floor.name].mesh_key
            assert floor_key in state.visibility, state.visibility_status
            assert floor_key in state.dirty.meshes
            state.consume_dirty()
            visibility_bake.clear_visibility_bake(floor.data)
            floor.data.update()
            view_layer.update()
            assert floor_key not in state.visibility
            assert floor_key in state.dirty.meshes
    finally:
        for obj in list(scene.objects):
            bpy.data.objects.remove(obj)


def test_bake_operator_to_render(engine):
    """End to end: the Bake Visibility operator (execute) stores bakes that the next render shadows with."""
    import bpy

    scene, sphere, floor = _scene("operator_bakes")
    unshadowed = fx.render(scene)["passes"]["Combined"]
    with bpy.context.temp_override(scene=scene, view_layer=scene.view_layers[0]):
        outcome = bpy.ops.sgprt.bake_visibility(target="ALL", resolution=8, term_mode="FIXED", terms=8)
    assert outcome == {"FINISHED"}
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    assert len(result["state"].visibility) == 2, result["state"].visibility_status
    assert {data.terms for data in result["state"].visibility.values()} == {8}
    shadowed = result["passes"]["Combined"]
    assert (shadowed[..., 0] < 0.5 * unshadowed[..., 0]).mean() > 0.03


def test_a_subdivided_floor_bakes_and_renders_shadowed_until_its_level_changes(engine):
    """End to end through a modifier: a floor under a Subdivision Surface (level 0 in the viewport, 1 in renders)
    baked by the operator (on a companion mesh of the render's faces) renders the sphere's shadow; at render level
    2 its bake is stale: the report names the floor and the change, and the image is exactly the one without the
    floor's bake."""
    import bpy

    from sg_prt_addon.blender import per_vertex_store, visibility_bake

    scene, sphere, floor = _scene("subdivided_floor")
    subdivision = floor.modifiers.new("Subdivision", "SUBSURF")
    subdivision.levels, subdivision.render_levels = 0, 1
    view_layer = scene.view_layers[0]

    def bake(obj):
        with bpy.context.temp_override(scene=scene, view_layer=view_layer, selected_objects=[obj]):
            return bpy.ops.sgprt.bake_visibility(target="SELECTED", resolution=8, term_mode="FIXED", terms=8)

    def render():
        result = fx.render(scene)
        assert "error" not in result, result.get("error")
        return result["passes"]["Combined"].copy(), result["state"]

    assert bake(sphere) == {"FINISHED"}                     # on its mesh: the same in every render below
    sphere_only, _ = render()
    assert bake(floor) == {"FINISHED"}
    assert per_vertex_store.companion_mesh(floor, visibility_bake.KIND) is not None
    assert not visibility_bake.has_visibility_bake(floor.data) and len(floor.data.polygons) == 16 * 16
    shadowed, state = render()
    floor_key = next(key for key in state.meshes if key.startswith(floor.name))
    assert floor_key in state.visibility and state.meshes[floor_key].vertex_count == 33 * 33, state.visibility_status
    darker = shadowed[..., 0] < 0.5 * sphere_only[..., 0]
    assert darker.mean() > 0.02                             # the sphere's shadow on the floor
    assert np.all(shadowed[..., :3] <= sphere_only[..., :3] * 1.001 + 1e-6)

    subdivision.render_levels = 2
    stale, state = render()
    assert floor_key not in state.visibility and state.meshes[floor_key].vertex_count == 65 * 65
    assert (f"object '{floor.name}' renders unshadowed: stale: its modifiers changed since the bake ('Subdivision' "
            "render levels 1 -> 2): re-bake") in state.unshadowed_warnings(), state.unshadowed_warnings()
    per_vertex_store.clear_object_record(floor, visibility_bake.KIND)
    unbaked, _ = render()
    np.testing.assert_array_equal(stale, unbaked)


def test_a_material_on_spherical_harmonics_with_a_visibility_bake_only_says_what_to_bake(engine):
    """The SH technique shadows from a transfer bake: an object baked for visibility alone renders unshadowed and
    the render says which bake its material needs; the SG floor beside it keeps its shadows and no such line."""
    scene, sphere, floor = _scene("sh_visibility_only")
    sphere.data.materials.append(fx.material("sh_visibility_only", technique="SH"))
    try:
        fx.bake_objects(scene, [sphere, floor], resolution=8)
        result = fx.render(scene)
    finally:
        fx.clear_bakes()
    assert "error" not in result, result.get("error")
    warnings = result["state"].unshadowed_warnings()
    assert warnings == [f"object '{sphere.name}' renders unshadowed: material 'sh_visibility_only' is shadowed by a "
                        "transfer bake and the object has a visibility bake only: press Bake Transfer in Render "
                        "Properties"], warnings
