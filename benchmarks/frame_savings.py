"""What the per-vertex diffuse visibility, the once-a-frame clamped-cosine terms, the clamped-cosine table,
the shared light visibility and the caches kept across final renders save, on the example scenes, each
against its own baseline in the same run.

Per scene (examples/build_scenes.py at --size, baked by the operator with its defaults):
- per-vertex diffuse visibility: steady frame (median of render_engine.debug["timed_redraws"]) with the
  broad diffuse lobes decoded at the vertices vs per pixel (techniques/sg/sg_lobes.py diffuse_visibility_rows
  forced to 0, the variant's per-pixel path); also the Combined difference between the two, relative
  RMSE over the surface pixels;
- clamped-cosine terms: steady frame with the environment lobes' lambda-only terms read from the scene
  block vs computed per pixel (the surface source patched back to sg_clamped_cosine_integral);
- clamped cosine from the table: steady frame with the lights', slice lobes' and products' integrals read
  from spherical.clamped_cosine_table vs the closed form (the surface source patched back); image change;
- light visibility shared by its products: steady frame with the narrow lights' products taking the
  light's visibility (SHARED_LIGHT_VISIBILITY) vs a decode each NDF lobe; image change;
- caches across renders: bpy.ops.render.render with the shader and environment-texture caches warm vs
  emptied before each render (what every render paid before).
Ratios: new / baseline, median over --rounds rounds, the pair rendered back to back each round.

    .venv/bin/python -m benchmarks.frame_savings [--size 512] [--rounds 3] [--scenes NAME ...]
"""
import argparse
import os
import statistics
import sys

import numpy as np

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

REDRAWS = 5
# the environment lobes' cosine integral as every pixel computed it before the scene block held the terms
TERMS_CALL = """(clamped_cosine_from_terms(dot(safe_normalize(scene.env_axis_sharpness[e].xyz), n),
                                             scene.env_axis_sharpness[e].w, scene.env_cosine_terms[2 * e],
                                             scene.env_cosine_terms[2 * e + 1]) *"""
PER_PIXEL_CALL = ("(sg_clamped_cosine_integral(scene.env_axis_sharpness[e].xyz, scene.env_axis_sharpness[e].w, "
                  "1.0, n) *")
# the lights', slice lobes' and products' cosine integrals: the table, and the closed form they used before
TABLE_CALL = "sg_clamped_cosine_integral_tabulated(clamped_cosine_table, "
CLOSED_FORM_CALL = "sg_clamped_cosine_integral("


def frame(per_vertex=True, terms=True, table=True, shared_light=True):
    """(steady frame seconds, Combined) of one render with the chosen paths."""
    from benchmarks.engine_vs_eevee import steady_frame
    from sg_prt_addon.engine import render_engine, shader_cache
    from sg_prt_addon.techniques import shader_sources
    from sg_prt_addon.techniques.sg import sg_lobes, sg_shading

    rows, read, shares = (sg_lobes.diffuse_visibility_rows, shader_sources.read, sg_shading.shares_light_visibility)
    substitutions = (([] if terms else [(TERMS_CALL, PER_PIXEL_CALL)])
                     + ([] if table else [(TABLE_CALL, CLOSED_FORM_CALL)]))

    def patched_read(path):
        text = read(path)
        if path.endswith("sg_shading.glsl"):
            for old, new in substitutions:
                assert old in text, "sg_shading.glsl no longer has the call this benchmark replaces"
                text = text.replace(old, new)
        return text

    if not per_vertex:
        sg_lobes.diffuse_visibility_rows = lambda environment: 0
    if not shared_light:
        sg_shading.shares_light_visibility = lambda light_data, bounds: False
    shader_sources.read = patched_read
    shader_cache.clear_cache()
    try:
        seconds = steady_frame(REDRAWS)
    finally:
        sg_lobes.diffuse_visibility_rows, shader_sources.read = rows, read
        sg_shading.shares_light_visibility = shares
        shader_cache.clear_cache()
    return seconds, render_engine.last_render["passes"]["Combined"].copy()


def render_seconds(warm):
    """bpy.ops.render.render's wall time, the shader and environment-texture caches kept or emptied."""
    from benchmarks.engine_vs_eevee import render_seconds as timed_render
    from sg_prt_addon.engine import renderer, shader_cache

    if not warm:
        shader_cache.clear_cache()
        renderer._environment_textures.clear()
    return timed_render()


def paired(rounds, new, old):
    """(median new / old, min, max, median new, median old) over rounds, the order alternating."""
    ratios, news, olds = [], [], []
    for index in range(rounds):
        first, second = (new, old) if index % 2 == 0 else (old, new)
        a, b = first(), second()
        n, o = (a, b) if index % 2 == 0 else (b, a)
        news.append(n)
        olds.append(o)
        ratios.append(n / o)
    return statistics.median(ratios), min(ratios), max(ratios), statistics.median(news), statistics.median(olds)


def measure_scene(name, size, rounds):
    from benchmarks.engine_vs_eevee import bake_all
    from examples import build_scenes

    scene = build_scenes.SCENES[name](size)
    scene.sgprt.render_samples = 1      # the frame, one sample (as EEVEE's); Render Samples: edge_samples.py
    bake_all(name)
    render_seconds(True)                       # compiles, prefilters
    rows = {}
    images = {}

    def timed(key, **paths):
        def run():
            seconds, images[key] = frame(**paths)
            return seconds
        return run

    rows["per-vertex diffuse visibility (frame)"] = paired(rounds, timed("new"), timed("per_pixel", per_vertex=False))
    rows["clamped-cosine terms once a frame (frame)"] = paired(rounds, timed("new"), timed("no_terms", terms=False))
    rows["clamped cosine from the table (frame)"] = paired(rounds, timed("new"), timed("closed_form", table=False))
    rows["light visibility shared by its products (frame)"] = paired(rounds, timed("new"),
                                                                    timed("decoded", shared_light=False))
    rows["shader + environment caches kept (render())"] = paired(rounds, lambda: render_seconds(True),
                                                                lambda: render_seconds(False))
    surface = np.abs(images["new"][..., :3]).sum(-1) > 0

    def change(baseline):
        difference = images["new"][..., :3][surface] - images[baseline][..., :3][surface]
        return float(np.sqrt(np.mean(difference ** 2) / np.mean(images[baseline][..., :3][surface] ** 2)))

    changes = {"per-vertex vs per-pixel diffuse visibility": change("per_pixel"),
               "table vs closed-form clamped cosine": change("closed_form"),
               "shared vs decoded light visibility": change("decoded")}
    return rows, changes


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--scenes", nargs="*", default=["suzanne_courtyard", "brushed_metal"])
    args = parser.parse_args(argv)

    import bpy

    from sg_prt_addon import render

    render.ensure_registered()
    print(f"{args.size}x{args.size}, Blender {bpy.app.version_string}, {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}")
    print("| scene | saving | new s | baseline s | ratio (min-max) |\n|---|---|---|---|---|")
    for name in args.scenes:
        rows, changes = measure_scene(name, args.size, args.rounds)
        for label, (ratio, low, high, new, old) in rows.items():
            print(f"| {name} | {label} | {new:.3f} | {old:.3f} | {ratio:.3f} ({low:.3f}-{high:.3f}) |", flush=True)
        for label, change in changes.items():
            print(f"| {name} | {label}: Combined, relative RMSE | {change:.1e} | | |", flush=True)
    print(f"load average {os.getloadavg()[0]:.1f} at the end")


if __name__ == "__main__":
    main()
