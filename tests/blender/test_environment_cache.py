"""The engine's environment cache (scene_state.environment_data): keyed by pixel content, bounded."""
import numpy as np
import pytest

pytest.importorskip("bpy")


def _world(name, seed):
    from sg_prt_addon.blender.export import WorldExport
    pixels = np.random.default_rng(seed).uniform(0.1, 2.0, (16, 32, 3)).astype(np.float32)
    return WorldExport(image_name=name, equirect=pixels)


def test_same_pixels_share_one_prefilter_and_new_pixels_do_not(monkeypatch):
    from sg_prt_addon.engine import scene_state

    monkeypatch.setattr(scene_state, "_environment_cache", {})
    first = scene_state.environment_data(_world("sky.exr", 1), layer_size=8)
    renamed = scene_state.environment_data(_world("sky.001.exr", 1), layer_size=8)      # a reloaded copy
    assert renamed is first
    edited_world = _world("sky.exr", 1)
    edited_world.equirect[3, 5, 0] += 0.25          # one texel edited (the old checksum-by-sum missed swaps)
    edited = scene_state.environment_data(edited_world, layer_size=8)
    assert edited is not first
    swapped_world = _world("sky.exr", 1)
    swapped_world.equirect[[0, 1]] = swapped_world.equirect[[1, 0]]         # same sum, other pixels
    assert scene_state.environment_data(swapped_world, layer_size=8) is not first
    assert scene_state.environment_data(_world("sky.exr", 1), layer_size=16) is not first   # other layer size


def test_cache_keeps_the_most_recent_few(monkeypatch):
    from sg_prt_addon.engine import scene_state

    monkeypatch.setattr(scene_state, "_environment_cache", {})
    size = scene_state.ENVIRONMENT_CACHE_SIZE
    first = scene_state.environment_data(_world("a", 0), layer_size=8)
    for seed in range(1, size):
        scene_state.environment_data(_world("b", seed), layer_size=8)
    assert scene_state.environment_data(_world("a", 0), layer_size=8) is first      # used again: most recent
    scene_state.environment_data(_world("c", size), layer_size=8)                    # evicts seed 1, not seed 0
    assert len(scene_state._environment_cache) == size
    assert scene_state.environment_data(_world("a", 0), layer_size=8) is first
