"""Frame time of SG-PRT beside EEVEE on the example scenes, shadowed, in one process on one machine.

Per scene (examples/build_scenes.py at --size, visibility baked by the operator with its defaults):
- SG-PRT render(): wall time of bpy.ops.render.render (export, upload, shaders from Mesa's cache,
  draw, read back three passes, write the result), median of --renders after a warm-up render;
- steady frame: draw + read back (render_engine.debug["timed_redraws"]), with and without the
  depth pre-pass;
- viewport: a new viewport's first draw, a redraw with nothing changed (the image is shown again)
  and one after an edit (viewport_timing.time_viewport_redraws: view_draw's work, minus the window);
- EEVEE with node materials matched to the SG-PRT settings (benchmarks.matched_materials) at 1
  and 16 samples, after a first render that compiles its shaders.
Ratios are against EEVEE's 1-sample render measured in the same run.  Errors against the
Monte Carlo reference are benchmarks.error_vs_time's.

    .venv/bin/python -m benchmarks.engine_vs_eevee [--size 512] [--scenes NAME ...] [--update-doc]
"""
import argparse
import os
import statistics
import sys
import textwrap
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

SECTION_TITLE = "## Engine frame vs EEVEE"


def render_seconds():
    """Wall time of one render of the context's scene; raises if SG-PRT reported an error."""
    import bpy

    from sg_prt_addon.engine import render_engine

    render_engine.last_render.clear()
    start = time.perf_counter()
    bpy.ops.render.render()
    seconds = time.perf_counter() - start
    if "error" in render_engine.last_render:
        raise RuntimeError(render_engine.last_render["error"])
    return seconds


def bake_all(name, **options):
    """Bake the visibility of every mesh of the context's scene (the operator, with `options`); raises if it did
    not finish (`name`: the scene's, in the message)."""
    import bpy

    if bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL", **options) != {"FINISHED"}:
        raise RuntimeError(f"{name}: the visibility bake did not finish")


def steady_frame(redraws, depth_prepass=True):
    """Median steady-state SG-PRT frame (draw + read back 3 passes) of one render's redraws."""
    from sg_prt_addon.engine import render_engine, renderer

    renderer.Renderer.depth_prepass = depth_prepass
    render_engine.debug["timed_redraws"] = redraws
    try:
        render_seconds()
    finally:
        render_engine.debug["timed_redraws"] = 0
        renderer.Renderer.depth_prepass = True
    return statistics.median(render_engine.last_render["timings"]["frames"])


def viewport_redraws(redraws):
    """(first draw, median redraw with nothing changed, median redraw after a material edit) seconds."""
    from sg_prt_addon.engine import render_engine
    from validation import viewport_timing

    def measure(depsgraph, state, renderer, camera):
        width, height = renderer.size
        first, unchanged, draws, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, redraws)
        assert draws == 1, "a redraw with nothing changed drew the scene again"
        name = next(iter(state.materials))

        def edit(edited_state):
            edited_state.dirty.materials.add(name)      # what view_update records after a material edit

        _, edited, _, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, redraws, edit=edit)
        return first, statistics.median(unchanged), statistics.median(edited)

    render_engine.debug["after_frame"] = measure
    try:
        render_seconds()
    finally:
        render_engine.debug["after_frame"] = None
    return render_engine.last_render["after_frame"]


def measure_scene(name, size, renders, redraws, eevee_samples):
    import bpy

    from benchmarks import matched_materials
    from examples import build_scenes
    from sg_prt_addon.engine import render_engine

    scene = build_scenes.SCENES[name](size)
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    depsgraph = bpy.context.evaluated_depsgraph_get()
    triangles = sum(len(obj.evaluated_get(depsgraph).data.loop_triangles)
                    for obj in scene.objects if obj.type == "MESH")
    start = time.perf_counter()
    bake_all(name)
    figures = {"scene": name, "triangles": triangles, "bake": time.perf_counter() - start,
               "load_start": os.getloadavg()[0]}
    figures["first_render"] = render_seconds()
    state = render_engine.last_render["state"]
    figures["shadowed_meshes"] = f"{len(state.visibility)}/{len(state.meshes)}"
    figures["render"] = statistics.median(render_seconds() for _ in range(renders))
    figures["frame"] = steady_frame(redraws)
    figures["frame_no_prepass"] = steady_frame(redraws, depth_prepass=False)
    figures["viewport_first"], figures["viewport_unchanged"], figures["viewport_edited"] = viewport_redraws(redraws)

    matched_materials.match_scene(scene)
    for index, samples in enumerate(eevee_samples):
        matched_materials.configure_eevee(scene, samples)
        if index == 0:
            figures["eevee_first"] = render_seconds()       # compiles EEVEE's shaders
        figures[f"eevee_{samples}"] = render_seconds()
    figures["load_end"] = os.getloadavg()[0]
    return figures


