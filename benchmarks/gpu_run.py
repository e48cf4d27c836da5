"""Frame times of SG-PRT beside EEVEE on this machine's GPU: the example scenes and the scaling scenes.

    bash benchmarks/gpu_run.sh [--resolution 1920x1080] [--output out/gpu_run] [--smoke]

(gpu_run.sh makes the venv and runs this module.)  Builds the example scenes (examples/build_scenes.py),
bakes their visibility (the operator's defaults; --smoke: resolution 8) and saves them baked in
OUTPUT/scenes; then renders each of them and the scaling scenes of benchmarks/scaling.py (every axis at its
full sizes, the image at --resolution except on the resolution axis) with SG-PRT and with EEVEE at 1 sample
(benchmarks.scaling.measure_scene: render() after a warm-up, the steady frame, EEVEE after a warm-up), and
writes OUTPUT/gpu_run.json and OUTPUT/gpu_run.md with the GPU (gpu.platform) and the Blender version.
--smoke: a small image, one example scene and two scaling scenes, one render each (the test suite's run).
"""
import argparse
import json
import os
import statistics
import sys
import time
from pathlib import Path

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

SMOKE_RESOLUTION = (160, 90)
SMOKE_EXAMPLES = ["brushed_metal"]
SMOKE_SCALING = {"objects": [1, 10]}
SMOKE_BAKE_RESOLUTION = 8


def resolution(text):
    """WIDTHxHEIGHT -> (width, height)."""
    width, _, height = text.lower().partition("x")
    return int(width), int(height)


def platform():
    """The GPU as Blender sees it (gpu.platform), asked inside an SG-PRT render of a small scene: the pip
    module has a GPU context only there."""
    from benchmarks import engine_vs_eevee, scaling
    from sg_prt_addon.engine import render_engine

    def read(*_frame):
        import gpu

        found = {"renderer": gpu.platform.renderer_get(), "vendor": gpu.platform.vendor_get(),
                 "version": gpu.platform.version_get()}
        if hasattr(gpu.platform, "backend_type_get"):
            found["backend"] = gpu.platform.backend_type_get()
        return found

    scaling.build_scene(scaling.ScalingScene(triangles=1000, width=64, height=64))
    render_engine.debug["after_frame"] = read
    try:
        engine_vs_eevee.render_seconds()
    finally:
        render_engine.debug["after_frame"] = None
    return render_engine.last_render["after_frame"]


def example_scene(name, image_size, scenes_dir, bake_resolution, renders, redraws):
    """{scene, kind, triangles, objects, bake, render, frame, eevee} of an example scene, built, baked and
    saved into scenes_dir."""
    from benchmarks import engine_vs_eevee, scaling
    from examples import build_scenes

    scene = build_scenes.SCENES[name]()
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    scene.render.resolution_x, scene.render.resolution_y = image_size
    options = {"resolution": bake_resolution} if bake_resolution else {}
    start = time.perf_counter()
    engine_vs_eevee.bake_all(name, **options)
    bake = time.perf_counter() - start
    build_scenes.save_scene(Path(scenes_dir) / f"{name}.blend")
    row = {"scene": name, "kind": "example", "triangles": scaling.scene_triangles(scene),
           "objects": sum(obj.type == "MESH" for obj in scene.objects), "bake": bake}
    row.update(scaling.measure_scene(scene, renders, redraws))
    return row


def scaling_rows(axes, image_size, renders, redraws):
    """Rows of the scaling scenes (benchmarks.scaling.measure_axis) and the log-log slopes of each axis."""
    from benchmarks import scaling

    results = {axis: scaling.measure_axis(axis, sizes, renders, redraws, image_size=image_size)
               for axis, sizes in axes.items()}
    rows = [{"scene": f"{axis} {point['size']}", "kind": "scaling", "triangles": point["triangles"],
             "objects": point["scene"]["objects"], "image": [point["scene"]["width"], point["scene"]["height"]],
             **{key: point[key] for key in ("render", "frame", "eevee")}}
            for axis, points in results.items() for point in points]
    slopes = scaling.summarize(results) if all(len(points) > 1 for points in results.values()) else {}
    return rows, slopes


