"""Error vs time of the SG-PRT engine beside its baselines, on the two example scenes.

    .venv/bin/python -m benchmarks.error_vs_time [--size 512] [--noise 0.015] [--quick]
    .venv/bin/python -m benchmarks.error_vs_time --markdown     # the ERROR_VS_TIME.md section from the JSON
    .venv/bin/python -m benchmarks.error_vs_time --update-doc   # ... written into docs/ERROR_VS_TIME.md

For each scene of examples/build_scenes.py (suzanne_courtyard, brushed_metal), in one process
on one machine:

1. the error reference: the Monte Carlo reference renderer (validation.reference, exact direct light)
   at enough samples per pixel for about ``--noise`` mean relative standard error, capped by a time
   budget (``--reference-seconds``, predicted from the 16-spp curve point); its noise floor
   (validation.image_error.rmse_noise_floor) is recorded and taken out of the errors;
2. SG-PRT (``bpy.ops.render.render`` wall time after a warm-up render of the same setting, and
   the steady-state frame, median of ``render_engine.debug["timed_redraws"]`` redraws) at: no
   bake (unshadowed); visibility bake resolution 8 / 16 / 32 (the bake operator's default error
   target for the PCA terms); fixed PCA terms 4 / 8 / 16 / all 47 at resolution 32; prefilter
   layer size 64 / 256 (128 is the default); NDF lobe count 2 / 4 / 8 of the anisotropic
   material (6 is the scene's); every material's view warp with one or two lobes per NDF lobe
   (material.sgprt.sg.view_warp PAPER and SPLIT2; SPLIT3, three, is the default); every material with the
   factored-BRDF technique (mccool2001), unshadowed and baked; every material with the spherical-harmonics
   technique (kautz2002) at SH orders 3 / 5 / 6, unshadowed and with a transfer bake of order 6 (each lower
   order reads its leading block).  Bake time is reported apart (a precomputation);
3. baselines: the reference renderer at 1 / 4 / 16 samples per pixel (independent seeds), EEVEE
   at 1 / 16 / 64 samples and Cycles (CPU, direct light only) at 1 / 4 / 16 / 64 samples, both
   with node materials matched to ``material.sgprt`` (benchmarks/matched_materials.py says how
   and what differs) and EEVEE set up for direct light as far as it goes.

Errors are relative RMSE over the surface pixels (camera rays that hit a mesh) against the error
reference; the plotted figure subtracts the reference's own noise in quadrature
(``corrected_error``).  Writes docs/error_vs_time.json (every row) and
docs/images/error_vs_time.png (a panel per scene, log time, Pareto front), prints the table and
the issue's targets: SG-PRT shadowed full render() / EEVEE 1-sample render <= 0.1, and SG-PRT's
error below EEVEE 16 samples'.

PCA terms: the sweep truncates one bake of all 47 terms (made by the operator with
term_mode FIXED) and hands the truncations to the engine through
``scene_state.visibility_provider``: PCA keeps the leading eigenvectors in order and each
vertex's weights are projections, so a FIXED bake of N terms stores the same numbers as the
first N of a larger one (and costs the same rays), without N more bakes.
"""
import argparse
import datetime
import json
import math
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

JSON_PATH = ROOT / "docs" / "error_vs_time.json"
PLOT_PATH = ROOT / "docs" / "images" / "error_vs_time.png"
DOC_PATH = ROOT / "docs" / "ERROR_VS_TIME.md"
SECTION_TITLE = "## Error vs time"
SCENES = ("suzanne_courtyard", "brushed_metal", "hammered_metal")

FULL = dict(size=512, noise=0.015, max_reference_spp=256, reference_seconds=240, reference_curve=(1, 4, 16),
            bake_resolutions=(8, 16, 32),
            fixed_terms=(4, 8, 16, 47), layer_sizes=(64, 256), lobe_counts=(2, 4, 8), warp_modes=("PAPER", "SPLIT2"),
            eevee_samples=(1, 16, 64), cycles_samples=(1, 4, 16, 64), redraws=3, sh_orders=(3, 5, 6))
QUICK = dict(size=64, noise=0.06, max_reference_spp=32, reference_seconds=20, reference_curve=(1, 4),
             bake_resolutions=(8,),
             fixed_terms=(4, 47), layer_sizes=(64,), lobe_counts=(2,), warp_modes=("SPLIT2",), eevee_samples=(1, 16),
             cycles_samples=(1, 4), redraws=2, sh_orders=(3,))


# ----------------------------------------------------------------------------- pure logic (tested)

def quadrature_difference(total, part):
    """sqrt(total^2 - part^2), 0 where the part explains it all; None if either is None."""
    if total is None or part is None:
        return None
    return math.sqrt(max(total * total - part * part, 0.0))


