"""Render Samples (scene.sgprt.render_samples): final renders average frames moved by sub-pixel offsets
(engine.anti_aliasing.pixel_jitter).  Four samples sample the same points as a render twice as large, so their
average must equal that render box-filtered down (Cycles' 1-pixel box filter); the render panel shows it.
Specular Anti-Aliasing (scene.sgprt.specular_anti_aliasing, sg_shading.glsl shade_footprint): one frame
shading each pixel over its footprint comes close to the box-filtered frames the jitter averages."""
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
    # each jittered frame's shading covers its cell of the pixel: the whole pixel for one frame, none when off
    assert [anti_aliasing.specular_footprint(n) for n in (1, 4, 16)] == [1.0, 0.5, 0.25]
    assert anti_aliasing.specular_footprint(16, enabled=False) == 0.0


def _scene(name, size, samples, specular_anti_aliasing=False, roughness=0.25):
    scene = fx.new_scene(name, size, size)
    scene.sgprt.render_samples = samples
    scene.sgprt.specular_anti_aliasing = specular_anti_aliasing
    fx.world_colour(scene, (0.05, 0.05, 0.05))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(fx.material(name + "_m", model="GGX", roughness=roughness,
                                             diffuse_color=(0.3, 0.3, 0.3), specular_color=(0.6, 0.6, 0.6)))
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
    scene = bpy.data.scenes.new("specular_aa_default")
    assert scene.sgprt.specular_anti_aliasing          # on unless turned off


def _surface_rmse(image, reference, mask):
    return float(np.sqrt(np.mean((image[mask, :3] - reference[mask, :3]) ** 2)) / np.mean(reference[mask, :3]))


def test_specular_anti_aliasing_comes_close_to_the_box_filter(engine):
    """A GGX 0.1 highlight on a 16-pixel sphere is narrower than a pixel: the pixel centres catch or miss it.
    Shading each pixel over its footprint must remove nearly all of that error against 64 jittered frames (the
    box filter of the same shading); a diffuse material is left as it was."""
    renders = {}
    for key, samples, footprint in (("reference", 64, False), ("centre", 1, False), ("footprint", 1, True),
                                    ("footprint 16", 16, True), ("centre 16", 16, False)):
        result = fx.render(_scene(f"specular_aa_{key}", 32, samples, footprint, roughness=0.1))
        assert "error" not in result
        renders[key] = result["passes"]["Combined"].copy()
        if key == "centre":
            mask = result["passes"]["Diffuse"][..., 3] > 0.5      # the sphere's pixels
    errors = {key: _surface_rmse(image, renders["reference"], mask) for key, image in renders.items()
              if key != "reference"}
    print("relative RMSE against 64 jittered frames: " + ", ".join(f"{k} {v:.3f}" for k, v in errors.items()))
    # measured: centre 3.43, footprint 0.031; with 16 frames 0.040 (centre) and 0.131 (footprint: each frame
    # shades its cell of the pixel): the highlight lies within 1/20 of one pixel, where the 8 x 8 reference
    # itself is uncertain by a few percent, which on its value of 16 (the surface's mean is 0.05) is the RMSE
    assert errors["centre"] > 1.0                               # the aliasing is there to remove
    assert errors["footprint"] < 0.05
    assert errors["footprint 16"] < 0.2

    diffuse = {}
    for footprint in (False, True):
        scene = _scene(f"specular_aa_diffuse_{footprint}", 32, 1, footprint)
        scene.objects[f"specular_aa_diffuse_{footprint}_sphere"].data.materials[0].sgprt.specular_color = (0, 0, 0)
        diffuse[footprint] = fx.render(scene)["passes"]["Combined"].copy()
    np.testing.assert_allclose(diffuse[True], diffuse[False], rtol=1e-5, atol=1e-6)     # measured: 2.2e-7
