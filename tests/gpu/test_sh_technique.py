"""The spherical-harmonics technique (techniques/sh/spherical_harmonics.py, kautz2002) on the GPU against its
numpy mirror (techniques/sh/sh_shading.py), from the G-buffer: isotropic tables with a roughness texture, an
anisotropic map, point, spot and sun lights, a world colour and an environment, orders and windows; and
the material settings, saved and reopened."""
import engine_fixtures as fx
import numpy as np
import pytest

TOLERANCE = 1e-4         # max relative error of the shader against the mirror, per pass
# An SH shading value is a signed sum of terms as large as the pass's brightest pixels (its ringing can
# cancel to zero): float32 (and the GPU's atan, 3e-6 rad) leave up to 5e-6 of the pass's largest value on
# any pixel, so the error is relative to max(|value|, 5% of that largest value); measured 7e-6 to 8.3e-5
FLOOR_FRACTION = 0.05


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


ROUGHNESS = np.ones((8, 8, 4), np.float32)
ROUGHNESS[..., 0] = np.linspace(0.3, 1.6, 8)[None, :]


def _mirror_errors(result):
    from sg_prt_addon.techniques.sh import sh_shading, spherical_harmonics

    passes, state = result["passes"], result["state"]
    camera, uv = passes["camera"], passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    environment = spherical_harmonics.environment_coefficients(state.environment)
    errors = {}
    for material_id in np.unique(uv[covered][:, 2]).astype(int):
        params = state.materials[material_of_id[material_id]]
        mask = covered & (np.abs(uv[..., 2] - material_id) < 0.25)
        view_origin = camera.position if camera.is_perspective else camera.forward
        textures = {"roughness": ROUGHNESS} if "roughness" in params.textures else {}
        diffuse, specular = sh_shading.shade_fragments(
            params, textures, spherical_harmonics.table_for(params), environment,
            passes["gbuffer_position"][mask][:, :3], passes["gbuffer_normal"][mask][:, :3],
            passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), view_origin, camera.is_perspective, state.light_data())
        for name, expected in (("Diffuse", diffuse), ("Specular", specular)):
            actual = passes[name][mask][:, :3]
            assert np.all(np.isfinite(actual)) and expected.max() > 0
            errors[(params.name, name)] = float(fx.relative_error(actual, expected, FLOOR_FRACTION).max())
    return errors, covered


