"""Truth suite: the SG-PRT engine scored against Cycles (direct light only), EEVEE beside it.

    .venv/bin/python -m benchmarks.truth_suite [--size 256] [--cycles-samples 512] [--scenes a,b,c]
    .venv/bin/python -m benchmarks.truth_suite --quick --scenes diffuse_point,ggx030_point   # smoke run
    .venv/bin/python -m benchmarks.truth_suite --markdown     # the ACCURACY.md section from the JSON
    .venv/bin/python -m benchmarks.truth_suite --update-doc   # ... written into docs/ACCURACY.md
    .venv/bin/python -m benchmarks.truth_suite --scenes a,b --into docs/truth_suite.json   # those scenes rerun

(--markdown and --update-doc read the JSON of an earlier run and render nothing.  Note that
``python -m benchmarks.accuracy`` rewrites docs/ACCURACY.md from its own topics only and drops this
section: run ``--update-doc`` again after it.)

Seventeen scenes (SCENES below: Suzanne subdivided twice on a floor (once a floor of object scale 10), a UV
sphere over a floor, a torus over a floor; Lambert, GGX from roughness 0.05 to 0.6, Beckmann 0.3, anisotropic
Ashikhmin-Shirley and GGX; lit by
courtyard.exr / sunset.exr, a uniform sky (a constant world, Blender's default kind), a small point light, a sun, a large sphere light, a spot light), each
built from Blender's primitives in a fresh empty file and rendered, one after another in one
process, by:

1. SG-PRT unshadowed (no bake), then with visibility baked for every mesh by the Bake Visibility
   operator at its defaults (``bpy.ops.render.render`` wall time after a warm-up render; the bake
   time is reported apart: a precomputation), its render settings at their defaults; "SG-PRT 1
   sample", the same with Render Samples 1: one point a pixel (its centre, its specular over the
   filter's footprint) where Cycles filters the pixel's neighbourhood, which on sub-pixel highlights
   and silhouettes alone makes most of the error; "SG-PRT 2x2", one sample at twice the size, filtered
   down with the scene's pixel filter;
   "SG-PRT 16 samples", Render Samples 16 of every pixel (Edges Only off).  SG-PRT
   reads only ``material.sgprt``; it renders before the node trees are rewritten for Cycles and
   EEVEE (step 2), in every scene; then the same bake rendered by each of the engine's other
   techniques (TECHNIQUE_METHODS: every material switched to it, then back; the SH technique after a
   transfer bake of every mesh);
2. the truth: Cycles on the CPU, direct light only (``max_bounces`` 0, no denoising), Blender's
   pixel filter as it defaults (Blackman-Harris 1.5 px, which SG-PRT reads too), node materials matched to the SG-PRT settings (benchmarks/matched_materials.py),
   ``--cycles-samples`` per pixel, rendered twice with seeds 1 and 2; the truth is the mean of the
   two.  Its noise floor is the relative RMSE between the two seed images divided by 2: the
   difference of two independent images carries sqrt(2) x one image's noise and their mean
   1/sqrt(2) of it, so rmse(seed1 - seed2) / 2 is the RMSE a perfect image would score against the
   truth (the truth's own noise, in the same relative units).  "Cycles unshadowed": the same with every
   mesh seen by camera rays alone (CAST_NOTHING: no shadows, no reflections of one another), the truth
   without visibility; "SG-PRT unshadowed" is also scored against it (shading_relative_rmse: the shading's
   own error, error_budget_table);
3. Cycles at 1 sample per pixel and at "equal time": as many samples as fit in SG-PRT's render()
   time (at least 1; Cycles' fixed cost per render and its cost per sample are measured from the
   1-sample and the truth renders of the same scene), an independent seed (3 and 4);
4. EEVEE at 1, 16 and 64 samples (matched materials, set up for direct light as far as it goes,
   ``matched_materials.configure_eevee``), after a first render that compiles its shaders.

Scores over the surface pixels (camera rays that hit a mesh, as benchmarks/error_vs_time.py finds
them, eroded by one pixel to drop the silhouettes): relative RMSE and relative mean bias
(validation.image_error) and HDR-FLIP (NVIDIA's ``flip_evaluator`` package, the mean of its
per-pixel error map over the same pixels; the test image is laid over the truth's background
first, so a difference in the background does not bleed into the scored pixels through FLIP's
filters; FLIP's exposure range comes from the truth image, the same for every method of a scene).
The errors are raw: the truth's noise floor is reported beside them, not taken out.

Lights: Blender's units as lighting.lights states them (the same for every renderer); point and spot
lights keep Blender's Soft Falloff (on), which SG-PRT models as Cycles does (lighting.lights.light_cap_extent).

Writes docs/truth_suite.json (every row; ``--quick`` runs write out/truth_suite_quick.json unless
``--json`` says otherwise) and, per scene, out/truth/<scene>.png: Cycles truth | SG-PRT | EEVEE 16
samples, side by side, clipped to [0, 1] and gamma 2.2.  Goals (issue): SG-PRT's HDR-FLIP below
EEVEE 16 samples'; relative RMSE below 0.10 for glossy scenes (roughness >= 0.1) and 0.05 for
diffuse ones.

``score_scene(name, size, cycles_samples, methods)`` runs a small version of one scene and returns
its rows (for a gpu-tier test).  The pure parts (rows, noise floor, equal-time samples, goals,
tables, tone mapping) need no bpy and are tested in tests/core/test_truth_suite.py.
"""
import argparse
import contextlib
import datetime
import json
import math
import os
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.error_vs_time import _number, _signed, corrected_error, quadrature_difference  # noqa: E402  (the same cell formats)

JSON_PATH = ROOT / "docs" / "truth_suite.json"
QUICK_JSON_PATH = ROOT / "out" / "truth_suite_quick.json"
# {"description": ..., "rows": [...], "cycles_samples": the truth's, optional}
BEFORE_JSON_PATH = ROOT / "docs" / "truth_suite_before.json"
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
PNG_DIR = ROOT / "out" / "truth"
SECTION_TITLE = "## Truth suite (against Cycles)"

TRUTH_SEEDS = (1, 2)
CYCLES_ONE_SAMPLE_SEED = 3
CYCLES_EQUAL_TIME_SEED = 4
GLOSSY_RMSE_GOAL = 0.10           # relative RMSE, glossy scenes of roughness >= GLOSSY_MIN_ROUGHNESS
DIFFUSE_RMSE_GOAL = 0.05
GLOSSY_MIN_ROUGHNESS = 0.1

FULL = dict(size=256, cycles_samples=512, eevee_samples=(1, 16, 64))
QUICK = dict(size=64, cycles_samples=32, eevee_samples=(1, 16))

METHODS = ("SG-PRT", "SG-PRT 1 sample", "SG-PRT unshadowed", "SG-PRT 2x2", "SG-PRT 16 samples", "Factored BRDF",
           "Spherical harmonics", "Cycles", "Cycles unshadowed", "Cycles 1 sample", "Cycles equal time", "EEVEE")
# Cycles' ray visibility a mesh loses for "Cycles unshadowed" (the truth without visibility): camera rays alone
CAST_NOTHING = ("visible_shadow", "visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter")
# the engine's other techniques: method -> (the technique every material is switched to, the bake it reads
# besides the visibility bake: None, or "transfer" (the transfer bake at the operator's defaults))
TECHNIQUE_METHODS = {"Factored BRDF": ("FACTORED", None), "Spherical harmonics": ("SH", "transfer")}
ANTI_ALIASING_SAMPLES = 16  # "SG-PRT 16 samples": Render Samples (scene.sgprt.render_samples) of every pixel, 4 x 4
SUPERSAMPLING = 2          # "SG-PRT 2x2": the engine at twice the size, filtered down by the scene's pixel filter


# ----------------------------------------------------------------------------- pure logic (tested)

def make_row(scene, method, setting, seconds, relative_rmse=None, relative_bias=None, hdr_flip=None,
             noise_floor=None, **extra):
    """One result row (a JSON-ready dict); extra fields (samples, bake_seconds, ...) are kept as given."""
    def number(value):
        return None if value is None else float(value)

    row = {"scene": scene, "method": method, "setting": setting, "seconds": number(seconds),
           "relative_rmse": number(relative_rmse), "relative_bias": number(relative_bias),
           "hdr_flip": number(hdr_flip), "noise_floor": number(noise_floor)}
    row.update(extra)
    return row


