"""A node tree's textured emission under every technique: a plane filling an orthographic view, its material's
Emission Color an image (black base, black world, no lights), renders the image (times the strength) through
each technique's shader, the same in each."""
import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 16
STRENGTH = 2.0


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()


def _emitting_material(name, image, **settings):
    """SG-PRT settings (the technique and what it needs) with the look read from a node tree: a black
    Principled BSDF whose Emission Color is `image`."""
    import bpy

    material = fx.material(name, **settings)
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    principled = next(node for node in tree.nodes if node.type == "BSDF_PRINCIPLED")
    principled.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    principled.inputs["Emission Strength"].default_value = STRENGTH
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], principled.inputs["Emission Color"])
    material.sgprt.source = "NODE_TREE"
    return material


def _render(name, material):
    import bpy

    scene = fx.new_scene(name, SIZE, SIZE)
    fx.world_colour(scene, (0.0, 0.0, 0.0))
    plane = fx.plane(scene, name + "_plane", (0.0, 0.0, 0.0), size=2.0)
    plane.data.materials.append(material)
    scene.camera.location = (0.0, 0.0, 3.0)
    scene.camera.rotation_euler = (0.0, 0.0, 0.0)
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 2.0
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    assert bpy.data.materials[material.name].sgprt.source == "NODE_TREE"
    return result


def test_emission_texture_renders_alike_under_every_technique(engine, tmp_path):
    from sg_prt_addon.blender import lobe_fit
    from sg_prt_addon.spherical import texture_fetch

    image = fx.image("emission_waves", fx.waves())
    fitted = _emitting_material("emission_fitted", image, technique="SG_FITTED")
    fx.fit_lobes(fitted, fx.svbrdf_table_file(tmp_path), lobe_count=1, shadowing_components=1)
    assert lobe_fit.fit_status(fitted)[0] == "VALID"
    materials = {"SG_PARAMETRIC": _emitting_material("emission_sg", image, technique="SG_PARAMETRIC"),
                 "SH": _emitting_material("emission_sh", image, technique="SH"),
                 "FACTORED": _emitting_material("emission_factored", image, technique="FACTORED", model="GGX"),
                 "SG_BISCALE": _emitting_material("emission_biscale", image, technique="SG_BISCALE", biscale={
                     "height_image": fx.image("emission_tile", np.zeros((4, 4, 4), np.float32)), "samples": 64}),
                 "SG_FITTED": fitted}
    images = {}
    for technique, material in materials.items():
        result = _render(f"emission_{technique.lower()}", material)
        params = result["state"].materials[material.name]
        assert params.technique == technique and params.textures["emission"] == image.name
        images[technique] = result["passes"]["Combined"][..., :3]
    # the image at the pixels' UVs (row 0 at the bottom, as the passes), away from the border the filter reaches
    centres = (np.arange(SIZE) + 0.5) / SIZE
    uv = np.stack(np.broadcast_arrays(centres[None, :], centres[:, None]), -1).astype(np.float32)
    expected = STRENGTH * texture_fetch.bilinear(fx.waves(), uv, wrap=True)[..., :3]
    inner = (slice(2, -2), slice(2, -2))
    for technique, combined in images.items():
        np.testing.assert_allclose(combined, images["SG_PARAMETRIC"], atol=1e-5, err_msg=technique)
        error = np.abs(combined[inner] - expected[inner]).max() / expected[inner].mean()
        assert error < 0.03, (technique, error)
