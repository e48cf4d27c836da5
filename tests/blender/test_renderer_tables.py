"""DrawContext's tables (engine/renderer.py): a table of the code alone is built once and read from the disk
cache by the next process; an environment's table is remade when the scene's environment is another one (it
was keyed by id(), which a new environment can reuse once the old one is freed)."""
import types

import numpy as np
import pytest

pytest.importorskip("bpy")


@pytest.fixture()
def context(monkeypatch, tmp_path):
    from sg_prt_addon.engine import renderer

    monkeypatch.setenv("SG_PRT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(renderer, "_texture", lambda array: ("texture", np.array(array)))   # no GPU here

    def new_context(environment=None):
        draw_context = renderer._DrawContext.__new__(renderer._DrawContext)
        draw_context.renderer = renderer.Renderer()
        draw_context.inputs = types.SimpleNamespace(environment=environment)
        return draw_context

    return new_context


def test_a_table_is_built_once_then_read_from_disk_by_a_new_renderer(context):
    calls = []

    def build():
        calls.append(1)
        return np.full((2, 3, 4), 0.25, np.float32)

    first = context()
    texture = first.table("example", build)
    assert first.table("example", build) is texture and len(calls) == 1
    second = context()                      # another process's renderer: nothing in memory
    read = second.table("example", lambda: pytest.fail("built again despite the disk entry"))
    np.testing.assert_array_equal(read[1], texture[1])


def test_an_environment_table_follows_the_environment(context):
    from sg_prt_addon.lighting.scene_lighting import EnvironmentData

    draw_context = context(EnvironmentData(colour=np.ones(3, np.float32)))
    first = draw_context.environment_table("sky", lambda: np.ones((1, 1, 4), np.float32))
    assert draw_context.environment_table("sky", lambda: pytest.fail("remade for the same environment")) is first
    draw_context.inputs = types.SimpleNamespace(environment=EnvironmentData(colour=np.zeros(3, np.float32)))
    remade = draw_context.environment_table("sky", lambda: np.zeros((1, 1, 4), np.float32))
    assert remade is not first and remade[1].max() == 0
    assert len(draw_context.renderer.environment_tables) == 1         # the old environment's table is dropped
