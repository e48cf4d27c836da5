"""A spherical-harmonics material with a stored lobe fit (SH BRDF: Lobe Fit): Fit Lobes on an SH material makes
the fit what it tabulates, the choice survives save and reopen, the panels say what renders, and a fit the
technique cannot tabulate is refused with its reason (techniques/sh/blender)."""
import numpy as np
import pytest
import recording_layout
from exported_material import export_with_warnings

from validation import brdf_generators

bpy = pytest.importorskip("bpy")


@pytest.fixture(scope="module")
def table_path(tmp_path_factory):
    from sg_prt_addon.measured import svbrdf_table

    path = str(tmp_path_factory.mktemp("sh_fitted_settings") / "table.npz")
    table, _ = brdf_generators.generate_svbrdf_table(size=8, seed=5)
    svbrdf_table.write_svbrdf_table(path, table)
    return path


def _sh_material(name, **settings):
    bpy.ops.mesh.primitive_cube_add()
    material = bpy.data.materials.new(name)
    bpy.context.active_object.data.materials.append(material)
    material.sgprt.technique = "SH"
    for key, value in settings.items():
        setattr(material.sgprt.sh, key, value)
    return material


def _fit(material, path, **options):
    with bpy.context.temp_override(material=material):
        assert bpy.ops.sgprt.fit_lobes(filepath=path, **options) == {"FINISHED"}


def _labels(material):
    panel = bpy.types.SGPRT_PT_material_lobe_fit
    return [text for kind, text in recording_layout.draw(panel, type("Context", (), {"material": material})())
            if kind == "label"]


def test_a_fit_on_an_sh_material_is_tabulated_and_the_choice_survives_reopening(empty_file, table_path, tmp_path):
    from sg_prt_addon.blender import panels

    material = _sh_material("sh_fit_saved", order=6)
    assert material.sgprt.sh.brdf == "MODEL"
    assert _labels(material) == ["No fitted lobes: renders the model above"]
    _fit(material, table_path, lobe_count=2, shadowing_components=4)
    assert (material.sgprt.technique, material.sgprt.sh.brdf) == ("SH", "LOBE_FIT")
    params, warnings = export_with_warnings(material)
    assert params.technique == "SH" and params.fitted is not None and not warnings
    assert params.fitted.layers.shape[1:3] == (8, 8)
    calls = recording_layout.draw(panels.SGPRT_PT_material, type("Context", (), {"material": material})())
    assert {("prop", "order"), ("prop", "window"), ("prop", "brdf")} <= set(calls)
    assert ("prop", "view_warp") not in calls
    assert "Tabulated per texel by the SH technique" in _labels(material)

    material.use_fake_user = True
    path = tmp_path / "sh_fitted.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    reopened = bpy.data.materials["sh_fit_saved"]
    assert (reopened.sgprt.technique, reopened.sgprt.sh.brdf, reopened.sgprt.sh.order) == ("SH", "LOBE_FIT", 6)
    again, warnings = export_with_warnings(reopened)
    assert again.technique == "SH" and not warnings
    np.testing.assert_array_equal(again.fitted.layers, params.fitted.layers)

    reopened.sgprt.sh.brdf = "MODEL"            # the model again: the fit stays stored and unused
    model, _ = export_with_warnings(reopened)
    assert model.technique == "SH" and model.fitted is None
    assert any("set SH BRDF to Lobe Fit" in text for text in _labels(reopened))


def test_fits_it_cannot_tabulate_are_refused_with_the_reason(empty_file, table_path, monkeypatch):
    """No fit: SH with the model; a free-axes fit or one whose tables are too large: the fitted SG lobes."""
    from sg_prt_addon.harmonics import fitted_table

    material = _sh_material("sh_fit_refused", brdf="LOBE_FIT")
    params, warnings = export_with_warnings(material)
    assert params.technique == "SH" and params.fitted is None
    assert any("no usable lobe fit (no fitted lobes): its model is tabulated" in w for w in warnings), warnings

    _fit(material, table_path, lobe_count=1, shadowing_components=3)
    monkeypatch.setattr(fitted_table, "MAX_TABLE_BYTES", 2 ** 17)
    params, warnings = export_with_warnings(material)
    assert params.technique == "SG_FITTED" and params.fitted is not None
    assert any("cannot tabulate its lobe fit (its 8x8 texels' tables at order 5 would take 0.25 MB, more than 0.125" in w
               and "rendered with Fitted SG Lobes" in w for w in warnings), warnings
    monkeypatch.undo()

    _fit(material, table_path, lobe_count=3, axes="FREE", shadowing_components=3)
    assert material.sgprt.sh.brdf == "LOBE_FIT" and material.sgprt.lobe_fit.free_axes
    params, warnings = export_with_warnings(material)
    assert params.technique == "SG_FITTED" and params.fitted is not None
    assert any("cannot tabulate its lobe fit (its lobes leave the normal by up to" in w for w in warnings), warnings
    assert any(text.startswith("Free axes: SH tabulates lobes about the normal only") for text in _labels(material))
