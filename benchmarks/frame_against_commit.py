"""The steady frame of the example scenes on this tree against an earlier commit's tree, alternated in fresh processes.

The commit's tree is `git archive`d to a temporary folder.  Each round runs, for each scene, one process per tree
with that tree first on sys.path: the scene built by that tree's examples/build_scenes.py at --size, baked by its
operator at its defaults, Render Samples 1 (the setting's first default; a tree without it draws one frame anyway),
and its engine_vs_eevee.steady_frame (draw + read back, the median of --redraws redraws of one render).  The
ratio is this tree's frame over the commit's of the same round, median and range: what every change between the
two costs the frame together, where docs/PERFORMANCE.md "What each accuracy feature costs the frame" measures
each against its parent.

    .venv/bin/python -m benchmarks.frame_against_commit [--commit d145f8e] [--size 512] [--rounds 3] [--scenes NAME ...]

The default commit is the tree before the truth suite and the SG technique's accuracy work.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

DEFAULT_COMMIT = "d145f8e"
DEFAULT_SCENES = ("suzanne_courtyard", "brushed_metal")

# run in a fresh interpreter with a tree's root as argv[1]: prints the steady frame as JSON on its last line
_ONE_FRAME = """
import json, sys
sys.path.insert(0, sys.argv[1])
import bpy
from sg_prt_addon import render
render.ensure_registered()
from examples import build_scenes
from benchmarks.engine_vs_eevee import steady_frame
scene = build_scenes.SCENES[sys.argv[2]](int(sys.argv[3]))
if bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL") != {"FINISHED"}:
    raise SystemExit("the visibility bake did not finish")
if hasattr(scene.sgprt, "render_samples"):
    scene.sgprt.render_samples = 1
steady_frame(2)
print(json.dumps(steady_frame(int(sys.argv[4]))))
"""


def frame_seconds(tree, scene, size, redraws):
    """The steady frame of `scene` drawn by the tree at `tree`, in a process of its own."""
    done = subprocess.run([sys.executable, "-c", _ONE_FRAME, tree, scene, str(size), str(redraws)],
                          capture_output=True, text=True, cwd=tree)
    if done.returncode != 0:
        raise RuntimeError(f"{scene} on {tree} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def export_tree(commit, folder):
    """`git archive` of `commit` unpacked into `folder`."""
    archive = subprocess.run(["git", "archive", commit], cwd=REPO_ROOT, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", folder], input=archive, check=True)


def alternated(rounds, label, commit, commit_seconds, tree_seconds, digits):
    """Runs commit_seconds() and tree_seconds() in turn, `rounds` times, printing each pair under `label`:
    (commit's median, this tree's median, median of this tree's over the commit's, its low, its high)."""
    before, now = [], []
    for _ in range(rounds):
        before.append(commit_seconds())
        now.append(tree_seconds())
        print(f"{label}: {commit} {before[-1]:.{digits}f} s, this tree {now[-1]:.{digits}f} s", flush=True)
    ratios = [b / a for a, b in zip(before, now)]
    return statistics.median(before), statistics.median(now), statistics.median(ratios), min(ratios), max(ratios)


def ratio_table(results, commit, key_header, what, digits):
    """Markdown table of ``alternated``'s results by key: `what` (the frame, the bake) on both trees."""
    lines = [f"| {key_header} | {what} {commit} | {what} now | now / {commit} (range) |", "|---|---|---|---|"]
    for key, (before, now, ratio, low, high) in results.items():
        lines.append(f"| {key} | {before:.{digits}f} s | {now:.{digits}f} s | {ratio:.2f} ({low:.2f}-{high:.2f}) |")
    return "\n".join(lines)


def measure(commit, scenes, size, rounds, redraws):
    """{scene: (commit's frame, this tree's frame, ratio median, low, high)} (medians over the rounds)."""
    results = {}
    with tempfile.TemporaryDirectory(prefix="sgprt-tree-") as folder:
        export_tree(commit, folder)
        for scene in scenes:
            results[scene] = alternated(rounds, scene, commit,
                                        lambda: frame_seconds(folder, scene, size, redraws),
                                        lambda: frame_seconds(REPO_ROOT, scene, size, redraws), digits=4)
    return results


def table(results, commit):
    return ratio_table(results, commit, "scene", "frame", digits=3)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default=DEFAULT_COMMIT)
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--redraws", type=int, default=7)
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    args = parser.parse_args(argv)
    results = measure(args.commit, args.scenes, args.size, args.rounds, args.redraws)
    print()
    print(table(results, args.commit))


if __name__ == "__main__":
    main()