def truth_and_noise_floor(first, second, mask=None):
    """(truth, noise floor) of two Cycles renders of independent seeds: the truth is their mean; the
    noise floor is the relative RMSE between them (over ``mask``, relative to the truth's mean) / 2,
    the RMSE a perfect image scores against the truth: rms(a - b) = sqrt(2) sigma for images of
    noise sigma each, the mean's noise is sigma / sqrt(2) = rms(a - b) / 2."""
    import numpy as np

    first, second = np.asarray(first, np.float64), np.asarray(second, np.float64)
    truth = 0.5 * (first + second)
    difference = (first - second)[..., :3]
    scale = truth[..., :3]
    if mask is not None:
        difference, scale = difference[mask], scale[mask]
    floor = float(np.sqrt(np.mean(difference ** 2)) / max(float(np.mean(scale)), 1e-30) / 2.0)
    return truth, floor


def equal_time_samples(budget_seconds, one_sample_seconds, many_seconds, many_samples):
    """Cycles samples per pixel that fit in ``budget_seconds``, from a render of 1 sample and one of
    ``many_samples`` (a fixed cost per render plus a cost per sample, fitted through the two); at
    least 1."""
    if many_samples > 1 and many_seconds > one_sample_seconds:
        per_sample = (many_seconds - one_sample_seconds) / (many_samples - 1)
    else:
        per_sample = max(many_seconds, 1e-9) / max(many_samples, 1)
    fixed = max(one_sample_seconds - per_sample, 0.0)
    return max(1, int(math.floor((budget_seconds - fixed) / max(per_sample, 1e-12) + 1e-9)))


def rmse_goal(kind, roughness):
    """The issue's relative RMSE goal of a scene: 0.05 diffuse, 0.10 glossy of roughness >= 0.1,
    None (no goal) for sharper glossy scenes."""
    if kind == "diffuse":
        return DIFFUSE_RMSE_GOAL
    if kind == "glossy" and roughness is not None and roughness >= GLOSSY_MIN_ROUGHNESS:
        return GLOSSY_RMSE_GOAL
    return None


def find_row(rows, scene, method, setting=None):
    return next((row for row in rows if row["scene"] == scene and row["method"] == method
                 and (setting is None or row["setting"] == setting)), None)


def eevee_row(rows, scene, samples):
    return next((row for row in rows if row["scene"] == scene and row["method"] == "EEVEE"
                 and row.get("samples") == samples), None)


def goal_check(rows, scene, kind, roughness):
    """The issue's goals for one scene: SG-PRT's HDR-FLIP below EEVEE 16 samples' (flip_met), and
    SG-PRT's relative RMSE below rmse_goal(kind, roughness) (rmse_met).  None where a figure or the
    goal is missing."""
    engine = find_row(rows, scene, "SG-PRT")
    eevee16 = eevee_row(rows, scene, 16)
    check = {"scene": scene, "kind": kind, "roughness": roughness, "rmse_goal": rmse_goal(kind, roughness),
             "flip_met": None, "rmse_met": None}
    if engine is None:
        return check
    check["engine_rmse"], check["engine_flip"] = engine["relative_rmse"], engine["hdr_flip"]
    if eevee16 is not None:
        check["eevee16_flip"] = eevee16["hdr_flip"]
        if engine["hdr_flip"] is not None and eevee16["hdr_flip"] is not None:
            check["flip_met"] = engine["hdr_flip"] < eevee16["hdr_flip"]
    if check["rmse_goal"] is not None and engine["relative_rmse"] is not None:
        check["rmse_met"] = engine["relative_rmse"] < check["rmse_goal"]
    return check


def _met(value):
    return "n/a" if value is None else ("met" if value else "NOT met")


def kind_label(info):
    """A scene's kind for the tables: diffuse, or glossy with its roughness."""
    kind = info.get("kind", "-")
    if kind == "glossy" and info.get("roughness") is not None:
        kind = f"glossy {info['roughness']:g}"
    return kind


