"""Blender tier: the real pip bpy, the add-on registered once per session."""
import pytest

bpy = pytest.importorskip("bpy")


@pytest.fixture(scope="session")
def addon():
    import sg_prt_addon
    sg_prt_addon.register()
    yield sg_prt_addon
    sg_prt_addon.unregister()


@pytest.fixture
def empty_file(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene
