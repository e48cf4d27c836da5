"""What the lobes of an anisotropic NDF cost a frame, against 4 lobes (the default before 2026-12-06), in one run.

Per scene (the truth suite's anisotropic ones, benchmarks/truth_suite.py, at --size), every mesh is baked once
by the operator; then every anisotropic material is given each lobe count in turn, rendered once off the clock
(its shader variant and lobe table), and its steady frame (draw + read back, the median of the redraws of one
render) measured, the counts alternated --rounds times.  The ratio is to 4 lobes, the median of the rounds.
What the lobes buy against Cycles is the truth suite's (docs/ACCURACY.md).

    .venv/bin/python -m benchmarks.anisotropic_lobes_cost [--size 512] [--rounds 3] [--lobes 4 6 8]
"""
import argparse
import os
import statistics
import sys

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

DEFAULT_SCENES = ("aniso_ggx_torus_hdri", "aniso_torus_hdri")
BASELINE_LOBES = 4
REDRAWS = 5


def set_lobes(count):
    """Every anisotropic material of the file at ``count`` lobes; returns how many there are."""
    import bpy

    from sg_prt_addon.reflectance import models

    materials = [m for m in bpy.data.materials if m.sgprt.model in models.ANISOTROPIC]
    for material in materials:
        material.sgprt.lobe_count = count
    return len(materials)


def measure_scene(name, size, rounds, lobe_counts):
    from benchmarks import scene_benchmark
    from benchmarks.engine_vs_eevee import bake_all, steady_frame

    scene = scene_benchmark.build(name, "truth_suite", size)
    scene.render.engine = "SG_PRT"
    bake_all(name)
    frames = {count: [] for count in lobe_counts}
    for _ in range(rounds):
        for count in lobe_counts:
            if not set_lobes(count):
                raise RuntimeError(f"{name}: no anisotropic material")
            steady_frame(REDRAWS)                           # the variant's compile and table, off the clock
            frames[count].append(steady_frame(REDRAWS))
    baseline = frames[BASELINE_LOBES]
    return dict(scene=name, frames={count: statistics.median(f) for count, f in frames.items()},
                ratios={count: sorted(new / old for new, old in zip(f, baseline)) for count, f in frames.items()})


def table(rows, lobe_counts):
    head = " | ".join(f"{count} lobes: frame s, / {BASELINE_LOBES} (range)" for count in lobe_counts)
    lines = [f"| scene | {head} |", "|---|" + "---|" * len(lobe_counts)]
    for row in rows:
        cells = []
        for count in lobe_counts:
            ratios = row["ratios"][count]
            cells.append(f"{row['frames'][count]:.3f}, {statistics.median(ratios):.2f} "
                         f"({ratios[0]:.2f}-{ratios[-1]:.2f})")
        lines.append(f"| {row['scene']} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    parser.add_argument("--lobes", nargs="*", type=int, default=[BASELINE_LOBES, 6, 8])
    args = parser.parse_args(argv)
    lobe_counts = sorted(set(args.lobes) | {BASELINE_LOBES})

    from sg_prt_addon import render
    render.ensure_registered()
    rows = []
    for name in args.scenes:
        row = measure_scene(name, args.size, args.rounds, lobe_counts)
        print(f"{name}: {row}", flush=True)
        rows.append(row)
    print()
    print(table(rows, lobe_counts))


if __name__ == "__main__":
    main()