ROWS = (("SG-PRT first render (export, prefilter, SG fit, compile, upload)", "first_render"),
        ("SG-PRT render() (bpy.ops.render.render)", "render"),
        ("SG-PRT steady frame (draw + read back 3 passes)", "frame"),
        ("SG-PRT steady frame without the depth pre-pass", "frame_no_prepass"),
        ("viewport: first draw", "viewport_first"),
        ("viewport: redraw, nothing changed", "viewport_unchanged"),
        ("viewport: redraw after a material edit", "viewport_edited"),
        ("EEVEE first render (compiles)", "eevee_first"))


def section(results, size, command, eevee_samples):
    import bpy

    intro = (f"`{command}` ({size}x{size}, Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa "
             f"llvmpipe; {time.strftime('%Y-%m-%d')}). Written by the benchmark (`--update-doc`). Every scene "
             "is baked (operator defaults) and renders with SSDF shadows; EEVEE uses node materials matched "
             "by benchmarks/matched_materials.py. Ratios: seconds / EEVEE's 1-sample render in the same run.")
    lines = [SECTION_TITLE, "", textwrap.fill(intro, 100), ""]
    header = "| what | " + " | ".join(f"{r['scene']} s | ratio" for r in results) + " |"
    lines += [header, "|---|" + "---|---|" * len(results)]
    rows = list(ROWS) + [(f"EEVEE {samples} sample(s)", f"eevee_{samples}") for samples in eevee_samples]
    for label, key in rows:
        cells = []
        for r in results:
            base = r[f"eevee_{eevee_samples[0]}"]
            cells.append(f"{r[key]:.3f} | {r[key] / base:.3f}")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    notes = "Per scene: " + "; ".join(
        f"{r['scene']}: {r['triangles']} triangles, shadowed meshes {r['shadowed_meshes']}, bake {r['bake']:.1f} s, "
        f"load average {r['load_start']:.1f} -> {r['load_end']:.1f}, depth pre-pass speed-up "
        f"{r['frame_no_prepass'] / r['frame']:.2f}x" for r in results) + "."
    base = f"eevee_{eevee_samples[0]}"
    target = "The target, render() at most 0.1 of EEVEE's 1-sample render: " + "; ".join(
        f"{r['scene']} {r['render'] / r[base]:.3f} ({'met' if r['render'] <= 0.1 * r[base] else 'not met'})"
        for r in results) + "."
    lines += ["", textwrap.fill(notes, 100), "", textwrap.fill(target, 100), ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--scenes", nargs="*", default=["suzanne_courtyard", "brushed_metal"])
    parser.add_argument("--renders", type=int, default=7)   # a median of 7: render() drifts by +-20% run to run here
    parser.add_argument("--redraws", type=int, default=7)
    parser.add_argument("--eevee-samples", type=int, nargs="*", default=[1, 16])
    parser.add_argument("--update-doc", action="store_true", help="rewrite the section of docs/PERFORMANCE.md")
    args = parser.parse_args(argv)

    from sg_prt_addon import render

    render.ensure_registered()
    results = [measure_scene(name, args.size, args.renders, args.redraws, args.eevee_samples)
               for name in args.scenes]
    command = (".venv/bin/python -m benchmarks.engine_vs_eevee" + (f" --size {args.size}" if args.size != 512 else "")
               + (" --update-doc" if args.update_doc else ""))
    text = section(results, args.size, command, args.eevee_samples)
    print(text)
    if args.update_doc:
        from benchmarks import markdown_sections
        markdown_sections.update_file(markdown_sections.PERFORMANCE_DOC, SECTION_TITLE, text)
    return results


if __name__ == "__main__":
    main()
