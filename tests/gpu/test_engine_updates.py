"""Viewport update logic (SceneState.update with depsgraph.updates): what an edit re-exports.

view_draw needs a window, but view_update's logic is plain Python over depsgraph.updates:
it runs here from a depsgraph_update_post handler, as Blender calls it after each edit.
"""
import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture()
def tracked_scene(blender):
    """A scene with two spheres and a light, a synced SceneState and a handler feeding it updates."""
    fx.ensure_registered()
    bpy = blender
    # the context's scene: its depsgraph is the one Blender evaluates and reports updates for
    scene = bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    material = fx.material("updates_material", roughness=0.3)
    first = fx.uv_sphere(scene, "updates_a", (0.0, 0.0, 1.0), segments=12, rings=6)
    first.data.materials.append(material)
    second = fx.uv_sphere(scene, "updates_b", (2.0, 0.0, 1.0), segments=12, rings=6)
    fx.point_light(scene, "updates_light", (0.0, -2.0, 3.0), 100.0)
    view_layer = bpy.context.view_layer
    try:
        with fx.tracked_state(scene, view_layer) as state:
            assert set(state.objects) == {first.name, second.name} and len(state.lights) == 1
            yield bpy, scene, view_layer, state, material, first, second
    finally:
        for obj in list(scene.objects):
            bpy.data.objects.remove(obj)


def _exports():
    from sg_prt_addon.blender import export
    return export.export_counter["meshes"]


def test_material_edit_does_not_reexport_meshes(tracked_scene):
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    before = _exports()
    material.sgprt.roughness = 0.8
    material.update_tag()            # what the properties editor does after an edit
    view_layer.update()
    assert _exports() == before
    assert state.materials[material.name].roughness == pytest.approx(0.8)
    dirty = state.consume_dirty()
    assert dirty.materials == {material.name} and not dirty.meshes


def test_transform_edit_moves_without_reexport(tracked_scene):
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    before = _exports()
    second.location.x = 3.5
    view_layer.update()
    assert _exports() == before
    assert state.objects[second.name].matrix_world[0, 3] == pytest.approx(3.5)
    assert not state.consume_dirty().meshes


def test_geometry_edit_reexports_only_that_mesh(tracked_scene):
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    before = _exports()
    second.data.vertices[0].co.x += 0.25
    second.data.update()
    view_layer.update()
    assert _exports() == before + 1
    dirty = state.consume_dirty()
    assert dirty.meshes == {state.objects[second.name].mesh_key}
    moved = state.meshes[state.objects[second.name].mesh_key].positions
    assert np.any(np.isclose(moved[:, 0], second.data.vertices[0].co.x))


def test_light_edit_and_removed_object(tracked_scene):
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    before = _exports()
    light = next(obj for obj in scene.objects if obj.type == "LIGHT")
    light.data.energy = 250.0
    light.data.update_tag()
    view_layer.update()
    assert state.consume_dirty().lights
    assert state.lights[0].colour_intensity[0] == pytest.approx(250.0 / (4 * np.pi))
    second_name = second.name
    bpy.data.objects.remove(second)
    view_layer.update()
    assert second_name not in state.objects and first.name in state.objects
    assert _exports() == before



def test_linked_duplicates_export_their_mesh_once(tracked_scene):
    """Linked duplicates of a plain mesh share its export: added, the mesh is exported once for all of them;
    an edit of the mesh re-exports it once, not once per object; a modifier gives an object its own export."""
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    before = _exports()
    duplicates = []
    for index in range(3):
        duplicate = fx.add_object(scene, bpy.data.objects.new(f"updates_duplicate{index}", first.data))
        duplicate.location = (-2.0 * (index + 1), 0.0, 1.0)
        duplicates.append(duplicate)
    view_layer.update()
    key = state.objects[first.name].mesh_key
    assert all(state.objects[duplicate.name].mesh_key == key for duplicate in duplicates)
    assert state.objects[second.name].mesh_key != key and _exports() == before + 1
    state.consume_dirty()
    first.data.vertices[0].co.x += 0.25
    first.data.update()
    view_layer.update()
    assert _exports() == before + 2 and state.consume_dirty().meshes == {key}
    duplicates[0].modifiers.new("updates_bevel", "BEVEL")
    view_layer.update()
    assert state.objects[duplicates[0].name].mesh_key != key
    assert state.objects[duplicates[1].name].mesh_key == key


def test_world_space_export_matches_blender(tracked_scene):
    """export.to_world against Blender's own evaluated world-space vertex positions and normals."""
    from sg_prt_addon.blender import export

    bpy, scene, view_layer, state, material, first, second = tracked_scene
    first.scale = (1.0, -2.0, 0.5)        # mirrored and non-uniform
    first.rotation_euler = (0.3, 0.2, 0.1)
    view_layer.update()
    entry = state.objects[first.name]
    world = export.to_world(state.meshes[entry.mesh_key], entry.matrix_world)
    matrix = np.array(first.matrix_world)
    expected = np.array([matrix @ np.append(v.co, 1.0) for v in first.data.vertices])[:, :3]
    corners = np.array([loop.vertex_index for loop in first.data.loops])
    np.testing.assert_allclose(world.positions, expected[corners], atol=1e-5)
    blender_normals = np.array([n.vector for n in first.data.corner_normals]) if hasattr(
        first.data, "corner_normals") else None
    if blender_normals is not None:
        normal_matrix = np.linalg.inv(matrix[:3, :3]).T
        reference = blender_normals @ normal_matrix.T
        reference /= np.linalg.norm(reference, axis=1, keepdims=True)
        np.testing.assert_allclose(world.normals, reference, atol=1e-5)
    assert np.all(world.tangents[:, 3] == -state.meshes[entry.mesh_key].tangents[:, 3])


