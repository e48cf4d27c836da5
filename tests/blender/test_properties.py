"""Material settings: defaults, save/reload round trip, register/unregister/register."""
import bpy
import numpy as np
import pytest
import recording_layout

from sg_prt_addon.blender import properties

EDITED_VALUES = {
    "model": "ASHIKHMIN_SHIRLEY", "diffuse_color": (0.1, 0.2, 0.3), "specular_color": (0.7, 0.6, 0.5),
    "roughness": 0.0625, "ior": 2.25, "exponent": 3500.0, "alpha_x": 0.375, "alpha_y": 0.015625,
    "nu": 12.5, "nv": 40000.0, "lobe_count": 7, "normal_strength": 2.5, "tangent_source": "OBJECT_AXIS",
    "tangent_axis": (0.0, 0.6, 0.8), "tangent_rotation": 0.75, "show_textures": False,
}


def _value(settings, name):
    value = getattr(settings, name)
    return tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value


def test_defaults_are_a_plausible_glossy_material(empty_file):
    settings = bpy.data.materials.new("Default").sgprt
    assert settings.model == "GGX"
    assert _value(settings, "diffuse_color") == pytest.approx((0.5, 0.5, 0.5))
    assert _value(settings, "specular_color") == pytest.approx((0.25, 0.25, 0.25))
    assert settings.roughness == pytest.approx(0.3)
    assert settings.lobe_count == 0       # Auto: the model's own count (models.lobes_of)
    assert settings.sg.view_warp == "SPLIT3"
    assert all(getattr(settings, f"{name}_texture") is None for name in properties.TEXTURED_PARAMETERS)
    assert settings.normal_map is None


def test_every_model_lists_only_existing_parameters(addon):
    names = set(properties.SGPRT_PG_material.__annotations__)
    from sg_prt_addon.reflectance import models

    assert [item.identifier for item in properties.SGPRT_PG_material.bl_rna.properties["model"].enum_items] \
        == list(models.NAMES)
    for model in models.MODELS:
        assert set(model.panel_parameters) <= names
    for name in properties.TEXTURED_PARAMETERS:
        assert f"{name}_texture" in names


def test_values_and_images_survive_save_and_reopen(empty_file, tmp_path):
    material = bpy.data.materials.new("Edited")
    for name, value in EDITED_VALUES.items():
        setattr(material.sgprt, name, value)
    images = {}
    for index, name in enumerate(properties.TEXTURED_PARAMETERS + ("normal",)):
        image = bpy.data.images.new(f"image_{name}", 4, 4, float_buffer=True)
        rgba = np.full((16, 4), index / 16.0, np.float32)
        rgba[:, 3] = 1.0  # alpha 1: a zero alpha is not guaranteed to survive packing
        image.pixels.foreach_set(rgba.ravel())
        image.pack()
        images[name] = image.name
        setattr(material.sgprt, "normal_map" if name == "normal" else f"{name}_texture", image)
    material.use_fake_user = True
    path = tmp_path / "settings.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))

    bpy.ops.wm.read_factory_settings(use_empty=True)
    assert "Edited" not in bpy.data.materials
    bpy.ops.wm.open_mainfile(filepath=str(path))
    reopened = bpy.data.materials["Edited"].sgprt
    for name, value in EDITED_VALUES.items():
        assert _value(reopened, name) == (pytest.approx(value) if not isinstance(value, str) else value), name
    for index, name in enumerate(properties.TEXTURED_PARAMETERS + ("normal",)):
        image = reopened.normal_map if name == "normal" else getattr(reopened, f"{name}_texture")
        assert image is not None and image.name == images[name]
        pixels = np.empty(64, np.float32)
        image.pixels.foreach_get(pixels)
        assert np.all(pixels.reshape(16, 4)[:, :3] == np.float32(index / 16.0)), name


def test_register_unregister_register(addon):
    from sg_prt_addon.blender import panels
    builtin = [p for p in panels._builtin_panels()]
    assert builtin, "no built-in panel was opted into the engine"
    addon.unregister()
    try:
        assert not hasattr(bpy.types.Material, "sgprt")
        with pytest.raises(TypeError):
            bpy.context.scene.render.engine = "SG_PRT"
        assert all("SG_PRT" not in panel.COMPAT_ENGINES for panel in builtin)
    finally:
        addon.register()
    assert hasattr(bpy.types.Material, "sgprt")
    assert all("SG_PRT" in panel.COMPAT_ENGINES for panel in builtin)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.context.scene.render.engine = "SG_PRT"
    assert bpy.data.materials.new("After").sgprt.model == "GGX"


def test_edits_from_python_reach_the_depsgraph(empty_file):
    material = bpy.data.materials.new("Tagged")
    bpy.ops.mesh.primitive_plane_add()
    bpy.context.active_object.data.materials.append(material)
    bpy.context.evaluated_depsgraph_get().update()
    updated = []

    def record(scene, depsgraph):
        updated.extend(update.id.original.name for update in depsgraph.updates)

    bpy.app.handlers.depsgraph_update_post.append(record)
    try:
        material.sgprt.roughness = 0.7
        bpy.context.evaluated_depsgraph_get().update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(record)
    assert "Tagged" in updated


@pytest.mark.parametrize("model, auto", [("ASHIKHMIN_SHIRLEY", 4), ("WARD_ANISO", 4), ("GGX_ANISO", 6)])
def test_the_panel_says_what_auto_lobes_are_and_only_at_auto(empty_file, model, auto):
    from sg_prt_addon.blender import panels

    material = bpy.data.materials.new(f"Lobes {model}")
    material.sgprt.source = "SETTINGS"
    material.sgprt.model = model
    context = type("Context", (), {"material": material})()
    assert ("label", f"Auto: {auto}") in recording_layout.draw(panels.SGPRT_PT_material, context)
    material.sgprt.lobe_count = 5
    calls = recording_layout.draw(panels.SGPRT_PT_material, context)
    assert ("prop", "lobe_count") in calls and not any(kind == "label" and text.startswith("Auto") for kind, text in calls)
