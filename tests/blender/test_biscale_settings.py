"""A bi-scale material's settings in Blender (material.sgprt.biscale): its panel, what export makes of them,
and the clear word when they cannot be rendered (techniques/biscale/blender/biscale_source.py)."""
import numpy as np
import pytest
import recording_layout
from exported_material import export_with_warnings

bpy = pytest.importorskip("bpy")


def _height_image(name, heights):
    image = bpy.data.images.new(name, heights.shape[1], heights.shape[0], float_buffer=True)
    pixels = np.repeat(np.flipud(heights)[..., None], 4, axis=-1).astype(np.float32)
    image.pixels.foreach_set(pixels.ravel())
    return image


def _biscale(name, **settings):
    material = bpy.data.materials.new(name)
    material.sgprt.technique = "SG_BISCALE"
    for key, value in settings.items():
        setattr(material.sgprt, key, value)
    material.sgprt.biscale.samples = 512
    material.sgprt.biscale.lobes = 4
    return material


def _drawn(panel, material):
    return recording_layout.draw(panel, type("Context", (), {"material": material})())


def test_panel_shows_the_tile_of_the_chosen_source(empty_file):
    from sg_prt_addon.blender import panels
    from sg_prt_addon.techniques.biscale import blender as biscale_side

    material = _biscale("panel_biscale", model="GGX")
    material.sgprt.biscale.height_image = _height_image("panel_height", np.zeros((8, 8)))
    calls = _drawn(biscale_side.SGPRT_PT_material_biscale, material)
    assert ("template_ID", "height_image") in calls and ("prop", "height_scale") in calls
    assert ("prop", "tile_object") not in calls
    export_with_warnings(material)
    assert any(kind == "label" and "lobes from 128 triangles" in text for kind, text in
               _drawn(biscale_side.SGPRT_PT_material_biscale, material))
    material.sgprt.biscale.source = "OBJECT"
    calls = _drawn(biscale_side.SGPRT_PT_material_biscale, material)
    assert ("prop", "tile_object") in calls and ("template_ID", "height_image") not in calls
    # shown only while the material renders bi-scale
    context = type("Context", (), {"engine": panels.ENGINE_ID, "material": material})()
    assert biscale_side.SGPRT_PT_material_biscale.poll(context)
    material.sgprt.technique = "SG_PARAMETRIC"
    assert not biscale_side.SGPRT_PT_material_biscale.poll(context)


def test_export_gives_the_tables_and_what_it_reads(empty_file):
    from sg_prt_addon.biscale import bvndf

    material = _biscale("export_biscale", model="BLINN_PHONG", exponent=200.0)
    material.sgprt.biscale.height_image = _height_image("export_height", 0.05 * np.eye(8))
    params, warnings = export_with_warnings(material)
    assert params.technique == "SG_BISCALE" and isinstance(params.biscale, bvndf.BVNDF) and not warnings
    assert params.reads == (("IMAGE", "export_height"),)
    assert params.biscale.lobe_count == 4 and params.biscale.resolution == 12
    # the same tile and settings: the cached tables
    assert export_with_warnings(material)[0].biscale is params.biscale


def test_a_mask_and_a_second_height_field_make_two_tiles(empty_file):
    from sg_prt_addon.biscale import bvndf
    from sg_prt_addon.techniques.biscale import blender as biscale_side

    material = _biscale("masked_biscale", model="GGX")
    settings = material.sgprt.biscale
    settings.height_image = _height_image("masked_first", 0.05 * np.eye(8))
    settings.mask = _height_image("masked_mask", np.tri(8))
    params, warnings = export_with_warnings(material)
    assert any("no second height image: the mask is not applied" in warning for warning in warnings)
    assert isinstance(params.biscale, bvndf.BVNDF) and "biscale_mask" not in params.textures
    assert ("template_ID", "second_height_image") in _drawn(biscale_side.SGPRT_PT_material_biscale, material)
    settings.second_height_image = _height_image("masked_second", np.zeros((8, 8)))
    params, warnings = export_with_warnings(material)
    assert isinstance(params.biscale, bvndf.MaskedTiles) and params.biscale.lobe_count == 4 + 4
    assert params.textures["biscale_mask"] == "masked_mask" and not warnings
    assert ("IMAGE", "masked_second") in params.reads


@pytest.mark.parametrize("case, expected", [
    ("no image", "no usable small-scale geometry (no height image)"),
    ("nan", "no usable small-scale geometry (the height field has 1 texel(s) that are not finite"),
    ("anisotropic", "needs an isotropic small-scale model"),
    ("fresnel", "does not apply fresnel"),
])
def test_what_cannot_render_bi_scale_is_said(empty_file, case, expected):
    material = _biscale(f"bad_{case.replace(' ', '_')}", model="GGX_ANISO" if case == "anisotropic" else "GGX")
    heights = np.zeros((8, 8))
    if case == "nan":
        heights[3, 4] = np.nan
    if case != "no image":
        material.sgprt.biscale.height_image = _height_image(f"bad_{case}_height", heights)
    if case == "fresnel":
        material.sgprt.fresnel = "SCHLICK"
    params, warnings = export_with_warnings(material)
    assert any(expected in warning for warning in warnings), warnings
    assert params.technique == ("SG_BISCALE" if case == "fresnel" else "SG_PARAMETRIC")
