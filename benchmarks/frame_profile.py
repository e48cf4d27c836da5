"""Where the steady frame goes: the SG surface shader with one part taken out at a time, against the whole shader.

llvmpipe has no profiler a shader can use, and it runs both sides of every branch, so a part's cost is found by
leaving it out: each of PARTS is a set of edits of the fragment source (the SG techniques' fragment_source,
wrapped for the run) that replaces the part with a constant.  Per scene (the example scenes at --size, baked by
the operator at its defaults, Render Samples 1): the steady frame (draw + read back, the median of --redraws
redraws of one render) of the whole shader and of each part left out, alternated --rounds times in one process.
The ratio is the variant's frame over its base's of the same round (median and range): the whole shader's, or
for the parts measured with Specular Anti-Aliasing's grid off, the frame with the grid off.  A part's share of
its base is 1 - ratio.  A part a scene's variant leaves out already (the light tail without lights, the visible
part without an environment) measures its base again: its ratio is 1 within the noise.  The edits change the
image: they measure costs, they are not settings.

    .venv/bin/python -m benchmarks.frame_profile [--size 512] [--rounds 3] [--scenes NAME ...]
"""
import argparse
import contextlib
import os
import statistics
import sys

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
if REPO_ROOT not in sys.path:
    sys.path.insert(0, REPO_ROOT)

_NO_GRID = ("  if (footprint > 0.0) {", "  if (false) {")
_CENTRE_SHADING = ("  shade_surface(position, normal, tangent, p, q, diffuse_color, specular_color, true, diffuse, "
                   "specular);\n  if (side == 1) {")

GRID_PART = "specular anti-aliasing grid"
# (part, what the variant leaves out, edits (old text, new text) of the fragment source); a part whose edits
# are _NO_GRID and more is measured against GRID_PART's frame (the grid off)
PARTS = (
    (GRID_PART, "shade_footprint's grid: its loop and the side computed",
     (_NO_GRID,)),
    ("the grid's loop body, never entered", "the side forced to 1: the loop is compiled in but no pixel enters it",
     ((_CENTRE_SHADING, "  side = min(side, 1);\n" + _CENTRE_SHADING),)),
    ("SSDF decodes (grid off)", "every per-pixel visibility (lobes, lights, the visible side) taken as 1",
     (_NO_GRID,
      ("#define LOBE_VISIBILITY(axis, sharpness) lobe_visibility(axis, sharpness, n)",
       "#define LOBE_VISIBILITY(axis, sharpness) 1.0"),
      ("#define LIGHT_VISIBILITY(axis, sharpness) light_cap_visibility(axis, light_cap_radius(sharpness))",
       "#define LIGHT_VISIBILITY(axis, sharpness) 1.0"),
      ("#define VISIBLE_PART_LOOKUP\n", "\n"))),
    ("the visible fractions' fh forms (grid off)",
     "product_visible_fraction (eq. 30-31: three erf, an exp, a sine, once a lobe decode): a clamp of its inputs",
     (_NO_GRID, ("float product_visible_fraction(float theta_d, vec3 local, float lam)\n{",
                 "float product_visible_fraction(float theta_d, vec3 local, float lam)\n{\n"
                 "  return clamp(theta_d + local.z * lam, 0.0, 1.0);"))),
    ("the visible part's side and turn (grid off)", "VISIBLE_PART_LOOKUP: the lobe read at its axis",
     (_NO_GRID, ("#define VISIBLE_PART_LOOKUP\n", "\n"))),
    ("half the SSDF rows (grid off)", "the decode's sum over the rows past the eighth",
     (_NO_GRID, ("for (int layer = first; layer < layer_count; ++layer) {",
                 "for (int layer = first; layer < min(layer_count, 8); ++layer) {"))),
    ("environment lookups of the slice lobes (grid off)", "environment_radiance at the slice lobes: 1",
     (_NO_GRID, ("environment_radiance(lookup_axis, lookup_sharpness)", "vec3(1.0)"))),
    ("the light tail (grid off)", "LIGHT_TAIL: the model's BRDF at each light's centre",
     (_NO_GRID, ("#define LIGHT_TAIL\n", "\n"))),
    ("all shading (the frame's floor)", "shade_surface: a constant colour",
     ((_CENTRE_SHADING, "  diffuse = vec3(float(side));\n  specular = vec3(0.0);\n  if (true) {"),)),
)
DEFAULT_SCENES = ("suzanne_courtyard", "brushed_metal")


