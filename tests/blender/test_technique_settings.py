"""Each technique's own settings (material.sgprt.<group>, declared by its package's Blender side): defaults, a
file that stored them flat on material.sgprt under their old names, and the material panel's rows, which are
the chosen technique's alone."""
import bpy
import recording_layout


def _rows(material):
    from sg_prt_addon.blender import panels

    context = type("Context", (), {"material": material})()
    return {name for kind, name in recording_layout.draw(panels.SGPRT_PT_material, context) if kind == "prop"}


def test_defaults(empty_file):
    settings = bpy.data.materials.new("defaults").sgprt
    assert settings.sg.view_warp == "SPLIT3"
    assert (settings.sh.order, settings.sh.window, settings.sh.brdf) == (5, "NONE", "MODEL")


def test_settings_stored_flat_by_older_files_are_moved_into_their_groups(empty_file, tmp_path):
    """Files saved before the groups hold sh_order, sh_window, sh_brdf and view_warp as ID properties of
    material.sgprt (enums as their item index): reopened, the values are the groups' and the old keys gone."""
    material = bpy.data.materials.new("old_flat")
    material.use_fake_user = True
    material.sgprt.technique = "SH"
    material.sgprt["sh_order"] = 7
    material.sgprt["sh_window"] = 2          # LANCZOS
    material.sgprt["sh_brdf"] = 1            # LOBE_FIT
    material.sgprt["view_warp"] = 2          # PAPER
    path = tmp_path / "old_flat.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.wm.open_mainfile(filepath=str(path))
    settings = bpy.data.materials["old_flat"].sgprt
    assert (settings.sh.order, settings.sh.window, settings.sh.brdf) == (7, "LANCZOS", "LOBE_FIT")
    assert settings.sg.view_warp == "PAPER"
    assert not {"sh_order", "sh_window", "sh_brdf", "view_warp"} & set(settings.keys())


def test_the_panel_shows_the_chosen_techniques_rows_alone(empty_file):
    material = bpy.data.materials.new("rows")
    material.sgprt.source = "SETTINGS"
    assert "view_warp" in _rows(material) and "order" not in _rows(material)
    material.sgprt.technique = "SH"
    assert {"order", "window", "brdf"} <= _rows(material) and "view_warp" not in _rows(material)
    material.sgprt.technique = "FACTORED"            # factors the BRDF: no view warp to choose
    assert not {"view_warp", "order", "window", "brdf"} & _rows(material)
