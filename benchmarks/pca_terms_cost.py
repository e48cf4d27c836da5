"""What the bake's default PCA error target costs a frame, against an earlier target, in one run.

Per scene (the truth suite's, benchmarks/truth_suite.py, at --size), every mesh is baked by the operator at
the default error target (visibility.pca.DEFAULT_ERROR_TARGET) and at --baseline-target; the PCA is nested
(a bake keeping fewer terms stores the leading terms of one keeping more), so the baseline is the default
bake truncated to the baseline's term counts.  The steady frame (draw + read back, the median of the
redraws of one render) of the two is measured back to back, --rounds times; the ratio is default /
baseline, the median of the rounds.  What the terms buy against Cycles is the truth suite's (docs/ACCURACY.md).

    .venv/bin/python -m benchmarks.pca_terms_cost [--size 512] [--rounds 3] [--scenes NAME ...]
"""
import argparse
import os
import statistics
import sys

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

DEFAULT_SCENES = ("ggx010_hdri", "ggx035_metal_hdri", "aniso_ggx_torus_hdri", "diffuse_hdri")
BASELINE_TARGET = 0.015         # the default before 0.01 (2026-12-06; 0.02 before that)
REDRAWS = 5


def baked(name, error_target):
    """{object name: stored bake} of every mesh of the context's scene, baked by the operator at ``error_target``."""
    import bpy

    from benchmarks.engine_vs_eevee import bake_all
    from sg_prt_addon.blender import visibility_bake

    bake_all(name, error_target=error_target)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    return {obj.name: visibility_bake.visibility_for_object(obj.evaluated_get(depsgraph))
            for obj in bpy.context.scene.objects if obj.type == "MESH"}


def measure_scene(name, size, rounds, baseline_target):
    from benchmarks import scene_benchmark
    from benchmarks.engine_vs_eevee import steady_frame
    from benchmarks.error_vs_time import SceneRun
    from sg_prt_addon.engine import scene_state
    from sg_prt_addon.visibility import pca

    scene = scene_benchmark.build(name, "truth_suite", size)
    scene.render.engine = "SG_PRT"
    baseline_terms = {key: bake.terms for key, bake in baked(name, baseline_target).items()}
    full = baked(name, pca.DEFAULT_ERROR_TARGET)
    default_terms = {key: bake.terms for key, bake in full.items()}
    truncated = {key: SceneRun.truncated({key: bake}, baseline_terms[key])[key] for key, bake in full.items()}
    frames = {"default": [], "baseline": []}
    try:
        for _ in range(rounds):
            for label, bakes in (("baseline", truncated), ("default", full)):
                SceneRun.use_bakes(bakes)
                steady_frame(REDRAWS)                       # the upload of the other bake, off the clock
                frames[label].append(steady_frame(REDRAWS))
    finally:
        scene_state.visibility_provider = None
    ratios = [new / old for new, old in zip(frames["default"], frames["baseline"])]
    return dict(scene=name, baseline_terms=baseline_terms, default_terms=default_terms,
                baseline_frame=statistics.median(frames["baseline"]), default_frame=statistics.median(frames["default"]),
                ratio=statistics.median(ratios), ratio_range=(min(ratios), max(ratios)))


def table(rows, baseline_target):
    from sg_prt_addon.visibility import pca

    def terms(counts):
        return "/".join(str(counts[key]) for key in sorted(counts))

    lines = [f"| scene | terms at {baseline_target} rad (objects by name) | terms at {pca.DEFAULT_ERROR_TARGET} rad | "
             "frame s before | frame s now | now / before (range) |", "|---|---|---|---|---|---|"]
    for row in rows:
        low, high = row["ratio_range"]
        lines.append(f"| {row['scene']} | {terms(row['baseline_terms'])} | {terms(row['default_terms'])} | "
                     f"{row['baseline_frame']:.4f} | {row['default_frame']:.4f} | {row['ratio']:.3f} "
                     f"({low:.3f}-{high:.3f}) |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    parser.add_argument("--baseline-target", type=float, default=BASELINE_TARGET)
    args = parser.parse_args(argv)

    from sg_prt_addon import render
    render.ensure_registered()
    rows = []
    for name in args.scenes:
        row = measure_scene(name, args.size, args.rounds, args.baseline_target)
        print(f"{name}: {row}", flush=True)
        rows.append(row)
    print()
    print(table(rows, args.baseline_target))


if __name__ == "__main__":
    main()
