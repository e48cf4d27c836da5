"""A node tree's numbers are uniforms (techniques/material_textures.py NodeConstants): editing a value node that
feeds a computed slot changes what renders without compiling a shader, and two materials that differ only in
their numbers share one."""
import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 16


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()


def _mixing_material(name, factor):
    """An Emission whose Color mixes a Noise Texture's colour with red by a Value node."""
    from benchmarks.cycles_truth import empty_node_material

    material, tree, output = empty_node_material(name)
    emission = tree.nodes.new("ShaderNodeEmission")
    noise, mix, value = (tree.nodes.new(kind) for kind in ("ShaderNodeTexNoise", "ShaderNodeMix", "ShaderNodeValue"))
    mix.data_type = "RGBA"
    value.outputs[0].default_value = factor
    tree.links.new(value.outputs[0], mix.inputs["Factor"])
    tree.links.new(noise.outputs["Color"], mix.inputs["A"])
    mix.inputs["B"].default_value = (0.9, 0.1, 0.05, 1.0)
    tree.links.new(mix.outputs["Result"], emission.inputs["Color"])
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material, value


def _render(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return result["passes"]["Combined"][..., :3].copy()


def test_a_value_edit_renders_without_a_compile(engine):
    from sg_prt_addon.engine import shader_cache

    scene = fx.new_scene("node_constants", SIZE, SIZE)
    fx.world_colour(scene, (0.0, 0.0, 0.0))
    material, value = _mixing_material("node_constants", 0.25)
    fx.plane(scene, "node_constants_plane", (0.0, 0.0, 0.0), size=2.0).data.materials.append(material)
    scene.camera.location, scene.camera.rotation_euler = (0.0, 0.0, 3.0), (0.0, 0.0, 0.0)
    scene.camera.data.type, scene.camera.data.ortho_scale = "ORTHO", 2.0
    quarter = _render(scene)
    compiled = shader_cache.compile_count["surface"]
    value.outputs[0].default_value = 0.75
    three_quarters = _render(scene)
    value.outputs[0].default_value = 0.5
    half = _render(scene)
    assert shader_cache.compile_count["surface"] == compiled          # the numbers changed, not the shader
    assert np.abs(three_quarters - quarter).max() > 0.1                # and what renders did
    np.testing.assert_allclose(half, 0.5 * (quarter + three_quarters), atol=1e-5)     # the mix is linear in it

    other, _ = _mixing_material("node_constants_other", 0.6)
    fx.plane(scene, "node_constants_other_plane", (0.0, 0.0, -1.0), size=2.0).data.materials.append(other)
    _render(scene)
    assert shader_cache.compile_count["surface"] == compiled          # a second material, the same graph
