"""Every texture and target within the GPU's side limit (engine/gpu_limits.py): baked meshes of every row count
render the same at the driver's limit and at smaller ones forced by SG_PRT_MAX_TEXTURE_SIZE; what cannot fit is
named, and the rest of the scene renders."""
import dataclasses

import engine_fixtures as fx
import numpy as np
import pytest

from sg_prt_addon.engine import gpu_limits
from sg_prt_addon.visibility import per_vertex

# packed rows [1, w_0 .. w_{N-1}]: 1-3 terms make one vec4 row, 63 terms MAX_ROWS
TERM_COUNTS = (1, 2, 3, 4, 7, 15, 31, 63)
FORCED_SIDES = (8192, 4096)


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _scene(name, floor_segments=16):
    scene = fx.new_scene(name, 48, 48)
    scene.camera.location = (0.0, -5.5, 4.0)
    scene.camera.rotation_euler = (np.radians(52.0), 0.0, 0.0)
    fx.world_colour(scene, (0.3, 0.3, 0.3))         # the diffuse lobes' per-vertex passes run
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 0.9), radius=0.8, segments=16, rings=8)
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=6.0, segments=floor_segments)
    fx.point_light(scene, name + "_light", (1.2, -0.6, 3.6), 600.0, radius=0.05)
    return scene, sphere, floor


def _truncated(bake, terms):
    """The bake's PCA cut to its first `terms` terms (a bake at that count, without baking again)."""
    return dataclasses.replace(bake, coefficients=np.ascontiguousarray(bake.coefficients[:, :terms]),
                               basis=np.ascontiguousarray(bake.basis[:terms]), terms=terms,
                               rms_error_by_terms=bake.rms_error_by_terms[:terms + 1])


def _render(scene, monkeypatch, side):
    if side is None:
        monkeypatch.delenv(gpu_limits.LIMIT_VARIABLE, raising=False)
    else:
        monkeypatch.setenv(gpu_limits.LIMIT_VARIABLE, str(side))
    result = dict(fx.render(scene))         # render_engine.last_render, which the next render clears
    assert "error" not in result, result.get("error")
    return result


def test_every_row_count_renders_the_same_at_every_texture_limit(engine, monkeypatch):
    from sg_prt_addon.engine import scene_state

    scene, sphere, floor = _scene("texture_limits")
    unbaked = _render(scene, monkeypatch, None)["passes"]["Combined"]
    bakes = fx.bake_objects(scene, [sphere, floor], resolution=8, terms=per_vertex.MAX_TERMS,
                            max_terms=per_vertex.MAX_TERMS)
    try:
        for terms in TERM_COUNTS:
            cut = {name: _truncated(bake, terms) for name, bake in bakes.items()}
            scene_state.visibility_provider = lambda object_eval, cut=cut: cut.get(object_eval.name)
            at_driver = _render(scene, monkeypatch, None)
            assert len(at_driver["state"].visibility) == 2, at_driver["state"].visibility_status
            image = at_driver["passes"]["Combined"]
            assert np.all(np.isfinite(image))
            # shadowed: the sphere's shadow on the floor, nothing brighter than unbaked
            assert (image[..., 0] < 0.5 * unbaked[..., 0]).mean() > 0.02, terms
            assert np.all(image[..., :3] <= unbaked[..., :3] * 1.001 + 1e-6)
            for side in FORCED_SIDES:
                smaller = _render(scene, monkeypatch, side)
                assert smaller["state"].warnings == at_driver["state"].warnings
                # another layout of the same rows: the same image
                np.testing.assert_allclose(smaller["passes"]["Combined"], image, atol=1e-6, err_msg=f"{terms}, {side}")
    finally:
        fx.clear_bakes()


def test_the_layout_fits_every_side(engine):
    """Any row count, the passes' texels and the vertices' sums fit a row of vertices_per_row(side) vertices."""
    from sg_prt_addon.techniques import shader_sources
    from sg_prt_addon.techniques.sg import sg_lobes

    for side in (gpu_limits.SMALLEST_SIDE, 4096, 8192, 16384, gpu_limits.driver_texture_size()):
        per_row = per_vertex.vertices_per_row(side)
        for texels in (per_vertex.MAX_ROWS, sg_lobes.COVERAGE_TEXELS, shader_sources.max_varyings()
                       - shader_sources.SURFACE_VARYINGS):
            assert per_row * texels <= side
        assert per_vertex.texture_refusal(per_row * side, side) is None
        assert "over this GPU's limit" in per_vertex.texture_refusal(per_row * side + 1, side)