def markdown(report):
    gpu = report["gpu"]
    width, height = report["resolution"]
    lines = [f"# SG-PRT on {gpu['renderer']}", "",
             f"Blender {report['blender']}, {gpu['vendor']}, OpenGL {gpu['version']}"
             + (f" ({gpu['backend']})" if gpu.get("backend") else "") + f"; {width}x{height}; "
             f"{report['date']}; `{report['command']}`{' (smoke run)' if report['smoke'] else ''}.", "",
             "render(): bpy.ops.render.render after a warm-up (export, upload, draw, read back); frame: draw + "
             "read back 3 passes; EEVEE: 1 sample, matched node materials, after a warm-up; ratios against "
             "EEVEE in the same run.", "",
             "| scene | triangles | objects | SG-PRT render() s | SG-PRT frame s | EEVEE s | render() / EEVEE | "
             "frame / EEVEE |", "|---|---|---|---|---|---|---|---|"]
    for row in report["scenes"]:
        lines.append(f"| {row['scene']} | {row['triangles']} | {row['objects']} | {row['render']:.4f} | "
                     f"{row['frame']:.4f} | {row['eevee']:.4f} | {row['render_ratio']:.3f} | "
                     f"{row['frame_ratio']:.3f} |")
    if report["slopes"]:
        lines += ["", "Log-log slopes (benchmarks.scaling.summarize): " + "; ".join(
            f"{axis}: render() {slopes['slope_render']:.2f}, frame {slopes['slope_frame']:.2f}, EEVEE "
            f"{slopes['slope_eevee']:.2f}" for axis, slopes in report["slopes"].items()) + "."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--resolution", type=resolution, default=None,
                        help=f"WIDTHxHEIGHT (default 1920x1080; --smoke: {SMOKE_RESOLUTION[0]}x{SMOKE_RESOLUTION[1]})")
    parser.add_argument("--output", type=Path, default=Path(REPO_ROOT) / "out" / "gpu_run")
    parser.add_argument("--smoke", action="store_true", help="a small image, few scenes, one render each")
    parser.add_argument("--examples", nargs="*", default=None, help="example scenes (default: every one)")
    parser.add_argument("--renders", type=int, default=None, help="SG-PRT render() timed after the warm-up "
                                                                  "(median; default 5, --smoke 1)")
    args = parser.parse_args(argv)
    image_size = args.resolution or (SMOKE_RESOLUTION if args.smoke else (1920, 1080))
    renders = args.renders or (1 if args.smoke else 5)
    redraws = 1 if args.smoke else 5

    import bpy

    from benchmarks import scaling
    from examples import build_scenes
    from sg_prt_addon import render

    render.ensure_registered()
    examples = args.examples if args.examples is not None else (SMOKE_EXAMPLES if args.smoke else list(build_scenes.SCENES))
    axes = SMOKE_SCALING if args.smoke else {axis: spec[2] for axis, spec in scaling.AXES.items()}
    scenes_dir = args.output / "scenes"
    scenes_dir.mkdir(parents=True, exist_ok=True)
    gpu = platform()
    print(f"GPU: {gpu['renderer']} ({gpu['vendor']}, OpenGL {gpu['version']}); Blender {bpy.app.version_string}",
          flush=True)
    rows = [example_scene(name, image_size, scenes_dir, SMOKE_BAKE_RESOLUTION if args.smoke else None, renders,
                          redraws) for name in examples]
    scaled, slopes = scaling_rows(axes, image_size, renders, redraws)
    rows += scaled
    for row in rows:
        row["render_ratio"] = row["render"] / row["eevee"]
        row["frame_ratio"] = row["frame"] / row["eevee"]
        print(f"{row['scene']}: SG-PRT render() {row['render']:.4f} s, frame {row['frame']:.4f} s, EEVEE "
              f"{row['eevee']:.4f} s: render() / EEVEE {row['render_ratio']:.3f}, frame / EEVEE "
              f"{row['frame_ratio']:.3f}", flush=True)
    report = {"blender": bpy.app.version_string, "gpu": gpu, "resolution": list(image_size), "smoke": args.smoke,
              "date": time.strftime("%Y-%m-%d %H:%M"), "command": "bash benchmarks/gpu_run.sh " + " ".join(
                  sys.argv[1:] if argv is None else argv), "scenes": rows, "slopes": slopes,
              "median_render_ratio": statistics.median(row["render_ratio"] for row in rows)}
    (args.output / "gpu_run.json").write_text(json.dumps(report, indent=1), encoding="utf-8")
    (args.output / "gpu_run.md").write_text(markdown(report), encoding="utf-8")
    print(f"GPU: {gpu['renderer']}; Blender {report['blender']}; median render() / EEVEE "
          f"{report['median_render_ratio']:.3f}; wrote {args.output / 'gpu_run.json'} and "
          f"{args.output / 'gpu_run.md'}", flush=True)
    return report


if __name__ == "__main__":
    from sg_prt_addon import render as batch_render

    main()
    batch_render.exit_process(0)
