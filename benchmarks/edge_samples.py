"""Render Samples' Edges Only (scene.sgprt.sample_edges_only): how close it comes to sampling every pixel, and
what it costs, on the truth suite's scenes and the example scenes.

Per scene (visibility baked by the operator at its defaults), in one process, Specular Anti-Aliasing on (the
default):
- the reference: SAMPLES samples of every pixel (jittered frames, Edges Only off);
- Edges Only at SAMPLES samples and one sample (no anti-aliasing): relative RMSE against the reference over
  the surface pixels (the Diffuse pass's alpha), and the share of the one sample's error Edges Only removes;
  the share of the pixels it sampled;
- bpy.ops.render.render's wall time of the three, alternated round by round so all see the same load, medians,
  and the ratios to one sample.

    .venv/bin/python -m benchmarks.edge_samples [--scenes ...] [--rounds N] [--update-doc]

--update-doc writes the "Edges Only" sections of docs/ACCURACY.md and docs/PERFORMANCE.md.
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

TITLE = "## Edges Only"
SAMPLES = 16
# (scene, builder module, size): the truth suite's scenes with lights and its sharpest glossy ones at its
# size, the example scenes at the documented frame size
SCENES = (("diffuse_point", "truth_suite", 128), ("diffuse_sun", "truth_suite", 128),
          ("ggx030_point", "truth_suite", 128), ("ggx030_spot", "truth_suite", 128),
          ("sphere_floor_ggx_point", "truth_suite", 128), ("ggx010_hdri", "truth_suite", 128),
          ("ggx035_metal_hdri", "truth_suite", 128), ("suzanne_courtyard", "examples", 512),
          ("brushed_metal", "examples", 512))
SETTINGS = (("one", 1, True), ("edges", SAMPLES, True), ("every", SAMPLES, False))


def render(scene, samples, edges_only):
    """(Combined RGB, surface mask, seconds, timings) of one final render of `scene`, the context's."""
    import numpy as np

    from benchmarks.engine_vs_eevee import render_seconds
    from sg_prt_addon.engine import render_engine

    scene.sgprt.render_samples = samples
    scene.sgprt.sample_edges_only = edges_only
    seconds = render_seconds()
    passes = render_engine.last_render["passes"]
    return (passes["Combined"][..., :3].astype(np.float64), passes["Diffuse"][..., 3] > 0.5, seconds,
            dict(render_engine.last_render["timings"]))


def measure_scene(name, builder, size, _redraws, rounds):
    from benchmarks.engine_vs_eevee import bake_all
    from validation import image_error

    scene = scene_benchmark.build(name, builder, size)
    bake_all(name)
    images = {}
    for key, samples, edges_only in SETTINGS:
        render(scene, samples, edges_only)                      # warm: compiles, uploads
        images[key], mask, _, timings = render(scene, samples, edges_only)
        if key == "edges":
            figures = {"scene": name, "size": size, "edge_pixels": timings["edge_pixels"],
                       "edge_tiles": timings["edge_tiles"]}
    for key in ("one", "edges"):
        figures[f"rmse_{key}"] = image_error.relative_rmse(images[key], images["every"], mask)
    figures["removed"] = 1.0 - figures["rmse_edges"] / figures["rmse_one"]
    seconds = {key: [] for key, _, _ in SETTINGS}
    for _ in range(rounds):
        for key, samples, edges_only in SETTINGS:
            seconds[key].append(render(scene, samples, edges_only)[2])
    figures.update({f"seconds_{key}": statistics.median(values) for key, values in seconds.items()})
    figures["load"] = os.getloadavg()[0]
    return figures


def accuracy_section(results, command):
    from sg_prt_addon.blender import properties

    intro = (f"`{command}` (benchmarks/edge_samples.py says how). Reference: the same engine and bake, "
             f"{SAMPLES} samples of every pixel (jittered frames); Edges Only takes them at the pixels where the "
             "frame shaded at the pixels' centres differs from a neighbour by more than the threshold (default "
             f"{properties.DEFAULT_EDGE_THRESHOLD}), elsewhere that frame. Relative RMSE over the surface pixels "
             "against the reference: what Edges Only leaves out, beside what one sample leaves out. What the "
             "samples do against Cycles is in the truth suite's rows.")
    lines = [TITLE, "", textwrap.fill(intro, 100), "",
             "| scene | size | pixels sampled | 1 sample RMSE | Edges Only RMSE | error removed |",
             "|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} | {r['size']} | {r['edge_pixels']:.1%} | {r['rmse_one']:.4f} | "
                     f"{r['rmse_edges']:.4f} | {r['removed']:.1%} |")
    return "\n".join(lines) + "\n"


def performance_section(results, command):
    import bpy

    intro = (f"`{command}` (Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa llvmpipe; "
             f"{time.strftime('%Y-%m-%d')}; benchmarks/edge_samples.py says how): bpy.ops.render.render's wall "
             f"time with one sample, {SAMPLES} samples at the edges (Edges Only, the default) and {SAMPLES} "
             "samples of every pixel, alternated in one process, medians, Specular Anti-Aliasing on. Edges "
             "Only pays the frame at the pixels' centres, the edge pass, and each tile holding an edge drawn "
             f"{int(SAMPLES ** 0.5)} times larger (one pass of the vertices a tile) with only the edge pixels "
             "and those the pixel filter reaches from them (Blackman-Harris 1.5: one) shaded. Seconds are this "
             "run's machine; compare the ratios.")
    lines = [TITLE, "", textwrap.fill(intro, 100), "",
             "| scene | size | pixels sampled (tiles) | 1 sample s | Edges Only s | every pixel s | Edges Only / 1 "
             "| every pixel / 1 | load |", "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['scene']} | {r['size']} | {r['edge_pixels']:.1%} ({r['edge_tiles']}) | "
                     f"{r['seconds_one']:.3f} | {r['seconds_edges']:.3f} | {r['seconds_every']:.3f} | "
                     f"{r['seconds_edges'] / r['seconds_one']:.2f} | {r['seconds_every'] / r['seconds_one']:.2f} | "
                     f"{r['load']:.1f} |")
    return "\n".join(lines) + "\n"


def sections(results, command, _args):
    from benchmarks import markdown_sections

    return [(markdown_sections.ACCURACY_DOC, TITLE, accuracy_section(results, command)),
            (markdown_sections.PERFORMANCE_DOC, TITLE, performance_section(results, command))]


def main(argv=None):
    return scene_benchmark.main("edge_samples", __doc__.split("\n")[0], SCENES, 5, measure_scene, sections, argv)


if __name__ == "__main__":
    main()