def test_a_mesh_past_the_limit_is_named_and_the_rest_renders(engine, monkeypatch):
    """At the smallest side (1024: 32 vertices a row, 32,768 vertices) a floor of 36,481 vertices cannot have its
    visibility textures: it renders unshadowed, named with why; the sphere keeps its shadows."""
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.visibility.pipeline import BakeResult

    scene, sphere, floor = _scene("texture_limit_refused", floor_segments=190)
    # a glossy floor: the random bakes below are visible almost everywhere, which a diffuse floor barely shows
    floor.data.materials.append(fx.material("texture_limit_glossy"))
    resolution, terms = 8, 3
    rng = np.random.default_rng(1)

    def bake(count):
        return BakeResult(coefficients=rng.normal(0.0, 0.05, (count, terms)).astype(np.float32),
                          basis=rng.normal(0.0, 0.05, (terms, resolution, resolution)).astype(np.float32),
                          mean=np.ones((resolution, resolution), np.float32), resolution=resolution, terms=terms,
                          rms_error=0.0, rms_error_by_terms=np.zeros(terms + 1), vertex_count=count,
                          topology_hash="")
    assert len(floor.data.vertices) > per_vertex.vertices_per_row(gpu_limits.SMALLEST_SIDE) * gpu_limits.SMALLEST_SIDE
    bakes = {floor.name: bake(len(floor.data.vertices)), sphere.name: bake(len(sphere.data.vertices))}
    scene_state.visibility_provider = lambda object_eval: bakes.get(object_eval.name)
    try:
        at_driver = _render(scene, monkeypatch, None)
        smallest = _render(scene, monkeypatch, gpu_limits.SMALLEST_SIDE)
    finally:
        fx.clear_bakes()
    assert not any("limit" in line for line in at_driver["state"].warnings), at_driver["state"].warnings
    named = [line for line in smallest["state"].warnings if "over this GPU's limit" in line]
    assert len(named) == 1 and named[0].startswith(f"object '{floor.name}' renders without its visibility bake")
    assert np.all(np.isfinite(smallest["passes"]["Combined"]))
    # the floor as without its bake, the sphere with its own: the image differs from the driver's only on the floor
    assert not np.allclose(smallest["passes"]["Combined"], at_driver["passes"]["Combined"])


def test_an_image_past_the_limit_is_rendered_smaller_and_named(engine, monkeypatch):
    scene, sphere, floor = _scene("texture_limit_image")
    wide = np.ones((4, gpu_limits.SMALLEST_SIDE * 2 + 3, 4), np.float32)
    wide[..., :3] = np.linspace(0.2, 0.9, wide.shape[1])[None, :, None]
    material = fx.material("texture_limit_image", diffuse_color_texture=fx.image("texture_limit_wide", wide))
    floor.data.materials.append(material)
    at_driver = _render(scene, monkeypatch, None)
    smallest = _render(scene, monkeypatch, gpu_limits.SMALLEST_SIDE)
    assert not any("texture_limit_wide" in line for line in at_driver["state"].warnings)
    named = [line for line in smallest["state"].warnings if "texture_limit_wide" in line]
    # the atlas of its mip levels is half as wide again: the image must fit in 2/3 of the side
    assert named == [f"image 'texture_limit_wide' is {wide.shape[1]} x 4, over this GPU's limit of "
                     f"{gpu_limits.SMALLEST_SIDE} texels a side (with its mip levels): rendered at 1/4 of its size"]
    # a smooth ramp box-averaged by 4: the same floor within the ramp's step over 4 texels
    np.testing.assert_allclose(smallest["passes"]["Combined"], at_driver["passes"]["Combined"], atol=2e-3)


def test_a_render_past_the_limit_says_so(engine, monkeypatch):
    import bpy

    scene, *_ = _scene("texture_limit_size")
    scene.render.resolution_x = gpu_limits.SMALLEST_SIDE + 1
    scene.render.resolution_y = 4
    monkeypatch.setenv(gpu_limits.LIMIT_VARIABLE, str(gpu_limits.SMALLEST_SIDE))
    with pytest.raises(RuntimeError, match=r"over this GPU's limit of 1024 a side"):
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)


def test_within_side_box_averages(engine):
    from sg_prt_addon.engine.renderer import within_side

    pixels = np.arange(5 * 7 * 4, dtype=np.float32).reshape(5, 7, 4)
    same, factor = within_side(pixels, 7)
    assert factor == 1 and same is pixels
    half, factor = within_side(pixels, 4)
    assert factor == 2 and half.shape == (3, 4, 4)
    np.testing.assert_allclose(half[0, 0], pixels[:2, :2].mean(axis=(0, 1)))
    np.testing.assert_allclose(half[2, 3], pixels[4, 6])        # the last box: the edge texel repeated
