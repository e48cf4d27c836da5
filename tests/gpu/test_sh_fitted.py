"""The SH technique rendering a stored lobe fit (SH BRDF: Lobe Fit; techniques/sh/spherical_harmonics.py,
harmonics/fitted_table.py) on the GPU against its numpy mirror (techniques/sh/sh_shading.py): a generated 8 x 8
SVBRDF table fitted by ``bpy.ops.sgprt.fit_lobes`` on an SH material (the fit becomes what it tabulates),
its texels' tables read at the UV's nearest texel, each lobe's vector rotated and weighed by its colour and
S(o) / (pi o.z); under an environment or a world colour, point, spot and sun lights, beside a parametric SH
material; and with a transfer bake, the path the parametric tables take."""
import engine_fixtures as fx
import numpy as np
import pytest
from test_sh_technique import FLOOR_FRACTION, TOLERANCE, lit_scene


@pytest.fixture(scope="module")
def fitted_material(blender, tmp_path_factory):
    from sg_prt_addon.blender import lobe_fit

    fx.ensure_registered()
    material = fx.material("sh_fitted_table", technique="SH", model="GGX", roughness=0.4)
    fx.fit_lobes(material, fx.svbrdf_table_file(tmp_path_factory.mktemp("sh_fitted")), lobe_count=2,
                 shadowing_components=5)
    assert lobe_fit.fit_status(material)[0] == "VALID" and not material.sgprt.lobe_fit.free_axes
    assert (material.sgprt.technique, material.sgprt.sh.brdf) == ("SH", "LOBE_FIT")
    return material


def _mirror_errors(result, transfer=False):
    """{(material, pass): max relative error} of the GPU's passes against sh_shading.shade_fragments."""
    from sg_prt_addon.techniques.sh import sh_shading, spherical_harmonics

    passes, state = result["passes"], result["state"]
    camera, uv = passes["camera"], passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    environment = spherical_harmonics.environment_coefficients(state.environment)
    objects = np.rint(passes["gbuffer_normal"][..., 3]).astype(int) - 1
    errors = {}
    for object_index in np.unique(objects[covered]):
        mask = covered & (objects == object_index)
        params = state.materials[material_of_id[int(np.rint(uv[mask][0, 2]))]]
        order, inputs = params.sh_order, None
        if transfer:
            order, inputs = fx.pixel_sh_transfer(result, mask, params)
        diffuse, specular = sh_shading.shade_fragments(
            params, {}, spherical_harmonics.table_for(params, order), environment,
            passes["gbuffer_position"][mask][:, :3], passes["gbuffer_normal"][mask][:, :3],
            passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), camera.position if camera.is_perspective
            else camera.forward, camera.is_perspective, state.light_data(), transfer=inputs)
        for name, expected in (("Diffuse", diffuse), ("Specular", specular)):
            actual = passes[name][mask][:, :3]
            assert np.all(np.isfinite(actual)) and expected.max() > 0
            errors[(params.name, name)] = float(fx.relative_error(actual, expected, FLOOR_FRACTION).max())
    return errors


def _scene(name, fitted_material, world, order, window):
    scene = lit_scene(name, world)
    fitted_material.sgprt.sh.order, fitted_material.sgprt.sh.window = order, window
    glossy = fx.material(name + "_ggx", technique="SH", sh={"order": order, "window": window}, model="GGX",
                         roughness=0.4, diffuse_color=(0.2, 0.25, 0.3), specular_color=(0.8, 0.7, 0.6))
    fx.uv_sphere(scene, name + "_a", (-1.1, 0.0, 1.0), radius=0.9).data.materials.append(fitted_material)
    fx.uv_sphere(scene, name + "_b", (1.1, 0.0, 1.0), radius=0.9).data.materials.append(glossy)
    return scene


@pytest.mark.parametrize("world, order, window", [("environment", 5, "NONE"), ("colour", 3, "HANNING")])
def test_shader_matches_mirror(fitted_material, world, order, window):
    """Measured max 6.5e-5 (order 8, Lanczos: 4.6e-5)."""
    with fx.recorded_variant_keys() as keys:
        result = fx.render(_scene(f"sh_fitted_{world}_{order}", fitted_material, world, order, window),
                           gbuffer=True, environment_layer_size=32)
    assert "error" not in result, result.get("error")
    params = result["state"].materials[fitted_material.name]
    assert params.technique == "SH" and params.fitted is not None and params.fitted.layers.shape[1:3] == (8, 8)
    assert {(key.order, key.fitted_lobes, key.fitted_components) for key in keys} == {(order, 2, 5), (order, 0, 0)}
    errors = _mirror_errors(result)
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE
    # the texels differ: the sphere shows the table's spatial variation
    passes = result["passes"]
    on_sphere = (passes["gbuffer_uv"][..., 3] > 0.5) & (
        np.abs(passes["gbuffer_uv"][..., 2] - passes["material_ids"][fitted_material.name]) < 0.25)
    diffuse = passes["Diffuse"][..., :3][on_sphere]
    assert on_sphere.mean() > 0.1 and np.std(diffuse[:, 0] / np.maximum(diffuse.sum(axis=1), 1e-6)) > 0.01


def test_transfer_shadows_match_the_mirror(fitted_material):
    """The fitted sphere over a parametric SH floor, both baked at order 4: the GPU as the mirror, and the
    fitted sphere's shading changed by the bake."""
    import bpy

    from sg_prt_addon.blender import transfer_bake

    scene = fx.new_scene("sh_fitted_transfer", 96, 96)
    scene.camera.location = (0.0, -5.0, 3.0)
    scene.camera.rotation_euler = (1.05, 0.0, 0.0)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    fx.point_light(scene, "sh_fitted_transfer_light", (0.5, -0.5, 4.0), 800.0, radius=0.3)
    fitted_material.sgprt.sh.order, fitted_material.sgprt.sh.window = 5, "NONE"
    sphere = fx.uv_sphere(scene, "sh_fitted_transfer_sphere", (0.0, 0.0, 1.0), radius=0.8, segments=24, rings=12)
    sphere.data.materials.append(fitted_material)
    floor = fx.grid(scene, "sh_fitted_transfer_floor", (0.0, 0.0, 0.0), size=5.0, segments=24)
    floor.data.materials.append(fx.material("sh_fitted_transfer_floor_mat", technique="SH", model="COOK_TORRANCE",
                                            roughness=0.3, diffuse_color=(0.7, 0.7, 0.7)))
    try:
        unshadowed = fx.render(scene, gbuffer=True, environment_layer_size=32)["passes"]["Specular"].copy()
        with bpy.context.temp_override(scene=scene):
            assert bpy.ops.sgprt.bake_transfer("EXEC_DEFAULT", target="ALL", order=4, directions=256,
                                               term_mode="FIXED", terms=6) == {"FINISHED"}
        with fx.recorded_variant_keys() as keys:
            result = fx.render(scene, gbuffer=True, environment_layer_size=32)
        assert "error" not in result, result.get("error")
        assert {(key.order, key.transfer_layers, key.fitted_lobes) for key in keys} == {(4, 2, 2), (4, 2, 0)}
        errors = _mirror_errors(result, transfer=True)
        print("max relative error", errors)
        assert max(errors.values()) <= TOLERANCE
        assert not np.allclose(result["passes"]["Specular"], unshadowed, rtol=1e-3)
    finally:
        for obj in (sphere, floor):
            transfer_bake.clear_transfer_bake(obj.data)