def markdown_table(rows, scenes):
    """One line per scene (``scenes``: ordered names) of the figures the summary shows."""
    lines = ["| scene | kind | SG-PRT rel. RMSE | SG-PRT bias | SG-PRT HDR-FLIP | SG-PRT unshadowed RMSE "
             "| EEVEE 16 HDR-FLIP | EEVEE 16 RMSE | Cycles equal-time HDR-FLIP (spp) | noise floor "
             "| SG-PRT s | Cycles s | SG-PRT 1 sample RMSE / HDR-FLIP / s | SG-PRT 2x2 RMSE / HDR-FLIP "
             "| SG-PRT 16 samples RMSE / HDR-FLIP / s |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, info in scenes.items():
        engine = find_row(rows, name, "SG-PRT") or {}
        unshadowed = find_row(rows, name, "SG-PRT unshadowed") or {}
        eevee16 = eevee_row(rows, name, 16) or {}
        equal = find_row(rows, name, "Cycles equal time") or {}
        truth = find_row(rows, name, "Cycles") or {}
        one_sample = find_row(rows, name, "SG-PRT 1 sample") or {}
        supersampled = find_row(rows, name, "SG-PRT 2x2") or {}
        sampled = find_row(rows, name, "SG-PRT 16 samples") or {}
        kind = kind_label(info)
        equal_cell = _number(equal.get("hdr_flip"))
        if equal.get("samples") is not None:
            equal_cell += f" ({equal['samples']})"
        lines.append(
            f"| {name} | {kind} | {_number(engine.get('relative_rmse'))} | {_signed(engine.get('relative_bias'))} | "
            f"{_number(engine.get('hdr_flip'))} | {_number(unshadowed.get('relative_rmse'))} | "
            f"{_number(eevee16.get('hdr_flip'))} | {_number(eevee16.get('relative_rmse'))} | {equal_cell} | "
            f"{_number(truth.get('noise_floor', engine.get('noise_floor')))} | {_number(engine.get('seconds'))} | "
            f"{_number(truth.get('seconds'))} | {_number(one_sample.get('relative_rmse'))} / "
            f"{_number(one_sample.get('hdr_flip'))} / {_number(one_sample.get('seconds'))} | "
            f"{_number(supersampled.get('relative_rmse'))} / "
            f"{_number(supersampled.get('hdr_flip'))} | {_number(sampled.get('relative_rmse'))} / "
            f"{_number(sampled.get('hdr_flip'))} / {_number(sampled.get('seconds'))} |")
    return "\n".join(lines)


def techniques_table(rows, scenes):
    """One line per scene: every technique of the engine (the SG lobes and TECHNIQUE_METHODS), relative RMSE /
    HDR-FLIP / render() seconds, with the same bake."""
    methods = ["SG-PRT"] + list(TECHNIQUE_METHODS)
    lines = ["| scene | kind | " + " | ".join(f"{'SG lobes' if m == 'SG-PRT' else m} RMSE / HDR-FLIP / s"
                                           for m in methods) + " | noise floor |",
             "|---|---|" + "---|" * len(methods) + "---|"]
    for name, info in scenes.items():
        kind = kind_label(info)
        cells = []
        for method in methods:
            row = find_row(rows, name, method) or {}
            cells.append(f"{_number(row.get('relative_rmse'))} / {_number(row.get('hdr_flip'))} / "
                         f"{_number(row.get('seconds'))}")
        truth = find_row(rows, name, "Cycles") or {}
        lines.append(f"| {name} | {kind} | " + " | ".join(cells) + f" | {_number(truth.get('noise_floor'))} |")
    return "\n".join(lines)


def error_budget_table(rows, scenes):
    """One line per scene of what SG-PRT's error is made of: the shading alone (the unshadowed engine against
    Cycles without visibility) and the rest, visibility's share in quadrature (the two are far from
    independent, so it is a guide, not a split)."""
    lines = ["| scene | kind | SG-PRT RMSE / less the truth's noise | shading alone: RMSE / bias | "
             "visibility's share | unshadowed truth's noise floor |", "|---|---|---|---|---|---|"]
    for name, info in scenes.items():
        engine = find_row(rows, name, "SG-PRT") or {}
        unshadowed = find_row(rows, name, "SG-PRT unshadowed") or {}
        truth = find_row(rows, name, "Cycles unshadowed") or {}
        total, shading = engine.get("relative_rmse"), unshadowed.get("shading_relative_rmse")
        share = quadrature_difference(total, shading)
        own = corrected_error(total, engine.get("noise_floor"))
        kind = kind_label(info)
        lines.append(f"| {name} | {kind} | {_number(total)} / {_number(own)} | {_number(shading)} / "
                     f"{_signed(unshadowed.get('shading_relative_bias'))} | {_number(share)} | "
                     f"{_number(truth.get('unshadowed_noise_floor'))} |")
    return "\n".join(lines)


def goal_lines(checks):
    """One line per scene: the two goals, met or not."""
    lines = []
    for check in checks:
        flip = (f"HDR-FLIP {_number(check.get('engine_flip'))} vs EEVEE 16 {_number(check.get('eevee16_flip'))} "
                f"({_met(check['flip_met'])})")
        if check["rmse_goal"] is None:
            rmse = f"RMSE {_number(check.get('engine_rmse'))} (no RMSE goal below roughness {GLOSSY_MIN_ROUGHNESS:g})"
        else:
            rmse = f"RMSE {_number(check.get('engine_rmse'))} < {check['rmse_goal']:.2f} ({_met(check['rmse_met'])})"
        lines.append(f"{check['scene']}: {flip}; {rmse}")
    return lines


def goal_summary(checks):
    """'FLIP below EEVEE 16: a/b scenes; RMSE goal: c/d scenes'."""
    flips = [c["flip_met"] for c in checks if c["flip_met"] is not None]
    rmses = [c["rmse_met"] for c in checks if c["rmse_met"] is not None]
    return (f"SG-PRT HDR-FLIP below EEVEE 16 samples': {sum(flips)}/{len(flips)} scenes; "
            f"relative RMSE goal: {sum(rmses)}/{len(rmses)} scenes")


def before_after_table(before_rows, after_rows, scenes):
    """Markdown table of SG-PRT's scores on the same scenes by two versions of the engine (rows as this
    module makes them; ``before_rows`` may hold only SG-PRT, SG-PRT 2x2 and Cycles rows)."""
    lines = ["| scene | RMSE before | RMSE after | bias before | bias after | HDR-FLIP before | HDR-FLIP after "
             "| 2x2 RMSE before | 2x2 RMSE after |",
             "|---|---|---|---|---|---|---|---|---|"]
    for scene in scenes:
        cells = [scene]
        pairs = [(find_row(before_rows, scene, "SG-PRT"), find_row(after_rows, scene, "SG-PRT"))]
        for key, formatter in (("relative_rmse", _number), ("relative_bias", _signed), ("hdr_flip", _number)):
            cells += [formatter(row and row.get(key)) for row in pairs[0]]
        cells += [_number(row and row.get("relative_rmse")) for row in
                  (find_row(before_rows, scene, "SG-PRT 2x2"), find_row(after_rows, scene, "SG-PRT 2x2"))]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def markdown_section(data, before=None):
    """The "Truth suite (against Cycles)" section of docs/ACCURACY.md, from the JSON this module writes;
    ``before``: (description, rows, its truth's samples or None) of an earlier run on the same scenes, shown
    beside."""
    machine = data["machine"]
    checks = [goal_check(data["rows"], name, info.get("kind"), info.get("roughness"))
              for name, info in data["scenes"].items()]
    eevee = ", ".join(str(s) for s in data["eevee_samples"])
    lines = [
        SECTION_TITLE, "",
        f"`.venv/bin/{data['command']}` ({data['size']}x{data['size']}; Cycles {data['cycles_samples']} spp x 2 "
        f"seeds; {data['runtime_seconds'] / 60:.1f} min in all; {machine['cpu']}, {machine['cores']} cores, "
        f"{machine['gl']}; Blender {data['blender']}; {data['date']})"
        + "".join(f"; {', '.join(run['scenes'])}: `.venv/bin/{run['command']}` ({run['runtime_seconds'] / 60:.1f} "
                  f"min; {run['date']})" for run in data.get("added_runs", ()))
        + ". Generated by `benchmarks/truth_suite.py` "
        "(`--update-doc` writes this section from docs/truth_suite.json).", "",
        "Truth: Cycles on the CPU, direct light only (max bounces 0, no denoising), Blender's pixel filter as it "
        "defaults (Blackman-Harris 1.5 px; SG-PRT and EEVEE read the same Filter Size), node "
        "materials matched to the SG-PRT settings (benchmarks/matched_materials.py, which lists what differs; "
        "the anisotropic ones through the Glossy BSDF's own Anisotropy mapping, not the Principled BSDF's), "
        "point and spot lights with Blender's Soft Falloff as it defaults (on), the mean of two renders of seeds 1 and 2. Noise floor: the relative RMSE between "
        "the two seed "
        "images / 2 (their difference has sqrt(2) x one image's noise, their mean 1/sqrt(2) of it): what a "
        "perfect image would score; errors are raw, not corrected for it. Scores over the surface pixels "
        "(camera rays that hit a mesh) eroded by one pixel: relative RMSE, bias (mean image - mean truth) / "
        "mean truth, mean HDR-FLIP (flip_evaluator; the test image over the truth's background). SG-PRT: "
        "visibility baked by the operator at its defaults, Light Shadows at their default (shadow maps for the "
        "point, spot and sun lights), Render Samples at theirs (16 at the edges, Edges Only), `render()` wall "
        "time after a warm-up render; 1 sample: Render Samples 1 (no anti-aliasing); unshadowed: no bake and no "
        "shadow maps. EEVEE at " + eevee + " samples (direct light as far as its settings go). "
        "Cycles equal time: as many samples as fit in SG-PRT's render() time (spp in brackets). "
        "Cycles s: one seed's render at the truth's samples. SG-PRT 2x2: the same bake, one sample, rendered at "
        "twice the size and filtered down by the scene's pixel filter. SG-PRT 16 samples: Render Samples 16 of "
        "every pixel (a 4 x 4 grid), render() seconds beside.",
        "",
        markdown_table(data["rows"], data["scenes"]), "",
        "The engine's techniques on the same scenes, each with the same bake (SG lobes: wang2009, the SG-PRT "
        "column above; Factored BRDF: mccool2001's p(o) q(h) p(i) r(o.h) of each material's model, 64 x 64 "
        "parabolic maps, its environment term as techniques/homomorphic/factored.py says; Spherical harmonics: kautz2002 "
        "at order 5 with a transfer bake of order 5 at the operator's defaults):", "",
        techniques_table(data["rows"], data["scenes"]), "",
        "What SG-PRT's error is made of: the shading alone is the unshadowed engine (no bake, no shadow maps) "
        "against Cycles with every mesh seen by camera rays alone (no shadow, diffuse, glossy, transmission or "
        "volume rays: the truth without visibility, the same samples and seeds); visibility's share is "
        "sqrt(RMSE^2 - shading^2), the rest; less the truth's noise: sqrt(RMSE^2 - noise floor^2), the engine's "
        "own error as far as the floor is the truth's noise (independent of the engine's, so their squares "
        "add):", "",
        error_budget_table(data["rows"], data["scenes"]), "",
        f"Goals (relative RMSE < {GLOSSY_RMSE_GOAL:.2f} glossy of roughness >= {GLOSSY_MIN_ROUGHNESS:g}, "
        f"< {DIFFUSE_RMSE_GOAL:.2f} diffuse): {goal_summary(checks)}.", ""]
    lines += [f"- {line}" for line in goal_lines(checks)]
    if before is not None:
        description, before_rows, before_samples = before
        same = ("the same scenes, size and truth samples" if before_samples in (None, data.get("cycles_samples"))
                else f"the same scenes and size; the truth at {before_samples} spp a seed then, "
                     f"{data.get('cycles_samples')} now")
        lines += ["", f"SG-PRT before and after ({description}; {same}):", "",
                  before_after_table(before_rows, data["rows"], list(data["scenes"]))]
    return "\n".join(lines) + "\n"


def merged_run(earlier, later):
    """An earlier run's JSON with a later run's scenes put in: their rows, scene entries and goals replace the
    earlier ones of the same names, the rest kept; the later run's command, date and time are listed under
    added_runs (the settings must be the same: a truth of other samples would not compare)."""
    for key in ("size", "cycles_samples", "eevee_samples"):
        if earlier[key] != later[key]:
            raise ValueError(f"the runs differ in {key}: {earlier[key]} and {later[key]}")
    names = set(later["scenes"])
    merged = dict(earlier)
    merged["rows"] = [row for row in earlier["rows"] if row["scene"] not in names] + later["rows"]
    merged["scenes"] = {**{k: v for k, v in earlier["scenes"].items() if k not in names}, **later["scenes"]}
    merged["goals"] = [goal for goal in earlier["goals"] if goal["scene"] not in names] + later["goals"]
    merged["added_runs"] = [run for run in earlier.get("added_runs", []) if not set(run["scenes"]) <= names] + [
        {"command": later["command"], "scenes": sorted(names), "date": later["date"],
         "runtime_seconds": later["runtime_seconds"]}]
    return merged


def replace_section(text, section):
    """``text`` (a markdown file) with this module's section replaced (benchmarks.markdown_sections)."""
    from benchmarks import markdown_sections
    return markdown_sections.replace_section(text, SECTION_TITLE, section)


def tone_map(image):
    """Linear (H, W, 3) radiance -> uint8 sRGB-ish for a PNG: clipped to [0, 1], gamma 2.2."""
    import numpy as np

    clipped = np.clip(np.nan_to_num(np.asarray(image, np.float64)[..., :3], nan=0.0), 0.0, 1.0)
    return np.round(255.0 * clipped ** (1.0 / 2.2)).astype(np.uint8)


def side_by_side(images, gap=2):
    """Tone-mapped images (None: black) left to right, ``gap`` white columns between them."""
    import numpy as np

    shape = next(np.shape(image) for image in images if image is not None)
    height = shape[0]
    panels = []
    for index, image in enumerate(images):
        if index:
            panels.append(np.full((height, gap, 3), 255, np.uint8))
        panels.append(np.zeros((height, shape[1], 3), np.uint8) if image is None else tone_map(image))
    return np.concatenate(panels, axis=1)


def parse_scene_list(text, known):
    """'a,b,c' -> ['a', 'b', 'c'] (all known names for None or ''); ValueError naming unknown ones."""
    if not text:
        return list(known)
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in known]
    if unknown:
        raise ValueError(f"unknown scene(s) {', '.join(unknown)}; known: {', '.join(known)}")
    return names


