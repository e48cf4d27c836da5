"""The factored-BRDF technique (techniques/homomorphic/factored.py, mccool2001) on the GPU against its numpy mirror
(techniques/homomorphic/factored_shading.py), from the G-buffer: lights, a world colour and an environment; and the
material setting that picks it, saved and reopened."""
import engine_fixtures as fx
import numpy as np
import pytest

TOLERANCE = 1e-4         # max relative error of the shader against the mirror, per pass


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _mirror_errors(result, shadowed=False):
    """Max relative error per (material, pass) of the shader against the mirror, the materials on one object
    each (with shadowed, the pixels' SSDF inputs rebuilt as the GPU interpolates them)."""
    from sg_prt_addon.techniques.homomorphic import factored, factored_shading

    passes, state = result["passes"], result["state"]
    camera, uv = passes["camera"], passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    errors = {}
    for material_id in np.unique(uv[covered][:, 2]).astype(int):
        params = state.materials[material_of_id[material_id]]
        mask = covered & (np.abs(uv[..., 2] - material_id) < 0.25)
        view_origin = camera.position if camera.is_perspective else camera.forward
        diffuse, specular = factored_shading.shade_fragments(
            params, {}, factored.tables_for(params), passes["gbuffer_position"][mask][:, :3],
            passes["gbuffer_normal"][mask][:, :3], passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), view_origin,
            camera.is_perspective, state.light_data(), state.environment,
            visibility=fx.pixel_visibility(result, mask) if shadowed else None)
        for name, expected in (("Diffuse", diffuse), ("Specular", specular)):
            actual = passes[name][mask][:, :3]
            assert np.all(np.isfinite(actual)) and expected.max() > 0
            errors[(params.name, name)] = float(fx.relative_error(actual, expected).max())
    return errors, covered


def _scene(name, world):
    scene = fx.new_scene(name, 96, 96)
    if world == "colour":
        fx.world_colour(scene, (0.15, 0.17, 0.2))
    else:
        fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    fx.point_light(scene, name + "_point", (1.5, -2.0, 3.0), 800.0, radius=0.2)
    fx.point_light(scene, name + "_sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    glossy = fx.material(name + "_ggx", technique="FACTORED", model="GGX", roughness=0.4,
                         diffuse_color=(0.2, 0.25, 0.3), specular_color=(0.8, 0.7, 0.6), fresnel="SCHLICK", multiscatter=True, layered_diffuse=True)
    brushed = fx.material(name + "_ward", technique="FACTORED", model="WARD_ANISO", alpha_x=0.3, alpha_y=0.1)
    fx.uv_sphere(scene, name + "_a", (-1.1, 0.0, 1.0), radius=0.9).data.materials.append(glossy)
    fx.uv_sphere(scene, name + "_b", (1.1, 0.0, 1.0), radius=0.9).data.materials.append(brushed)
    return scene


@pytest.mark.parametrize("world", ["colour", "environment"])
def test_shader_matches_mirror(engine, world):
    with fx.recorded_variant_keys() as keys:
        result = fx.render(_scene("factored_" + world, world), gbuffer=True, environment_layer_size=32)
    assert "error" not in result, result.get("error")
    assert {key.technique for key in keys} == {"FACTORED"}
    errors, covered = _mirror_errors(result)
    assert covered.mean() > 0.2
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE


@pytest.mark.parametrize("world", ["colour", "environment"])
def test_shadowed_shader_matches_mirror(engine, bakes, world):
    """A sphere over a floor, both baked: every light, environment lobe and the glossy lookup shadowed by its
    SSDF visibility, on the GPU as in the mirror; the floor darker under the sphere than without the bake."""
    scene = fx.new_scene("factored_shadow_" + world, 96, 96)
    scene.camera.location = (0.0, -5.0, 3.0)
    scene.camera.rotation_euler = (1.05, 0.0, 0.0)
    if world == "colour":
        fx.world_colour(scene, (0.15, 0.17, 0.2))
    else:
        fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    fx.point_light(scene, "factored_shadow_light_" + world, (0.5, -0.5, 4.0), 800.0, radius=0.2)
    sphere = fx.uv_sphere(scene, "factored_shadow_sphere_" + world, (0.0, 0.0, 1.0), radius=0.8, segments=24,
                          rings=12)
    sphere.data.materials.append(fx.material("factored_shadow_ggx_" + world, technique="FACTORED", model="GGX",
                                             roughness=0.4, diffuse_color=(0.6, 0.5, 0.4)))
    floor = fx.grid(scene, "factored_shadow_floor_" + world, (0.0, 0.0, 0.0), size=5.0, segments=24)
    floor.data.materials.append(fx.material("factored_shadow_floor_mat_" + world, technique="FACTORED",
                                            model="COOK_TORRANCE", roughness=0.3, diffuse_color=(0.7, 0.7, 0.7)))
    unshadowed = fx.render(scene, gbuffer=True, environment_layer_size=32)["passes"]["Diffuse"].copy()
    bakes(scene, [sphere, floor], resolution=12)
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True, environment_layer_size=32)
    assert "error" not in result, result.get("error")
    assert {key.visibility_layers > 0 for key in keys} == {True}
    errors, covered = _mirror_errors(result, shadowed=True)
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE
    darker = result["passes"]["Diffuse"][..., :3].sum() / unshadowed[..., :3].sum()
    assert darker < 0.97, darker


def test_technique_setting_survives_save_and_reopen(engine, tmp_path):
    import bpy

    material = fx.material("factored_saved", technique="FACTORED", model="GGX")
    material.use_fake_user = True
    path = tmp_path / "factored.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    assert bpy.data.materials["factored_saved"].sgprt.technique == "FACTORED"


def test_stored_factors_of_a_measured_brdf_render(engine, tmp_path):
    """A material with factors stored by the Factor BRDF operator (a generated MERL file) renders them, RGB,
    on the GPU as in the mirror; its own model's factorization is not used."""
    import bpy

    from sg_prt_addon.techniques.homomorphic import factored
    from validation import brdf_generators

    path = str(tmp_path / "measured.binary")
    brdf_generators.generate_merl(path)
    scene = _scene("factored_stored", "colour")
    material = bpy.data.materials["factored_stored_ggx"]
    sphere = bpy.data.objects["factored_stored_a"]
    with bpy.context.temp_override(scene=scene, object=sphere, material=material):
        assert bpy.ops.sgprt.factor_brdf(filepath=path, resolution=16) == {"FINISHED"}
    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    params = result["state"].materials["factored_stored_ggx"]
    assert params.factorization is not None and factored.tables_for(params) is params.factorization
    assert params.factorization.maps["p"].shape == (16, 16, 4)
    errors, _ = _mirror_errors(result)
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE
