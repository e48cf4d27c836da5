"""The cold frame: what one batch job (`blender -b scene.blend -E SG_PRT -f 1`, one process a frame) waits for,
beside a warm render() and beside EEVEE's cold and warm renders, every figure from the same run.

Each example scene is built and baked once, and saved twice: for SG-PRT, and with node materials matched for
EEVEE at 1 sample (benchmarks.matched_materials).  Then every measurement is a new process (this module's
`--child`), which registers the add-on, opens the .blend and renders twice: its first render is the cold one,
its second the warm one.  SG-PRT runs with an empty disk cache (the first job on a machine, or after the
add-on changed: engine/disk_cache.py) and with the cache its earlier jobs left; the process's wall time is
given too (Python, bpy and the add-on's import included).

    .venv/bin/python -m benchmarks.cold_start [--size 512] [--repeats 3] [--scenes NAME ...] [--update-doc]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

SECTION_TITLE = "## The cold frame (a batch job's first render)"
# the goal of issue 20: a cold job's render within this many warm render()s
COLD_GOAL = 2.0


def prepare(name, size, folder):
    """Build and bake scene `name`; save it for SG-PRT and for EEVEE; returns (sgprt .blend, eevee .blend)."""
    import bpy

    from benchmarks import engine_vs_eevee, matched_materials
    from examples import build_scenes
    from sg_prt_addon import render

    render.ensure_registered()
    scene = build_scenes.SCENES[name](size)
    engine_vs_eevee.bake_all(name)
    paths = os.path.join(folder, f"{name}_sgprt.blend"), os.path.join(folder, f"{name}_eevee.blend")
    bpy.ops.wm.save_as_mainfile(filepath=paths[0])
    matched_materials.match_scene(scene)
    matched_materials.configure_eevee(scene, 1)
    bpy.ops.wm.save_as_mainfile(filepath=paths[1])
    return paths


def child(blend):
    """In a new process: register, open, render twice; prints the seconds of each step as JSON."""
    started = time.perf_counter()
    from benchmarks.engine_vs_eevee import render_seconds
    from sg_prt_addon import render

    figures = {}
    for step, run in (("register", render.ensure_registered), ("open", lambda: render.open_blend(blend)),
                      ("first", render_seconds), ("warm", render_seconds)):
        start = time.perf_counter()
        run()
        figures[step] = time.perf_counter() - start
    figures["in_process"] = time.perf_counter() - started
    print("FIGURES " + json.dumps(figures), flush=True)


def run_child(blend, cache):
    """One measuring process; its figures and its wall time ("process")."""
    environment = dict(os.environ, SG_PRT_CACHE_DIR=cache, PYTHONPATH=REPO_ROOT)
    start = time.perf_counter()
    result = subprocess.run([sys.executable, "-m", "benchmarks.cold_start", "--child", blend], cwd=REPO_ROOT,
                            env=environment, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - start
    line = next((line for line in result.stdout.splitlines() if line.startswith("FIGURES ")), None)
    if result.returncode != 0 or line is None:
        raise RuntimeError(f"the measuring process failed ({result.returncode}):\n{result.stderr[-3000:]}")
    return dict(json.loads(line[len("FIGURES "):]), process=wall)


def measure_scene(name, size, repeats, folder):
    sgprt, eevee = prepare(name, size, folder)
    runs = {"empty": [], "cached": [], "eevee": []}
    for repeat in range(repeats):
        cache = tempfile.mkdtemp(prefix="cache-", dir=folder)
        runs["empty"].append(run_child(sgprt, cache))
        runs["cached"].append(run_child(sgprt, cache))
        runs["eevee"].append(run_child(eevee, cache))
    median = {kind: {step: statistics.median(run[step] for run in kind_runs) for step in kind_runs[0]}
              for kind, kind_runs in runs.items()}
    # one warm render() figure a scene: the median over every SG-PRT process's second render
    median["warm"] = statistics.median(run["warm"] for run in runs["empty"] + runs["cached"])
    median["scene"] = name
    median["load"] = os.getloadavg()[0]
    return median


ROWS = (("SG-PRT cold render, empty disk cache (prefilter, fits, tables, compile, upload)", "empty", "first"),
        ("SG-PRT cold render, disk cache filled by earlier jobs", "cached", "first"),
        ("SG-PRT warm render()", None, "warm"),
        ("SG-PRT job, whole process (Python, bpy, add-on, open, 2 renders), cache filled", "cached", "process"),
        ("EEVEE 1 sample cold render (compiles)", "eevee", "first"),
        ("EEVEE 1 sample warm render()", "eevee", "warm"),
        ("EEVEE job, whole process (2 renders)", "eevee", "process"))


def section(results, size, repeats, command):
    import bpy

    from sg_prt_addon.blender import properties

    intro = (f"`{command}` ({size}x{size}, Blender {bpy.app.version_string}, {os.cpu_count()} cores, Mesa "
             f"llvmpipe; {time.strftime('%Y-%m-%d')}). Written by the benchmark (`--update-doc`). Every figure is "
             f"the median of {repeats} new processes, each rendering twice (the first render is the cold one); "
             "ratios are to EEVEE's warm 1-sample render in the same run.  Scenes baked (operator defaults), "
             f"SG-PRT at its default render settings (Render Samples {properties.DEFAULT_RENDER_SAMPLES}, Edges "
             "Only: what a job renders).")
    lines = [SECTION_TITLE, "", textwrap.fill(intro, 110), ""]
    lines += ["| what | " + " | ".join(f"{r['scene']} s | ratio" for r in results) + " |",
              "|---|" + "---|---|" * len(results)]
    for label, kind, step in ROWS:
        cells = []
        for r in results:
            value = r[step] if kind is None else r[kind][step]
            cells.append(f"{value:.3f} | {value / r['eevee']['warm']:.3f}")
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    goal = (f"The goal, a cold job's render within {COLD_GOAL:g}x of a warm render(): " + "; ".join(
        f"{r['scene']} {r['cached']['first'] / r['warm']:.2f}x with the disk cache "
        f"({'met' if r['cached']['first'] <= COLD_GOAL * r['warm'] else 'not met'}), "
        f"{r['empty']['first'] / r['warm']:.2f}x without" for r in results) + ".")
    load = "Load average at the end of each scene: " + ", ".join(f"{r['load']:.1f}" for r in results) + "."
    lines += ["", textwrap.fill(goal, 110), "", load, ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=["suzanne_courtyard", "brushed_metal"])
    parser.add_argument("--update-doc", action="store_true", help="rewrite the section of docs/PERFORMANCE.md")
    parser.add_argument("--child", metavar="BLEND", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        return child(args.child)

    with tempfile.TemporaryDirectory(prefix="sg-prt-cold-") as folder:
        results = [measure_scene(name, args.size, args.repeats, folder) for name in args.scenes]
    command = (".venv/bin/python -m benchmarks.cold_start" + (f" --size {args.size}" if args.size != 512 else "")
               + (" --update-doc" if args.update_doc else ""))
    text = section(results, args.size, args.repeats, command)
    print(text)
    if args.update_doc:
        from benchmarks import markdown_sections
        markdown_sections.update_file(markdown_sections.PERFORMANCE_DOC, SECTION_TITLE, text)
    return results


if __name__ == "__main__":
    main()