_FLIP_WARNED = []


def hdr_flip(reference, test, mask=None, background_mask=None):
    """Mean HDR-FLIP of ``test`` against ``reference`` ((H, W, 3) linear float) over ``mask`` (None: all
    pixels); where ``background_mask`` is True the test takes the reference's pixels first.  None (and
    a one-line message, once) when the flip_evaluator package is missing."""
    try:
        import flip_evaluator as flip
    except ImportError:
        if not _FLIP_WARNED:
            print("HDR-FLIP skipped: the flip_evaluator package is missing "
                  "(.venv/bin/pip install flip-evaluator==1.7)", flush=True)
            _FLIP_WARNED.append(True)
        return None
    import numpy as np

    reference = np.ascontiguousarray(np.maximum(np.nan_to_num(np.asarray(reference)[..., :3]), 0.0), np.float32)
    test = np.maximum(np.nan_to_num(np.asarray(test)[..., :3]), 0.0).astype(np.float32)
    if background_mask is not None:
        test = np.where(np.asarray(background_mask)[..., None], reference, test)
    error_map, mean, _ = flip.evaluate(reference, np.ascontiguousarray(test), "HDR", applyMagma=False)
    error_map = np.asarray(error_map, np.float64).reshape(reference.shape[:2])
    if mask is None:
        return float(np.mean(error_map))
    return float(np.mean(error_map[mask]))


# ----------------------------------------------------------------------------- scenes (bpy)

@dataclass(frozen=True)
class Scene:
    """A truth-suite scene: ``build(size)`` makes it in a fresh empty file; kind 'diffuse' or
    'glossy' and the glossy roughness (Blender's, alpha = roughness^2) choose the RMSE goal."""
    build: object
    kind: str
    roughness: object = None
    notes: tuple = ()

    @property
    def description(self):
        return " ".join((self.build.__doc__ or "").split())


@contextlib.contextmanager
def _meshes_cast_nothing(scene):
    """Every mesh of the scene seen by camera rays alone for the block (no shadow, no reflection of one
    another): Cycles' truth without visibility, which the unshadowed engine is scored against."""
    saved = [(obj, [getattr(obj, name) for name in CAST_NOTHING]) for obj in scene.objects if obj.type == "MESH"]
    try:
        for obj, _ in saved:
            for name in CAST_NOTHING:
                setattr(obj, name, False)
        yield
    finally:
        for obj, values in saved:
            for name, value in zip(CAST_NOTHING, values):
                setattr(obj, name, value)


@contextlib.contextmanager
def _engine_settings(settings, **values):
    """scene.sgprt's `values` set for the block, then put back."""
    saved = {name: getattr(settings, name) for name in values}
    try:
        for name, value in values.items():
            setattr(settings, name, value)
        yield
    finally:
        for name, value in saved.items():
            setattr(settings, name, value)


def _start(size):
    import bpy

    from examples import build_scenes
    from sg_prt_addon import render

    scene = build_scenes._empty_file()
    render.ensure_registered()
    scene = bpy.context.scene
    scene.render.engine = build_scenes.ENGINE_ID
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return scene


def _lambert(name="Lambert", kd=0.7):
    from examples import build_scenes
    return build_scenes._material(name, model="GGX", diffuse_color=(kd, kd, kd), specular_color=(0.0, 0.0, 0.0),
                                  roughness=0.5)


def _ggx(name, roughness, kd, ks):
    from examples import build_scenes
    kd = (kd,) * 3 if isinstance(kd, (int, float)) else tuple(kd)
    ks = (ks,) * 3 if isinstance(ks, (int, float)) else tuple(ks)
    return build_scenes._material(name, model="GGX", roughness=roughness, diffuse_color=kd, specular_color=ks)


def _beckmann(name, roughness, kd, ks):
    from examples import build_scenes
    return build_scenes._material(name, model="BECKMANN", roughness=roughness, diffuse_color=(kd,) * 3,
                                  specular_color=(ks,) * 3)


def _floor(size=6.0, object_scale=1.0):
    """The 6 m floor; with object_scale, its mesh that many times smaller and the object scaled back up."""
    from examples import build_scenes
    floor = build_scenes._grid("Floor", size=size / object_scale, subdivisions=64)
    floor.scale = (object_scale,) * 3
    floor.data.materials.append(_lambert("Floor", 0.5))
    return floor


def _suzanne(material):
    import bpy

    from examples import build_scenes
    bpy.ops.mesh.primitive_monkey_add(size=2.0, location=(0.0, 0.0, 1.05))
    suzanne = bpy.context.active_object
    suzanne.name = "Suzanne"
    suzanne.rotation_euler = (math.radians(-20), 0.0, math.radians(20))
    suzanne.modifiers.new("Subdivision", "SUBSURF").levels = 2
    build_scenes._apply_modifiers(suzanne)
    suzanne.data.shade_smooth()
    suzanne.data.materials.append(material)
    return suzanne


def _suzanne_camera(scene):
    from examples import build_scenes
    return build_scenes._add_camera(scene, location=(3.05, -3.85, 2.4), target=(0.0, 0.0, 0.75))


def _sphere(material):
    import bpy
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=1.0, location=(0.0, 0.0, 1.1))
    sphere = bpy.context.active_object
    sphere.name = "Sphere"
    sphere.data.shade_smooth()
    if material is not None:            # None: no material, Blender's default surface
        sphere.data.materials.append(material)
    return sphere


def _sphere_camera(scene):
    from examples import build_scenes
    return build_scenes._add_camera(scene, location=(2.2, -3.9, 2.5), target=(0.0, 0.0, 0.85))


