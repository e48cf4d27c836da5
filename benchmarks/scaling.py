"""Scaling study: SG-PRT's frame and render() time against triangles, resolution, lights and objects, beside
EEVEE (1 sample) measured in the same run, with the log-log slope of each (a least-squares line through
log seconds against log size: 1 is linear, 2 at a resolution's side is linear in pixels).

    .venv/bin/python -m benchmarks.scaling [--quick] [--axes triangles resolution ...] [--update-doc]

Every scene is one builder (build_scene): spheres of one GGX material on a grid seen from above, one or
more point lights, a constant world, no visibility bake.  The axes change one thing each:
- triangles: one UV sphere of about that many triangles;
- resolution: the square image's side, on a 64k-triangle sphere;
- lights: point lights on a ring, on the same sphere;
- objects / instances: that many 320-triangle icospheres, as separate meshes or as linked duplicates
  sharing one mesh, shrunk so that together they cover about the same pixels at every count (the added
  work is then the objects' own, not more pixels); also stated as the linear cost of an extra object.
SG-PRT render(): median wall time of bpy.ops.render.render after a warm-up render (engine_vs_eevee's
render_seconds: a new SceneState and Renderer each time, so export and upload count); its steady frame:
draw + read back 3 passes (engine_vs_eevee.steady_frame).  EEVEE: node materials matched by
benchmarks/matched_materials.py, 1 sample, after a warm-up render that compiles its shaders.
"""
import argparse
import json
import math
import os
import statistics
import sys
import textwrap
import time
from dataclasses import asdict, dataclass, replace

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

SECTION_TITLE = "## Scaling"
PLOT_PATH = os.path.join(REPO_ROOT, "docs", "images", "scaling.png")
JSON_PATH = os.path.join(REPO_ROOT, "docs", "scaling.json")
ICOSPHERE_SUBDIVISIONS = 3      # bmesh's icosphere: 20 * 4^(3 - 1) = 320 triangles
FIELD_EXTENT = 4.0              # the objects' grid spans this many metres a side, whatever their count
OBJECT_COST_GOAL = 1e-4         # issue 20: under 0.1 ms of render() per extra object


@dataclass(frozen=True)
class ScalingScene:
    """What one scene of the study is made of."""
    triangles: int = 64_000         # of the one sphere (objects == 1 and not icospheres)
    objects: int = 1
    instanced: bool = False         # objects share one mesh (linked duplicates) instead of a copy each
    icospheres: bool = False        # objects are 320-triangle icospheres instead of a sphere of `triangles`
    lights: int = 1
    width: int = 512
    height: int = 512


# axis -> (label, the scene at a size, full sizes, --quick sizes)
AXES = {
    "triangles": ("triangles", lambda n: ScalingScene(triangles=n),
                  [1_000, 10_000, 100_000, 1_000_000, 2_000_000], [1_000, 8_000, 64_000]),
    "resolution": ("image side (pixels)", lambda n: ScalingScene(width=n, height=n),
                   [256, 512, 1024, 2048, 4096], [128, 256, 512]),
    "lights": ("point lights", lambda n: ScalingScene(lights=n), [1, 2, 4, 8, 16, 32], [1, 4, 16]),
    "objects": ("separate meshes (320 triangles each)", lambda n: ScalingScene(objects=n, icospheres=True),
                [1, 10, 100, 400, 1000, 5000], [1, 10, 100]),
    "instances": ("linked duplicates of one mesh (320 triangles)",
                  lambda n: ScalingScene(objects=n, icospheres=True, instanced=True),
                  [1, 10, 100, 400, 1000, 5000], [1, 10, 100]),
}


