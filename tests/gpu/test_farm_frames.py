"""A farm's frames equal one machine's: a baked .blend with an animated light, its frame range rendered by Open
Job Description's runner (openjd-cli) from farm/render_frames.yaml as separate tasks, each a separate process
(`python -m sg_prt_addon.render --frame N`) with its own empty SG-PRT disk cache, against the same frames rendered
one after another in this process, its caches warm."""
import os
import subprocess
import sys
from pathlib import Path

import engine_fixtures as fx
import numpy as np
import pytest

pytestmark = pytest.mark.one_tier          # openjd-cli is in the bpy 5.0 tier's requirements

ROOT = Path(__file__).resolve().parents[2]
TEMPLATE = ROOT / "farm" / "render_frames.yaml"
FRAMES = (1, 2, 3)


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _baked_animated_file(path):
    """A sphere over a floor under the forest HDRI and a point light moving over frames 1-3, baked by the Bake
    Visibility operator, saved alone in a file (the bake is stored in the .blend)."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = fx.new_scene("farm_scene", 48, 40)
    for other in [s for s in bpy.data.scenes if s != scene]:
        bpy.data.scenes.remove(other)
    scene.sgprt.render_samples = 16             # the default Edges Only sampling, as a farm renders
    fx.world_texture(scene, fx.studio_world_path("forest.exr"))
    fx.uv_sphere(scene, "farm_sphere", (0.0, 0.0, 1.0)).data.materials.append(
        fx.material("farm_glossy", model="GGX", roughness=0.3, diffuse_color=(0.4, 0.3, 0.2),
                    specular_color=(0.5, 0.5, 0.5)))
    fx.plane(scene, "farm_floor", (0.0, 0.0, 0.0)).data.materials.append(fx.material("farm_floor_material"))
    light = fx.point_light(scene, "farm_light", (2.0, -2.0, 3.0), 400.0, radius=0.2)
    for frame, x in zip(FRAMES, (2.0, 0.0, -2.0)):
        light.location.x = x
        light.keyframe_insert("location", frame=frame)
    scene.frame_start, scene.frame_end = FRAMES[0], FRAMES[-1]
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.sgprt.bake_visibility(target="ALL") == {"FINISHED"}
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return scene


def test_frames_rendered_as_separate_tasks_equal_one_process(engine, tmp_path):
    import bpy

    from sg_prt_addon import render

    blend = tmp_path / "farm.blend"
    scene = _baked_animated_file(blend)
    expected = {}
    for frame in FRAMES:
        written = render.render_to_file(scene, tmp_path / "local" / f"frame_{frame}.exr", frame=frame)
        expected[frame] = render.read_float_image(written)
    assert not np.array_equal(expected[1], expected[3])          # the light moved

    openjd = Path(sys.executable).with_name("openjd")
    result = subprocess.run([str(openjd), "run", str(TEMPLATE), "-p", f"BlendFile={blend}",
                             "-p", f"OutputDir={tmp_path / 'farm'}", "-p", f"Frames={FRAMES[0]}-{FRAMES[-1]}",
                             "-p", f"Python={sys.executable}", "-p", f"AddonRoot={ROOT}"],
                            capture_output=True, text=True, timeout=600,
                            env={**os.environ, "SG_PRT_CACHE_DIR": str(tmp_path / "unused")})
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert f"Chunks run: {len(FRAMES)}" in result.stdout or f"Tasks run: {len(FRAMES)}" in result.stdout, \
        result.stdout[-2000:]
    for frame in FRAMES:
        farm = render.read_float_image(tmp_path / "farm" / f"frame_{frame}.exr")
        np.testing.assert_array_equal(farm, expected[frame], err_msg=f"frame {frame}")
    # every task made its own cache: none was shared
    assert not (tmp_path / "unused").exists()
    bpy.ops.wm.read_factory_settings(use_empty=True)