def _torus(material):
    import bpy
    bpy.ops.mesh.primitive_torus_add(major_radius=1.2, minor_radius=0.45, major_segments=96, minor_segments=48,
                                     location=(0.0, 0.0, 1.75), rotation=(math.radians(70), 0.0, 0.0))
    torus = bpy.context.active_object
    torus.name = "Torus"
    torus.data.shade_smooth()
    torus.data.materials.append(material)
    return torus


def _torus_camera(scene):
    from examples import build_scenes
    return build_scenes._add_camera(scene, location=(1.5, -6.2, 2.9), target=(0.0, 0.0, 1.45))


def _hdri(scene, name="courtyard"):
    from examples import build_scenes
    return build_scenes._world_with_hdri(scene, build_scenes.bundled_hdri(name))


def _black_world(scene):
    from examples import build_scenes
    return build_scenes._world_with_colour(scene, (0.0, 0.0, 0.0))


def _white_world(scene):
    from examples import build_scenes
    return build_scenes._world_with_colour(scene, (1.0, 1.0, 1.0))


def _light(scene, kind, location, energy, radius=0.0, target=(0.0, 0.0, 0.8)):
    """A light aimed at ``target``, Blender's other settings at their defaults (Soft Falloff on)."""
    import bpy
    from mathutils import Vector

    light = bpy.data.objects.new(f"{kind.title()} Light", bpy.data.lights.new(f"{kind.title()} Light", kind))
    light.data.energy = energy
    if kind in ("POINT", "SPOT"):
        light.data.shadow_soft_size = radius       # Soft Falloff left at Blender's default (on)
    light.location = location
    light.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    scene.collection.objects.link(light)
    return light


POINT_LIGHT = dict(location=(2.5, -2.0, 4.0), energy=800.0, radius=0.05)


def _suzanne_on_floor(size, material, lighting):
    scene = _start(size)
    lighting(scene)
    _floor()
    _suzanne(material())
    _suzanne_camera(scene)
    return scene


def _point_lit(scene):
    _black_world(scene)
    _light(scene, "POINT", **POINT_LIGHT)


def build_diffuse_hdri(size=256):
    """Suzanne (Lambert kd 0.7) on a Lambert floor under courtyard.exr."""
    return _suzanne_on_floor(size, lambda: _lambert("Suzanne", 0.7), _hdri)


def build_diffuse_sky(size=256):
    """Suzanne (Lambert kd 0.7) on the floor under a uniform white sky (a constant world colour)."""
    return _suzanne_on_floor(size, lambda: _lambert("Suzanne", 0.7), _white_world)


def build_ggx035_metal_hdri(size=256):
    """Suzanne, gold-like GGX roughness 0.35 (kd 0.02, ks (0.9, 0.75, 0.5)), courtyard.exr."""
    return _suzanne_on_floor(size, lambda: _ggx("Gold", 0.35, 0.02, (0.9, 0.75, 0.5)), _hdri)


def build_ggx010_hdri(size=256):
    """Suzanne, GGX roughness 0.10 (kd 0.1, ks 0.8), courtyard.exr."""
    return _suzanne_on_floor(size, lambda: _ggx("Glossy", 0.10, 0.1, 0.8), _hdri)


def build_ggx030_point(size=256):
    """Suzanne, GGX roughness 0.30 (kd 0.05, ks 0.8), a small point light, black world."""
    return _suzanne_on_floor(size, lambda: _ggx("Glossy", 0.30, 0.05, 0.8), _point_lit)


def build_diffuse_point(size=256):
    """Suzanne (Lambert kd 0.7) on the floor, the same small point light, black world."""
    return _suzanne_on_floor(size, lambda: _lambert("Suzanne", 0.7), _point_lit)


def build_diffuse_sun(size=256):
    """Suzanne (Lambert kd 0.7), a sun of strength 3 and angle 0.05 rad, black world."""
    def lighting(scene):
        _black_world(scene)
        sun = _light(scene, "SUN", location=(3.0, -2.0, 5.0), energy=3.0, target=(0.0, 0.0, 0.0))
        sun.data.angle = 0.05
    return _suzanne_on_floor(size, lambda: _lambert("Suzanne", 0.7), lighting)


def build_diffuse_sun_scaled_floor(size=256):
    """diffuse_sun with the floor's mesh ten times smaller and its object scaled by 10 (the same 6 m floor)."""
    scene = _start(size)
    _black_world(scene)
    sun = _light(scene, "SUN", location=(3.0, -2.0, 5.0), energy=3.0, target=(0.0, 0.0, 0.0))
    sun.data.angle = 0.05
    _floor(object_scale=10.0)
    _suzanne(_lambert("Suzanne", 0.7))
    _suzanne_camera(scene)
    return scene


def build_beckmann030_point(size=256):
    """Suzanne, Beckmann roughness 0.30 (the Glossy BSDF's other distribution; kd 0.05, ks 0.8), the small point
    light, black world."""
    return _suzanne_on_floor(size, lambda: _beckmann("Beckmann", 0.30, 0.05, 0.8), _point_lit)


def build_diffuse_sphere_light(size=256):
    """Suzanne (Lambert kd 0.7), a sphere light of radius 0.75 about 3.2 m away, black world."""
    def lighting(scene):
        _black_world(scene)
        _light(scene, "POINT", location=(2.0, -1.5, 3.0), energy=600.0, radius=0.75)
    return _suzanne_on_floor(size, lambda: _lambert("Suzanne", 0.7), lighting)


def build_sphere_floor_ggx_hdri(size=256):
    """A smooth UV sphere (64 x 32), GGX roughness 0.35 (kd 0.05, ks 0.8), over a floor, courtyard.exr."""
    scene = _start(size)
    _hdri(scene)
    _floor()
    _sphere(_ggx("Glossy", 0.35, 0.05, 0.8))
    _sphere_camera(scene)
    return scene


def build_sphere_floor_ggx_point(size=256):
    """The sphere over the floor, GGX roughness 0.30 (kd 0.05, ks 0.8), the small point light."""
    scene = _start(size)
    _point_lit(scene)
    _floor()
    _sphere(_ggx("Glossy", 0.30, 0.05, 0.8))
    _sphere_camera(scene)
    return scene


def build_ggx060_mixed_hdri(size=256):
    """Suzanne, GGX roughness 0.6 (kd 0.5, ks 0.3), sunset.exr (an HDRI with the sun in it)."""
    return _suzanne_on_floor(size, lambda: _ggx("Mixed", 0.6, 0.5, 0.3), lambda scene: _hdri(scene, "sunset"))


def build_ggx005_torus_hdri(size=256):
    """A torus over a floor, GGX roughness 0.05 (kd 0.05, ks 0.9), courtyard.exr."""
    scene = _start(size)
    _hdri(scene)
    _floor(8.0)
    _torus(_ggx("Mirror-like", 0.05, 0.05, 0.9))
    _torus_camera(scene)
    return scene


def build_aniso_torus_hdri(size=256):
    """A torus over a floor, Ashikhmin-Shirley nu 50 nv 800 (6 NDF lobes, tangent the object's z axis),
    ks 0.8, kd 0.1, courtyard.exr."""
    from examples import build_scenes

    scene = _start(size)
    _hdri(scene)
    _floor(8.0)
    _torus(build_scenes._material("Brushed", model="ASHIKHMIN_SHIRLEY", diffuse_color=(0.1, 0.1, 0.1),
                                  specular_color=(0.8, 0.8, 0.8), nu=50.0, nv=800.0, lobe_count=6,
                                  tangent_source="OBJECT_AXIS", tangent_axis=(0.0, 0.0, 1.0)))
    _torus_camera(scene)
    return scene


def build_aniso_ggx_torus_hdri(size=256):
    """A torus over a floor, anisotropic GGX as a Principled BSDF of roughness 0.3 and Anisotropic 0.8 makes
    it (alpha_x 0.170 along the tangent, the object's z axis; alpha_y 0.048), ks 0.8, kd 0.1, courtyard.exr."""
    from examples import build_scenes
    from sg_prt_addon.reflectance import principled

    alpha_x, alpha_y = principled.anisotropic_alphas(0.3, 0.8)
    scene = _start(size)
    _hdri(scene)
    _floor(8.0)
    _torus(build_scenes._material("Brushed GGX", model="GGX_ANISO", diffuse_color=(0.1, 0.1, 0.1),
                                  specular_color=(0.8, 0.8, 0.8), alpha_x=float(alpha_x), alpha_y=float(alpha_y),
                                  tangent_source="OBJECT_AXIS", tangent_axis=(0.0, 0.0, 1.0)))
    _torus_camera(scene)
    return scene


