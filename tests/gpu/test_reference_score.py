"""The engine scored against the Monte Carlo reference on a scene with no cast shadows
(a convex sphere: its only occlusion is its own horizon, which the clamped cosine handles),
so the score measures the SG approximations of lighting and reflectance, not missing shadows."""
import numpy as np
import pytest
from scipy.ndimage import binary_erosion

import engine_fixtures as fx
from sg_prt_addon.core import image_error
from sg_prt_addon.core.reference import render_to_noise

SIZE = 64
POWER = 300.0


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _sphere_scene(name, model, **settings):
    scene = fx.new_scene(name, SIZE, SIZE)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0, segments=64, rings=32)
    sphere.data.materials.append(fx.material(name + "_material", model=model, **settings))
    fx.point_light(scene, name + "_light", (2.0, -3.0, 3.0), POWER, radius=0.1)
    return scene


def _score(scene):
    from sg_prt_addon.blender.reference_scene import reference_inputs

    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    combined = result["passes"]["Combined"]
    engine_image = combined[::-1, :, :3]                 # Blender rows start at the bottom
    # Interior pixels only: the reference anti-aliases silhouettes, the engine samples pixel centres.
    # (Combined is opaque over the world too; the Diffuse pass's alpha marks surfaces.)
    surface = binary_erosion(result["passes"]["Diffuse"][::-1, :, 3] > 0.5)
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    reference_scene, camera = reference_inputs(depsgraph, SIZE, SIZE)
    reference, error, _ = render_to_noise(reference_scene, camera, relative_error=0.012, max_samples=1024, seed=7)
    return (image_error.relative_rmse(engine_image, reference, surface),
            image_error.relative_mean_bias(engine_image, reference, surface),
            image_error.rmse_noise_floor(error, reference, surface))


@pytest.mark.parametrize("model, settings, rmse_bound", [
    ("GGX", dict(roughness=0.4, diffuse_color=(0.5, 0.5, 0.5), specular_color=(0.3, 0.3, 0.3)), 0.07),
    ("COOK_TORRANCE", dict(roughness=0.2, diffuse_color=(0.2, 0.3, 0.6), specular_color=(0.5, 0.5, 0.5)), 0.03),
])
def test_unshadowed_sphere_matches_the_reference(engine, model, settings, rmse_bound):
    rmse, bias, noise_floor = _score(_sphere_scene(f"score_{model.lower()}", model, **settings))
    print(f"{model}: relative RMSE {rmse:.4f} (reference noise floor {noise_floor:.4f}), bias {bias:+.4f}")
    assert noise_floor < 0.025
    assert rmse < rmse_bound
    assert abs(bias) < 0.03