def test_lights_beyond_the_shader_limit_are_merged_not_dropped():
    """More omni point lights than the shader takes: nearby ones drawn as one light of their summed power,
    none left out; area lights first get fewer patches; spot lights alone past the limit: the dimmest left out."""
    from sg_prt_addon.blender import export
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.techniques import shader_sources

    limit = shader_sources.MAX_POINT_LIGHTS
    lights = [export.LightExport(f"point{i}", "POINT", (0.0, 0.0, float(i)), (0.0, 0.0, -1.0), (float(i),) * 3)
              for i in range(limit + 3)]
    lights.append(export.LightExport("sun", "SUN", (0.0, 0.0, 0.0), (0.0, 0.0, -1.0), (2.0, 2.0, 2.0), angle=0.1))
    data = scene_state.light_data(lights)
    assert len(data.point_radius) == limit and len(data.sun_sharpness) == 1
    np.testing.assert_allclose(data.point_intensity[:, 0].sum(), sum(range(limit + 3)), rtol=1e-6)
    state = scene_state.SceneState()
    state.lights = lights
    assert state.dropped_lights(limit, shader_sources.MAX_SUNS) == []
    assert any("point lights drawn as" in line for line in state.light_budget_warnings(limit, shader_sources.MAX_SUNS))

    areas = [export.LightExport(f"area{i}", "AREA", (float(i), 0.0, 3.0), (0.0, 0.0, -1.0), (10.0,) * 3,
                                edge_u=(1.0, 0.0, 0.0), edge_v=(0.0, 1.0, 0.0)) for i in range(64)]
    state.lights = areas
    assert len(scene_state.light_data(areas).point_radius) == 64
    assert state.light_budget_warnings(limit, shader_sources.MAX_SUNS)[0].startswith(
        "area lights cut into 1 x 1 patches instead of 4 x 4")

    spots = [export.LightExport(f"spot{i}", "POINT", (0.0, 0.0, 1.0), (0.0, 0.0, -1.0), (float(i),) * 3,
                                is_spot=True, spot_size=1.0) for i in range(limit + 2)]
    state.lights = spots
    assert state.dropped_lights(limit, shader_sources.MAX_SUNS) == ["spot1", "spot0"]


def test_viewport_camera_from_view_matrices_matches_render_camera(tracked_scene):
    """view_draw builds its camera from region_data's matrices with export.camera_from_view:
    fed the scene camera's own matrices it must equal the final render's camera."""
    from sg_prt_addon.blender import export

    bpy, scene, view_layer, state, material, first, second = tracked_scene
    camera = bpy.data.objects.new("updates_camera", bpy.data.cameras.new("updates_camera"))
    scene.collection.objects.link(camera)
    camera.location = (1.0, -4.0, 2.0)
    camera.rotation_euler = (1.2, 0.1, 0.3)
    view_layer.update()
    depsgraph = view_layer.depsgraph
    rendered = export.export_camera(camera, depsgraph, 64, 48)
    projection = camera.calc_matrix_camera(depsgraph, x=64, y=48)
    viewport = export.camera_from_view(camera.matrix_world.inverted(), projection, True)
    np.testing.assert_allclose(viewport.view, rendered.view, atol=1e-6)
    np.testing.assert_allclose(viewport.projection, rendered.projection, atol=1e-6)
    np.testing.assert_allclose(viewport.position, (1.0, -4.0, 2.0), atol=1e-5)
    np.testing.assert_allclose(viewport.forward, rendered.forward, atol=1e-6)


def test_new_object_with_new_material_is_uploaded(tracked_scene):
    bpy, scene, view_layer, state, material, first, second = tracked_scene
    third = fx.uv_sphere(scene, "updates_c", (-2.0, 0.0, 1.0), segments=8, rings=4)
    fresh = fx.material("updates_fresh", model="BLINN_PHONG")
    third.data.materials.append(fresh)
    view_layer.update()
    dirty = state.consume_dirty()
    assert third.name in state.objects
    assert fresh.name in dirty.materials and state.objects[third.name].mesh_key in dirty.meshes


def test_area_lights_count_their_patches_against_the_limit():
    """An area light takes a point light a patch (about 4 x 4 at the default): past the limit every area light gets
    fewer patches, the same for all (here 3 x 3), and none is left out."""
    from sg_prt_addon.blender import export
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.techniques import shader_sources

    def area(i):
        return export.LightExport(f"area{i}", "AREA", (0.0, 0.0, 3.0), (0.0, 0.0, -1.0), (100.0 + i,) * 3,
                                  edge_u=(1.0, 0.0, 0.0), edge_v=(0.0, 1.0, 0.0))
    fitting = shader_sources.MAX_POINT_LIGHTS // 16
    lights = [area(i) for i in range(fitting + 2)]
    data = scene_state.light_data(lights)
    assert len(data.point_radius) == 9 * (fitting + 2)
    assert np.all(data.point_emitter[:, 0] == 1) and np.all(data.spot_size < 0)
    assert np.allclose(data.point_intensity.sum(axis=0), sum(100.0 + i for i in range(fitting + 2)) / np.pi,
                       rtol=1e-5)                       # each light's patches carry P / pi along its normal
    state = scene_state.SceneState()
    state.lights = lights
    assert state.dropped_lights(shader_sources.MAX_POINT_LIGHTS, shader_sources.MAX_SUNS) == []
    assert len(scene_state.light_data(lights[:1], area_patches=2).point_radius) == 4
