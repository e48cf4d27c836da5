"""Render Samples (scene.sgprt.render_samples): final renders average frames moved by sub-pixel offsets
(engine.anti_aliasing.pixel_jitter).  Four samples sample the same points as a render twice as large, so their
average must equal that render box-filtered down (Cycles' 1-pixel box filter); the render panel shows it."""
import engine_fixtures as fx
import numpy as np
import pytest

from sg_prt_addon.engine import anti_aliasing


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def test_pixel_jitter_patterns():
    grid = anti_aliasing.pixel_jitter(4)
    np.testing.assert_allclose(sorted(map(tuple, grid)), [(-0.25, -0.25), (-0.25, 0.25), (0.25, -0.25), (0.25, 0.25)])
    assert np.array_equal(anti_aliasing.pixel_jitter(1), [[0.0, 0.0]])
    r2 = anti_aliasing.pixel_jitter(7)
    assert r2.shape == (7, 2) and np.all(r2 >= -0.5) and np.all(r2 < 0.5)
    assert np.abs(r2.mean(axis=0)).max() < 1e-12         # centred: every stratum once per axis
    assert len(set(np.round(r2[:, 1], 9))) == 7


def _scene(name, size, samples):
    scene = fx.new_scene(name, size, size)
    scene.sgprt.render_samples = samples
    fx.world_colour(scene, (0.05, 0.05, 0.05))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(fx.material(name + "_m", model="GGX", roughness=0.25, diffuse_color=(0.3, 0.3, 0.3),
                                             specular_color=(0.6, 0.6, 0.6)))
    fx.point_light(scene, name + "_light", (2.0, -3.0, 3.0), 300.0, radius=0.05)
    return scene


def test_four_samples_equal_a_box_filtered_double_size_render(engine):
    small = dict(fx.render(_scene("samples4", 32, 4)))        # last_render is reused by the next render
    assert "error" not in small and small["timings"]["samples"] == 4
    large = fx.render(_scene("samples1_large", 64, 1))
    assert large["timings"]["samples"] == 1
    for name in ("Combined", "Diffuse", "Specular"):
        image = large["passes"][name]
        filtered = image.reshape(32, 2, 32, 2, 4).mean(axis=(1, 3))
        error = np.abs(small["passes"][name] - filtered).max() / np.abs(filtered).max()
        print(f"{name}: max |4 samples - 2x box-filtered| / max = {error:.2e}")
        assert error < 1e-4
    centre = fx.render(_scene("samples1", 32, 1))["passes"]["Combined"]
    assert np.abs(centre - small["passes"]["Combined"]).max() > 1e-2       # the samples did change the image


def test_render_panel_shows_the_setting(engine):
    import bpy

    from sg_prt_addon.blender import panels

    assert bpy.types.Scene.bl_rna.properties.get("sgprt") is not None
    assert panels.SGPRT_PT_sampling.is_registered and panels.SGPRT_PT_sampling.bl_context == "render"
