"""SSDF shadows (wang2009 eq. 39-43) scored against the Monte Carlo reference (exact ray-traced
visibility): (a) the sharp shadow of a sphere lit by a small point light on a 64 x 64 floor,
(b) environment shadows of the sphere under courtyard.exr.  Each scene is rendered twice by the
engine, with the bakes (HAS_VISIBILITY) and without (unshadowed), and scored as
test_reference_score.py scores: relative RMSE over the surface pixels (Diffuse-pass alpha,
eroded by one pixel) against validation.reference.render_to_noise.  The shadowed image must beat the
unshadowed one clearly, so the shadows are real; the bounds are measured values + margin."""
import os

import engine_fixtures as fx
import numpy as np
import pytest
from scipy.ndimage import binary_erosion

from validation import image_error
from validation.reference import render_to_noise

pytestmark = pytest.mark.reference      # against the Monte Carlo reference: the two full tiers run it

SIZE = 64
BAKE_RESOLUTION = 16


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _scene(name):
    scene = fx.new_scene(name, SIZE, SIZE)
    scene.camera.location = (0.0, -5.5, 4.0)
    scene.camera.rotation_euler = (np.radians(52.0), 0.0, 0.0)
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 0.9), radius=0.8, segments=48, rings=24)
    sphere.data.materials.append(fx.material(name + "_sphere_mat", model="GGX", roughness=0.4,
                                             diffuse_color=(0.6, 0.5, 0.4), specular_color=(0.3, 0.3, 0.3)))
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=6.0, segments=64)
    floor.data.materials.append(fx.material(name + "_floor_mat", model="GGX", roughness=0.6,
                                            diffuse_color=(0.7, 0.7, 0.7), specular_color=(0.05, 0.05, 0.05)))
    return scene, sphere, floor


