"""The bi-scale technique (SG_BISCALE, iwasaki2012) in the engine: its GLSL against its numpy mirror
(techniques.biscale.biscale_shading.shade_fragments: its lobe source in sg_shading's stages) on the G-buffer's pixels, under a point light
with an environment map and under a constant world; a material whose tile is unusable renders as a single
scale with a warning that says why."""
import engine_fixtures as fx
import numpy as np
import pytest
from test_engine_mirror import _mirror
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


@pytest.mark.parametrize("world, specular", [("texture", 0.8), ("colour", 0.8), ("colour", 0.0)])
def test_biscale_shader_matches_its_mirror(blender, world, specular):
    """The GLSL against the mirror; a zero specular colour is the diffuse-only variant (no slice code)."""
    fx.ensure_registered()
    material = biscale_material(f"biscale_{world}_{specular}", biscale_reference.egg_crate(32), model="GGX",
                                roughness=0.35, diffuse_color=(0.4, 0.3, 0.2), specular_color=(specular,) * 3)
    result = fx.render(_scene(f"biscale_mirror_{world}_{specular}", material, world), gbuffer=True)
    state = result["state"]
    assert state.materials[material.name].technique == "SG_BISCALE"
    if specular:
        errors = _errors(result)
        assert max(errors.values()) < TOLERANCE, errors
    else:
        expected, covered = _mirror(result, use_visibility=False)
        actual = result["passes"]["Diffuse"][..., :3][covered]
        assert fx.relative_error(actual, expected["Diffuse"][covered]).max() < TOLERANCE
        assert result["passes"]["Specular"][..., :3][covered].max() == 0


def test_masked_tiles_shader_matches_its_mirror(blender):
    """Two tiles chosen by a checker mask (iwasaki2012 fig. 1c), Blinn-Phong at the small scale."""
    fx.ensure_registered()
    material = biscale_material("biscale_masked", biscale_reference.egg_crate(16), model="BLINN_PHONG",
                                exponent=150.0, diffuse_color=(0.2, 0.25, 0.3), specular_color=(0.6, 0.6, 0.6))
    checker = (np.add.outer(np.arange(8), np.arange(8)) % 2).astype(np.float32)
    mask = fx.image("biscale_masked_mask", np.repeat(checker[..., None], 4, axis=-1))
    second = np.repeat(np.flipud(biscale_reference.grooves(16))[..., None], 4, axis=-1).astype(np.float32)
    settings = material.sgprt.biscale
    settings.mask = mask
    settings.second_height_image = fx.image("biscale_masked_second", second)
    settings.second_height_scale = 1.0
    result = fx.render(_scene("biscale_mirror_masked", material, "texture"), gbuffer=True)
    params = result["state"].materials[material.name]
    assert params.technique == "SG_BISCALE" and params.biscale.first_lobes == 8 and params.biscale.lobe_count == 16
    from sg_prt_addon.blender import export

    textures = {material.name: {"biscale_mask": export.texture_pixels(mask, "biscale_mask")}}
    expected, covered = _mirror(result, textures, use_visibility=False)
    for name in ("Diffuse", "Specular"):
        actual = result["passes"][name][..., :3][covered]
        assert expected[name][covered].max() > 0
        assert fx.relative_error(actual, expected[name][covered]).max() < TOLERANCE, name


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


def test_an_edited_height_field_or_tile_mesh_is_followed(blender):
    """What view_update sees: painting the height image, or editing the tile mesh, exports the material again
    with the new tile's tables (a new signature); a redraw without an edit keeps them."""
    import bpy

    fx.ensure_registered()
    scene = bpy.context.scene
    for obj in list(scene.objects):
        bpy.data.objects.remove(obj)
    material = biscale_material("biscale_edit", biscale_reference.egg_crate(16), model="GGX", roughness=0.3)
    sphere = fx.uv_sphere(scene, "biscale_edit_sphere", (0.0, 0.0, 1.0), segments=12, rings=6)
    sphere.data.materials.append(material)
    tile = fx.grid(scene, "biscale_edit_tile", (5.0, 0.0, 0.0), size=1.0, segments=8)
    view_layer = bpy.context.view_layer
    try:
        with fx.tracked_state(scene, view_layer) as state:
            first = state.materials[material.name].biscale.signature
            image = material.sgprt.biscale.height_image
            pixels = np.repeat(np.flipud(biscale_reference.egg_crate(16, amplitude=0.1))[..., None], 4, axis=-1)
            image.pixels.foreach_set(pixels.astype(np.float32).ravel())
            image.update()
            image.update_tag()                           # what painting the image tags
            view_layer.update()
            assert material.name in state.consume_dirty().materials
            second = state.materials[material.name].biscale.signature
            assert second != first
            view_layer.update()                          # nothing changed: nothing exported
            assert material.name not in state.consume_dirty().materials
            # the mesh tile: a bump in the grid is a new tile
            material.sgprt.biscale.source = "OBJECT"
            material.sgprt.biscale.tile_object = tile
            view_layer.update()
            state.consume_dirty()
            flat = state.materials[material.name].biscale.signature
            tile.data.vertices[40].co.z += 0.1
            tile.data.update()
            view_layer.update()
            assert material.name in state.consume_dirty().materials
            assert state.materials[material.name].biscale.signature not in (flat, second)
    finally:
        for obj in list(scene.objects):
            bpy.data.objects.remove(obj)