def corrected_error(relative_rmse, noise_floor):
    """Relative RMSE with the reference's own noise removed in quadrature: E|x - r|^2 = |x - truth|^2 +
    noise^2 for an image x independent of the reference's noise r; 0 if the noise explains it all."""
    return quadrature_difference(relative_rmse, noise_floor)


def pareto_front(points):
    """Indices of the points (seconds, error) that no other point beats in both (<= in both, < in one),
    ordered by time.  Points with None in either are left out."""
    valid = [(s, e, i) for i, (s, e) in enumerate(points) if s is not None and e is not None]
    valid.sort(key=lambda p: (p[0], p[1]))
    front, best = [], math.inf
    for seconds, error, index in valid:
        if error < best:
            front.append(index)
            best = error
    return front


def make_row(scene, method, setting, seconds, relative_rmse, noise_floor, *, frame_seconds=None,
             bake_seconds=None, relative_bias=None, group=None, parameters=None, load_average=None):
    """One result row (a dict, JSON-ready)."""
    return {
        "scene": scene, "method": method, "group": group or method, "setting": setting,
        "parameters": dict(parameters or {}),
        "seconds": None if seconds is None else float(seconds),
        "frame_seconds": None if frame_seconds is None else float(frame_seconds),
        "bake_seconds": None if bake_seconds is None else float(bake_seconds),
        "relative_rmse": None if relative_rmse is None else float(relative_rmse),
        "corrected_rmse": corrected_error(relative_rmse, noise_floor) if relative_rmse is not None
        else float(noise_floor) if method == "reference" else None,
        "noise_floor": float(noise_floor),
        "relative_bias": None if relative_bias is None else float(relative_bias),
        "load_average": load_average,
    }


def target_check(rows, scene):
    """The issue's targets for one scene from its rows: the SG-PRT default shadowed row (parameters
    'target': True) against EEVEE at 1 and 16 samples; and the issue's "ratio at equal or lower
    error": the fastest shadowed SG-PRT setting (any row but the unshadowed group) with a lower error
    than EEVEE at 16 samples, against EEVEE at 1 sample.  None where a row is missing."""
    def find(predicate):
        return next((row for row in rows if row["scene"] == scene and predicate(row)), None)

    engine = find(lambda row: row["method"] == "SG-PRT" and row["parameters"].get("target"))
    eevee1 = find(lambda row: row["method"] == "EEVEE" and row["parameters"].get("samples") == 1)
    eevee16 = find(lambda row: row["method"] == "EEVEE" and row["parameters"].get("samples") == 16)
    check = {"scene": scene, "engine_setting": engine and engine["setting"]}
    if engine and eevee1:
        check["time_ratio"] = engine["seconds"] / eevee1["seconds"]
        check["time_target_met"] = check["time_ratio"] <= 0.1
    if engine and eevee16:
        check["engine_error"] = engine["corrected_rmse"]
        check["eevee16_error"] = eevee16["corrected_rmse"]
        check["error_target_met"] = engine["corrected_rmse"] < eevee16["corrected_rmse"]
    if eevee1 and eevee16:
        better = [row for row in rows if row["scene"] == scene and row["method"] == "SG-PRT"
                  and row["group"] != "SG-PRT unshadowed" and row["corrected_rmse"] is not None
                  and row["corrected_rmse"] < eevee16["corrected_rmse"]]
        if better:
            fastest = min(better, key=lambda row: row["seconds"])
            check["matched_setting"] = fastest["setting"]
            check["matched_error"] = fastest["corrected_rmse"]
            check["matched_time_ratio"] = fastest["seconds"] / eevee1["seconds"]
    return check


def _number(value, digits=3):
    if value is None:
        return "-"
    if abs(value) >= 100:
        return f"{value:.0f}"
    if abs(value) >= 10:
        return f"{value:.1f}"
    return f"{value:.{digits}f}"


def _signed(value):
    return "-" if value is None else f"{value:+.3f}"


