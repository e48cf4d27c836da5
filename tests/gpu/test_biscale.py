"""The bi-scale technique (SG_BISCALE, iwasaki2012) in the engine: its GLSL against its numpy mirror
(techniques.biscale_shading through sg_shading.shade_fragments) on the G-buffer's pixels, under a point light
with an environment map and under a constant world; a material whose tile is unusable renders as a single
scale with a warning that says why."""
import engine_fixtures as fx
import numpy as np
import pytest
from test_fitted_mirror import _errors

from validation import biscale_reference

TOLERANCE = 2e-3


def biscale_material(name, heights, **settings):
    import bpy  # noqa: F401  (Blender is loaded by the fixture)

    pixels = np.repeat(np.flipud(heights)[..., None], 4, axis=-1).astype(np.float32)
    image = fx.image(f"{name}_height", pixels)
    material = fx.material(name, technique="SG_BISCALE", **settings)
    material.sgprt.biscale.height_image = image
    material.sgprt.biscale.height_scale = 1.0
    material.sgprt.biscale.samples = 2048
    material.sgprt.biscale.lobes = 8
    return material


def _scene(name, material, world):
    scene = fx.new_scene(name, 96, 96)
    if world == "texture":
        fx.world_texture(scene, fx.studio_world_path(), strength=0.6)
    else:
        fx.world_colour(scene, (0.3, 0.35, 0.4))
    sphere = fx.uv_sphere(scene, f"{name}_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(material)
    fx.point_light(scene, f"{name}_point", (2.0, -3.0, 3.0), 600.0, radius=0.1)
    return scene


@pytest.mark.parametrize("world", ["texture", "colour"])
def test_biscale_shader_matches_its_mirror(blender, world):
    fx.ensure_registered()
    material = biscale_material(f"biscale_{world}", biscale_reference.egg_crate(32), model="GGX", roughness=0.35,
                                diffuse_color=(0.4, 0.3, 0.2), specular_color=(0.8, 0.8, 0.8))
    result = fx.render(_scene(f"biscale_mirror_{world}", material, world), gbuffer=True)
    state = result["state"]
    assert state.materials[material.name].technique == "SG_BISCALE"
    errors = _errors(result)
    assert max(errors.values()) < TOLERANCE, errors


def test_unusable_tile_renders_single_scale_with_a_reason(blender):
    import bpy

    fx.ensure_registered()
    material = fx.material("biscale_missing", technique="SG_BISCALE", model="GGX")
    bpy.data.images.new("biscale_empty", 4, 4)
    scene = _scene("biscale_missing_scene", material, "colour")
    result = fx.render(scene)
    assert "error" not in result
    assert result["state"].materials[material.name].technique == "SG_PARAMETRIC"
    assert any("no usable small-scale geometry (no height image)" in w for w in result["state"].warnings)
