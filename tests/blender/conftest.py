"""Blender tier: the real pip bpy, the add-on registered once per session."""
import pytest

bpy = pytest.importorskip("bpy")


@pytest.fixture(scope="session")
def addon():
    """The add-on, registered once per process (the gpu tier may have registered it already)."""
    import sg_prt_addon
    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()
    return sg_prt_addon


@pytest.fixture
def empty_file(addon):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene
