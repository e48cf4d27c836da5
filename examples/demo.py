"""The main job: build the example scene, bake its visibility, render it with SG-PRT, score it against the
Monte Carlo reference, and write out/demo.png, out/reference.png, out/side_by_side.png
and out/report.md (docs/images/demo.png is a copy of side_by_side.png).

    .venv/bin/python examples/demo.py [--output out] [--size 256] [--noise 0.02] [--bake-resolution 32]
"""
import argparse
import platform
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import bpy  # noqa: E402

from examples import build_scenes  # noqa: E402
from sg_prt_addon import render
from sg_prt_addon.visibility.raytrace import RayTracer
from validation import image_error
from validation.reference import mean_relative_error, render_to_noise
from validation.reference_scene import reference_inputs

SCENE = "suzanne_courtyard"


def save_display_png(rgb, path, scene):
    """A linear (H, W, 3) image written as PNG through the scene's colour management."""
    height, width = rgb.shape[:2]
    image = bpy.data.images.new("display", width, height, float_buffer=True)
    settings = scene.render.image_settings
    file_format, settings.file_format = settings.file_format, "PNG"   # save_render writes the scene's format
    try:
        rgba = np.concatenate([rgb, np.ones((height, width, 1))], axis=-1)[::-1]
        image.pixels.foreach_set(np.ascontiguousarray(rgba, np.float32).ravel())
        image.save_render(str(path), scene=scene)
    finally:
        settings.file_format = file_format
        bpy.data.images.remove(image)


def surface_mask(reference_scene, camera):
    tracer = RayTracer(reference_scene.vertices, reference_scene.triangles)
    origins, directions = camera.primary_rays()
    hits = tracer.intersect(origins.reshape(-1, 3), directions.reshape(-1, 3))
    return hits.hit.reshape(camera.height, camera.width)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default=str(ROOT / "out"))
    parser.add_argument("--size", type=int, default=256, help="image width and height")
    parser.add_argument("--noise", type=float, default=0.02, help="reference's target mean relative noise")
    parser.add_argument("--bake-resolution", type=int, default=32, help="stored SSDF resolution per vertex")
    arguments = parser.parse_args(argv)
    output = Path(arguments.output)
    output.mkdir(parents=True, exist_ok=True)
    clock = render.StageClock()

    clock.run("register add-on", render.ensure_registered)
    clock.run("build scene", build_scenes.SCENES[SCENE], arguments.size)
    blend = clock.run("save scene", build_scenes.save_scene, output / "scenes" / f"{SCENE}.blend")
    scene = clock.run("open scene", render.open_blend, blend)
    result = clock.run("bake visibility", bpy.ops.sgprt.bake_visibility, "EXEC_DEFAULT", target="ALL",
                       resolution=arguments.bake_resolution)
    if result != {"FINISHED"}:
        raise RuntimeError(f"the visibility bake did not finish: {result}")
    # The first render pays for prefiltering the environment; the second is the frame time.
    clock.run("engine render (first, prefilters)", render.render_to_file, scene, output / "demo.exr")
    exr = clock.run("engine render", render.render_to_file, scene, output / "demo.exr")
    sampling = engine_sampling(scene)
    engine_image = render.read_float_image(exr)
    save_display_png(engine_image, output / "demo.png", scene)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    reference_scene, camera = clock.run("export for reference", reference_inputs, depsgraph,
                                        arguments.size, arguments.size)
    reference, error, samples = clock.run("reference render", render_to_noise, reference_scene, camera,
                                          relative_error=arguments.noise, max_samples=256)
    save_display_png(reference, output / "reference.png", scene)
    save_display_png(np.concatenate([engine_image, reference], axis=1), output / "side_by_side.png", scene)
    mask = surface_mask(reference_scene, camera)

    figures = {
        "relative RMSE vs reference (surface pixels)": image_error.relative_rmse(engine_image, reference, mask),
        "relative mean bias vs reference (surface pixels)": image_error.relative_mean_bias(engine_image, reference,
                                                                                           mask),
        "reference noise floor of that RMSE": image_error.rmse_noise_floor(error, reference, mask),
        "reference mean relative noise": mean_relative_error(reference, error),
    }
    write_report(output / "report.md", arguments.size, len(reference_scene.triangles), samples, clock.durations,
                 figures, sampling)
    print(f"[sg-prt] wrote {output / 'demo.png'}, {output / 'reference.png'}, {output / 'report.md'}", flush=True)
    return figures


def engine_sampling(scene):
    """How the last render sampled its pixels, in words (scene.sgprt's Render Samples)."""
    from sg_prt_addon.engine import render_engine

    settings = scene.sgprt
    timings = render_engine.last_render.get("timings", {})
    words = f"Render Samples {settings.render_samples}"
    if "edge_pixels" in timings:
        words += f", Edges Only ({timings['edge_pixels']:.1%} of the pixels sampled, the rest one sample)"
    return words


def write_report(path, size, triangles, samples, durations, figures, sampling):
    lines = [f"# SG-PRT demo: {SCENE}", "",
             f"{size}x{size} pixels, {triangles} triangles, bpy {bpy.app.version_string}, "
             f"{platform.machine()}, Python {platform.python_version()}, {time.strftime('%Y-%m-%d %H:%M')}.", "",
             f"Images: demo.png (SG-PRT, {sampling}), reference.png (Monte Carlo, exact direct light, "
             f"{samples} samples per pixel over each pixel's area).", "", "## Timings", "", "| stage | seconds |", "|---|---|"]
    lines += [f"| {name} | {seconds:.2f} |" for name, seconds in durations.items()]
    lines += ["", "## Error", "", "| figure | value |", "|---|---|"]
    lines += [f"| {name} | {value:.4f} |" for name, value in figures.items()]
    lines += [""]
    Path(path).write_text("\n".join(lines))


if __name__ == "__main__":
    main()
