"""The example scenes build and save, and the batch entry renders a saved one in a fresh process."""
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
from examples import build_scenes  # noqa: E402


def test_example_scenes_build_and_batch_render(addon, tmp_path):
    paths = {}
    for name, build in build_scenes.SCENES.items():
        scene = build(resolution=48)
        meshes = [obj for obj in scene.objects if obj.type == "MESH"]
        assert len(meshes) >= 2 and scene.camera is not None and scene.render.engine == "SG_PRT"
        assert all(slot.material is not None and hasattr(slot.material, "sgprt")
                   for obj in meshes for slot in obj.material_slots)
        paths[name] = build_scenes.save_scene(tmp_path / f"{name}.blend")

    output = tmp_path / "brushed_metal.png"
    completed = subprocess.run([sys.executable, "-m", "sg_prt_addon.render", str(paths["brushed_metal"]),
                                "-o", str(output), "--width", "40", "--height", "32"],
                               cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert completed.returncode == 0, completed.stdout[-2000:] + completed.stderr[-2000:]
    stages = [line for line in completed.stdout.splitlines() if line.startswith("[sg-prt] ")]
    assert [line.split(":")[0] for line in stages[:3]] == ["[sg-prt] register add-on", "[sg-prt] open scene",
                                                          "[sg-prt] render"]
    image = bpy.data.images.load(str(output))
    try:
        assert tuple(image.size) == (40, 32)
        pixels = np.empty(40 * 32 * 4, np.float32)
        image.pixels.foreach_get(pixels)
        assert pixels.reshape(-1, 4)[:, :3].max() > 0.2, "the point-lit torus should show"
    finally:
        bpy.data.images.remove(image)


def test_batch_render_names_a_missing_file(tmp_path):
    completed = subprocess.run([sys.executable, "-m", "sg_prt_addon.render", str(tmp_path / "nothing.blend"),
                                "-o", str(tmp_path / "out.png")], cwd=ROOT, capture_output=True, text=True,
                               timeout=300)
    assert completed.returncode != 0
    assert "error: no such .blend file" in completed.stderr and "nothing.blend" in completed.stderr
    assert "Traceback" not in completed.stderr


def test_build_scenes_reads_its_own_arguments_under_a_blender_binary():
    """`blender -b --python examples/build_scenes.py -- out` hands the script Blender's argv: the output folder
    is what follows '--' (it used to be argv[1], '-b')."""
    assert build_scenes.script_arguments(["blender", "-b", "--python", "examples/build_scenes.py", "--", "out"]) \
        == ["out"]
    assert build_scenes.script_arguments(["examples/build_scenes.py", "out/scenes"]) == ["out/scenes"]
    assert build_scenes.script_arguments(["blender", "-b", "--python", "examples/build_scenes.py"]) == []
