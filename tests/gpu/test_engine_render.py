"""Final renders through bpy.ops.render.render: passes, world background, compile errors."""
import numpy as np
import pytest

import engine_fixtures as fx


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def test_engine_class_contract(engine):
    from sg_prt_addon import engine as engine_package

    (cls,) = engine_package.classes
    assert cls.bl_idname == "SG_PRT" and cls.bl_label == "SG-PRT"
    assert cls.bl_use_gpu_context and not cls.bl_use_preview


def test_passes_and_world_background(engine):
    scene = fx.new_scene("render_passes", 96, 64)
    fx.world_colour(scene, (0.2, 0.3, 0.4))
    fx.uv_sphere(scene, "render_sphere", (0.0, 0.0, 1.0), radius=1.0)
    fx.point_light(scene, "render_light", (1.0, -3.0, 3.0), 500.0)
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    assert result["written_passes"] == ["Combined", "Diffuse", "Specular"]
    passes = result["passes"]
    combined, diffuse, specular = (passes[name] for name in ("Combined", "Diffuse", "Specular"))
    assert combined.shape == (64, 96, 4)
    surface = diffuse[..., 3] > 0.5
    assert 0.1 < surface.mean() < 0.9
    np.testing.assert_allclose(combined[surface][:, :3], (diffuse + specular)[surface][:, :3], rtol=1e-6, atol=1e-7)
    # behind the sphere: the world colour at alpha 1, nothing in the light passes
    np.testing.assert_allclose(combined[~surface], np.broadcast_to([0.2, 0.3, 0.4, 1.0], combined[~surface].shape),
                               rtol=1e-6)
    assert np.all(diffuse[~surface] == 0) and np.all(specular[~surface] == 0)
    # the lit side is brighter than the world-lit side
    assert diffuse[surface][:, :3].max() > 2 * np.median(diffuse[surface][:, :3])
    scene.render.film_transparent = True
    transparent = fx.render(scene)["passes"]["Combined"]
    assert np.all(transparent[~surface][:, 3] == 0)


def test_compile_error_names_variant_and_line(engine, monkeypatch):
    import bpy
    from sg_prt_addon.engine import render_engine, shader_variants

    original = shader_variants.fragment_source
    broken_line = "  vec3 view_local = view * frame_that_does_not_exist;"

    def broken(key):
        return original(key).replace("  vec3 view_local = view * frame;", broken_line)

    monkeypatch.setattr(shader_variants, "fragment_source", broken)
    shader_variants.clear_cache()
    scene = fx.new_scene("render_broken", 16, 16)
    fx.uv_sphere(scene, "broken_sphere", (0.0, 0.0, 1.0), segments=8, rings=4)
    with pytest.raises(RuntimeError, match=r"SG-PRT shader variant \[GGX, 1 lobe\(s\), no lights"):
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name, write_still=False)
    message = render_engine.last_render["error"]
    lines = broken(shader_variants.VariantKey()).split("\n")
    number = next(n for n, line in enumerate(lines, 1) if broken_line in line)
    assert f"fragment line {number}: `frame_that_does_not_exist' undeclared" in message
    assert f"{number:5d}> {lines[number - 1]}" in message