def lit_scene(name, world):
    """The SH mirror tests' scene: a world colour or courtyard.exr, a point, a sun and a spot light."""
    scene = fx.new_scene(name, 96, 96)
    if world == "colour":
        fx.world_colour(scene, (0.15, 0.17, 0.2))
    else:
        fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    fx.point_light(scene, name + "_point", (1.5, -2.0, 3.0), 800.0, radius=0.5)
    fx.point_light(scene, name + "_sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    spot = fx.point_light(scene, name + "_spot", (-2.0, -2.0, 2.5), 600.0, radius=0.1, kind="SPOT")
    spot.rotation_euler = (0.9, 0.0, -0.8)
    return scene


def _scene(name, world, order, window):
    scene = lit_scene(name, world)
    glossy = fx.material(name + "_ggx", technique="SH", sh={"order": order, "window": window}, model="GGX",
                         roughness=0.4, diffuse_color=(0.2, 0.25, 0.3), specular_color=(0.8, 0.7, 0.6),
                         fresnel="SCHLICK", multiscatter=True, layered_diffuse=True)
    glossy.sgprt.roughness_texture = fx.image(name + "_rough", ROUGHNESS)    # the layer's roughness follows it
    brushed = fx.material(name + "_as", technique="SH", sh={"order": order, "window": window}, model="ASHIKHMIN_SHIRLEY",
                          nu=20.0, nv=200.0)
    fx.uv_sphere(scene, name + "_a", (-1.1, 0.0, 1.0), radius=0.9).data.materials.append(glossy)
    fx.uv_sphere(scene, name + "_b", (1.1, 0.0, 1.0), radius=0.9).data.materials.append(brushed)
    return scene


@pytest.mark.parametrize("world, order, window", [("colour", 5, "NONE"), ("environment", 5, "NONE"),
                                                   ("environment", 3, "HANNING"), ("colour", 8, "LANCZOS")])
def test_shader_matches_mirror(engine, world, order, window):
    with fx.recorded_variant_keys() as keys:
        result = fx.render(_scene(f"sh_{world}_{order}", world, order, window), gbuffer=True,
                           environment_layer_size=32)
    assert "error" not in result, result.get("error")
    assert {key.technique for key in keys} == {"SH"} and {key.order for key in keys} == {order}
    assert {key.isotropic for key in keys} == {True, False}
    errors, covered = _mirror_errors(result)
    assert covered.mean() > 0.2
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE


def test_settings_survive_save_and_reopen(engine, tmp_path):
    import bpy

    material = fx.material("sh_saved", technique="SH", model="GGX", sh={"order": 7, "window": "LANCZOS"})
    material.use_fake_user = True
    path = tmp_path / "sh.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    settings = bpy.data.materials["sh_saved"].sgprt
    assert (settings.technique, settings.sh.order, settings.sh.window) == ("SH", 7, "LANCZOS")


@pytest.fixture
def transfer_scene(engine):
    """A glossy sphere over a Cook-Torrance floor, both SH, under courtyard.exr and a point light."""
    scene = fx.new_scene("sh_transfer", 96, 96)
    scene.camera.location = (0.0, -5.0, 3.0)
    scene.camera.rotation_euler = (1.05, 0.0, 0.0)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    fx.point_light(scene, "sh_transfer_light", (0.5, -0.5, 4.0), 800.0, radius=0.3)
    sphere = fx.uv_sphere(scene, "sh_transfer_sphere", (0.0, 0.0, 1.0), radius=0.8, segments=24, rings=12)
    sphere.data.materials.append(fx.material("sh_transfer_ggx", technique="SH", model="GGX", roughness=0.4,
                                             diffuse_color=(0.6, 0.5, 0.4)))
    floor = fx.grid(scene, "sh_transfer_floor", (0.0, 0.0, 0.0), size=5.0, segments=24)
    floor.data.materials.append(fx.material("sh_transfer_floor_mat", technique="SH", model="COOK_TORRANCE",
                                            roughness=0.3, diffuse_color=(0.7, 0.7, 0.7)))
    yield scene, sphere, floor
    from sg_prt_addon.blender import transfer_bake

    for obj in (sphere, floor):
        transfer_bake.clear_transfer_bake(obj.data)


def _transfer_mirror_errors(result):
    from sg_prt_addon.techniques.sh import sh_shading, spherical_harmonics

    passes, state = result["passes"], result["state"]
    camera, uv = passes["camera"], passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    environment = spherical_harmonics.environment_coefficients(state.environment)
    errors = {}
    objects = np.rint(passes["gbuffer_normal"][..., 3]).astype(int) - 1
    for object_index in np.unique(objects[covered]):
        mask = covered & (objects == object_index)
        material_id = int(np.rint(uv[mask][0, 2]))
        params = state.materials[{i: n for n, i in passes["material_ids"].items()}[material_id]]
        order, inputs = fx.pixel_sh_transfer(result, mask, params)
        diffuse, specular = sh_shading.shade_fragments(
            params, {}, spherical_harmonics.table_for(params, order), environment,
            passes["gbuffer_position"][mask][:, :3], passes["gbuffer_normal"][mask][:, :3],
            passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), camera.position, camera.is_perspective,
            state.light_data(), transfer=inputs)
        for name, expected in (("Diffuse", diffuse), ("Specular", specular)):
            actual = passes[name][mask][:, :3]
            assert np.all(np.isfinite(actual)) and expected.max() > 0
            errors[(params.name, name)] = float(fx.relative_error(actual, expected, FLOOR_FRACTION).max())
    return errors


@pytest.mark.parametrize("bake_order, at_vertices", [(4, True), (4, False), (5, True)])
def test_transfer_shadows_match_the_mirror(transfer_scene, monkeypatch, bake_order, at_vertices):
    """Both objects' transfer baked by the operator (the materials' order 5 shades at min(5, the bake's)), its
    terms summed at the vertices (order 5 with a light: 26 vec4 varyings, 31 with the surface's, within the
    driver's 32) or per pixel (VERTEX_TRANSFER off, as at orders 6-8): the GPU as the mirror, and the floor
    under the sphere darker than without the transfer."""
    import bpy

    from sg_prt_addon.techniques.sh import spherical_harmonics

    monkeypatch.setattr(spherical_harmonics, "VERTEX_TRANSFER", at_vertices)
    scene, sphere, floor = transfer_scene
    unshadowed = fx.render(scene, gbuffer=True, environment_layer_size=32)["passes"]["Diffuse"].copy()
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.sgprt.bake_transfer("EXEC_DEFAULT", target="ALL", order=bake_order, directions=256,
                                           term_mode="FIXED", terms=6) == {"FINISHED"}
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True, environment_layer_size=32)
    assert "error" not in result, result.get("error")
    order = min(bake_order, 5)
    rows = -(-(3 * (order * order + 1) + order * order) // 4) if at_vertices else 0
    assert {(key.order, key.transfer_layers, key.vertex_transfer) for key in keys} == {(order, 2, rows)}
    errors = _transfer_mirror_errors(result)
    print("max relative error", errors)
    assert max(errors.values()) <= TOLERANCE
    darker = result["passes"]["Diffuse"][..., :3].sum() / unshadowed[..., :3].sum()
    assert darker < 0.95, darker
