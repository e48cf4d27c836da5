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


def test_a_new_process_reads_the_environment_from_disk_bit_exact(monkeypatch, tmp_path):
    """The in-memory cache emptied (a new process) reads the disk entry: the same arrays to the bit, and
    neither the prefilter nor the fit runs again."""
    from sg_prt_addon.engine import scene_state

    monkeypatch.setenv("SG_PRT_CACHE_DIR", str(tmp_path))
    monkeypatch.setattr(scene_state, "_environment_cache", {})
    built = scene_state.environment_data(_world("sky.exr", 7), layer_size=8)
    assert len(list(tmp_path.glob("environment-*.npz"))) == 1

    monkeypatch.setattr(scene_state, "_environment_cache", {})
    monkeypatch.setattr(scene_state, "_prefilter_and_fit", lambda *_: pytest.fail("rebuilt despite the entry"))
    read = scene_state.environment_data(_world("sky.exr", 7), layer_size=8)
    assert read is not built
    for name in ("lobe_axis", "lobe_sharpness", "lobe_amplitude"):
        np.testing.assert_array_equal(getattr(read, name), getattr(built, name))
        assert getattr(read, name).dtype == getattr(built, name).dtype
    for name in ("layers", "sharpness", "content_size", "texcoord_scale", "texcoord_offset", "mean_radiance"):
        np.testing.assert_array_equal(getattr(read.prefiltered, name), getattr(built.prefiltered, name))
        assert getattr(read.prefiltered, name).dtype == getattr(built.prefiltered, name).dtype
    assert read.prefiltered.levels_per_octave == built.prefiltered.levels_per_octave
    assert read.prefiltered.log2_min_sharpness == built.prefiltered.log2_min_sharpness
