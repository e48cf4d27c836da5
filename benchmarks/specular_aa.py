"""Specular Anti-Aliasing (scene.sgprt.specular_anti_aliasing): what it removes of the pixel-centre
shading's aliasing, and what it costs, on the example scenes and the truth suite's glossy scenes.

Per scene (visibility baked by the operator at its defaults), in one process:
- the reference: the same engine, Specular Anti-Aliasing off, averaging REFERENCE_SAMPLES frames
  jittered on a regular grid (Render Samples: the exact 1-pixel box filter of the same shading, up to
  that grid's resolution);
- the engine with the setting off and on, one frame each: relative RMSE against the reference over the
  surface pixels (the Diffuse pass's alpha), and the share of the off image's error the setting removes;
- their steady frames (draw + read back, render_engine.debug["timed_redraws"], median), alternated
  off / on so both see the same load, and the ratio on / off.

    .venv/bin/python -m benchmarks.specular_aa [--update-doc]

--update-doc writes the "Specular anti-aliasing" sections of docs/ACCURACY.md and docs/PERFORMANCE.md.
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

ACCURACY_TITLE = "## Specular anti-aliasing"
PERFORMANCE_TITLE = "## Specular anti-aliasing"
REFERENCE_SAMPLES = 64          # an 8 x 8 grid of jittered frames
# (scene, builder module, size): the example scenes at the documented frame size, the truth suite's
# sharpest glossy scenes at its size
SCENES = (("suzanne_courtyard", "examples", 512), ("brushed_metal", "examples", 512),
          ("ggx030_point", "truth_suite", 128), ("ggx010_hdri", "truth_suite", 128),
          ("ggx005_torus_hdri", "truth_suite", 128), ("ggx035_metal_hdri", "truth_suite", 128),
          ("aniso_torus_hdri", "truth_suite", 128))


def render(scene, anti_aliasing, samples=1, redraws=0):
    """(Combined RGB, surface mask, steady frame seconds or None) of one final render."""
    import bpy
    import numpy as np

    from sg_prt_addon.engine import render_engine

    scene.sgprt.specular_anti_aliasing = anti_aliasing
    scene.sgprt.render_samples = samples
    scene.sgprt.sample_edges_only = False       # the reference: every pixel's jittered frames
    # the 1-pixel box: the footprint's square is the pixel, the jittered frames its exact box filter
    scene.sgprt.pixel_filter_type, scene.render.filter_size = "BOX", 1.0
    render_engine.debug["timed_redraws"] = redraws
    render_engine.last_render.clear()
    try:
        bpy.ops.render.render()
    finally:
        render_engine.debug["timed_redraws"] = 0
        scene.sgprt.render_samples = 1
    if "error" in render_engine.last_render:
        raise RuntimeError(render_engine.last_render["error"])
    passes = render_engine.last_render["passes"]
    frames = render_engine.last_render["timings"].get("frames")
    return (passes["Combined"][..., :3].astype(np.float64), passes["Diffuse"][..., 3] > 0.5,
            statistics.median(frames) if frames else None)


def measure_scene(name, builder, size, redraws, rounds):
    from benchmarks.engine_vs_eevee import bake_all
    from validation import image_error

    scene = scene_benchmark.build(name, builder, size)
    bake_all(name)
    reference, mask, _ = render(scene, False, REFERENCE_SAMPLES)
    figures = {"scene": name, "size": size}
    for key, enabled in (("off", False), ("on", True)):
        image, _, _ = render(scene, enabled)
        figures[f"rmse_{key}"] = image_error.relative_rmse(image, reference, mask)
        figures[f"bias_{key}"] = image_error.relative_mean_bias(image, reference, mask)
    frames = {"off": [], "on": []}
    for _ in range(rounds):
        for key, enabled in (("off", False), ("on", True)):
            frames[key].append(render(scene, enabled, redraws=redraws)[2])
    figures.update(frame_off=statistics.median(frames["off"]), frame_on=statistics.median(frames["on"]))
    figures["removed"] = 1.0 - figures["rmse_on"] / figures["rmse_off"]
    figures["cost"] = figures["frame_on"] / figures["frame_off"]
    return figures


def accuracy_section(results, command):
    intro = (f"`{command}` (benchmarks/specular_aa.py says how). Reference: the same engine and bake with the "
             f"setting off, {REFERENCE_SAMPLES} jittered frames (Render Samples: an exact 1-pixel box filter of "
             "the same shading), so the rows measure the sub-pixel sampling alone, not the shading's own error "
             "(the truth suite scores that against Cycles). Relative RMSE over the surface pixels of one frame. "
             "Read: the footprint cannot reach triangle edges and silhouettes, where a pixel's attributes are "
             "not one affine function (Render Samples covers those; their share of what is left is not measured "
             "here); at 512 px the example scenes' highlights "
             "are wider than a pixel, and their whole error against the box filter is their silhouettes'.")
    lines = [ACCURACY_TITLE, "", textwrap.fill(intro, 100), "",
             "| scene | size | pixel centre (off) RMSE / bias | footprint (on) RMSE / bias | error removed |",
             "|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} | {r['size']} | {r['rmse_off']:.3f} / {r['bias_off']:+.3f} | "
                     f"{r['rmse_on']:.3f} / {r['bias_on']:+.3f} | {r['removed']:.1%} |")
    return "\n".join(lines) + "\n"


def performance_section(results, command):
    import bpy

    intro = (f"`{command}` (Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa llvmpipe; "
             f"{time.strftime('%Y-%m-%d')}): the steady frame (draw + read back) with Specular Anti-Aliasing "
             "off and on, alternated in one process, medians. The extra cost is the pixels shaded again: those "
             "where the normal turns by more than 4/3 of the NDF's width within the pixel (nearly all of a "
             "subdivided Suzanne's at 128 px with GGX 0.1, few at 512 px on the example scenes).")
    lines = [PERFORMANCE_TITLE, "", textwrap.fill(intro, 100), "",
             "| scene | size | frame off (s) | frame on (s) | on / off |", "|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} | {r['size']} | {r['frame_off']:.4f} | {r['frame_on']:.4f} | "
                     f"{r['cost']:.2f} |")
    return "\n".join(lines) + "\n"


def sections(results, command, _args):
    from benchmarks import markdown_sections

    return [(markdown_sections.ACCURACY_DOC, ACCURACY_TITLE, accuracy_section(results, command)),
            (markdown_sections.PERFORMANCE_DOC, PERFORMANCE_TITLE, performance_section(results, command))]


def main(argv=None):
    return scene_benchmark.main("specular_aa", __doc__.split("\n")[0], SCENES, 3, measure_scene, sections, argv)


if __name__ == "__main__":
    main()