def markdown_table(rows):
    """Markdown table of the rows (Pareto-front rows of each scene in bold)."""
    lines = ["| scene | method | setting | seconds | frame s | bake s | rel. RMSE | corrected | noise floor | bias "
             "| load |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    front = set()
    for scene in dict.fromkeys(row["scene"] for row in rows):
        indexed = [(i, row) for i, row in enumerate(rows) if row["scene"] == scene]
        chosen = pareto_front([(row["seconds"], row["corrected_rmse"]) for _, row in indexed])
        front.update(indexed[k][0] for k in chosen)
    for index, row in enumerate(rows):
        setting = f"**{row['setting']}**" if index in front else row["setting"]
        load = row.get("load_average")
        lines.append(f"| {row['scene']} | {row['method']} | {setting} | {_number(row['seconds'])} | "
                     f"{_number(row['frame_seconds'])} | {_number(row['bake_seconds'], 1)} | "
                     f"{_number(row['relative_rmse'])} | {_number(row['corrected_rmse'])} | "
                     f"{_number(row['noise_floor'])} | {_signed(row.get('relative_bias'))} | {_number(load, 1)} |")
    return "\n".join(lines)


def target_lines(checks):
    lines = []
    for check in checks:
        parts = [f"{check['scene']} ({check.get('engine_setting')}):"]
        if "time_ratio" in check:
            parts.append(f"SG-PRT render() / EEVEE 1 sample = {check['time_ratio']:.3f} (target <= 0.1: "
                         f"{'met' if check['time_target_met'] else 'NOT met'});")
        if "engine_error" in check:
            parts.append(f"error {check['engine_error']:.3f} vs EEVEE 16 samples {check['eevee16_error']:.3f} "
                         f"(target lower: {'met' if check['error_target_met'] else 'NOT met'})")
        if "matched_setting" in check:
            parts[-1] += ";"
            parts.append(f"fastest shadowed setting below EEVEE 16's error: {check['matched_setting']}, error "
                         f"{check['matched_error']:.3f}, render() / EEVEE 1 sample = {check['matched_time_ratio']:.3f} "
                         f"({'met' if check['matched_time_ratio'] <= 0.1 else 'NOT met'})")
        lines.append(" ".join(parts))
    return lines


def markdown_section(data, image="images/error_vs_time.png"):
    """The "Error vs time" section of docs/ERROR_VS_TIME.md, from the JSON this module writes."""
    machine = data["machine"]
    per_scene = "; ".join(f"{name}: {info['triangles']} triangles, reference {info['reference_spp']} spp "
                          f"({info['reference_noise']:.1%} mean relative noise, noise floor "
                          f"{info['noise_floor']:.3f}, {info['reference_seconds']:.0f} s)"
                          for name, info in data["scenes"].items())
    lines = [SECTION_TITLE, "",
             f"`.venv/bin/{data['command']}` ({data['size']}x{data['size']}; "
             f"{data['runtime_seconds'] / 60:.1f} min in all; "
             f"{machine['cpu']}, {machine['cores']} cores, {machine['gl']}; Blender {data['blender']}; "
             f"{data['date']}; load average {data['load_average_start']:.1f} at the start, "
             f"{data['load_average_end']:.1f} at the end). Generated by `benchmarks/error_vs_time.py` "
             f"(`--update-doc` writes this section from docs/error_vs_time.json).", "",
             f"Scenes: {per_scene}. Error: relative RMSE over surface pixels against the reference; "
             "'corrected' takes the reference's noise floor out in quadrature (plotted). Seconds: the "
             "full `bpy.ops.render.render` wall time (SG-PRT after a warm-up render of the same "
             "setting; EEVEE and Cycles after a first render that compiles); frame s: SG-PRT's "
             "steady-state redraw; bake s: the visibility bake through the operator, apart. "
             "Bias: (mean image - mean reference) / mean reference over the same pixels. "
             "Bold: the scene's Pareto front. " + _frame_note(data) + "EEVEE and Cycles use node materials matched in "
             "benchmarks/matched_materials.py (EEVEE supports neither the Beckmann nor the "
             "Ashikhmin-Shirley distribution and shades them as GGX; Cycles' anisotropic lobe does not "
             "match ours on the torus, see that module); EEVEE: "
             + ", ".join(f"{k} {v}" for k, v in data["eevee_settings"].items()) + ".",
             "", f"![error vs time]({image})", "", markdown_table(data["rows"]), "",
             "Targets (SG-PRT bake resolution 32, default terms, 128 px prefilter layers; its render() at the "
             "default Render Samples, 16 at the edges (Edges Only), against EEVEE's 1 sample, which has no "
             "anti-aliasing: the section Edges Only gives their cost over one sample):", ""]
    lines += [f"- {line}" for line in target_lines(data["targets"])]
    return "\n".join(lines) + "\n"


def _frame_note(data):
    """Runs made before validation/reference_scene.py gave the reference the engine's anisotropy frame
    (commit 189bc1f) set that frame from the benchmark side and say so in their JSON."""
    fixed = sorted({name for info in data["scenes"].values()
                    for name in info.get("reference_object_axis_tangents", ())})
    if not fixed:
        return ""
    return (f"This run gave the reference the engine's object-axis anisotropy frame for {', '.join(fixed)} "
            "from the benchmark side (the same tangents validation/reference_scene.py computes since commit "
            "189bc1f; before it the reference took UV tangents). ")


def replace_section(text, section):
    """``text`` (a markdown file) with this module's section replaced (benchmarks.markdown_sections)."""
    from benchmarks import markdown_sections
    return markdown_sections.replace_section(text, SECTION_TITLE, section)


def merge_runs(runs):
    """Merge independent Monte Carlo runs [(samples per pixel n, mean image, standard error)] into one
    (mean, standard error), exactly as one run of sum(n) samples would give (pooled sums of squared
    deviations, Chan et al.; each run needs n >= 2)."""
    import numpy as np

    count, mean, squares = None, None, None
    for n, image, error in runs:
        n = float(n)
        run_squares = np.where(np.isfinite(error), np.asarray(error, np.float64) ** 2 * n * (n - 1), 0.0)
        if count is None:
            count, mean, squares = n, np.asarray(image, np.float64), run_squares
            continue
        delta = np.asarray(image, np.float64) - mean
        squares = squares + run_squares + delta ** 2 * (count * n / (count + n))
        mean = mean + delta * (n / (count + n))
        count += n
    return mean, np.sqrt(squares / (count - 1) / count)


# ----------------------------------------------------------------------------- measuring (bpy)

def _load():
    return round(os.getloadavg()[0], 2)


def machine_info():
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as handle:
            cpu = next(line.split(":", 1)[1].strip() for line in handle if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "machine": platform.machine(), "system": platform.system(),
            "python": platform.python_version(), "gl": "Mesa llvmpipe (no GPU)"}


def _read_render_result(scene, folder):
    """(H, W, 3) float pixels of the last render, row 0 at the top (written as a float EXR)."""
    import bpy
    import numpy as np

    from sg_prt_addon import render

    settings = scene.render.image_settings
    settings.file_format, settings.color_depth = "OPEN_EXR", "32"
    path = os.path.join(folder, "render.exr")
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    return render.read_float_image(path).astype(np.float64)


class SceneRun:
    """Everything measured on one example scene."""

    def __init__(self, name, config, log):
        self.name, self.config, self.log = name, config, log
        self.rows = []
        self.info = {}

    # -- scoring
    def score(self, image, against=None):
        """(relative RMSE, relative bias) of an image over the surface pixels; against: (reference, noise
        floor) in place of the error reference."""
        from validation import image_error
        reference = self.reference if against is None else against[0]
        return (image_error.relative_rmse(image, reference, self.mask),
                image_error.relative_mean_bias(image, reference, self.mask))

    def add(self, method, setting, seconds, image=None, against=None, **fields):
        rmse, bias = self.score(image, against) if image is not None else (None, None)
        floor = self.noise_floor if against is None else against[1]
        row = make_row(self.name, method, setting, seconds, rmse, floor, relative_bias=bias,
                       load_average=_load(), **fields)
        if image is not None:       # per material (index into info["material_names"]): where the error is
            from validation import image_error
            reference = self.reference if against is None else against[0]
            row["material_rmse"] = {
                str(index): image_error.relative_rmse(image, reference, self.mask & (self.material_map == index))
                for index in self.material_indices}
        self.rows.append(row)
        self.log(f"  {method:10s} {setting:34s} {_number(seconds):>8s} s  frame {_number(row['frame_seconds']):>6s}"
                 f"  bake {_number(row['bake_seconds'], 1):>5s}  rmse {_number(rmse)}  corrected "
                 f"{_number(row['corrected_rmse'])}  load {row['load_average']}")
        return row

    # -- stages
    def run(self):
        import bpy
        import numpy as np

        from examples import build_scenes
        from sg_prt_addon import render
        from sg_prt_addon.visibility.raytrace import RayTracer
        from validation.reference_scene import reference_inputs

        render.ensure_registered()
        size = self.config["size"]
        build_scenes.SCENES[self.name](size)
        scene = self.scene = bpy.context.scene
        scene.render.resolution_x = scene.render.resolution_y = size
        scene.render.resolution_percentage = 100
        depsgraph = bpy.context.evaluated_depsgraph_get()
        self.reference_scene, self.camera = reference_inputs(depsgraph, size, size)
        self.tracer = RayTracer(self.reference_scene.vertices, self.reference_scene.triangles)
        origins, directions = self.camera.primary_rays()
        hits = self.tracer.intersect(origins.reshape(-1, 3), directions.reshape(-1, 3))
        self.mask = hits.hit.reshape(size, size)
        self.material_map = self.reference_scene.material_index[np.maximum(hits.triangle, 0)].reshape(size, size)
        self.material_indices = [int(k) for k in np.unique(self.material_map[self.mask])]
        self.info.update(triangles=int(len(self.reference_scene.triangles)),
                         surface_pixels=int(self.mask.sum()))
        self.log(f"{self.name}: {size}x{size}, {self.info['triangles']} triangles, "
                 f"{self.info['surface_pixels']} surface pixels")
        self.reference_stage()
        self.engine_stage()
        self.blender_stage()
        self.tracer.close()
        return self.rows

    def reference_stage(self):
        """The error reference is the merge of independent runs: the curve's runs of 4 and more samples
        per pixel and a last run sized by the noise target and the time budget.  Each such curve point
        is scored against the merge of the other runs (independent of it), with that merge's noise
        floor; the 1-sample point (no standard error of its own) against the whole reference."""
        import numpy as np

        from validation import image_error
        from validation.reference import mean_relative_error, render_reference

        runs = []                                 # (spp, seconds, image, standard error)
        for spp in self.config["reference_curve"]:
            start = time.perf_counter()
            image, error = render_reference(self.reference_scene, self.camera, spp, seed=1000 + spp,
                                            tracer=self.tracer)
            runs.append((spp, time.perf_counter() - start, image, error))
        merged = [run for run in runs if run[0] >= 2]
        pilot_spp, pilot_seconds, pilot_image, pilot_error = runs[-1]
        pilot_noise = mean_relative_error(pilot_image, pilot_error)
        have = sum(run[0] for run in merged)
        spent = sum(run[1] for run in merged)
        wanted = math.ceil(pilot_spp * (pilot_noise / self.config["noise"]) ** 2)
        affordable = have + math.floor(pilot_spp * (self.config["reference_seconds"] - spent)
                                       / max(pilot_seconds, 1e-3))
        total = int(np.clip(min(wanted, affordable), have + 2, self.config["max_reference_spp"]))
        self.log(f"  reference: {pilot_spp} spp gave {pilot_noise:.3f} noise in {pilot_seconds:.1f} s -> {total} spp "
                 f"in all ({wanted} for {self.config['noise']:.3f}, {affordable} in "
                 f"{self.config['reference_seconds']} s)")
        start = time.perf_counter()
        image, error = render_reference(self.reference_scene, self.camera, total - have, seed=1, tracer=self.tracer)
        merged.append((total - have, time.perf_counter() - start, image, error))
        self.reference, self.reference_error = merge_runs([(n, i, e) for n, _, i, e in merged])
        seconds = sum(run[1] for run in merged)
        self.noise_floor = image_error.rmse_noise_floor(self.reference_error, self.reference, self.mask)
        noise = mean_relative_error(self.reference, self.reference_error)
        self.info.update(reference_spp=total, reference_seconds=seconds, reference_noise=noise,
                         noise_floor=self.noise_floor,
                         reference_runs=[{"samples": n, "seconds": t} for n, t, _, _ in merged])
        self.add("reference", f"{total} spp (error reference)", seconds, group="reference",
                 parameters={"samples": total, "error_reference": True, "mean_relative_noise": noise})
        for spp, seconds_k, image, _ in runs:
            against = None
            if spp >= 2:
                others = [(n, i, e) for n, _, i, e in merged if not (n == spp and i is image)]
                other_image, other_error = merge_runs(others)
                against = (other_image, image_error.rmse_noise_floor(other_error, other_image, self.mask))
            self.add("reference", f"{spp} spp", seconds_k, image, against=against, parameters={"samples": spp})

    # -- SG-PRT
    def engine_render(self, setting, group, parameters=None, bake_seconds=None):
        import bpy

        from sg_prt_addon.engine import render_engine

        scene = self.scene
        scene.render.engine = "SG_PRT"
        render_engine.debug["timed_redraws"] = self.config["redraws"]
        bpy.ops.render.render()                            # warm-up: compile, prefilter, upload; redraws
        result = render_engine.last_render
        if "error" in result:
            raise RuntimeError(f"SG-PRT render failed ({setting}): {result['error']}")
        frame = statistics.median(result["timings"]["frames"]) if result["timings"].get("frames") else None
        render_engine.debug["timed_redraws"] = 0
        start = time.perf_counter()
        bpy.ops.render.render()
        seconds = time.perf_counter() - start
        result = render_engine.last_render
        if "error" in result:
            raise RuntimeError(f"SG-PRT render failed ({setting}): {result['error']}")
        image = result["passes"]["Combined"][::-1, :, :3].astype("float64")
        state = result["state"]
        self.info.setdefault("material_names", list(state.materials))   # the reference's material order
        parameters = dict(parameters or {})
        parameters["visibility"] = {key: status for key, status in state.visibility_status.items()}
        parameters["visibility_terms"] = {key: data.terms for key, data in state.visibility.items()}
        return self.add("SG-PRT", setting, seconds, image, frame_seconds=frame, bake_seconds=bake_seconds,
                        group=group, parameters=parameters)

    def bake(self, resolution, **options):
        """Bake every mesh with the operator; (seconds, {object name: StoredBake}) (arrays read back)."""
        import bpy

        from sg_prt_addon.blender import visibility_bake

        start = time.perf_counter()
        result = bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL", resolution=resolution, **options)
        seconds = time.perf_counter() - start
        if result != {"FINISHED"}:
            raise RuntimeError(f"the visibility bake did not finish: {result}")
        depsgraph = bpy.context.evaluated_depsgraph_get()
        stored = {}
        for obj in self.scene.objects:
            if obj.type == "MESH":
                bake = visibility_bake.visibility_for_object(obj.evaluated_get(depsgraph))
                if bake is None or not bake.usable:
                    raise RuntimeError(f"{obj.name}: no usable bake after baking ({bake and bake.message})")
                stored[obj.name] = bake
        return seconds, stored

    @staticmethod
    def use_bakes(bakes):
        """Hand the engine these bakes ({object name: bake}; None: no visibility at all)."""
        from sg_prt_addon.engine import scene_state

        scene_state.visibility_provider = (lambda object_eval: None) if bakes is None else \
            (lambda object_eval: bakes.get(object_eval.name))

    @staticmethod
    def truncated(bakes, terms):
        """The first ``terms`` PCA terms of stored bakes (what a FIXED bake of that many terms stores)."""
        from types import SimpleNamespace

        return {name: SimpleNamespace(coefficients=bake.coefficients[:, :terms].copy(), basis=bake.basis[:terms],
                                      mean=bake.mean, terms=terms, resolution=bake.resolution)
                for name, bake in bakes.items()}

    def engine_stage(self):
        from sg_prt_addon.engine import render_engine, scene_state
        from sg_prt_addon.spherical import warp

        config = self.config
        try:
            self.use_bakes(None)
            self.engine_render("no bake (unshadowed)", "SG-PRT unshadowed", {"bake": None})
            default_bakes = None
            for resolution in config["bake_resolutions"]:
                scene_state.visibility_provider = None
                seconds, bakes = self.bake(resolution)
                self.use_bakes(bakes)
                terms = sorted({bake.terms for bake in bakes.values()})
                is_default = resolution == max(config["bake_resolutions"])
                if is_default:
                    default_bakes = bakes
                self.engine_render(f"bake R={resolution}, {'/'.join(map(str, terms))} terms", "SG-PRT bake R",
                                   {"bake_resolution": resolution, "terms": terms, "target": is_default},
                                   bake_seconds=seconds)
            resolution = max(config["bake_resolutions"])
            seconds, all_terms = self.bake(resolution, term_mode="FIXED", terms=max(config["fixed_terms"]))
            for terms in config["fixed_terms"]:
                bakes = all_terms if terms == max(config["fixed_terms"]) else self.truncated(all_terms, terms)
                self.use_bakes(bakes)
                self.engine_render(f"R={resolution}, {terms} terms (fixed)", "SG-PRT terms",
                                   {"bake_resolution": resolution, "terms": terms},
                                   bake_seconds=seconds if terms == max(config["fixed_terms"]) else None)
            self.use_bakes(default_bakes)
            if self.reference_scene.environment is not None:
                for layer_size in config["layer_sizes"]:
                    render_engine.debug["environment_layer_size"] = layer_size
                    try:
                        self.engine_render(f"R={resolution}, prefilter layers {layer_size}", "SG-PRT layers",
                                           {"bake_resolution": resolution, "environment_layer_size": layer_size})
                    finally:
                        render_engine.debug["environment_layer_size"] = None
            anisotropic = [material for material in self._materials()
                           if material.sgprt.model in ("ASHIKHMIN_SHIRLEY", "WARD_ANISO")]
            for material in anisotropic:
                default = material.sgprt.lobe_count
                try:
                    for lobes in config["lobe_counts"]:
                        material.sgprt.lobe_count = lobes
                        self.engine_render(f"R={resolution}, {lobes} NDF lobes ({default} default)", "SG-PRT lobes",
                                           {"bake_resolution": resolution, "lobe_count": lobes,
                                            "material": material.name})
                finally:
                    material.sgprt.lobe_count = default
            materials = self._materials()
            defaults = {material.name: material.sgprt.sg.view_warp for material in materials}
            try:
                for mode in config["warp_modes"]:
                    for material in materials:
                        material.sgprt.sg.view_warp = mode
                    self.engine_render(f"R={resolution}, view warp {mode.lower()} ({warp.DEFAULT_MODE} default)",
                                       "SG-PRT warp", {"bake_resolution": resolution, "warp_mode": mode})
            finally:
                for material in materials:
                    material.sgprt.sg.view_warp = defaults[material.name]
            self.factored_stage(materials, default_bakes, resolution)
            self.harmonics_stage(materials)
        finally:
            scene_state.visibility_provider = None
            render_engine.debug["timed_redraws"] = 0

    def factored_stage(self, materials, bakes, resolution):
        """Every material with the factored-BRDF technique (mccool2001): unshadowed and with the bakes (the
        warm-up render factorizes each model; the timed one reuses the factors)."""
        defaults = {material.name: material.sgprt.technique for material in materials}
        try:
            for material in materials:
                material.sgprt.technique = "FACTORED"
            self.use_bakes(None)
            self.engine_render("factored BRDF (mccool2001), unshadowed", "Factored BRDF",
                               {"technique": "FACTORED", "bake": None})
            self.use_bakes(bakes)
            self.engine_render(f"factored BRDF, bake R={resolution}", "Factored BRDF",
                               {"technique": "FACTORED", "bake_resolution": resolution})
        finally:
            for material in materials:
                material.sgprt.technique = defaults[material.name]

    def harmonics_stage(self, materials):
        """Every material with the SH technique (kautz2002) at each of config["sh_orders"]: unshadowed, then
        with a transfer bake (the operator's defaults, of the highest order), removed afterwards."""
        import bpy

        from sg_prt_addon.blender import transfer_bake

        orders = self.config["sh_orders"]
        defaults = {material.name: (material.sgprt.technique, material.sgprt.sh.order) for material in materials}
        try:
            for material in materials:
                material.sgprt.technique = "SH"
            self.use_bakes(None)
            for order in orders:
                for material in materials:
                    material.sgprt.sh.order = order
                self.engine_render(f"SH order {order} (kautz2002), unshadowed", "Spherical harmonics",
                                   {"technique": "SH", "sh_order": order, "transfer": None})
            start = time.perf_counter()
            result = bpy.ops.sgprt.bake_transfer("EXEC_DEFAULT", target="ALL", order=max(orders))
            seconds = time.perf_counter() - start
            if result != {"FINISHED"}:
                raise RuntimeError(f"the transfer bake did not finish: {result}")
            for order in orders:
                for material in materials:
                    material.sgprt.sh.order = order
                self.engine_render(f"SH order {order}, transfer order {max(orders)}", "SH + transfer",
                                   {"technique": "SH", "sh_order": order, "transfer": max(orders)},
                                   bake_seconds=seconds if order == max(orders) else None)
        finally:
            for material in materials:
                material.sgprt.technique, material.sgprt.sh.order = defaults[material.name]
            for obj in self.scene.objects:
                if obj.type == "MESH":
                    transfer_bake.clear_transfer_bake(obj.data)

    def _materials(self):
        found = {}
        for obj in self.scene.objects:
            if obj.type == "MESH":
                for slot in obj.material_slots:
                    if slot.material is not None:
                        found[slot.material.name] = slot.material
        return list(found.values())

    # -- EEVEE and Cycles
    def blender_stage(self):
        import bpy

        from benchmarks import matched_materials

        scene = self.scene
        self.info["matched_materials"] = matched_materials.match_scene(scene)
        with tempfile.TemporaryDirectory() as folder:
            for engine, samples_list, configure in (
                    ("EEVEE", self.config["eevee_samples"], matched_materials.configure_eevee),
                    ("Cycles", self.config["cycles_samples"], matched_materials.configure_cycles)):
                for index, samples in enumerate(samples_list):
                    settings = configure(scene, samples)
                    if index == 0:       # shader compile / kernel load and scene sync: reported apart
                        start = time.perf_counter()
                        bpy.ops.render.render()
                        self.info[f"{engine.lower()}_first_render_seconds"] = time.perf_counter() - start
                        self.info[f"{engine.lower()}_settings"] = {k: v for k, v in settings.items()
                                                                   if k != "taa_render_samples" and k != "samples"}
                    start = time.perf_counter()
                    bpy.ops.render.render()
                    seconds = time.perf_counter() - start
                    image = _read_render_result(scene, folder)
                    self.add(engine, f"{samples} sample{'s' if samples > 1 else ''}", seconds, image,
                             parameters={"samples": samples})


# ----------------------------------------------------------------------------- output

def plot(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    styles = {"SG-PRT unshadowed": ("#9467bd", "v"), "SG-PRT bake R": ("#d62728", "o"),
              "SG-PRT terms": ("#ff7f0e", "s"), "SG-PRT layers": ("#e377c2", "D"), "SG-PRT lobes": ("#8c564b", "^"),
              "SG-PRT warp": ("#7f7f7f", "<"), "Factored BRDF": ("#bcbd22", ">"),
              "Spherical harmonics": ("#aec7e8", "p"), "SH + transfer": ("#393b79", "*"),
              "reference": ("#2ca02c", "P"), "EEVEE": ("#1f77b4", "X"), "Cycles": ("#17becf", "h")}
    scenes = list(data["scenes"])
    figure, axes = plt.subplots(1, len(scenes), figsize=(6.0 * len(scenes), 4.6), squeeze=False)
    for axis, scene in zip(axes[0], scenes):
        rows = [row for row in data["rows"] if row["scene"] == scene and row["corrected_rmse"] is not None]
        for group, (colour, marker) in styles.items():
            chosen = [row for row in rows if row["group"] == group]
            if not chosen:
                continue
            axis.scatter([row["seconds"] for row in chosen], [row["corrected_rmse"] for row in chosen], c=colour,
                         marker=marker, s=42, label=group, zorder=3)
            frames = [row for row in chosen if row["frame_seconds"]]
            if frames:
                axis.scatter([row["frame_seconds"] for row in frames], [row["corrected_rmse"] for row in frames],
                             facecolors="none", edgecolors=colour, marker=marker, s=30, zorder=2, linewidths=0.8)
        for row in rows:
            if row["method"] != "SG-PRT":
                axis.annotate(row["setting"].replace(" (error reference)", " ref"), (row["seconds"],
                              row["corrected_rmse"]), fontsize=6.5, xytext=(4, 3), textcoords="offset points")
        front = [rows[i] for i in pareto_front([(row["seconds"], row["corrected_rmse"]) for row in rows])]
        axis.step([row["seconds"] for row in front], [row["corrected_rmse"] for row in front], where="post",
                  color="black", linewidth=1.0, linestyle="--", label="Pareto front", zorder=1)
        axis.axhline(data["scenes"][scene]["noise_floor"], color="grey", linewidth=0.8, linestyle=":",
                     label="reference noise floor")
        axis.set_xscale("log")
        axis.set_yscale("log")
        axis.set_xlabel("seconds (full render; hollow: SG-PRT steady frame)")
        axis.set_ylabel("relative RMSE vs reference (noise-corrected)")
        axis.set_title(f"{scene}, {data['size']}x{data['size']}")
        axis.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="best")
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=80)
    plt.close(figure)


