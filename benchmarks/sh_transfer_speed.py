"""The SH technique's frame with a transfer bake, its terms summed per pixel against summed at the vertices
(techniques/sh/spherical_harmonics.py VERTEX_TRANSFER), beside the unshadowed frame, in one process.

Per scene (examples/build_scenes.py at --size, every material SH at order 5): the unshadowed frame --repeats
times, then the transfer bake (operator defaults), then the two ways of summing alternated --repeats times;
each measurement is a render() after a render that compiles and builds the tables, then the steady frame
(draw + read back 3 passes, median of 7 redraws; benchmarks.engine_vs_eevee.steady_frame).  Medians; the
machine's load printed beside them.  Also the largest difference of the two ways' passes (float32 rounding:
the sums are the same by linearity).

    .venv/bin/python -m benchmarks.sh_transfer_speed [--size 512] [--repeats 5] [--scenes NAME ...]
"""
import argparse
import os
import statistics
import sys

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

WAYS = (("summed per pixel", False), ("summed at the vertices", True))
PASSES = ("Combined", "Diffuse", "Specular")


def _measure(figures, label, redraws):
    from benchmarks.engine_vs_eevee import render_seconds, steady_frame
    from sg_prt_addon.engine import render_engine

    render_seconds()                                    # compiles the variant, builds its tables
    figures.setdefault((label, "render"), []).append(render_seconds())
    images = {name: np.array(render_engine.last_render["passes"][name][..., :3]) for name in PASSES}
    figures.setdefault((label, "frame"), []).append(steady_frame(redraws))
    return images


def measure_scene(name, size, repeats, redraws=7):
    import bpy

    from examples import build_scenes
    from sg_prt_addon.techniques.sh import spherical_harmonics

    scene = build_scenes.SCENES[name](size)
    for obj in scene.objects:
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None:
                slot.material.sgprt.technique = "SH"
    figures = {}
    for _ in range(repeats):
        _measure(figures, "unshadowed", redraws)
    if bpy.ops.sgprt.bake_transfer("EXEC_DEFAULT", target="ALL") != {"FINISHED"}:
        raise RuntimeError(f"{name}: the transfer bake did not finish")
    images = {}
    try:
        for _ in range(repeats):
            for label, at_vertices in WAYS:
                spherical_harmonics.VERTEX_TRANSFER = at_vertices
                images[label] = _measure(figures, label, redraws)
    finally:
        spherical_harmonics.VERTEX_TRANSFER = True
    (first, _), (second, _) = WAYS
    difference = max(float(np.abs(images[first][p] - images[second][p]).max() / np.abs(images[first][p]).max())
                     for p in PASSES)
    return {key: statistics.median(values) for key, values in figures.items()}, difference


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--scenes", nargs="*", default=["suzanne_courtyard", "brushed_metal"])
    arguments = parser.parse_args(argv)
    import sg_prt_addon
    sg_prt_addon.register()
    print(f"\n{arguments.size}x{arguments.size}, SH order 5, seconds (medians of {arguments.repeats})")
    print("| scene | SH | render() | steady frame | frame / unshadowed |\n|---|---|---|---|---|")
    for name in arguments.scenes:
        figures, difference = measure_scene(name, arguments.size, arguments.repeats)
        unshadowed = figures[("unshadowed", "frame")]
        for label in ("unshadowed",) + tuple(label for label, _ in WAYS):
            row = label if label == "unshadowed" else "transfer " + label
            print(f"| {name} | {row} | {figures[(label, 'render')]:.3f} | {figures[(label, 'frame')]:.3f} | "
                  f"{figures[(label, 'frame')] / unshadowed:.2f} |")
        print(f"| {name} | the two ways' largest difference / the pass's peak: {difference:.1e} | | | |")
    print(f"load average {os.getloadavg()[0]:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
