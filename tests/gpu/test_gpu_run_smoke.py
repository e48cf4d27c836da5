"""benchmarks/gpu_run.sh, the run made for a machine with a GPU, as a smoke run here (llvmpipe): in the
tests' own venv (no new one), a small image, one example scene and two scaling scenes, in a process of its
own; its JSON has every field with positive times, and its Markdown table is written."""
import json
import os
import subprocess
import sys
import time

import pytest

pytestmark = pytest.mark.one_tier     # the script, not the Blender it drives: the bpy 5.0 tier runs it

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCENE_FIELDS = {"scene", "kind", "triangles", "objects", "render", "frame", "eevee", "render_ratio", "frame_ratio"}


@pytest.fixture(scope="module")
def smoke_run(tmp_path_factory):
    output = tmp_path_factory.mktemp("gpu_run")
    venv = os.path.dirname(os.path.dirname(sys.executable))     # the tests' own, not a new one
    start = time.perf_counter()
    completed = subprocess.run(["bash", os.path.join(REPO_ROOT, "benchmarks", "gpu_run.sh"), "--smoke",
                                "--output", str(output)], env={**os.environ, "SGPRT_GPU_RUN_VENV": venv},
                               capture_output=True, text=True, timeout=300)
    seconds = time.perf_counter() - start
    assert completed.returncode == 0, completed.stdout[-3000:] + completed.stderr[-3000:]
    return output, completed.stdout, seconds


def test_smoke_run_writes_its_figures(smoke_run):
    output, stdout, seconds = smoke_run
    report = json.loads((output / "gpu_run.json").read_text())
    assert {"blender", "gpu", "resolution", "smoke", "scenes", "slopes", "median_render_ratio"} <= set(report)
    assert report["smoke"] and report["resolution"] == [160, 90]
    assert report["gpu"]["renderer"] and report["gpu"]["vendor"] and report["blender"]
    kinds = [row["kind"] for row in report["scenes"]]
    assert kinds.count("example") == 1 and kinds.count("scaling") == 2
    for row in report["scenes"]:
        assert SCENE_FIELDS <= set(row), row
        assert all(row[key] > 0 for key in ("render", "frame", "eevee", "render_ratio", "triangles")), row
    assert report["scenes"][0]["bake"] > 0
    assert (output / "scenes" / f"{report['scenes'][0]['scene']}.blend").is_file()
    table = (output / "gpu_run.md").read_text()
    assert report["gpu"]["renderer"] in table and table.count("\n| ") == 1 + len(report["scenes"])
    assert "render() / EEVEE" in stdout
    # about 15 s (bpy 5.0) to 40 s (5.3) on this project's machines; the rest is a loaded machine's margin
    assert seconds < 90, f"the smoke run took {seconds:.0f} s"
