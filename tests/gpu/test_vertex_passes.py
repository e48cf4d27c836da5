"""The per-vertex passes of the diffuse lobes' visibility (techniques/sg/sg_lobes.py draw_diffuse_visibility): the
SSDF's coverage at the quadrature points depends on the bake alone, so a redraw keeps it (the object target
asked for with the same buffers is current) and a new bake draws it again; the lobes' fractions, which follow
the world and the object's transform, are drawn every frame."""
import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


@pytest.fixture
def pass_counts(monkeypatch):
    """Full-screen passes drawn by the techniques, by name."""
    from sg_prt_addon.engine import renderer

    counts = {}
    original = renderer._DrawContext.full_screen_batch

    def counted(self, shader, name):
        counts[name] = counts.get(name, 0) + 1
        return original(self, shader, name)

    monkeypatch.setattr(renderer._DrawContext, "full_screen_batch", counted)
    return counts


def _scene(name):
    scene = fx.new_scene(name, 32, 32)
    fx.world_colour(scene, (0.5, 0.5, 0.5))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 0.9), radius=0.8, segments=16, rings=8)
    sphere.data.materials.append(fx.material(name + "_sphere_mat", model="GGX", roughness=0.4,
                                             diffuse_color=(0.6, 0.5, 0.4), specular_color=(0.1, 0.1, 0.1)))
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=4.0, segments=8)
    floor.data.materials.append(fx.material(name + "_floor_mat", diffuse_color=(0.7, 0.7, 0.7)))
    return scene, sphere, floor


def test_coverage_is_drawn_once_a_bake(engine, bakes, pass_counts):
    from sg_prt_addon.engine import render_engine

    scene, sphere, floor = _scene("vertex_passes")
    bakes(scene, [sphere, floor], resolution=8)
    render_engine.debug["timed_redraws"] = 2
    render_engine.debug["after_frame"] = lambda depsgraph, state, renderer, camera: renderer.read_output("diffuse")
    try:
        result = fx.render(scene)
    finally:
        render_engine.debug["timed_redraws"] = 0
        render_engine.debug["after_frame"] = None
    assert "error" not in result, result.get("error")
    # two baked objects, three frames (the render and two redraws)
    assert pass_counts == {"vertex_coverage": 2, "vertex_visibility": 6}, pass_counts
    # the redraws, with the coverage kept, shade as the first frame did
    first, last = result["passes"]["Diffuse"], result["after_frame"]
    assert np.abs(last - first).max() <= 1e-6 * np.abs(first).max()
    # a new bake: its buffers are new, the coverage is drawn again
    pass_counts.clear()
    bakes(scene, [sphere, floor], resolution=12)
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    assert pass_counts == {"vertex_coverage": 2, "vertex_visibility": 2}, pass_counts


def test_a_failed_coverage_pass_is_drawn_again(engine, bakes, monkeypatch):
    """A viewport whose coverage pass failed (an error injected into its draw) draws it again at its next
    redraw, and then shows what the final render shows: a failed pass is not taken for a current one."""
    from sg_prt_addon.engine import render_engine, renderer

    scene, sphere, floor = _scene("vertex_passes_failed")
    bakes(scene, [sphere, floor], resolution=8)
    original = renderer._DrawContext.full_screen_batch
    drawn, failures = [], []

    def failing_once(self, shader, name):
        if name == "vertex_coverage":
            if not failures:
                failures.append(name)
                raise RuntimeError("injected")
            drawn.append(name)
        return original(self, shader, name)

    def viewport(depsgraph, state, renderer_, camera):
        width, height = renderer_.size
        state.mark_all_dirty()                           # a new viewport uploads everything
        frame = render_engine.ViewportFrame()
        monkeypatch.setattr(renderer._DrawContext, "full_screen_batch", failing_once)
        try:
            with pytest.raises(RuntimeError, match="injected"):
                frame.update(state, camera, width, height)
            assert frame.update(state, camera, width, height)      # a failed draw is tried again
        finally:
            monkeypatch.setattr(renderer._DrawContext, "full_screen_batch", original)
        return frame.renderer.read_output("combined")

    render_engine.debug["after_frame"] = viewport
    try:
        result = fx.render(scene)
    finally:
        render_engine.debug["after_frame"] = None
    assert "error" not in result, result.get("error")
    assert failures == ["vertex_coverage"] and drawn == ["vertex_coverage", "vertex_coverage"]   # both objects
    np.testing.assert_allclose(result["after_frame"], result["passes"]["Combined"], rtol=1e-5, atol=1e-6)