class MissingEdit(LookupError):
    """An edit's text is not in the variant's fragment source."""


def base_of(edits):
    """The part whose frame a part's ratio is taken against: GRID_PART's for the parts measured with the grid
    off, else None (the whole shader's)."""
    return GRID_PART if edits[0] == _NO_GRID and len(edits) > 1 else None


def edited(source, edits):
    """`source` with each (old, new) of `edits` replaced; MissingEdit if an old text is not there."""
    for old, new in edits:
        if old not in source:
            raise MissingEdit(old.strip().splitlines()[0])
        source = source.replace(old, new)
    return source


@contextlib.contextmanager
def fragment_edits(edits_of_run):
    """Within: the SG techniques' fragment sources go through `edited` with the edits the list `edits_of_run`
    holds at the time (set it between renders, then shader_cache.forget_assembled_sources)."""
    from sg_prt_addon.engine import shader_cache
    from sg_prt_addon.techniques.sg import sg_lobes

    whole = sg_lobes.SGLobes.fragment_source

    def fragment_source(technique, key):
        return edited(whole(technique, key), edits_of_run)

    sg_lobes.SGLobes.fragment_source = fragment_source
    try:
        yield
    finally:
        sg_lobes.SGLobes.fragment_source = whole
        shader_cache.clear_cache()


def measure_scene(name, size, rounds, redraws):
    """({part: (ratio median, low, high)}, the whole shader's frame seconds, the grid-off frame seconds)."""
    from benchmarks import scene_benchmark
    from benchmarks.engine_vs_eevee import bake_all, steady_frame
    from sg_prt_addon.engine import shader_cache

    scene = scene_benchmark.build(name, "examples", size)
    scene.render.engine = "SG_PRT"
    bake_all(name)
    scene.sgprt.render_samples = 1
    current = []

    def frame(edits):
        current[:] = edits
        shader_cache.forget_assembled_sources()
        steady_frame(2)                     # compile, JIT and first draw off the clock
        return steady_frame(redraws)

    variants = [(None, ())] + [(part, edits) for part, _, edits in PARTS]
    frames = {part: [] for part, _ in variants}
    with fragment_edits(current):
        for _ in range(rounds):
            for part, edits in variants:
                frames[part].append(frame(list(edits)))
    ratios = {}
    for part, _, edits in PARTS:
        each = [variant / base for variant, base in zip(frames[part], frames[base_of(edits)])]
        ratios[part] = (statistics.median(each), min(each), max(each))
    return ratios, statistics.median(frames[None]), statistics.median(frames[GRID_PART])


def table(results):
    names = list(results)
    lines = ["| part left out | what the variant does | against | "
             + " | ".join(f"{name}: frame / base (range)" for name in names) + " |",
             "|---|---|---|" + "---|" * len(names),
             "| (the whole shader) | | | " + " | ".join(f"{results[name][1]:.4f} s" for name in names) + " |",
             "| (the grid off) | | | " + " | ".join(f"{results[name][2]:.4f} s" for name in names) + " |"]
    for part, what, edits in PARTS:
        against = "the grid off" if base_of(edits) else "the whole shader"
        cells = [f"{ratio:.2f} ({low:.2f}-{high:.2f})"
                 for ratio, low, high in (results[name][0][part] for name in names)]
        lines.append(f"| {part} | {what} | {against} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--redraws", type=int, default=7)
    parser.add_argument("--scenes", nargs="*", default=list(DEFAULT_SCENES))
    args = parser.parse_args(argv)

    from sg_prt_addon import render
    render.ensure_registered()
    results = {}
    for name in args.scenes:
        results[name] = measure_scene(name, args.size, args.rounds, args.redraws)
        print(f"{name}: {results[name]}", flush=True)
    print()
    print(table(results))


if __name__ == "__main__":
    main()
