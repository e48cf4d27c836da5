"""Drives a real Blender window (run by tests/ui/test_real_blender.py inside the chroot, under Xvfb, with
--enable-event-simulate) as a user would, one step a timer tick: the viewport in Rendered shading, a material
edit, a render border, the render panels, the Bake button (modal, with progress), a second bake cancelled with
Esc, and Fit Lobes on a MERL file.  Takes a
screenshot of the screen at each step (ImageMagick's `import`: Blender's own screenshot is black under Xvfb)
and writes what it saw to OUT/result.json, with the areas' places for the test's pixel checks.

    blender scene.blend --enable-event-simulate --python drive_window.py -- OUT MERL_FILE
"""
import json
import subprocess
import sys
import time

import bpy

OUT, MERL = sys.argv[sys.argv.index("--") + 1:][:2]
result = {"steps": [], "errors": []}
state = {"step": 0, "since": time.monotonic(), "shots": 0}


def screenshot(name):
    path = f"{OUT}/{name}.png"
    subprocess.run(["import", "-window", "root", path], check=True, timeout=60)
    return path


def colours(path):
    done = subprocess.run(["convert", path, "-format", "%k", "info:"], capture_output=True, text=True, timeout=60)
    return int(done.stdout.strip() or 0)


def area(kind):
    window = bpy.context.window_manager.windows[0]
    found = max((a for a in window.screen.areas if a.type == kind), key=lambda a: a.width * a.height)
    return window, found, next(r for r in found.regions if r.type == "WINDOW")


def place(kind):
    window, found, region = area(kind)
    return {"x": region.x, "y": region.y, "width": region.width, "height": region.height,
            "window_height": window.height}


def bake_record():
    mesh = bpy.data.objects["Suzanne"].data
    record = mesh.get("sgprt_ssdf")
    return None if record is None else str(record.get("date", "")) + "/" + str(record.get("face_hash", ""))


def elapsed():
    return time.monotonic() - state["since"]


def next_step(name, **seen):
    result["steps"].append({"name": name, "seconds": round(elapsed(), 2), **seen})
    state["step"] += 1
    state["since"] = time.monotonic()


def wait_for_ui():
    # Blender needs seconds to draw its first frame on llvmpipe: poll the screen, not a fixed sleep
    if colours(screenshot("first")) > 100:
        next_step("ui drawn")
    elif elapsed() > 90:
        raise RuntimeError("the window never drew its UI")


def rendered_viewport():
    window, view, _ = area("VIEW_3D")
    view.spaces[0].shading.type = "RENDERED"
    view.spaces[0].region_3d.view_perspective = "CAMERA"
    window, properties, _ = area("PROPERTIES")
    bpy.context.view_layer.objects.active = bpy.data.objects["Suzanne"]
    properties.spaces[0].context = "MATERIAL"
    next_step("rendered shading", view=place("VIEW_3D"), properties=place("PROPERTIES"))


def settle(name, seconds):
    def step():
        if elapsed() > seconds:
            screenshot(name)
            next_step(name)
    return step


def edit_material():
    material = bpy.data.objects["Suzanne"].active_material
    material.sgprt.diffuse_color = (0.9, 0.05, 0.02)
    material.sgprt.specular_color = (0.02, 0.02, 0.02)
    next_step("material edited", material=material.name)


def render_border():
    """The scene's render border over the middle of the camera frame: the viewport shows it alone."""
    render = bpy.context.scene.render
    render.use_border = True
    render.border_min_x, render.border_max_x, render.border_min_y, render.border_max_y = 0.3, 0.7, 0.35, 0.75
    window, view, region = area("VIEW_3D")
    with bpy.context.temp_override(window=window, area=view, region=region):
        engine = sys.modules[next(name for name in sys.modules if name.endswith("sg_prt.engine.render_engine"))]
        rect = engine.viewport_border_rect(bpy.context, bpy.context.scene, region.width, region.height)
    next_step("render border", rect=list(rect))


def no_render_border():
    bpy.context.scene.render.use_border = False
    next_step("render border off")


def render_panels():
    area("PROPERTIES")[1].spaces[0].context = "RENDER"
    next_step("render context")


def invoke_bake(name):
    def step():
        window, properties, region = area("PROPERTIES")
        before = bake_record()
        with bpy.context.temp_override(window=window, area=properties, region=region):
            returned = bpy.ops.sgprt.bake_visibility("INVOKE_DEFAULT", target="ALL")
        next_step(name, returned=sorted(returned), record_before=before)
    return step


def progress_shot():
    if elapsed() > 1.0:
        screenshot("bake_progress")
        next_step("bake progress")


def wait_job(name, operator_class, seen=bake_record):
    def step():
        if not getattr(bpy.types, operator_class)._running:     # one job of a kind at a time: the flag
            next_step(name, record=seen())
        elif elapsed() > 300:
            raise RuntimeError(f"{name}: the job did not end")
    return step


def lobe_fit():
    fit = bpy.data.objects["Suzanne"].active_material.sgprt.lobe_fit
    return f"{fit.lobe_count} lobes, error {fit.fit_error:.3f}, {fit.date}" if fit.date else None


def material_panels():
    window, properties, region = area("PROPERTIES")
    properties.spaces[0].context = "MATERIAL"
    material = bpy.data.objects["Suzanne"].active_material
    # the material (the tab has not drawn yet, so the editor's context holds none this tick)
    with bpy.context.temp_override(window=window, area=properties, region=region, material=material):
        # the material tab's panels that poll true here: (class, label)
        shown = sorted((cls.__name__, cls.bl_label) for cls in bpy.types.Panel.__subclasses__()
                       if getattr(cls, "bl_space_type", "") == "PROPERTIES"
                       and getattr(cls, "bl_context", "") == "material"
                       and (not hasattr(cls, "poll") or cls.poll(bpy.context)))
    next_step("material context", panels=shown)


def invoke_fit():
    window, properties, region = area("PROPERTIES")
    with bpy.context.temp_override(window=window, area=properties, region=region):
        returned = bpy.ops.sgprt.fit_lobes("INVOKE_DEFAULT", filepath=MERL, lobe_count=1)
    next_step("fit invoked", returned=sorted(returned))


def press_escape():
    if elapsed() > 0.5:
        window = bpy.context.window_manager.windows[0]
        window.event_simulate("ESC", "PRESS")
        window.event_simulate("ESC", "RELEASE")
        next_step("escape pressed")


STEPS = [wait_for_ui, rendered_viewport, settle("viewport_rendered", 20), edit_material,
         settle("viewport_edited", 15), render_border, settle("viewport_border", 10), no_render_border,
         render_panels, settle("render_panels", 8),
         invoke_bake("bake invoked"), progress_shot, wait_job("bake finished", "SGPRT_OT_bake_visibility"),
         invoke_bake("second bake invoked"), press_escape,
         wait_job("second bake ended", "SGPRT_OT_bake_visibility"),
         material_panels, settle("material_panels", 3), invoke_fit,
         wait_job("fit finished", "SGPRT_OT_fit_lobes", lobe_fit)]


def tick():
    try:
        if state["step"] < len(STEPS):
            STEPS[state["step"]]()
            return 0.25
    except Exception as error:              # report, then quit: the test reads result.json
        result["errors"].append(f"{STEPS[state['step']].__name__}: {type(error).__name__}: {error}")
    with open(f"{OUT}/result.json", "w") as handle:
        json.dump(result, handle, indent=1)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(tick, first_interval=1.0)
