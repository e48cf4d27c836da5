"""Bi-scale materials (iwasaki2012): the editing latency and the frame, in one process on one machine.

1. From a changed height field (64^2 and 256^2 texels, validation.biscale_reference.random_bumps) to the new
   tile tables (biscale.bvndf.compute), by step: the tile's triangles and facets, the ray tracer, the sample
   points' masking and shadowing towards the 144 lattice directions, the NDF's spherical EM, the amplitudes.
   Median of --runs.
2. In the engine (pip bpy, examples/build_scenes.py's hammered_metal at --size): the steady frame with the
   bi-scale material (16 lobes and 8, the three-lobe and the one-lobe view warp) against the same scene with
   that material on the SG technique (its small-scale BRDF as one scale: the baseline, measured in the same
   run), and the viewport's next frame after the height image is edited (export again, upload, draw), beside
   its frame after a plain material edit.

    .venv/bin/python -m benchmarks.biscale_editing [--size 512] [--runs 5]
"""
import argparse
import os
import statistics
import sys
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)


def tile_steps(resolution, runs):
    """Median seconds of each step of the tables from a height field of resolution^2 texels."""
    from sg_prt_addon.biscale import bvndf, microgeometry
    from validation import biscale_reference

    steps = {}
    for run in range(runs):
        heights = biscale_reference.random_bumps(resolution, seed=run)
        clock = time.perf_counter()
        marks = []

        def mark(name):
            nonlocal clock
            now = time.perf_counter()
            marks.append((name, now - clock))
            clock = now

        geometry = microgeometry.from_height_field(heights)
        geometry.facets()
        mark("tile")
        tracer = microgeometry.TiledTracer(geometry)
        mark("ray tracer")
        tile = bvndf.trace_tile(geometry, tracer=tracer)
        tracer.close()
        mark("masking and shadowing")
        lobes = bvndf.fit_ndf(geometry)
        mark("NDF fit (spherical EM)")
        bvndf.from_samples(tile, *lobes, bvndf.DEFAULT_RESOLUTION)
        mark("amplitudes and diffuse tables")
        for name, seconds in marks:
            steps.setdefault(name, []).append(seconds)
    return {name: statistics.median(values) for name, values in steps.items()}


def engine_figures(size, redraws):
    import bpy
    import numpy as np

    from benchmarks.engine_vs_eevee import render_seconds, steady_frame
    from examples import build_scenes
    from sg_prt_addon.engine import render_engine
    from validation import biscale_reference, viewport_timing

    build_scenes.SCENES["hammered_metal"](size)
    material = bpy.data.materials["Hammered Gold"]
    render_seconds()                                     # compiles, prefilters, computes the tables
    figures = {"bi-scale frame, 16 lobes, warp split3 (the defaults)": steady_frame(redraws)}
    image = material.sgprt.biscale.height_image
    edits = iter(range(1, 1000))

    def measure(depsgraph, state, renderer, camera):
        width, height = renderer.size
        exports = []

        def paint(edited_state):                         # a new height field, as painting it would give
            heights = biscale_reference.random_bumps(image.size[0], amplitude=0.04, seed=next(edits))
            pixels = np.repeat(heights[::-1, :, None], 4, axis=-1).astype(np.float32)
            image.pixels.foreach_set(pixels.ravel())
            start = time.perf_counter()
            edited_state._export_readers({("IMAGE", image.name)}, edited_state.dirty)
            exports.append(time.perf_counter() - start)

        def touch(edited_state):
            edited_state.dirty.materials.add(material.name)

        _, painted, _, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, redraws, edit=paint)
        _, touched, _, _ = viewport_timing.time_viewport_redraws(state, camera, width, height, redraws, edit=touch)
        return statistics.median(exports), statistics.median(painted), statistics.median(touched)

    render_engine.debug["after_frame"] = measure
    try:
        render_seconds()
    finally:
        render_engine.debug["after_frame"] = None
    export, painted, touched = render_engine.last_render["after_frame"]
    figures.update({"height edit: export (tables)": export, "height edit: next frame": painted,
                    "material edit: next frame": touched})
    for lobes, warp in ((16, "PAPER"), (8, "SPLIT3"), (8, "PAPER")):
        material.sgprt.biscale.lobes, material.sgprt.sg.view_warp = lobes, warp
        render_seconds()
        figures[f"bi-scale frame, {lobes} lobes, warp {warp.lower()}"] = steady_frame(redraws)
    material.sgprt.biscale.lobes, material.sgprt.sg.view_warp = 16, "SPLIT3"
    material.sgprt.technique = "SG_PARAMETRIC"
    render_seconds()
    figures["single-scale frame (SG technique)"] = steady_frame(redraws)
    return figures


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--redraws", type=int, default=5)
    arguments = parser.parse_args(argv)
    import sg_prt_addon
    sg_prt_addon.register()
    for resolution in (64, 256):
        steps = tile_steps(resolution, arguments.runs)
        print(f"\nheight field {resolution}^2: tables in {sum(steps.values()):.3f} s (median of {arguments.runs})")
        for name, seconds in steps.items():
            print(f"  {name:34s} {seconds:.3f} s")
    figures = engine_figures(arguments.size, arguments.redraws)
    baseline = figures["single-scale frame (SG technique)"]
    print(f"\nhammered_metal at {arguments.size}x{arguments.size}, seconds (ratio to the single-scale frame, same run)")
    for name, seconds in figures.items():
        print(f"  {name:52s} {seconds:.4f}  ({seconds / baseline:.2f}x)")


if __name__ == "__main__":
    main()
