"""Frame time of each technique on the example scenes, beside EEVEE, in one process on one machine.

Per scene (examples/build_scenes.py at --size): every material switched to each technique in turn
(SG_PARAMETRIC unshadowed and with the visibility bake, FACTORED unshadowed and with the visibility bake,
SH unshadowed and with the transfer bake, at the materials' SH order 5; the bakes' times printed apart),
the steady frame (draw + read back 3 passes, median of --redraws) and render() (median of --renders,
after a first render that factorizes, prefilters and compiles), then EEVEE at 1 sample with matched node
materials.  Ratios against EEVEE measured in the same run.

    .venv/bin/python -m benchmarks.technique_speed [--size 512] [--scenes NAME ...] [--techniques NAME ...]
"""
import argparse
import os
import statistics
import sys
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

RUNS = (("SG_PARAMETRIC", False), ("SG_PARAMETRIC", True), ("FACTORED", False), ("FACTORED", True),
        ("SH", False), ("SH", True))
BAKES = {"SG_PARAMETRIC": "visibility", "FACTORED": "visibility", "SH": "transfer"}


def _set_technique(scene, technique):
    for obj in scene.objects:
        for slot in getattr(obj, "material_slots", ()):
            if slot.material is not None:
                slot.material.sgprt.technique = technique


def measure_scene(name, size, renders, redraws, runs=RUNS):
    import bpy

    from benchmarks import matched_materials
    from benchmarks.engine_vs_eevee import render_seconds, steady_frame
    from examples import build_scenes

    scene = build_scenes.SCENES[name](size)
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    figures = {}
    operators = {"visibility": bpy.ops.sgprt.bake_visibility, "transfer": bpy.ops.sgprt.bake_transfer}
    clears = {"visibility": bpy.ops.sgprt.clear_visibility, "transfer": bpy.ops.sgprt.clear_transfer}
    for technique, baked in runs:
        kind = BAKES[technique]
        for other in operators:          # only this run's bake present: "unshadowed" means no bake at all
            if other != kind or not baked:
                clears[other](target="ALL")
        if baked:
            start = time.perf_counter()
            if operators[kind]("EXEC_DEFAULT", target="ALL") != {"FINISHED"}:
                raise RuntimeError(f"{name}: the {kind} bake did not finish")
            figures[(kind, "bake")] = time.perf_counter() - start
        _set_technique(scene, technique)
        label = technique + (" + bake" if baked else "")
        start = time.perf_counter()
        render_seconds()
        figures[(label, "first")] = time.perf_counter() - start
        figures[(label, "render")] = statistics.median(render_seconds() for _ in range(renders))
        figures[(label, "frame")] = steady_frame(redraws)
    matched_materials.match_scene(scene)
    matched_materials.configure_eevee(scene, 1)
    render_seconds()                                     # compiles EEVEE's shaders
    figures[("EEVEE 1 sample", "render")] = statistics.median(render_seconds() for _ in range(renders))
    return figures


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--scenes", nargs="*", default=["suzanne_courtyard", "brushed_metal"])
    parser.add_argument("--renders", type=int, default=5)
    parser.add_argument("--redraws", type=int, default=7)
    parser.add_argument("--techniques", nargs="*", default=sorted(BAKES), choices=sorted(BAKES),
                        help="the techniques' rows to measure (default: all)")
    arguments = parser.parse_args(argv)
    runs = tuple(run for run in RUNS if run[0] in arguments.techniques)
    import sg_prt_addon
    sg_prt_addon.register()
    results = {name: measure_scene(name, arguments.size, arguments.renders, arguments.redraws, runs)
               for name in arguments.scenes}
    print(f"\n{arguments.size}x{arguments.size}, seconds (ratio to EEVEE 1 sample, same run)")
    for name, figures in results.items():
        eevee = figures[("EEVEE 1 sample", "render")]
        print(f"\n{name}: EEVEE 1 sample render {eevee:.3f} s")
        print(f"{'technique':28s} {'first render':>14s} {'render()':>16s} {'steady frame':>16s}")
        for technique, baked in runs:
            label = technique + (" + bake" if baked else "")
            first, render, frame = (figures[(label, k)] for k in ("first", "render", "frame"))
            print(f"{label:28s} {first:14.3f} {render:9.3f} ({render / eevee:4.2f}) {frame:9.3f} ({frame / eevee:4.2f})")
        print("bakes: " + ", ".join(f"{kind} {figures[(kind, 'bake')]:.1f} s" for kind in ("visibility", "transfer")
                                    if (kind, "bake") in figures))
    return 0


if __name__ == "__main__":
    sys.exit(main())
