"""The viewport's redraw logic (render_engine.ViewportFrame, what view_draw runs) inside a real render's
GPU context: the scene is drawn again only when something changed, and the image is the final render's."""
import dataclasses

import engine_fixtures as fx
import numpy as np
import pytest

from validation import viewport_timing


@pytest.fixture(scope="module")
def viewport_scene(blender):
    fx.ensure_registered()
    scene = fx.new_scene("viewport_frame", 96, 64)
    material = fx.material("viewport_frame_material", model="GGX", roughness=0.3)
    sphere = fx.uv_sphere(scene, "viewport_frame_sphere", (0.0, 0.0, 1.0), segments=16, rings=8)
    sphere.data.materials.append(material)
    fx.plane(scene, "viewport_frame_floor", (0.0, 0.0, 0.0))
    fx.point_light(scene, "viewport_frame_light", (2.0, -3.0, 4.0), 500.0, radius=0.2)
    fx.world_colour(scene, (0.05, 0.06, 0.08))
    yield scene, material
    blender.data.scenes.remove(scene)


def _render_with(scene, after_frame):
    from sg_prt_addon.engine import render_engine

    render_engine.debug["after_frame"] = after_frame
    try:
        result = fx.render(scene)
    finally:
        render_engine.debug["after_frame"] = None
    assert "error" not in result, result.get("error")
    return result


def test_unchanged_redraws_reuse_the_image(viewport_scene):

    scene, _ = viewport_scene

    def redraw(depsgraph, state, renderer, camera):
        return viewport_timing.time_viewport_redraws(state, camera, *renderer.size, count=4)

    result = _render_with(scene, redraw)
    first, redraws, draws, image = result["after_frame"]
    assert draws == 1 and len(redraws) == 4
    # the viewport draws what the final render drew: same state, camera and shaders
    np.testing.assert_allclose(image, result["passes"]["Combined"], rtol=1e-5, atol=1e-6)


def test_edits_and_view_changes_redraw(viewport_scene):
    from sg_prt_addon.engine import render_engine

    scene, material = viewport_scene

    def edit_material(state):
        state.dirty.materials.add(material.name)        # what view_update records after an edit

    def check(depsgraph, state, renderer, camera):
        width, height = renderer.size
        edited = viewport_timing.time_viewport_redraws(state, camera, width, height, count=3, edit=edit_material)
        frame = render_engine.ViewportFrame()
        drew = [frame.update(state, camera, width, height)]
        view = camera.view.copy()
        view[0, 3] += 0.1                                # the view moved
        moved = dataclasses.replace(camera, view=view)
        drew.append(frame.update(state, moved, width, height))
        drew.append(frame.update(state, moved, width, height))
        drew.append(frame.update(state, moved, width + 2, height))     # the region was resized
        drew.append(frame.update(state, moved, width + 2, height, background_alpha=0.0))   # transparent film
        return edited[2], drew

    result = _render_with(scene, check)
    draws_with_edits, drew = result["after_frame"]
    assert draws_with_edits == 4
    assert drew == [True, True, False, True, True]
