"""What a user does with a real Blender binary: install the zip, render a file from the command line (one
frame and an animation), and use the add-on in a window (tests/ui/drive_window.py)."""
import json
import shutil
import subprocess
import sys

import numpy as np
import pytest
from real_blender_harness import GUEST_REPO, ROOT

from sg_prt_addon.render import read_float_image


@pytest.fixture(scope="module")
def scene_file(real_blender):
    """suzanne_courtyard.blend written by the real Blender itself (examples/build_scenes.py under `blender -b`)."""
    real_blender.run("blender", "-b", "--python", f"{GUEST_REPO}/examples/build_scenes.py", "--",
                     real_blender.guest(real_blender.work / "scenes"), "suzanne_courtyard")
    path = real_blender.work / "scenes" / "suzanne_courtyard.blend"
    assert path.is_file()
    return path


def test_the_zip_installs_and_registers(real_blender):
    probe = ("import bpy, json; print('RESULT ' + json.dumps({'addons': list(bpy.context.preferences.addons.keys()), "
             "'engines': [getattr(c, 'bl_idname', '') for c in bpy.types.RenderEngine.__subclasses__()], "
             "'version': bpy.app.version_string}))")
    completed = real_blender.run("blender", "-b", "--python-expr", probe)
    result = json.loads(next(line for line in completed.stdout.splitlines() if line.startswith("RESULT "))[7:])
    assert "bl_ext.user_default.sg_prt" in result["addons"], result
    assert "SG_PRT" in result["engines"] and result["version"].startswith("4.3"), result


def test_command_line_renders_a_frame_and_an_animation_like_the_pip_module(real_blender, scene_file, tmp_path):
    """`blender -b scene.blend -E SG_PRT -o ... -f 1` and `-a` over two frames write the frames, and leave the
    disk cache in the extension's user folder; the frame is the pip module's render of the same file (python -m
    sg_prt_addon.render) to 8-bit rounding."""
    quarter = "import bpy; bpy.context.scene.render.resolution_percentage = 25"         # 128 x 128
    out = real_blender.work / "frames"
    blend = real_blender.guest(scene_file)
    real_blender.run("blender", "-b", blend, "--python-expr", quarter, "-E", "SG_PRT",
                     "-o", real_blender.guest(out) + "/still_", "-F", "PNG", "-f", "1")
    real_blender.run("blender", "-b", blend, "--python-expr", quarter, "-E", "SG_PRT",
                     "-o", real_blender.guest(out) + "/anim_", "-F", "PNG", "-s", "1", "-e", "2", "-a")
    assert sorted(path.name for path in out.glob("anim_*.png")) == ["anim_0001.png", "anim_0002.png"]
    # the first job left its environment and tables in the extension's user folder for the next ones
    probe = ("import bpy, json, os; folder = bpy.utils.extension_path_user('bl_ext.user_default.sg_prt', "
             "path='cache'); print('RESULT ' + json.dumps(sorted(os.listdir(folder)) if os.path.isdir(folder) else []))")
    completed = real_blender.run("blender", "-b", "--python-expr", probe)
    entries = json.loads(next(line for line in completed.stdout.splitlines() if line.startswith("RESULT "))[7:])
    assert any(name.startswith("environment-") for name in entries), entries
    assert any(name.startswith("table-") for name in entries), entries
    still = read_float_image(out / "still_0001.png")
    assert still.shape == (128, 128, 3) and still.std() > 0.05          # a picture, not a flat colour

    pip_png = tmp_path / "pip.png"
    subprocess.run([sys.executable, "-m", "sg_prt_addon.render", str(scene_file), "-o", str(pip_png),
                    "--width", "128", "--height", "128"], cwd=ROOT, check=True, capture_output=True, timeout=600)
    difference = np.abs(read_float_image(pip_png) - still)
    assert difference.mean() < 2 / 255 and np.percentile(difference, 99) < 8 / 255, \
        (difference.mean(), np.percentile(difference, 99), difference.max())


def _region(image, place):
    """The pixels of an area's main region in a screenshot (Blender's y runs up from the window's bottom)."""
    top = place["window_height"] - (place["y"] + place["height"])
    return image[top:top + place["height"], place["x"]:place["x"] + place["width"]]