def _sphere_mesh(name, triangles):
    """A smooth UV sphere of radius 1 with about `triangles` triangles (twice as many segments as rings:
    4 rings (rings - 1) triangles)."""
    import bmesh
    import bpy

    rings = max(3, round(0.5 + math.sqrt(triangles / 4.0)))
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_uvsphere(bm, u_segments=2 * rings, v_segments=rings, radius=1.0, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    mesh.shade_smooth()
    return mesh


def _icosphere_mesh(name):
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")         # as Blender's primitives have (calc_uvs fills a layer, makes none)
    bmesh.ops.create_icosphere(bm, subdivisions=ICOSPHERE_SUBDIVISIONS, radius=1.0, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    mesh.shade_smooth()
    return mesh


def build_scene(spec):
    """A new file holding the scene of a ScalingScene, with the SG-PRT engine; returns the scene."""
    import bpy

    from examples import build_scenes

    scene = build_scenes._empty_file()
    scene.render.engine = build_scenes.ENGINE_ID
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    scene.render.resolution_x, scene.render.resolution_y = spec.width, spec.height
    scene.render.resolution_percentage = 100
    build_scenes._world_with_colour(scene, (0.05, 0.06, 0.08))
    material = build_scenes._material("Glaze", model="GGX", diffuse_color=(0.6, 0.25, 0.1),
                                      specular_color=(0.5, 0.5, 0.5), roughness=0.3)
    shared = _icosphere_mesh("Sphere") if spec.icospheres else _sphere_mesh("Sphere", spec.triangles)
    shared.materials.append(material)
    side = math.ceil(math.sqrt(spec.objects))
    spacing = FIELD_EXTENT / side
    for index in range(spec.objects):
        mesh = shared if spec.instanced or index == 0 else shared.copy()
        obj = bpy.data.objects.new(f"Sphere.{index:04d}", mesh)
        row, column = divmod(index, side)
        obj.location = ((column + 0.5) * spacing - FIELD_EXTENT / 2, (row + 0.5) * spacing - FIELD_EXTENT / 2, 0.0)
        obj.scale = (0.4 * spacing,) * 3
        scene.collection.objects.link(obj)
    for index in range(spec.lights):
        angle = 2 * math.pi * index / spec.lights
        light = bpy.data.objects.new(f"Light.{index:02d}", bpy.data.lights.new(f"Light.{index:02d}", "POINT"))
        light.data.energy = 1500.0 / spec.lights        # the same total light at every count
        light.data.shadow_soft_size = 0.1
        light.location = (3.0 * math.cos(angle), 3.0 * math.sin(angle), 4.0)
        scene.collection.objects.link(light)
    build_scenes._add_camera(scene, location=(0.0, -5.0, 6.0), target=(0.0, 0.0, 0.0))
    return scene


def scene_triangles(scene):
    import bpy

    depsgraph = bpy.context.evaluated_depsgraph_get()
    return sum(len(obj.evaluated_get(depsgraph).data.loop_triangles) for obj in scene.objects if obj.type == "MESH")


def measure_scene(scene, renders, redraws, eevee_renders=1):
    """{"render", "frame", "eevee"} seconds of the context's scene (SG-PRT, then EEVEE 1 sample), each after
    a warm-up render, and the parts of SG-PRT's render() (render_frame's timings of the median one):
    "export" (scene state and camera), "upload", "draw_and_read"; the rest of render() is Blender's
    (the render's depsgraph, the result) and the report's."""
    from benchmarks import engine_vs_eevee, matched_materials
    from sg_prt_addon.engine import render_engine

    engine_vs_eevee.render_seconds()            # warm-up: Mesa's shader cache, the first export
    timed = []
    for _ in range(renders):
        seconds = engine_vs_eevee.render_seconds()
        timed.append((seconds, dict(render_engine.last_render["timings"])))
    seconds, timings = sorted(timed, key=lambda item: item[0])[len(timed) // 2]
    figures = {"render": seconds, **{part: timings[part] for part in ("export", "upload", "draw_and_read")},
               "frame": engine_vs_eevee.steady_frame(redraws)}
    matched_materials.match_scene(scene)
    matched_materials.configure_eevee(scene, 1)
    engine_vs_eevee.render_seconds()            # warm-up: EEVEE compiles its shaders
    figures["eevee"] = statistics.median(engine_vs_eevee.render_seconds() for _ in range(eevee_renders))
    return figures


def measure_axis(axis, sizes, renders, redraws, eevee_renders=1, image_size=None):
    """[{size, triangles, scene, render, frame, eevee}] of one axis, printed as they come.  image_size:
    (width, height) of every image instead of ScalingScene's (not on the resolution axis)."""
    _label, spec_of, _full, _quick = AXES[axis]
    points = []
    for size in sizes:
        spec = spec_of(size)
        if image_size is not None and axis != "resolution":
            spec = replace(spec, width=image_size[0], height=image_size[1])
        scene = build_scene(spec)
        point = {"size": size, "triangles": scene_triangles(scene), "scene": asdict(spec)}
        point.update(measure_scene(scene, renders, redraws, eevee_renders))
        points.append(point)
        print(f"{axis} {size}: {point['triangles']} triangles, render() {point['render']:.4f} s, frame "
              f"{point['frame']:.4f} s, EEVEE 1 sample {point['eevee']:.3f} s", flush=True)
    return points


def log_log_slope(sizes, seconds):
    """The slope of a least-squares line through (log size, log seconds)."""
    return float(np.polyfit(np.log(np.asarray(sizes, float)), np.log(np.asarray(seconds, float)), 1)[0])


def linear_slope(sizes, seconds):
    """Seconds per unit of size of a least-squares line (the cost of an extra object)."""
    return float(np.polyfit(np.asarray(sizes, float), np.asarray(seconds, float), 1)[0])


TIMES = (("render", "SG-PRT render()"), ("frame", "SG-PRT frame"), ("eevee", "EEVEE 1 sample"))


def summarize(results):
    """axis -> {what: log-log slope over every size, and over the two largest (fixed costs weigh on the small
    sizes)}, plus seconds per extra object on the objects' axes."""
    summary = {}
    for axis, points in results.items():
        sizes = [point["size"] for point in points]
        entry = {f"slope_{key}": log_log_slope(sizes, [point[key] for point in points]) for key, _ in TIMES}
        entry.update({f"end_slope_{key}": log_log_slope(sizes[-2:], [point[key] for point in points[-2:]])
                      for key, _ in TIMES})
        if axis in ("objects", "instances"):
            parts = {key: [point[key] for point in points] for key, _ in TIMES}
            parts["prepared"] = [point["export"] + point["upload"] for point in points]
            parts["draw_and_read"] = [point["draw_and_read"] for point in points]
            parts["rest"] = [point["render"] - prepared - point["draw_and_read"]
                             for point, prepared in zip(points, parts["prepared"])]
            entry.update({f"per_object_{key}": linear_slope(sizes, seconds) for key, seconds in parts.items()})
        summary[axis] = entry
    return summary


def _compact(number):
    """1000 -> 1k, 2000000 -> 2M: a tick's label."""
    for scale, suffix in ((1_000_000, "M"), (1_000, "k")):
        if number >= scale and number % (scale // 10) == 0:
            return f"{number / scale:g}{suffix}"
    return str(number)


def plot(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    figure, axes = plt.subplots(1, len(results), figsize=(3.6 * len(results), 3.4), squeeze=False)
    for subplot, (axis, points) in zip(axes[0], results.items()):
        sizes = [point["size"] for point in points]
        for (key, label), marker in zip(TIMES, "osX"):
            subplot.plot(sizes, [point[key] for point in points], marker=marker, label=label)
        subplot.set_xscale("log")
        subplot.set_yscale("log")
        subplot.set_xticks(sizes, [_compact(size) for size in sizes], fontsize=7)
        subplot.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        subplot.set_xlabel(AXES[axis][0], fontsize=8)
        subplot.set_ylabel("seconds")
        subplot.set_title(axis)
        subplot.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    figure.tight_layout()
    figure.savefig(path, dpi=90)
    plt.close(figure)


def section(results, summary, command, plot_name):
    import bpy

    intro = (f"`{command}` (Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa llvmpipe; "
             f"{time.strftime('%Y-%m-%d')}). Written by the benchmark (`--update-doc`; figures also in "
             "docs/scaling.json). Scenes: benchmarks/scaling.py's build_scene (one GGX material, point "
             "lights, a constant world, no visibility bake), 512x512 unless the axis is the resolution. "
             "render(): bpy.ops.render.render, median after a warm-up, and its parts (render_frame's timings: the "
             "scene state's export and the upload; the draw and read back; the rest is Blender's own, its "
             "depsgraph for the render and the result, and the render's report); frame: draw + read back 3 "
             "passes; EEVEE: 1 sample, matched node materials, after a warm-up. "
             "Slopes: least-squares fit of log seconds against log size (on the resolution axis, the image's side: "
             "2 is linear in pixels).")
    lines = [SECTION_TITLE, "", textwrap.fill(intro, 100), "", f"![scaling]({plot_name})", ""]
    for axis, points in results.items():
        lines += [f"| {AXES[axis][0]} | triangles drawn | render() s | of which export + upload | draw + read back | "
                  "the rest | frame s | EEVEE s | render() / EEVEE |", "|---|---|---|---|---|---|---|---|---|"]
        for point in points:
            prepared = point["export"] + point["upload"]
            lines.append(f"| {point['size']} | {point['triangles']} | {point['render']:.4f} | {prepared:.4f} | "
                         f"{point['draw_and_read']:.4f} | {point['render'] - prepared - point['draw_and_read']:.4f} | "
                         f"{point['frame']:.4f} | {point['eevee']:.3f} | {point['render'] / point['eevee']:.3f} |")
        slopes = summary[axis]
        text = f"{axis}: log-log slope " + ", ".join(
            f"{label} {slopes['slope_' + key]:.2f} ({slopes['end_slope_' + key]:.2f} between the two largest)"
            for key, label in TIMES)
        if "per_object_render" in slopes:
            text += "; per extra object " + ", ".join(f"{label} {1e3 * slopes['per_object_' + key]:.3f} ms"
                                                      for key, label in TIMES)
            text += (f" (render()'s export + upload {1e3 * slopes['per_object_prepared']:.3f} ms, draw + read back "
                     f"{1e3 * slopes['per_object_draw_and_read']:.3f} ms, the rest "
                     f"{1e3 * slopes['per_object_rest']:.3f} ms)")
            goal = "met" if slopes["per_object_render"] < OBJECT_COST_GOAL else "not met"
            text += f" (goal: render() under {1e3 * OBJECT_COST_GOAL:.1f} ms, {goal})"
        lines += ["", textwrap.fill(text + ".", 100), ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--axes", nargs="*", choices=list(AXES), default=list(AXES))
    parser.add_argument("--quick", action="store_true", help="small sizes (a few minutes)")
    parser.add_argument("--renders", type=int, default=3)
    parser.add_argument("--redraws", type=int, default=3)
    parser.add_argument("--update-doc", action="store_true",
                        help="rewrite the section of docs/PERFORMANCE.md, docs/scaling.json and the plot")
    args = parser.parse_args(argv)

    from sg_prt_addon import render

    render.ensure_registered()
    results = {axis: measure_axis(axis, AXES[axis][3] if args.quick else AXES[axis][2], args.renders, args.redraws)
               for axis in args.axes}
    summary = summarize(results)
    command = (".venv/bin/python -m benchmarks.scaling" + (" --quick" if args.quick else "")
               + (f" --axes {' '.join(args.axes)}" if args.axes != list(AXES) else "")
               + (" --update-doc" if args.update_doc else ""))
    text = section(results, summary, command, "images/scaling.png")
    print(text)
    if args.update_doc:
        from benchmarks import markdown_sections
        plot(results, PLOT_PATH)
        with open(JSON_PATH, "w", encoding="utf-8") as handle:
            json.dump({"results": results, "summary": summary}, handle, indent=1)
        markdown_sections.update_file(markdown_sections.PERFORMANCE_DOC, SECTION_TITLE, text)
    return results, summary


if __name__ == "__main__":
    main()