def test_saved_file_reopens_and_renders_the_same_image(blender, tmp_path):
    """Settings, the packed height image and the tile object survive; the reopened file computes the same
    tables (the same seed) and renders the same image."""
    import bpy

    fx.ensure_registered()
    material = biscale_material("biscale_saved", biscale_reference.random_bumps(16), model="BLINN_PHONG",
                                exponent=300.0, diffuse_color=(0.2, 0.3, 0.4), specular_color=(0.7, 0.6, 0.5))
    material.sgprt.biscale.height_image.pack()
    material.sgprt.biscale.lobes = 6
    scene = _scene("biscale_saved_scene", material, "colour")
    before = fx.render(scene)["passes"]["Combined"].copy()
    assert before[..., :3].max() > 0.05
    path = tmp_path / "biscale.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    settings = bpy.data.materials["biscale_saved"].sgprt
    assert (settings.technique, settings.biscale.source, settings.biscale.lobes, settings.biscale.samples,
            settings.biscale.height_image.name) == ("SG_BISCALE", "IMAGE", 6, 2048, "biscale_saved_height")
    result = fx.render(bpy.data.scenes["biscale_saved_scene"])
    assert result["state"].materials["biscale_saved"].technique == "SG_BISCALE"
    np.testing.assert_array_equal(result["passes"]["Combined"], before)


@pytest.fixture(scope="module")
def fitted_table(blender, tmp_path_factory):
    """A generated 8 x 8 SVBRDF table (spatially varying kd, eta, roughness) to fit the small-scale BRDF to."""
    return fx.svbrdf_table_file(tmp_path_factory.mktemp("biscale_fitted"))


def test_lobe_fit_small_scale_shader_matches_its_mirror(blender, fitted_table):
    """A measured small-scale BRDF (iwasaki2012 fig. 8): Fit Lobes on a bi-scale material makes the fit its
    small-scale BRDF (the technique stays); its per-texel lobes, colours and M (S(o) in each facet's frame)
    under the tile's lobes, the GLSL against the mirror."""
    fx.ensure_registered()
    material = biscale_material("biscale_fitted", biscale_reference.egg_crate(32), model="GGX", roughness=0.35)
    fx.fit_lobes(material, fitted_table, lobe_count=2, shadowing_components=5)
    assert (material.sgprt.technique, material.sgprt.biscale.small_scale) == ("SG_BISCALE", "LOBE_FIT")
    for world in ("texture", "colour"):
        result = fx.render(_scene(f"biscale_fitted_{world}", material, world), gbuffer=True)
        params = result["state"].materials[material.name]
        assert params.technique == "SG_BISCALE" and params.fitted is not None
        assert params.fitted.layers.shape[1:3] == (8, 8)
        errors = _errors(result)
        assert max(errors.values()) < TOLERANCE, (world, errors)
    # the model as the small scale again: the fit stays stored and unused
    material.sgprt.biscale.small_scale = "MODEL"
    params = fx.render(_scene("biscale_fitted_model", material, "colour"))["state"].materials[material.name]
    assert params.technique == "SG_BISCALE" and params.fitted is None


def test_unusable_lobe_fit_renders_single_scale_with_a_reason(blender, fitted_table):
    """Lobe Fit chosen with no fit, or with a free-axes fit (not isotropic): the model, a single scale, and why;
    a usable fit with no tile: the fit, a single scale."""
    fx.ensure_registered()
    material = biscale_material("biscale_no_fit", biscale_reference.egg_crate(16), model="GGX")
    material.sgprt.biscale.small_scale = "LOBE_FIT"
    result = fx.render(_scene("biscale_no_fit_scene", material, "colour"))
    assert result["state"].materials[material.name].technique == "SG_PARAMETRIC"
    assert any("no usable small-scale lobe fit (no fitted lobes)" in w for w in result["state"].warnings), \
        result["state"].warnings
    fx.fit_lobes(material, fitted_table, lobe_count=3, axes="FREE", shadowing_components=3)
    result = fx.render(_scene("biscale_free_scene", material, "colour"))
    assert result["state"].materials[material.name].technique == "SG_PARAMETRIC"
    assert any("its lobes leave the normal" in w for w in result["state"].warnings), result["state"].warnings
    fx.fit_lobes(material, fitted_table, lobe_count=1)
    material.sgprt.biscale.height_image = None
    result = fx.render(_scene("biscale_fit_no_tile_scene", material, "colour"))
    assert result["state"].materials[material.name].technique == "SG_FITTED"
    assert any("no usable small-scale geometry (no height image): rendered as a single scale with its lobe fit" in w
               for w in result["state"].warnings), result["state"].warnings
