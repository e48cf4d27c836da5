"""The technique seam: a technique written as a test fixture (the package normal_display/: the technique and
its Blender side, with a setting of its own and its panel row) plugs in by registering alone, renders next to the built-in one in the same scene, and goes away cleanly; the draw
loop, the shader cache and the scene state name no technique."""
import glob
import os
import re
import tokenize

import engine_fixtures as fx
import normal_display
import numpy as np
import pytest

SIZE = 64
ENGINE_DIR = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "sg_prt_addon", "engine")
BLENDER_DIR = os.path.join(os.path.dirname(ENGINE_DIR), "blender")


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


def test_fixture_technique_brings_its_own_setting_and_panel_row(registered):
    """Registering the fixture (one line) adds its setting at material.sgprt.normal_display, its row to the
    material panel when a material picks it, and the setting reaches its shader; unregistering takes the
    setting away and gives it back with its stored value when registered again."""
    import bpy

    from sg_prt_addon import techniques
    from sg_prt_addon.blender import panels
    from tests.blender import recording_layout

    scene = _scene("seam_own")
    material = bpy.data.materials["seam_own_normals"]
    material.sgprt.source = "SETTINGS"
    material.sgprt.normal_display.brightness = 0.5
    context = type("Context", (), {"material": material})()
    calls = recording_layout.draw(panels.SGPRT_PT_material, context)
    assert ("prop", "brightness") in calls and ("prop", "view_warp") not in calls
    plain = recording_layout.draw(panels.SGPRT_PT_material, type("Context", (), {
        "material": bpy.data.materials["seam_own_plain"]})())
    assert ("prop", "view_warp") in plain and ("prop", "brightness") not in plain

    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    passes = result["passes"]
    shown = passes["gbuffer_normal"][..., 3] == list(result["state"].objects).index("seam_own_normals") + 1
    assert shown.sum() > 200
    np.testing.assert_allclose(passes["Diffuse"][shown][:, :3],
                               registered.mirror(passes["gbuffer_normal"][shown][:, :3], 0.5), atol=2e-6)

    techniques.unregister(normal_display.NAME)
    try:
        assert not hasattr(material.sgprt, "normal_display")
    finally:
        techniques.register(normal_display.TECHNIQUE)
    assert material.sgprt.normal_display.brightness == 0.5


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


# Tokens of text, not code: strings, comments, and the literal parts of f-strings (tokens of their own from
# Python 3.12)
TEXT_TOKENS = {tokenize.STRING, tokenize.COMMENT, getattr(tokenize, "FSTRING_MIDDLE", tokenize.STRING)}


def _code_of(path):
    """A module's code without its strings and comments (labels and tooltips may speak of a technique)."""
    with open(path, encoding="utf-8") as handle:
        tokens = tokenize.generate_tokens(handle.readline)
        return " ".join(token.string for token in tokens if token.type not in TEXT_TOKENS)


def test_engine_and_blender_glue_name_no_technique():
    """The draw loop, the shader cache, the scene state and the Blender glue (blender/) reach techniques through
    the registry only: a technique's settings, panel rows, operators and fallbacks live in its own package."""
    from sg_prt_addon import techniques

    # technique names as whole words ("SH" is in "SHADER"), the rest as the fragments they are
    patterns = {name: r"\b" + re.escape(name) + r"\b" for name in techniques.names()}
    patterns.update({word: re.escape(word) for word in ("sg_lobes", "sg_parametric", "sg_fitted", "sg_biscale",
                                                         "biscale_shading", "FITTED", "VariantKey",
                                                         "ssdf_coefficients", "fitted_texels", "fitted_m_factor",
                                                         "anisotropy_table", "ggx_", "spherical_harmonics",
                                                         "sh_shading", "factored")})
    patterns.update({f"techniques.{package}": rf"techniques\.{package}\b" for package in ("sg", "sh", "homomorphic", "biscale")})
    for file_name in ("renderer.py", "shader_cache.py", "scene_state.py"):
        with open(os.path.join(ENGINE_DIR, file_name), encoding="utf-8") as handle:
            source = handle.read()
        found = sorted(word for word, pattern in patterns.items() if re.search(pattern, source))
        assert not found, f"engine/{file_name} names {found}"
    paths = sorted(glob.glob(os.path.join(BLENDER_DIR, "**", "*.py"), recursive=True))
    assert len(paths) > 15
    for path in paths:
        found = sorted(word for word, pattern in patterns.items() if re.search(pattern, _code_of(path)))
        assert not found, f"blender/{os.path.relpath(path, BLENDER_DIR)} names {found}"