def build_ggx030_spot(size=256):
    """Suzanne, GGX roughness 0.3 (kd 0.3, ks 0.5), a spot light (45 degrees, blend 0.2, radius 0.1)."""
    def lighting(scene):
        _black_world(scene)
        spot = _light(scene, "SPOT", location=(2.0, -2.5, 4.5), energy=1200.0, radius=0.1, target=(0.0, 0.0, 0.6))
        spot.data.spot_size = math.radians(45.0)
        spot.data.spot_blend = 0.2
    return _suzanne_on_floor(size, lambda: _ggx("Glossy", 0.3, 0.3, 0.5), lighting)


def _ashikhmin_shirley_roughness(exponent):
    """Blender roughness (sqrt of alpha) of an (n.h)^exponent lobe (matched_materials.phong_alpha)."""
    return round(math.sqrt(math.sqrt(2.0 / (exponent + 2.0))), 3)


SCENES = {
    "diffuse_hdri": Scene(build_diffuse_hdri, "diffuse"),
    "diffuse_sky": Scene(build_diffuse_sky, "diffuse"),
    "ggx035_metal_hdri": Scene(build_ggx035_metal_hdri, "glossy", 0.35),
    "ggx010_hdri": Scene(build_ggx010_hdri, "glossy", 0.10),
    "ggx030_point": Scene(build_ggx030_point, "glossy", 0.30),
    "diffuse_point": Scene(build_diffuse_point, "diffuse"),
    "diffuse_sun": Scene(build_diffuse_sun, "diffuse"),
    "diffuse_sphere_light": Scene(build_diffuse_sphere_light, "diffuse"),
    "sphere_floor_ggx_hdri": Scene(build_sphere_floor_ggx_hdri, "glossy", 0.35),
    "sphere_floor_ggx_point": Scene(build_sphere_floor_ggx_point, "glossy", 0.30),
    "ggx060_mixed_hdri": Scene(build_ggx060_mixed_hdri, "glossy", 0.6),
    "ggx005_torus_hdri": Scene(build_ggx005_torus_hdri, "glossy", 0.05),
    # the sharper axis (nv 800) as a Blender roughness: 0.22; the wide one (nu 50): 0.44
    "aniso_torus_hdri": Scene(build_aniso_torus_hdri, "glossy", _ashikhmin_shirley_roughness(800.0)),
    "ggx030_spot": Scene(build_ggx030_spot, "glossy", 0.3),
    # the narrow axis (alpha 0.048) as a Blender roughness: 0.22; the Principled node's roughness: 0.3
    "aniso_ggx_torus_hdri": Scene(build_aniso_ggx_torus_hdri, "glossy", 0.22),
    "diffuse_sun_scaled_floor": Scene(build_diffuse_sun_scaled_floor, "diffuse"),
    "beckmann030_point": Scene(build_beckmann030_point, "glossy", 0.3),
}


# ----------------------------------------------------------------------------- measuring (bpy)

