"""The technique seam: a technique written as a test fixture (normal_display_technique.py) plugs in by
registering alone, renders next to the built-in one in the same scene, and goes away cleanly; the draw
loop, the shader cache and the scene state name no technique."""
import os
import re

import engine_fixtures as fx
import normal_display_technique as normal_display
import numpy as np
import pytest

SIZE = 64
ENGINE_DIR = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "sg_prt_addon", "engine")


@pytest.fixture
def registered(blender):
    from sg_prt_addon import techniques

    fx.ensure_registered()
    techniques.register(normal_display.TECHNIQUE)
    try:
        yield normal_display.TECHNIQUE
    finally:
        techniques.unregister(normal_display.NAME)


def _scene(name):
    scene = fx.new_scene(name, SIZE, SIZE)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    fx.point_light(scene, name + "_light", (1.0, -3.0, 3.0), 500.0)
    shown = fx.uv_sphere(scene, name + "_normals", (-1.1, 0.0, 1.0), segments=24, rings=12)
    shown.data.materials.append(fx.material(name + "_normals", technique=normal_display.NAME))
    plain = fx.uv_sphere(scene, name + "_plain", (1.1, 0.0, 1.0), segments=24, rings=12)
    plain.data.materials.append(fx.material(name + "_plain", model="GGX", roughness=0.4))
    return scene


def test_fixture_technique_renders_beside_the_builtin(registered):
    scene = _scene("seam")
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    assert {key.technique for key in keys} == {normal_display.NAME, "SG_PARAMETRIC"}
    passes = result["passes"]
    object_id = passes["gbuffer_normal"][..., 3]
    names = list(result["state"].objects)
    shown = object_id == names.index("seam_normals") + 1
    plain = object_id == names.index("seam_plain") + 1
    assert shown.sum() > 200 and plain.sum() > 200
    # the shader against its mirror, over the normals the G-buffer holds
    expected = registered.mirror(passes["gbuffer_normal"][shown][:, :3])
    np.testing.assert_allclose(passes["Diffuse"][shown][:, :3], expected, atol=2e-6)
    np.testing.assert_allclose(passes["Combined"][shown][:, :3], expected, atol=2e-6)
    assert np.all(passes["Specular"][shown][:, :3] == 0.0)
    # the built-in technique still shades its sphere: lit, with a highlight
    assert passes["Specular"][plain][:, :3].max() > 0.01
    assert not np.allclose(passes["Diffuse"][plain][:, :3], registered.mirror(passes["gbuffer_normal"][plain][:, :3]),
                           atol=0.05)


def test_unregistered_technique_falls_back_with_a_warning(registered, blender):
    """A material whose technique is gone (a file from a build that had it) renders with the default,
    and the render says so."""
    from sg_prt_addon import techniques

    scene = _scene("seam_gone")
    techniques.unregister(normal_display.NAME)
    try:
        result = fx.render(scene)
    finally:
        techniques.register(normal_display.TECHNIQUE)
    assert "error" not in result, result.get("error")
    state = result["state"]
    assert state.materials["seam_gone_normals"].technique == techniques.DEFAULT
    assert any("seam_gone_normals" in warning and "#900" in warning and "not available" in warning
               for warning in state.warnings), state.warnings


def test_registry_refuses_clashes(registered):
    from sg_prt_addon import techniques

    with pytest.raises(ValueError, match="already registered"):
        techniques.register(normal_display.NormalDisplay())
    clash = normal_display.NormalDisplay()
    clash.name = "TEST_OTHER"
    with pytest.raises(ValueError, match="enum number 900"):
        techniques.register(clash)
    with pytest.raises(KeyError, match="TEST_MISSING"):
        techniques.get("TEST_MISSING")
    with pytest.raises(ValueError):
        techniques.unregister(techniques.DEFAULT)


def test_engine_names_no_technique():
    """The draw loop, the shader cache and the scene state reach techniques through the registry only."""
    from sg_prt_addon import techniques

    # technique names as whole words ("SH" is in "SHADER"), the rest as the fragments they are
    patterns = {name: r"\b" + re.escape(name) + r"\b" for name in techniques.names()}
    patterns.update({word: re.escape(word) for word in ("sg_lobes", "sg_parametric", "sg_fitted", "FITTED",
                                                         "VariantKey", "ssdf_coefficients", "fitted_",
                                                         "anisotropy_table", "ggx_", "spherical_harmonics",
                                                         "sh_shading", "factored")})
    for file_name in ("renderer.py", "shader_cache.py", "scene_state.py"):
        with open(os.path.join(ENGINE_DIR, file_name), encoding="utf-8") as handle:
            source = handle.read()
        found = sorted(word for word, pattern in patterns.items() if re.search(pattern, source))
        assert not found, f"engine/{file_name} names {found}"
