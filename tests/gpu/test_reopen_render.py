"""A .blend saved with SG-PRT materials reopens with identical settings and renders an
identical image (textures packed, world image from disk)."""
import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _combined(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return np.array(result["passes"]["Combined"], copy=True)


def test_saved_file_reopens_and_renders_the_same_image(engine, tmp_path):
    import bpy

    scene = fx.new_scene("reopen_scene", 48, 40)
    fx.world_texture(scene, fx.studio_world_path("forest.exr"))
    rng = np.random.default_rng(5)
    roughness = fx.image("reopen_roughness", np.concatenate([rng.uniform(0.2, 1.0, (8, 8, 3)), np.ones((8, 8, 1))], -1))
    roughness.pack()
    sphere = fx.uv_sphere(scene, "reopen_sphere", (0.0, 0.0, 1.0))
    sphere.data.materials.append(fx.material("reopen_glossy", model="WARD_ANISO", alpha_x=0.3, alpha_y=0.08,
                                             lobe_count=3, diffuse_color=(0.3, 0.5, 0.2),
                                             specular_color=(0.6, 0.6, 0.6), alpha_x_texture=roughness,
                                             tangent_source="OBJECT_AXIS", tangent_rotation=0.4))
    fx.plane(scene, "reopen_floor", (0.0, 0.0, 0.0)).data.materials.append(
        fx.material("reopen_floor_material", model="COOK_TORRANCE", roughness=0.25, ior=1.8))
    fx.point_light(scene, "reopen_light", (2.0, -2.0, 3.0), 400.0, radius=0.2, kind="SPOT")
    before = _combined(scene)
    assert before[..., :3].max() > 0.05

    path = tmp_path / "reopen.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    reopened = bpy.data.materials["reopen_glossy"].sgprt
    assert (reopened.model, reopened.lobe_count, reopened.alpha_x_texture.name) == ("WARD_ANISO", 3, "reopen_roughness")
    after = _combined(bpy.data.scenes["reopen_scene"])
    np.testing.assert_array_equal(after, before)