class SceneRun:
    """Every method on one scene; rows scored against the Cycles truth of the same run."""

    def __init__(self, name, config, log=print, methods=METHODS):
        self.name, self.config, self.log = name, config, log
        self.spec = SCENES[name]
        self.methods = set(methods) | {"Cycles"}
        self.images = {}          # (method, setting) -> image
        self.unshadowed_truth = None      # Cycles without visibility ("Cycles unshadowed")
        self.pending = []         # rows waiting for the truth: (row, image)
        self.info = {"kind": self.spec.kind, "roughness": self.spec.roughness, "description": self.spec.description,
                     "notes": list(self.spec.notes)}
        self.stage_seconds = {}

    # -- set-up
    def build(self):
        import bpy
        from scipy import ndimage

        from sg_prt_addon.visibility.raytrace import RayTracer
        from validation.reference_scene import reference_inputs

        size = self.config["size"]
        self.spec.build(size)
        scene = self.scene = bpy.context.scene
        scene.render.resolution_x = scene.render.resolution_y = size
        scene.render.resolution_percentage = 100
        depsgraph = bpy.context.evaluated_depsgraph_get()
        reference_scene, camera = reference_inputs(depsgraph, size, size)
        tracer = RayTracer(reference_scene.vertices, reference_scene.triangles)
        try:
            origins, directions = camera.primary_rays()
            hits = tracer.intersect(origins.reshape(-1, 3), directions.reshape(-1, 3))
        finally:
            tracer.close()
        self.surface = hits.hit.reshape(size, size)
        self.mask = ndimage.binary_erosion(self.surface, iterations=1)
        self.info.update(triangles=int(len(reference_scene.triangles)), surface_pixels=int(self.surface.sum()),
                         scored_pixels=int(self.mask.sum()),
                         coverage=float(self.surface.mean()))
        if not self.mask.any():
            raise RuntimeError(f"{self.name}: no surface pixels in view")
        self.info["framing"] = self.framing(camera)
        self.log(f"{self.name}: {size}x{size}, {self.info['triangles']} triangles, "
                 f"{self.info['surface_pixels']} surface pixels ({self.info['scored_pixels']} scored), object "
                 f"{self.info['framing']:.0%} of the frame")

    def framing(self, camera):
        """Largest side of the projected extent of the meshes other than the floor (their vertices), as a
        fraction of the frame's side."""
        import numpy as np

        pixels = []
        for obj in self.scene.objects:
            if obj.type == "MESH" and obj.name != "Floor":
                mesh = obj.data
                points = np.empty(len(mesh.vertices) * 3)
                mesh.vertices.foreach_get("co", points)
                matrix = np.array(obj.matrix_world)
                points = points.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]
                pixels.append(camera.project(points)[0])
        if not pixels:
            return 0.0
        pixels = np.concatenate(pixels)
        extent = pixels.max(axis=0) - pixels.min(axis=0)
        return float(max(extent[0] / camera.width, extent[1] / camera.height))

    # -- rows
    def add(self, method, setting, seconds, image=None, **extra):
        row = make_row(self.name, method, setting, seconds, **extra)
        row["load_average"] = round(os.getloadavg()[0], 2)
        if image is not None:
            self.images[(method, setting)] = image
            self.pending.append((row, image))
        else:
            self.pending.append((row, None))
        self.log(f"  {method:18s} {setting:30s} {_number(seconds):>8s} s")
        return row

    def score_all(self):
        from validation import image_error

        rows = []
        for row, image in self.pending:
            row["noise_floor"] = self.noise_floor
            if image is not None:
                row["relative_rmse"] = image_error.relative_rmse(image, self.truth, self.mask)
                row["relative_bias"] = image_error.relative_mean_bias(image, self.truth, self.mask)
                flip = hdr_flip(self.truth, image, self.mask, background_mask=~self.surface)
                row["hdr_flip"] = None if flip is None else float(flip)
                if row["method"] == "SG-PRT unshadowed" and self.unshadowed_truth is not None:
                    # the shading alone: against the truth without visibility
                    row["shading_relative_rmse"] = image_error.relative_rmse(image, self.unshadowed_truth, self.mask)
                    row["shading_relative_bias"] = image_error.relative_mean_bias(image, self.unshadowed_truth,
                                                                                  self.mask)
                self.log(f"  {row['method']:18s} {row['setting']:30s} rmse {_number(row['relative_rmse'])}  "
                         f"bias {_signed(row['relative_bias'])}  HDR-FLIP {_number(row['hdr_flip'])}")
            rows.append(row)
        return rows

    # -- stages
    def run(self):
        start = time.perf_counter()
        self.build()
        self.stage_seconds["build"] = time.perf_counter() - start
        for stage in (self.engine_stage, self.cycles_stage, self.eevee_stage):
            start = time.perf_counter()
            stage()
            self.stage_seconds[stage.__name__] = time.perf_counter() - start
        self.info["stage_seconds"] = dict(self.stage_seconds)
        rows = self.score_all()
        self.log(f"  noise floor of the truth (rmse(seed 1 - seed 2) / 2): {self.noise_floor:.4f}")
        return rows

    def engine_render(self):
        """(seconds of the timed render after a warm-up, image, warm-up seconds)."""
        import bpy

        from sg_prt_addon.engine import render_engine

        self.scene.render.engine = "SG_PRT"
        render_engine.debug["timed_redraws"] = 0
        timings = []
        for _ in range(2):                      # warm-up (compile, prefilter, upload), then timed
            render_engine.last_render.clear()
            start = time.perf_counter()
            bpy.ops.render.render()
            timings.append(time.perf_counter() - start)
            if "error" in render_engine.last_render:
                raise RuntimeError(f"SG-PRT render failed: {render_engine.last_render['error']}")
        image = render_engine.last_render["passes"]["Combined"][::-1, :, :3].astype("float64")
        return timings[1], image, timings[0]

    def engine_stage(self):
        import bpy

        from sg_prt_addon.blender import visibility_bake

        self.engine_seconds = None
        if "SG-PRT unshadowed" in self.methods:      # no bake, and no shadow maps (they shadow unbaked objects)
            scene = bpy.context.scene
            light_shadows, scene.sgprt.light_shadows = scene.sgprt.light_shadows, "SSDF"
            try:
                seconds, image, warm = self.engine_render()
            finally:
                scene.sgprt.light_shadows = light_shadows
            self.add("SG-PRT unshadowed", "no bake, no shadow maps", seconds, image, warm_up_seconds=warm)
        if not self.methods & {"SG-PRT", "SG-PRT 2x2", "Cycles equal time"}:
            return
        start = time.perf_counter()
        options = {} if self.config.get("error_target") is None else {"error_target": self.config["error_target"]}
        result = bpy.ops.sgprt.bake_visibility("EXEC_DEFAULT", target="ALL", **options)
        bake_seconds = time.perf_counter() - start
        if result != {"FINISHED"}:
            raise RuntimeError(f"the visibility bake did not finish: {result}")
        depsgraph = bpy.context.evaluated_depsgraph_get()
        terms = {}
        for obj in self.scene.objects:
            if obj.type == "MESH":
                bake = visibility_bake.visibility_for_object(obj.evaluated_get(depsgraph))
                if bake is None or not bake.usable:
                    raise RuntimeError(f"{obj.name}: no usable bake after baking ({bake and bake.message})")
                terms[obj.name] = int(bake.terms)
        resolution = self.scene.sgprt_bake.resolution
        self.info.update(bake_seconds=bake_seconds, bake_resolution=resolution, bake_terms=terms,
                         bake_error_target=round(self.scene.sgprt_bake.error_target, 6))
        self.log(f"  bake: {bake_seconds:.1f} s at resolution {resolution}, terms {terms}")
        settings = self.scene.sgprt
        seconds, image, warm = self.engine_render()
        self.engine_seconds = seconds
        sampling = f"Render Samples {settings.render_samples}" + (", Edges Only" if settings.sample_edges_only else "")
        self.add("SG-PRT", f"bake R={resolution}, {sampling}", seconds, image, bake_seconds=bake_seconds,
                 warm_up_seconds=warm, bake_terms=terms)
        if "SG-PRT 1 sample" in self.methods:      # no anti-aliasing: what the samples buy
            with _engine_settings(settings, render_samples=1):
                seconds, image, warm = self.engine_render()
            self.add("SG-PRT 1 sample", f"bake R={resolution}, Render Samples 1", seconds, image,
                     warm_up_seconds=warm)
        if "SG-PRT 2x2" in self.methods:       # the same bake; what the pixel-centre sampling costs
            from sg_prt_addon.engine.pixel_filter import filter_supersampled
            from sg_prt_addon.engine.render_engine import scene_pixel_filter

            size = self.config["size"]
            render = self.scene.render
            render.resolution_x = render.resolution_y = SUPERSAMPLING * size
            try:
                with _engine_settings(settings, render_samples=1):
                    seconds, image, warm = self.engine_render()
            finally:
                render.resolution_x = render.resolution_y = size
            self.add("SG-PRT 2x2", f"bake R={resolution}, {SUPERSAMPLING}x size, filtered down", seconds,
                     filter_supersampled(image, scene_pixel_filter(self.scene), SUPERSAMPLING)[..., :image.shape[-1]],
                     warm_up_seconds=warm)
        if "SG-PRT 16 samples" in self.methods:      # the engine's anti-aliasing at every pixel
            with _engine_settings(settings, render_samples=ANTI_ALIASING_SAMPLES, sample_edges_only=False):
                seconds, image, warm = self.engine_render()
            self.add("SG-PRT 16 samples", f"bake R={resolution}, Render Samples {ANTI_ALIASING_SAMPLES} of every "
                     "pixel", seconds, image, warm_up_seconds=warm)
        for method, (technique, extra_bake) in TECHNIQUE_METHODS.items():
            if method in self.methods:
                setting, extra = f"bake R={resolution}, technique {technique}", {}
                if extra_bake == "transfer":
                    start = time.perf_counter()
                    if bpy.ops.sgprt.bake_transfer("EXEC_DEFAULT", target="ALL") != {"FINISHED"}:
                        raise RuntimeError("the transfer bake did not finish")
                    extra["transfer_bake_seconds"] = time.perf_counter() - start
                    setting += f", transfer order {self.scene.sgprt_transfer.order}"
                seconds, image, warm = self.technique_render(technique)
                self.add(method, setting, seconds, image, warm_up_seconds=warm, **extra)

    def technique_render(self, technique):
        """engine_render() with every material switched to ``technique``, then switched back."""
        import bpy

        materials = [m for m in bpy.data.materials if hasattr(m, "sgprt")]
        before = {material.name: material.sgprt.technique for material in materials}
        try:
            for material in materials:
                material.sgprt.technique = technique
            return self.engine_render()
        finally:
            for material in materials:
                material.sgprt.technique = before[material.name]

    def _cycles(self, samples, seed, folder):
        import bpy

        from benchmarks import error_vs_time, matched_materials

        settings = matched_materials.configure_cycles(self.scene, samples, seed)
        start = time.perf_counter()
        bpy.ops.render.render()
        seconds = time.perf_counter() - start
        self.info.setdefault("cycles_settings", {k: v for k, v in settings.items() if k != "samples"})
        return seconds, error_vs_time._read_render_result(self.scene, folder)

    def cycles_stage(self):
        import bpy

        from benchmarks import matched_materials

        samples = self.config["cycles_samples"]
        self.info["matched_materials"] = matched_materials.match_scene(self.scene)
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            matched_materials.configure_cycles(self.scene, 1, CYCLES_ONE_SAMPLE_SEED)
            bpy.ops.render.render()                       # first render: kernels, scene sync
            self.info["cycles_first_render_seconds"] = time.perf_counter() - start
            one_seconds, one_image = self._cycles(1, CYCLES_ONE_SAMPLE_SEED, folder)
            seeds = [self._cycles(samples, seed, folder) for seed in TRUTH_SEEDS]
            self.truth, self.noise_floor = truth_and_noise_floor(seeds[0][1], seeds[1][1], self.mask)
            self.truth_seconds = seeds[0][0]
            self.info.update(cycles_seed_seconds=[s for s, _ in seeds], cycles_one_sample_seconds=one_seconds,
                             noise_floor=self.noise_floor,
                             cycles_seconds_per_sample=(seeds[0][0] - one_seconds) / max(samples - 1, 1))
            seed_flip = hdr_flip(seeds[0][1], seeds[1][1], self.mask, background_mask=~self.surface)
            from validation import image_error
            self.add("Cycles", f"{samples} spp x 2 seeds (truth)", self.truth_seconds, samples=samples,
                     seeds=list(TRUTH_SEEDS), seed_relative_rmse=image_error.relative_rmse(seeds[0][1], seeds[1][1],
                                                                                           self.mask),
                     seed_hdr_flip=seed_flip)
            self.images[("Cycles", "truth")] = self.truth
            if "Cycles unshadowed" in self.methods:
                with _meshes_cast_nothing(self.scene):
                    seeds = [self._cycles(samples, seed, folder) for seed in TRUTH_SEEDS]
                self.unshadowed_truth, noise = truth_and_noise_floor(seeds[0][1], seeds[1][1], self.mask)
                self.add("Cycles unshadowed", f"{samples} spp x 2 seeds, meshes seen by camera rays alone",
                         seeds[0][0], samples=samples, seeds=list(TRUTH_SEEDS), unshadowed_noise_floor=noise)
            if "Cycles 1 sample" in self.methods:
                self.add("Cycles 1 sample", "1 spp", one_seconds, one_image, samples=1, seed=CYCLES_ONE_SAMPLE_SEED)
            if "Cycles equal time" in self.methods and self.engine_seconds is not None:
                equal = equal_time_samples(self.engine_seconds, one_seconds, seeds[0][0], samples)
                seconds, image = self._cycles(equal, CYCLES_EQUAL_TIME_SEED, folder)
                self.add("Cycles equal time", f"{equal} spp (SG-PRT {self.engine_seconds:.2f} s)", seconds, image,
                         samples=equal, seed=CYCLES_EQUAL_TIME_SEED, budget_seconds=self.engine_seconds)

    def eevee_stage(self):
        import bpy

        from benchmarks import error_vs_time, matched_materials

        if "EEVEE" not in self.methods:
            return
        with tempfile.TemporaryDirectory() as folder:
            for index, samples in enumerate(self.config["eevee_samples"]):
                settings = matched_materials.configure_eevee(self.scene, samples)
                if index == 0:                            # shader compilation: reported apart
                    start = time.perf_counter()
                    bpy.ops.render.render()
                    self.info["eevee_first_render_seconds"] = time.perf_counter() - start
                    self.info["eevee_settings"] = {k: v for k, v in settings.items() if k != "taa_render_samples"}
                start = time.perf_counter()
                bpy.ops.render.render()
                seconds = time.perf_counter() - start
                image = error_vs_time._read_render_result(self.scene, folder)
                self.add("EEVEE", f"{samples} sample{'s' if samples > 1 else ''}", seconds, image, samples=samples)

    def save_png(self, folder):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        engine = next((image for (method, _), image in self.images.items() if method == "SG-PRT"), None)
        eevee = next((image for (method, setting), image in self.images.items()
                      if method == "EEVEE" and setting == "16 samples"), None)
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{self.name}.png"
        plt.imsave(path, side_by_side([self.truth, engine, eevee]))
        return path


