"""An object's scale changes nothing but its size: a floor of Blender's default material (a Principled BSDF: a
glossy layer over the diffuse) renders the same whether it is a 20 m plane or a smaller one scaled up or down,
and a scaled sphere as its applied twin (the normal matrix scales normals by the inverse scale)."""
import engine_fixtures as fx
import numpy as np
import pytest


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _floor(name, scale):
    import bpy

    scene = fx.new_scene(name, 32, 32)
    scene.camera.location = (0.0, -4.0, 3.0)
    scene.camera.rotation_euler = (0.9, 0.0, 0.0)
    fx.world_colour(scene, (0.05, 0.05, 0.05))
    floor = fx.plane(scene, name + "_floor", (0.0, 0.0, 0.0), size=20.0 / scale)
    floor.scale = (scale, scale, scale)
    material = bpy.data.materials.new(name + "_default")
    material.use_nodes = True                     # Blender's default node material: a Principled BSDF
    floor.data.materials.append(material)
    sun = bpy.data.lights.new(name + "_sun", "SUN")
    light = bpy.data.objects.new(name + "_sun", sun)
    light.rotation_euler = (0.3, 0.0, 0.0)
    scene.collection.objects.link(light)
    return scene


def test_a_scaled_floor_renders_as_the_unscaled_one(engine):
    """Measured before the normal was made unit at the vertices: 0.90x of the unscaled floor at scale 10,
    the specular 3.6x."""
    renders = {}
    for scale in (0.1, 1.0, 10.0, 100.0):
        result = fx.render(_floor(f"scaled_floor_{scale:g}", scale))
        assert "error" not in result, result.get("error")
        renders[scale] = result["passes"]
    for scale in (0.1, 10.0, 100.0):
        for name in ("Combined", "Diffuse", "Specular"):
            np.testing.assert_allclose(renders[scale][name][..., :3], renders[1.0][name][..., :3], rtol=1e-4,
                                       atol=1e-6, err_msg=f"scale {scale}, {name}")


def test_a_scaled_glossy_sphere_renders_as_its_applied_twin(engine):
    """A sphere of radius 0.25 scaled 4x against one of radius 1, the same mesh otherwise, glossy with Schlick's
    Fresnel (it reads the view's cosine to the normal)."""
    images = []
    for radius, scale in ((0.25, 4.0), (1.0, 1.0)):
        name = f"scaled_sphere_{scale:g}"
        scene = fx.new_scene(name, 48, 48)
        fx.world_colour(scene, (0.1, 0.1, 0.1))
        fx.point_light(scene, name + "_light", (2.0, -3.0, 4.0), 800.0, radius=0.2)
        sphere = fx.uv_sphere(scene, name, (0.0, 0.0, 1.0), radius=radius, segments=24, rings=12)
        sphere.scale = (scale, scale, scale)
        sphere.data.materials.append(fx.material(name + "_ggx", model="GGX", roughness=0.3, fresnel="SCHLICK"))
        result = fx.render(scene)
        assert "error" not in result, result.get("error")
        images.append(result["passes"]["Combined"][..., :3])
    np.testing.assert_allclose(images[0], images[1], rtol=1e-3, atol=1e-4)
