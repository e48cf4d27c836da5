"""What the lights' shadow maps cost (scene.sgprt.light_shadows): the truth suite's scenes with lights at its size
and the brushed-metal example at 512, visibility baked by the operator at its defaults, in one process:

- render(): bpy.ops.render.render's own seconds (the steady frames it timed taken off), which draws the atlas (a
  final render makes a new renderer);
- the steady frame (draw + read back, render_engine.debug["timed_redraws"], median), which reuses the atlas as a
  viewport redraw that moves only the view does: the per-pixel lookups' cost alone;

each with Light Shadows on Baked Visibility (the SSDF) and on Shadow Maps, alternated so both see the same load;
medians of the rounds, and the ratios maps / SSDF.

    .venv/bin/python -m benchmarks.shadow_maps_speed [--rounds 5] [--update-doc]

--update-doc writes the "Light shadows: shadow maps" section of docs/PERFORMANCE.md.
"""
import os
import statistics
import sys
import textwrap
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

from benchmarks import scene_benchmark  # noqa: E402 (after the path)

TITLE = "## Light shadows: shadow maps"
SCENES = (("ggx030_point", "truth_suite", 128), ("diffuse_point", "truth_suite", 128),
          ("diffuse_sun", "truth_suite", 128), ("sphere_floor_ggx_point", "truth_suite", 128),
          ("ggx030_spot", "truth_suite", 128), ("brushed_metal", "examples", 512))
MODES = ("SSDF", "SHADOW_MAPS")


def timed_render(scene, mode, redraws):
    """(render() seconds, median steady frame seconds) with Light Shadows `mode`: the render's own seconds are
    bpy.ops.render.render's less the steady frames it was asked to time after it."""
    import bpy

    from sg_prt_addon.engine import render_engine

    scene.sgprt.light_shadows = mode
    render_engine.debug["timed_redraws"] = redraws
    try:
        start = time.perf_counter()
        bpy.ops.render.render()
        seconds = time.perf_counter() - start
    finally:
        render_engine.debug["timed_redraws"] = 0
    if "error" in render_engine.last_render:
        raise RuntimeError(render_engine.last_render["error"])
    frames = render_engine.last_render["timings"]["frames"]
    return seconds - sum(frames), statistics.median(frames)


def measure_scene(name, builder, size, redraws, rounds):
    from benchmarks.engine_vs_eevee import bake_all

    scene = scene_benchmark.build(name, builder, size)
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    bake_all(name)
    for mode in MODES:            # compile both variants before timing
        timed_render(scene, mode, 1)
    runs = {mode: [] for mode in MODES}
    for _ in range(rounds):
        for mode in MODES:
            runs[mode].append(timed_render(scene, mode, redraws))
    figures = {"scene": name, "size": size}
    for mode in MODES:
        figures[mode] = {"render": statistics.median(r[0] for r in runs[mode]),
                         "frame": statistics.median(r[1] for r in runs[mode])}
    figures["render_ratio"] = figures["SHADOW_MAPS"]["render"] / figures["SSDF"]["render"]
    figures["frame_ratio"] = figures["SHADOW_MAPS"]["frame"] / figures["SSDF"]["frame"]
    figures["load"] = os.getloadavg()[0]
    return figures


def section(results, command, rounds):
    import bpy

    intro = (f"`{command}` (Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa llvmpipe; "
             f"{time.strftime('%Y-%m-%d')}; benchmarks/shadow_maps_speed.py says how): Light Shadows on Baked "
             f"Visibility (the SSDF) and on Shadow Maps (tile side 1024), alternated in one process, medians of "
             f"{rounds} rounds.  render(): bpy.ops.render.render's own seconds (the steady frames it timed after it "
             "taken off), which draws the atlas (up to six 1024 x 1024 faces a point or spot light, one tile a "
             "sun); the steady frame reuses it, as a viewport redraw that only moves the view does, so it is the "
             "per-pixel lookups' cost.")
    lines = [TITLE, "", textwrap.fill(intro, 110), "",
             "| scene | size | render() SSDF s | render() maps s | maps / SSDF | frame SSDF s | frame maps s | "
             "maps / SSDF | load |", "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} | {r['size']} | {r['SSDF']['render']:.3f} | {r['SHADOW_MAPS']['render']:.3f} | "
                     f"{r['render_ratio']:.2f} | {r['SSDF']['frame']:.4f} | {r['SHADOW_MAPS']['frame']:.4f} | "
                     f"{r['frame_ratio']:.2f} | {r['load']:.1f} |")
    return "\n".join(lines) + "\n"


def sections(results, command, args):
    from benchmarks import markdown_sections

    return [(markdown_sections.PERFORMANCE_DOC, TITLE, section(results, command, args.rounds))]


def main(argv=None):
    scene_benchmark.main("shadow_maps_speed", __doc__.split("\n")[0], SCENES, 5, measure_scene, sections, argv)
    return 0


if __name__ == "__main__":
    sys.exit(main())