def score_scene(name, size, cycles_samples, methods=("SG-PRT", "Cycles"), eevee_samples=(16,), log=None,
                png_dir=None):
    """Run one scene at ``size`` with a ``cycles_samples`` truth and the given methods (METHODS; the
    Cycles truth always runs) and return its rows (scored; also the truth row, which has no error
    of its own but the noise floor)."""
    config = dict(size=int(size), cycles_samples=int(cycles_samples), eevee_samples=tuple(eevee_samples))
    run = SceneRun(name, config, log or (lambda message: None), methods)
    rows = run.run()
    if png_dir is not None:
        run.save_png(png_dir)
    return rows


# ----------------------------------------------------------------------------- output

def print_summary(data):
    print()
    print(markdown_table(data["rows"], data["scenes"]))
    print()
    print(techniques_table(data["rows"], data["scenes"]))
    print()
    print(error_budget_table(data["rows"], data["scenes"]))
    print()
    checks = [goal_check(data["rows"], name, info.get("kind"), info.get("roughness"))
              for name, info in data["scenes"].items()]
    for line in goal_lines(checks):
        print(line)
    print(goal_summary(checks))
    print("noise floor = relative RMSE between the two Cycles seed images / 2 (the mean of two independent "
          "images has 1/sqrt(2) of one image's noise, their difference sqrt(2) x)")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=None, help="image width and height (256; --quick: 64)")
    parser.add_argument("--cycles-samples", type=int, default=None,
                        help="Cycles samples per pixel of each of the truth's two seeds (512; --quick: 32)")
    parser.add_argument("--scenes", default=None, help="comma-separated scene names (default: all): "
                        + ", ".join(SCENES))
    parser.add_argument("--quick", action="store_true",
                        help="size 64, Cycles 32 spp, EEVEE 1 and 16 only (writes under out/)")
    parser.add_argument("--error-target", type=float, default=None,
                        help="the visibility bake's PCA error target, radians (default: the operator's)")
    parser.add_argument("--json", default=None, help=f"output JSON (default {JSON_PATH.relative_to(ROOT)}; "
                        f"--quick: {QUICK_JSON_PATH.relative_to(ROOT)})")
    parser.add_argument("--markdown", action="store_true", help="print the ACCURACY.md section from the JSON")
    parser.add_argument("--update-doc", action="store_true",
                        help="write that section from the JSON into docs/ACCURACY.md (no run)")
    parser.add_argument("--png-dir", default=str(PNG_DIR), help="where the side-by-side PNGs go (out/truth)")
    parser.add_argument("--into", default=None, metavar="JSON",
                        help="put the scenes run into this earlier run's JSON (their rows replaced, the others "
                             "kept; this run's command, date and time listed under added_runs)")
    parser.add_argument("--before", default=None, metavar="JSON",
                        help="with --markdown / --update-doc: rows of an earlier engine on the same scenes "
                             f"(default {BEFORE_JSON_PATH.relative_to(ROOT)} if present), shown beside")
    args = parser.parse_args(argv)
    json_path = Path(args.json) if args.json else (QUICK_JSON_PATH if args.quick else JSON_PATH)
    if args.markdown or args.update_doc:
        data = json.loads(json_path.read_text())
        before_path = Path(args.before) if args.before else BEFORE_JSON_PATH
        before = None
        if before_path.exists():
            recorded = json.loads(before_path.read_text())
            before = (recorded["description"], recorded["rows"], recorded.get("cycles_samples"))
        section = markdown_section(data, before)
        if args.update_doc:
            from benchmarks import markdown_sections
            markdown_sections.update_file(str(DOC_PATH), SECTION_TITLE, section)
            print(f"updated {DOC_PATH}")
        else:
            print(section)
        return data
    try:
        names = parse_scene_list(args.scenes, SCENES)
    except ValueError as error:
        parser.error(str(error))

    config = dict(QUICK if args.quick else FULL)
    if args.size:
        config["size"] = args.size
    if args.cycles_samples:
        config["cycles_samples"] = args.cycles_samples
    config["error_target"] = args.error_target
    started = time.perf_counter()
    load_start = round(os.getloadavg()[0], 2)

    def log(message):
        print(f"[{time.perf_counter() - started:7.1f} s] {message}", flush=True)

    import bpy

    from benchmarks import error_vs_time

    rows, scenes = [], {}
    for name in names:
        run = SceneRun(name, config, log)
        rows += run.run()
        scenes[name] = run.info
        log(f"  wrote {run.save_png(args.png_dir)} (Cycles truth | SG-PRT | EEVEE 16 samples)")
    command = "python -m benchmarks.truth_suite" + "".join(f" {a}" for a in (argv if argv is not None
                                                                                else sys.argv[1:]))
    data = {
        "command": command.strip(), "size": config["size"], "cycles_samples": config["cycles_samples"],
        "truth_seeds": list(TRUTH_SEEDS), "eevee_samples": list(config["eevee_samples"]),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "blender": bpy.app.version_string, "machine": error_vs_time.machine_info(),
        "load_average_start": load_start, "load_average_end": round(os.getloadavg()[0], 2),
        "runtime_seconds": time.perf_counter() - started,
        "noise_floor_definition": "relative RMSE between the two Cycles seed images / 2 (the truth is their mean)",
        "scenes": scenes, "rows": rows,
        "goals": [goal_check(rows, name, scenes[name]["kind"], scenes[name]["roughness"]) for name in names],
    }
    if args.into:
        json_path = Path(args.into)
        data = merged_run(json.loads(json_path.read_text()), data)
    json_path.parent.mkdir(parents=True, exist_ok=True)
    json_path.write_text(json.dumps(data, indent=1, default=str) + "\n")
    print_summary(data)
    print(f"\nwrote {json_path} in {data['runtime_seconds'] / 60:.1f} min")
    return data


if __name__ == "__main__":
    main()