def _engine_image(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    surface = binary_erosion(result["passes"]["Diffuse"][::-1, :, 3] > 0.5)
    return result["passes"]["Combined"][::-1, :, :3], surface, result


def _reference(scene, relative_error):
    from validation.reference_scene import reference_inputs

    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    reference_scene, camera = reference_inputs(depsgraph, SIZE, SIZE)
    reference, error, _ = render_to_noise(reference_scene, camera, relative_error=relative_error, max_samples=512, seed=11)
    return reference, error


def _scores(scene, sphere, floor, bakes, relative_error):
    unshadowed, surface, _ = _engine_image(scene)
    bakes(scene, [sphere, floor], resolution=BAKE_RESOLUTION)
    shadowed, surface_again, result = _engine_image(scene)
    assert len(result["state"].visibility) == 2, result["state"].visibility_status
    assert np.array_equal(surface, surface_again)
    reference, error = _reference(scene, relative_error)
    scores = {name: (image_error.relative_rmse(image, reference, surface),
                     image_error.relative_mean_bias(image, reference, surface))
              for name, image in (("shadowed", shadowed), ("unshadowed", unshadowed))}
    noise = image_error.rmse_noise_floor(error, reference, surface)
    if os.environ.get("SGPRT_SHADOW_DUMP"):          # a directory: .npy images to look at
        for name, image in (("shadowed", shadowed), ("unshadowed", unshadowed), ("reference", reference)):
            np.save(os.path.join(os.environ["SGPRT_SHADOW_DUMP"], f"{scene.name}_{name}.npy"), image)
    print(f"{scene.name}: " + ", ".join(f"{k} RMSE {v[0]:.4f} bias {v[1]:+.4f}" for k, v in scores.items())
          + f", reference noise floor {noise:.4f}")
    return scores, noise


def test_point_light_shadow_of_a_sphere_on_a_floor(engine, bakes):
    scene, sphere, floor = _scene("shadow_point")
    fx.world_colour(scene, (0.02, 0.02, 0.02))
    fx.point_light(scene, "shadow_point_light", (1.2, -0.6, 3.6), 600.0, radius=0.05)
    scores, noise = _scores(scene, sphere, floor, bakes, 0.012)
    assert noise < 0.04
    # measured (64 x 64, bake R = 16): shadowed 0.067 (bias +0.001), unshadowed 0.315 (bias +0.094),
    # reference noise floor 0.025
    assert scores["shadowed"][0] < 0.10
    assert abs(scores["shadowed"][1]) < 0.03
    assert scores["shadowed"][0] < 0.4 * scores["unshadowed"][0]


def test_environment_shadows_under_courtyard(engine, bakes):
    scene, sphere, floor = _scene("shadow_environment")
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    scores, noise = _scores(scene, sphere, floor, bakes, 0.025)
    assert noise < 0.04
    # measured (64 x 64, bake R = 16): shadowed 0.056 (bias +0.001; 0.062 with eq. 30's reading of the diffuse
    # lobes), unshadowed 0.194 (bias +0.101), reference noise floor 0.028
    assert scores["shadowed"][0] < 0.08
    assert abs(scores["shadowed"][1]) < 0.03
    assert scores["shadowed"][0] < 0.5 * scores["unshadowed"][0]


def test_environment_shadows_under_a_uniform_sky(engine, bakes):
    """A constant world (Blender's default kind): the diffuse lobe is the cosine, broad enough that eq.
    30's half-space reading of the SSDF at the normal took the sphere for half of the floor's sky; the
    quadrature of visibility.broad_lobes weighs the SSDF over the whole hemisphere."""
    scene, sphere, floor = _scene("shadow_uniform_sky")
    fx.world_colour(scene, (1.0, 1.0, 1.0))
    scores, noise = _scores(scene, sphere, floor, bakes, 0.01)
    assert noise < 0.02
    # measured (64 x 64, bake R = 16): shadowed 0.0175 (bias -0.005), unshadowed 0.197 (bias +0.114),
    # reference noise floor 0.010; eq. 30's reading at the vertices gave 0.062 (bias -0.051)
    assert scores["shadowed"][0] < 0.03
    assert abs(scores["shadowed"][1]) < 0.015
    assert scores["shadowed"][0] < 0.2 * scores["unshadowed"][0]


@pytest.mark.parametrize("world", ["courtyard", "colour"])
def test_per_vertex_diffuse_visibility(engine, bakes, world):
    """The broad diffuse lobes (the environment's SG mixture, or the constant world's cosine lobe) take
    their visibility at the vertices (the renderer's per-vertex passes, interpolated): the Diffuse pass
    against the same fractions computed at each pixel from its interpolated rows (techniques.sg.sg_shading, the
    same G-buffer pixels), relative RMSE over each object's pixels.  Measured (64 x 64, bake R = 16),
    courtyard: sphere 0.0018, floor 0.0005 (the courtyard score above: 0.0559, 0.0626 with eq. 30's
    reading at the vertices); colour: sphere 0.0017, floor 0.0004."""
    import dataclasses

    from sg_prt_addon.techniques.sg import sg_shading

    scene, sphere, floor = _scene("shadow_per_vertex_" + world)
    if world == "courtyard":
        fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    else:
        fx.world_colour(scene, (0.3, 0.3, 0.3))
    bakes(scene, [sphere, floor], resolution=BAKE_RESOLUTION)
    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    passes, state = result["passes"], result["state"]
    covered = passes["gbuffer_uv"][..., 3] > 0.5
    object_of_pixel = np.rint(passes["gbuffer_normal"][..., 3]).astype(int) - 1
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    camera = passes["camera"]
    errors = {}
    for index, obj in enumerate(state.objects):
        mask = covered & (object_of_pixel == index)
        per_vertex = fx.pixel_visibility(result, mask)
        name = material_of_id[int(passes["gbuffer_uv"][mask][0, 2])]

        def diffuse(visibility):
            return sg_shading.shade_fragments(
                state.materials[name], {}, passes["gbuffer_position"][mask][:, :3],
                passes["gbuffer_normal"][mask][:, :3], passes["gbuffer_tangent"][mask],
                fx.mirror_uv(passes["gbuffer_uv"][mask]), camera.position, camera.is_perspective,
                state.light_data(), state.environment, visibility=visibility)[0]

        interpolated = diffuse(per_vertex)
        at_pixels = sg_shading.vertex_diffuse_visibility(state.environment, per_vertex)   # the pixels' own rows
        per_pixel = diffuse(dataclasses.replace(per_vertex, diffuse=at_pixels))
        errors[obj] = float(np.sqrt(np.mean((interpolated - per_pixel) ** 2) / np.mean(per_pixel ** 2)))
        # the GPU image is the per-vertex one (the mirror tests hold it to 1e-3)
        gpu = passes["Diffuse"][mask][:, :3]
        assert np.abs(gpu - interpolated).max() <= 1e-3 * np.abs(interpolated).max() + 1e-6
    print("per-vertex diffuse visibility, relative RMSE of the Diffuse pass:", errors)
    assert len(errors) == 2 and all(error < 0.005 for error in errors.values()), errors


def test_per_vertex_pass_only_where_a_diffuse_term_reads_it(engine, bakes):
    """The per-vertex pass runs for the baked objects whose variants read it: not for one whose material
    has no diffuse term (zero colour), nor for one without a bake."""
    from sg_prt_addon.engine import render_engine

    scene, sphere, floor = _scene("per_vertex_needed")
    fx.world_colour(scene, (0.3, 0.3, 0.3))
    sphere.data.materials[0] = fx.material("per_vertex_needed_specular_only", model="GGX", roughness=0.4,
                                           diffuse_color=(0.0, 0.0, 0.0), specular_color=(0.5, 0.5, 0.5))
    unbaked = fx.uv_sphere(scene, "per_vertex_needed_unbaked", (1.8, 0.0, 0.6), radius=0.5, segments=16, rings=8)
    bakes(scene, [sphere, floor], resolution=8)
    render_engine.debug["after_frame"] = lambda depsgraph, state, renderer, camera: {
        key for key, targets in renderer.object_targets.items() if "diffuse_visibility" in targets}
    try:
        result = fx.render(scene)
    finally:
        render_engine.debug["after_frame"] = None
    assert "error" not in result, result.get("error")
    assert len(result["state"].visibility) == 2, "the sphere and the floor baked, the third sphere not"
    assert result["after_frame"] == {floor.name}, result["after_frame"]
    assert unbaked.name in result["state"].objects


def test_narrow_lights_share_their_visibility(engine, bakes):
    """A light narrower than sg_shading.SHARED_LIGHT_VISIBILITY_MAX_RADIUS on an object lends its own
    visibility to its products with the slice lobes (SHARED_LIGHT_VISIBILITY, one decode a light): the
    image against a decode each NDF lobe's products (the variant without it), relative RMSE over the
    surface pixels.  Measured (64 x 64, bake R = 16, light radius 0.25, up to 0.13 rad seen from the
    sphere's box): 2e-4.  A broad light (radius 1.5) keeps the decodes."""
    import bpy

    from sg_prt_addon.techniques.sg import sg_shading

    scene, sphere, floor = _scene("shared_light")
    fx.world_colour(scene, (0.02, 0.02, 0.02))
    light = fx.point_light(scene, "shared_light_light", (1.2, -0.6, 3.6), 600.0, radius=0.25)
    sphere.data.materials[0] = fx.material("shared_light_glossy", model="GGX", roughness=0.15,
                                           diffuse_color=(0.1, 0.1, 0.1), specular_color=(0.8, 0.8, 0.8))
    bakes(scene, [sphere, floor], resolution=BAKE_RESOLUTION)

    def render(shared=None):
        shares = sg_shading.shares_light_visibility
        if shared is not None:
            sg_shading.shares_light_visibility = lambda light_data, bounds: shared
        try:
            with fx.recorded_variant_keys() as keys:
                image, surface, _ = _engine_image(scene)
        finally:
            sg_shading.shares_light_visibility = shares
        return image.copy(), surface, {key.shared_light_visibility for key in keys if key.visibility_layers}

    shared_image, surface, flags = render()
    assert flags == {True}
    decoded_image, _, flags = render(shared=False)
    assert flags == {False}
    change = image_error.relative_rmse(shared_image, decoded_image, surface)
    print(f"shared light visibility: relative RMSE against a decode per product {change:.5f}")
    assert change < 2e-3

    light.data.shadow_soft_size = 1.5
    bpy.context.view_layer.update()
    _, _, flags = render()
    assert flags == {False}, "a light of 0.4 rad (floor) to 0.8 rad (sphere top) keeps the decodes"


def test_point_light_shadow_maps(engine, bakes):
    """Light Shadows = Shadow Maps on the point light scene above: without a bake the maps alone shadow; with the
    bake the maps' edge is nearer the reference than the SSDF's (docs/ACCURACY.md, "Shadow edge": the SSDF's is
    1.5-1.8x too wide).  Measured (64 x 64, bake R = 16, maps 1024): maps unbaked 0.059, maps baked 0.059, SSDF
    0.067; noise floor 0.025."""
    scene, sphere, floor = _scene("shadow_point_maps")
    fx.world_colour(scene, (0.02, 0.02, 0.02))
    fx.point_light(scene, "shadow_point_maps_light", (1.2, -0.6, 3.6), 600.0, radius=0.05)
    scene.sgprt.light_shadows = "SHADOW_MAPS"
    unbaked, surface, _ = _engine_image(scene)
    bakes(scene, [sphere, floor], resolution=BAKE_RESOLUTION)
    baked, _, result = _engine_image(scene)
    assert len(result["state"].visibility) == 2
    scene.sgprt.light_shadows = "SSDF"
    ssdf, _, _ = _engine_image(scene)
    reference, error = _reference(scene, 0.012)
    noise = image_error.rmse_noise_floor(error, reference, surface)
    scores = {name: image_error.relative_rmse(image, reference, surface)
              for name, image in (("maps unbaked", unbaked), ("maps baked", baked), ("SSDF", ssdf))}
    print(", ".join(f"{name} {value:.4f}" for name, value in scores.items()) + f", noise floor {noise:.4f}")
    assert noise < 0.04
    assert scores["maps unbaked"] < 0.075 and scores["maps baked"] < 0.075
    assert scores["maps baked"] < scores["SSDF"]
