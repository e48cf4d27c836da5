"""The visibility bake on this tree against an earlier commit's tree, alternated in fresh processes.

The commit's tree is `git archive`d to a temporary folder (benchmarks.frame_against_commit.export_tree).  Each
round bakes, for each size, bake_speed's scene (an icosphere over a floor) in one process per tree with that tree
first on sys.path, at that tree's operator defaults: the whole of bake_visibility (rays, SSDF, buried points, PCA)
on both cores.  The ratio is this tree's bake over the commit's of the same round, median and range.

    .venv/bin/python -m benchmarks.bake_against_commit [--commit fef3bc1] [--rounds 2] [20000 100000]

The default commit is where session 27's bake changes began.
"""
import argparse
import json
import subprocess
import sys
import tempfile

from benchmarks.bake_speed import sphere_over_floor
from benchmarks.frame_against_commit import REPO_ROOT, alternated, export_tree, ratio_table

DEFAULT_COMMIT = "fef3bc1"

# run in a fresh interpreter with a tree's root as argv[1]: prints the bake's seconds as JSON on its last line
_ONE_BAKE = """
import json, sys
sys.path.insert(0, sys.argv[1])
from benchmarks.bake_speed import sphere_over_floor
from sg_prt_addon.visibility import BakeOptions, bake_visibility
vertices, triangles, normals = sphere_over_floor(int(sys.argv[2]))
result = bake_visibility(vertices, triangles, normals, vertices, triangles, BakeOptions(), point_triangles=triangles)
print(json.dumps({"seconds": result.seconds}))
"""


def bake_seconds(tree, size):
    """bake_visibility's seconds on bake_speed's scene of about `size` vertices, by the tree at `tree`."""
    done = subprocess.run([sys.executable, "-c", _ONE_BAKE, tree, str(size)], capture_output=True, text=True,
                          cwd=tree)
    if done.returncode != 0:
        raise RuntimeError(f"the bake of {size} vertices on {tree} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])["seconds"]


def measure(commit, sizes, rounds):
    """{vertices: (commit's seconds, this tree's seconds, ratio median, low, high)} (medians over the rounds)."""
    results = {}
    with tempfile.TemporaryDirectory(prefix="sgprt-tree-") as folder:
        export_tree(commit, folder)
        for size in sizes:
            vertices = f"{len(sphere_over_floor(size)[0]):,}"       # this tree's scene: both build the same one
            results[vertices] = alternated(rounds, f"{vertices} vertices", commit,
                                           lambda: bake_seconds(folder, size),
                                           lambda: bake_seconds(REPO_ROOT, size), digits=1)
    return results


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--commit", default=DEFAULT_COMMIT)
    parser.add_argument("--rounds", type=int, default=2)
    parser.add_argument("sizes", nargs="*", type=int, default=[20000, 100000])
    args = parser.parse_args(argv)
    results = measure(args.commit, args.sizes, args.rounds)
    print()
    print(ratio_table(results, args.commit, "vertices", "bake", digits=1))


if __name__ == "__main__":
    main()
