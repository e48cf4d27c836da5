"""Light Shadows = Shadow Maps (scene.sgprt.light_shadows; lighting/shadow_maps.py, engine/shadow_pass.py): the
setting and its panel, saved and reopened; the atlas drawn once for frames that change only the view; an object
without a bake shadowed by the maps.  The lookups against their mirror: test_engine_mirror.test_shadow_maps; the
image against the Monte Carlo reference: test_shadows_reference.test_point_light_shadow_maps; the lookup without
a GPU: tests/core/test_shadow_maps.py."""
import os

import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _scene(name, light_shadows="SHADOW_MAPS"):
    scene = fx.new_scene(name, 48, 48)
    scene.sgprt.light_shadows = light_shadows
    scene.camera.location = (0.0, -5.5, 4.0)
    scene.camera.rotation_euler = (np.radians(52.0), 0.0, 0.0)
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 0.9), radius=0.8, segments=24, rings=12)
    sphere.data.materials.append(fx.material(name + "_mat", model="GGX", roughness=0.4, diffuse_color=(0.6, 0.5, 0.4),
                                             specular_color=(0.3, 0.3, 0.3)))
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=6.0, segments=16)
    floor.data.materials.append(fx.material(name + "_floor_mat", model="GGX", roughness=0.6,
                                            diffuse_color=(0.7, 0.7, 0.7), specular_color=(0.05, 0.05, 0.05)))
    fx.world_colour(scene, (0.02, 0.02, 0.02))
    fx.point_light(scene, name + "_light", (1.2, -0.6, 3.6), 600.0, radius=0.05)
    return scene


def test_setting_panel_and_file(engine, tmp_path):
    import bpy

    from sg_prt_addon.blender import panels
    from sg_prt_addon.lighting import shadow_maps

    assert panels.SGPRT_PT_shadows.is_registered and panels.SGPRT_PT_shadows.bl_context == "render"
    scene = bpy.data.scenes.new("shadow_maps_defaults")
    assert scene.sgprt.light_shadows == "SHADOW_MAPS" and scene.sgprt.shadow_map_size == shadow_maps.DEFAULT_SIZE
    scene.sgprt.light_shadows = "SSDF"
    scene.sgprt.shadow_map_size = 512
    path = os.path.join(tmp_path, "shadow_settings.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    reopened = bpy.data.scenes["shadow_maps_defaults"]
    assert reopened.sgprt.light_shadows == "SSDF" and reopened.sgprt.shadow_map_size == 512
    bpy.ops.wm.read_factory_settings(use_empty=True)
    fx.ensure_registered()


def test_unbaked_object_is_shadowed_and_the_atlas_is_drawn_once(engine):
    """No bake: the maps alone shadow the floor under the sphere (its diffuse there drops below a tenth of the lit
    floor's); three more frames of the same scene (debug timed_redraws) reuse the atlas."""
    from sg_prt_addon.engine import render_engine

    counts = []
    render_engine.debug["timed_redraws"] = 3
    render_engine.debug["after_frame"] = lambda depsgraph, state, renderer, camera: counts.append(
        renderer.shadow_atlas.draw_count)
    try:
        mapped = fx.render(_scene("maps_unbaked"))
    finally:
        render_engine.debug["timed_redraws"] = 0
        render_engine.debug["after_frame"] = None
    assert "error" not in mapped, mapped.get("error")
    assert counts == [1]
    mapped = mapped["passes"]["Diffuse"]        # (the next render replaces last_render's contents)
    unshadowed = fx.render(_scene("maps_unbaked_ssdf", light_shadows="SSDF"))["passes"]["Diffuse"]   # no bake
    ratio = mapped[..., 0] / np.maximum(unshadowed[..., 0], 1e-9)
    covered = unshadowed[..., 3] > 0.5
    print("shadowed fraction of the surface", float((ratio[covered] < 0.1).mean()))
    assert (ratio[covered] < 0.1).mean() > 0.05
    assert np.all(ratio[covered] <= 1.0 + 1e-4)


def test_objects_are_drawn_into_the_tiles_they_reach(engine):
    """lighting/shadow_maps.in_tile (by which the plan leaves out faces and engine/shadow_pass draws each object):
    a box below a light is in its -z face's tile and not in its +z face's; a box with
    a non-finite corner is always drawn (never culled wrongly)."""
    from sg_prt_addon.engine import shadow_pass
    from sg_prt_addon.lighting import shadow_maps
    from validation import shadow_map_scene

    shadow_plan = shadow_maps.plan(shadow_map_scene.lights(), shadow_map_scene.BOUNDS, 256)
    tiles = dict(shadow_plan.tiles)
    below = shadow_pass.world_corners([np.eye(4)], [[[-0.5, -0.5, 0.0], [0.5, 0.5, 1.0]]])
    unknown = np.full((1, 8, 3), np.nan)
    assert shadow_maps.in_tile(tiles[5], below)[0]                       # -z: looking down
    assert 4 not in tiles                                                # +z sees nothing of the box: not drawn
    above = shadow_pass.world_corners([np.eye(4)], [[[-0.5, -0.5, 5.0], [0.5, 0.5, 6.0]]])
    assert not shadow_maps.in_tile(tiles[5], above)[0]
    assert shadow_maps.in_tile(tiles[5], unknown)[0]


def test_object_without_shadow_visibility_casts_none(engine):
    """Object > Visibility > Ray Visibility > Shadow off: the sphere is left out of the maps, so the floor under it
    is lit as without shadows (as Cycles and EEVEE read the setting; with it on, the same scene's floor is shadowed:
    test_unbaked_object_is_shadowed_and_the_atlas_is_drawn_once)."""
    import bpy

    scene = _scene("maps_no_cast")
    bpy.data.objects["maps_no_cast_sphere"].visible_shadow = False
    mapped = fx.render(scene)["passes"]["Diffuse"]
    unshadowed = fx.render(_scene("maps_no_cast_ssdf", light_shadows="SSDF"))["passes"]["Diffuse"]
    covered = unshadowed[..., 3] > 0.5
    ratio = mapped[..., 0] / np.maximum(unshadowed[..., 0], 1e-9)
    print("pixels darker than half", float((ratio[covered] < 0.5).mean()))
    assert (ratio[covered] < 0.5).mean() < 0.002