def print_summary(data):
    print()
    print(markdown_table(data["rows"]))
    print()
    for line in target_lines(data["targets"]):
        print(line)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=None, help="image width and height (512; --quick: 64)")
    parser.add_argument("--noise", type=float, default=None, help="reference's target mean relative noise")
    parser.add_argument("--reference-seconds", type=float, default=None,
                        help="time budget of each error reference (caps its samples; 240 s)")
    parser.add_argument("--quick", action="store_true", help="a tiny smoke run (writes under out/)")
    parser.add_argument("--scenes", nargs="*", default=list(SCENES), choices=SCENES)
    parser.add_argument("--json", default=None, help=f"output JSON (default {JSON_PATH.relative_to(ROOT)})")
    parser.add_argument("--plot", default=None, help=f"output PNG (default {PLOT_PATH.relative_to(ROOT)})")
    parser.add_argument("--markdown", action="store_true", help="print the ERROR_VS_TIME.md section from the JSON")
    parser.add_argument("--update-doc", action="store_true", help="write that section into docs/ERROR_VS_TIME.md")
    args = parser.parse_args(argv)
    json_path = Path(args.json) if args.json else (ROOT / "out" / "error_vs_time_quick.json" if args.quick
                                                   else JSON_PATH)
    plot_path = Path(args.plot) if args.plot else (ROOT / "out" / "error_vs_time_quick.png" if args.quick
                                                   else PLOT_PATH)
    if args.markdown or args.update_doc:
        data = json.loads(json_path.read_text())
        section = markdown_section(data, os.path.relpath(plot_path, DOC_PATH.parent))
        if args.update_doc:
            from benchmarks import markdown_sections
            markdown_sections.update_file(str(DOC_PATH), SECTION_TITLE, section)
            print(f"updated {DOC_PATH}")
        else:
            print(section)
        return data

    config = dict(QUICK if args.quick else FULL)
    if args.size:
        config["size"] = args.size
    if args.noise:
        config["noise"] = args.noise
    if args.reference_seconds:
        config["reference_seconds"] = args.reference_seconds
    started = time.perf_counter()
    load_start = _load()

    def log(message):
        print(f"[{time.perf_counter() - started:7.1f} s] {message}", flush=True)

    import bpy
    rows, scenes = [], {}
    for name in args.scenes:
        run = SceneRun(name, config, log)
        rows += run.run()
        scenes[name] = run.info
    command = "python -m benchmarks.error_vs_time" + ("".join(f" {a}" for a in (argv if argv is not None
                                                                                    else sys.argv[1:])))
    data = {
        "command": command.strip(), "size": config["size"], "config": {k: list(v) if isinstance(v, tuple) else v
                                                                     for k, v in config.items()},
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "blender": bpy.app.version_string, "machine": machine_info(),
        "load_average_start": load_start, "load_average_end": _load(),
        "runtime_seconds": time.perf_counter() - started,
        "eevee_settings": next((info.get("eevee_settings") for info in scenes.values()), {}),
        "scenes": scenes, "rows": rows,
        "targets": [target_check(rows, name) for name in args.scenes],
    }
    for row in rows:      # every row carries the run's context too
        row.update(size=config["size"], blender=data["blender"], date=data["date"], machine=data["machine"]["cpu"])
    json_path.parent.mkdir(parents=True, exist_ok=True)
    json_path.write_text(json.dumps(data, indent=1, default=str) + "\n")
    plot(data, plot_path)
    print_summary(data)
    print(f"\nwrote {json_path} and {plot_path} in {data['runtime_seconds'] / 60:.1f} min")
    return data


if __name__ == "__main__":
    main()
