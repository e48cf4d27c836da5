"""The engine scored against the Monte Carlo reference on a scene with no cast shadows
(a convex sphere: its only occlusion is its own horizon, which the clamped cosine handles),
so the score measures the SG approximations of lighting and reflectance, not missing shadows."""
import engine_fixtures as fx
import numpy as np
import pytest
from scipy.ndimage import binary_erosion

from validation import image_error
from validation.reference import render_to_noise

pytestmark = pytest.mark.reference      # against the Monte Carlo reference: the two full tiers run it

SIZE = 64
POWER = 300.0


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _srgb_checker(name):
    """An 8-bit sRGB image (Blender's default for byte images): the engine and the reference
    must both decode it to scene-linear colour."""
    import bpy

    image = bpy.data.images.new(name, 8, 8, alpha=False)
    checker = (np.add.outer(np.arange(8), np.arange(8)) % 2).astype(np.float32)
    rgba = np.stack([0.2 + 0.7 * checker, 0.5 * np.ones((8, 8)), 0.9 - 0.7 * checker, np.ones((8, 8))], -1)
    image.pixels.foreach_set(rgba.astype(np.float32).ravel())
    assert not image.is_float and image.colorspace_settings.name == "sRGB"
    return image


def _sphere_scene(name, model, **settings):
    if settings.pop("srgb_texture", False):
        settings["diffuse_color_texture"] = _srgb_checker(name + "_checker")
    scene = fx.new_scene(name, SIZE, SIZE)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0, segments=64, rings=32)
    sphere.data.materials.append(fx.material(name + "_material", model=model, **settings))
    fx.point_light(scene, name + "_light", (2.0, -3.0, 3.0), POWER, radius=0.1)
    return scene


def _score(scene):
    from validation.reference_scene import reference_inputs

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
    ("GGX", dict(roughness=0.6, diffuse_color=(1.0, 1.0, 1.0), specular_color=(0.1, 0.1, 0.1),
                 srgb_texture=True), 0.05),
    # brushed along the object's z axis, turned 0.6 rad about the normal: 0.068 measured (0.376 while the
    # reference took the UV tangents whatever the material said)
    ("ASHIKHMIN_SHIRLEY", dict(nu=50.0, nv=800.0, lobe_count=6, diffuse_color=(0.1, 0.1, 0.1),
                               specular_color=(0.8, 0.8, 0.8), tangent_source="OBJECT_AXIS",
                               tangent_axis=(0.0, 0.0, 1.0), tangent_rotation=0.6), 0.1),
])
def test_unshadowed_sphere_matches_the_reference(engine, model, settings, rmse_bound):
    name = f"score_{model.lower()}" + ("_textured" if "srgb_texture" in settings else "")
    rmse, bias, noise_floor = _score(_sphere_scene(name, model, **dict(settings)))
    print(f"{model}: relative RMSE {rmse:.4f} (reference noise floor {noise_floor:.4f}), bias {bias:+.4f}")
    assert noise_floor < 0.025
    assert rmse < rmse_bound
    assert abs(bias) < 0.03