def test_a_window_renders_edits_and_bakes_with_esc(real_blender, scene_file):
    """In a window under Xvfb: the 3D view in Rendered shading shows the scene and follows a material edit,
    and with a render border shows it inside the border only; the render panels draw; Bake Visibility runs modal with progress and writes a bake; a second bake
    cancelled with Esc writes nothing and keeps the first; the material panels draw, one Surface panel among
    them, and Fit Lobes fits a MERL file."""
    from validation import brdf_generators

    out = real_blender.work / "window"
    out.mkdir()
    merl = real_blender.work / "analytic.binary"
    brdf_generators.generate_merl(str(merl))
    command = (f"Xvfb :99 -screen 0 1280x800x24 -nolisten tcp & sleep 2; DISPLAY=:99 blender "
               f"{real_blender.guest(scene_file)} --enable-event-simulate "
               f"--python {GUEST_REPO}/tests/ui/drive_window.py -- {real_blender.guest(out)} {real_blender.guest(merl)}")
    completed = real_blender.run("bash", "-c", command, timeout=900, check=False)
    assert (out / "result.json").is_file(), completed.stdout[-3000:] + completed.stderr[-3000:]
    result = json.loads((out / "result.json").read_text())
    assert not result["errors"], result
    steps = {step["name"]: step for step in result["steps"]}

    places = steps["rendered shading"]
    rendered = _region(read_float_image(out / "viewport_rendered.png"), places["view"])
    edited = _region(read_float_image(out / "viewport_edited.png"), places["view"])
    assert rendered.std() > 0.05                                   # the scene, not an empty or flat view
    change = edited - rendered
    changed = np.abs(change).max(axis=-1) > 0.05                   # Suzanne: the pixels the edit reached
    assert 0.01 < changed.mean() < 0.5, changed.mean()
    red_gain = (change[changed][:, 0] - change[changed][:, 1]).mean()
    assert red_gain > 0.05, red_gain                               # the viewport followed the edit to red
    # a render border: the frame shows inside it as before, and outside it the view is empty
    x0, y0, x1, y1 = steps["render border"]["rect"]
    bordered = _region(read_float_image(out / "viewport_border.png"), places["view"])
    rows = slice(places["view"]["height"] - y1 + 3, places["view"]["height"] - y0 - 3)     # 3 px in
    inside = np.abs(bordered[rows, x0 + 3:x1 - 3] - edited[rows, x0 + 3:x1 - 3]).mean()
    outside = np.abs(bordered[:, :max(x0 - 3, 1)] - edited[:, :max(x0 - 3, 1)]).mean()
    assert inside < 0.01 and outside > 0.05, (inside, outside)
    panels = _region(read_float_image(out / "render_panels.png"), places["properties"])
    material_panels = _region(read_float_image(out / "viewport_edited.png"), places["properties"])
    assert np.abs(panels - material_panels).mean() > 0.005         # the properties editor switched and drew

    assert steps["bake invoked"]["returned"] == ["RUNNING_MODAL"]
    assert steps["bake finished"]["record"] is not None
    assert steps["second bake invoked"]["returned"] == ["RUNNING_MODAL"]
    assert steps["second bake ended"]["record"] == steps["bake finished"]["record"]    # Esc kept the first
    # it ended on Esc, well before a bake's time (the first: about 17 s on a quiet machine)
    assert steps["second bake ended"]["seconds"] < 0.5 * steps["bake finished"]["seconds"], steps
    status_bar = slice(-24, None)                                  # the progress line: "SG-PRT bake 8%: ..."
    assert steps["fit invoked"]["returned"] == ["RUNNING_MODAL"]
    assert steps["fit finished"]["record"] is not None and steps["fit finished"]["record"].startswith("1 lobes")
    material = _region(read_float_image(out / "material_panels.png"), places["properties"])
    assert np.abs(material - panels).mean() > 0.005                # the material's panels, not the render's
    # one Surface panel, SG-PRT's, which draws the node tree's surface or its settings: not EEVEE's beside it
    shown = dict(map(tuple, steps["material context"]["panels"]))
    assert list(shown.values()).count("Surface") == 1 and shown.get("SGPRT_PT_material") == "Surface", shown
    progress = read_float_image(out / "bake_progress.png")[status_bar]
    assert np.abs(progress - read_float_image(out / "render_panels.png")[status_bar]).mean() > 0.002
    shots = ROOT / "out" / "ui"                                    # for the README's pictures (not committed)
    shots.mkdir(parents=True, exist_ok=True)
    for path in out.glob("*.png"):
        shutil.copy2(path, shots / path.name)
