"""A node tree's transparency as coverage (reflectance/coverage.py, surface_io.glsl surface_coverage) and its
holdout: a plane filling an orthographic view emits an image (black base, black world, no lights) over a
backdrop plane that emits a constant colour behind it.  Render Samples over every frame (not Edges Only) keep
the plane in a share of each pixel's samples that converges to its alpha, under every technique."""
import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 16
ALPHA = 0.4
BACKDROP = np.array([0.1, 0.3, 0.8])
SAMPLES = 16


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()


def _node_material(name, **settings):
    import bpy

    material = fx.material(name, **settings)
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    material.sgprt.source = "NODE_TREE"
    return material, material.node_tree


def _emitting(name, image, alpha=1.0, **settings):
    """A black Principled BSDF emitting `image` at `alpha`."""
    material, tree = _node_material(name, **settings)
    principled = next(node for node in tree.nodes if node.type == "BSDF_PRINCIPLED")
    principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    principled.inputs["Emission Strength"].default_value = 1.0
    principled.inputs["Alpha"].default_value = alpha
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Emission Color"])
    return material


def _backdrop(name):
    material, tree = _node_material(name)
    principled = next(node for node in tree.nodes if node.type == "BSDF_PRINCIPLED")
    principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    principled.inputs["Emission Color"].default_value = (*BACKDROP, 1.0)
    principled.inputs["Emission Strength"].default_value = 1.0
    return material


def _render(name, material, backdrop=True, samples=SAMPLES):
    scene = fx.new_scene(name, SIZE, SIZE)
    scene.sgprt.render_samples = samples
    scene.sgprt.sample_edges_only = False
    fx.world_colour(scene, (0.0, 0.0, 0.0))
    fx.plane(scene, name + "_plane", (0.0, 0.0, 0.0), size=2.0).data.materials.append(material)
    if backdrop:
        fx.plane(scene, name + "_backdrop", (0.0, 0.0, -0.5), size=3.0).data.materials.append(_backdrop(name + "_b"))
    scene.camera.location = (0.0, 0.0, 3.0)
    scene.camera.rotation_euler = (0.0, 0.0, 0.0)
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 2.0
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return result


def test_a_transparent_surface_shows_what_is_behind_under_every_technique(engine, tmp_path):
    """alpha x the plane's emission + (1 - alpha) x the backdrop's; before, the plane was drawn opaque (and the
    depth pre-pass would have hidden the backdrop)."""
    from sg_prt_addon.blender import lobe_fit

    image = fx.image("coverage_waves", fx.waves())
    opaque = _render("coverage_opaque", _emitting("coverage_opaque", image), backdrop=False)
    emitted = opaque["passes"]["Combined"][..., :3].copy()
    expected = ALPHA * emitted + (1.0 - ALPHA) * BACKDROP
    fitted = _emitting("coverage_fitted", image, ALPHA, technique="SG_FITTED")
    fx.fit_lobes(fitted, fx.svbrdf_table_file(tmp_path), lobe_count=1, shadowing_components=1)
    assert lobe_fit.fit_status(fitted)[0] == "VALID"
    materials = {"SG_PARAMETRIC": _emitting("coverage_sg", image, ALPHA, technique="SG_PARAMETRIC"),
                 "SH": _emitting("coverage_sh", image, ALPHA, technique="SH"),
                 "FACTORED": _emitting("coverage_factored", image, ALPHA, technique="FACTORED", model="GGX"),
                 "SG_BISCALE": _emitting("coverage_biscale", image, ALPHA, technique="SG_BISCALE", biscale={
                     "height_image": fx.image("coverage_tile", np.zeros((4, 4, 4), np.float32)), "samples": 64}),
                 "SG_FITTED": fitted}
    inner = (slice(2, -2), slice(2, -2))
    for technique, material in materials.items():
        result = _render(f"coverage_{technique.lower()}", material)
        params = result["state"].materials[material.name]
        assert params.technique == technique and params.alpha == pytest.approx(ALPHA)
        combined = result["passes"]["Combined"]
        assert np.allclose(combined[..., 3], 1.0, atol=1e-5), technique
        # the filtered share of samples that keep the plane is its alpha up to the dither's error, in units of
        # the contrast: measured 0.013 RMS, 0.051 at most (test_anti_aliasing simulates 0.029 and 0.09 over
        # all alphas)
        error = np.abs(combined[inner][..., :3] - expected[inner])
        contrast = np.abs(emitted[inner] - BACKDROP).max(axis=-1, keepdims=True)
        assert np.sqrt(np.mean((error / contrast) ** 2)) < 0.03, technique
        assert np.all(error <= 0.08 * contrast), (technique, float((error / contrast).max()))
        mean = np.abs(combined[inner][..., :3].mean((0, 1)) - expected[inner].mean((0, 1))) / expected[inner].mean()
        assert mean.max() < 0.01, (technique, mean)


def test_a_holdout_takes_its_share_of_the_alpha(engine):
    """Mix Shader (0.3) of an Emission and a Holdout: Combined is 0.7 x the emission with alpha 0.7, exactly,
    and nothing behind shows through (Cycles' holdout)."""
    image = fx.image("holdout_waves", fx.waves())
    emitted = _render("holdout_opaque", _emitting("holdout_opaque", image), backdrop=False, samples=1)
    expected = emitted["passes"]["Combined"].copy()      # (the next render replaces last_render's passes)
    material, tree = _node_material("holdout_mix")
    output = next(node for node in tree.nodes if node.type == "OUTPUT_MATERIAL")
    for node in [node for node in tree.nodes if node.type == "BSDF_PRINCIPLED"]:
        tree.nodes.remove(node)
    emission, holdout, mix = (tree.nodes.new(kind) for kind in ("ShaderNodeEmission", "ShaderNodeHoldout",
                                                                  "ShaderNodeMixShader"))
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], emission.inputs["Color"])
    mix.inputs["Fac"].default_value = 0.3
    tree.links.new(emission.outputs[0], mix.inputs[1])
    tree.links.new(holdout.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    result = _render("holdout_mix", material, samples=1)
    assert not [w for w in result["state"].warnings if "holdout_mix" in w], result["state"].warnings
    combined = result["passes"]["Combined"]
    np.testing.assert_allclose(combined[..., :3], 0.7 * expected[..., :3], rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(combined[..., 3], 0.7, atol=1e-6)
