"""Area and sphere lights rendered by SG-PRT against Cycles.

Each scene is a glossy sphere (a Principled dielectric of roughness 0.3, node tree only) under a black world
and one light: area lights of every shape and of sizes 0.5 to 5 square-on above it, tilted, facing away, with a
narrowed spread, over a floor it shadows (baked), and large sphere lights close to it.  Cycles renders the same file with direct light only, two
seeds: the truth is their mean, the noise floor rmse(seed 1 - seed 2) / 2.  Scores over the surfaces' pixels
(one pixel in from their silhouettes): relative RMSE and mean bias; a scene the light cannot reach scores its
largest pixel instead.  SG-PRT cuts an area light into about ``scene.sgprt.area_light_patches``^2 patches
(lighting.lights.area_light_patches); ``--patches`` sets it.

    .venv/bin/python -m benchmarks.area_lights [--size 128] [--cycles-samples 256] [--patches 4] [--update-doc]
    .venv/bin/python -m benchmarks.area_lights --speed       # render() by patch count, docs/PERFORMANCE.md
"""
import argparse
import json
import math
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
JSON_PATH = ROOT / "docs" / "area_lights.json"
BEFORE_JSON_PATH = ROOT / "docs" / "area_lights_before.json"      # the same run on cf05ec3 (area lights as spheres)
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
SECTION_TITLE = "## Area and sphere lights against Cycles"
SPHERE_CENTRE = (0.0, 0.0, 1.1)


def area(shape, size, size_y=None, location=(0.0, 0.0, 3.6), target=SPHERE_CENTRE, energy=None, spread=None,
         normalize=True):
    """An area light aimed at target; energy defaults to 60 W per square metre of the light's area (so
    every size lights the sphere about equally)."""
    def build(scene):
        from benchmarks import truth_suite
        from sg_prt_addon.lighting import lights

        area_m2 = lights.area_light_area(shape, size, size if size_y is None else size_y)
        light = truth_suite._light(scene, "AREA", location, 60.0 * max(area_m2, 1.0) if energy is None else energy,
                                   target=target).data
        light.shape, light.size, light.size_y = shape, size, size if size_y is None else size_y
        if spread is not None:
            light.spread = spread
        if hasattr(light, "normalize"):
            light.normalize = normalize
    return build


def sphere_light(radius, location, energy):
    def build(scene):
        from benchmarks import truth_suite
        truth_suite._light(scene, "POINT", location=location, energy=energy, radius=radius, target=SPHERE_CENTRE)
    return build


SCENES = {
    "square_0.5": area("SQUARE", 0.5),
    "square_2": area("SQUARE", 2.0),
    "square_5": area("SQUARE", 5.0),
    "rectangle_3x0.5_tilted": area("RECTANGLE", 3.0, 0.5, location=(1.8, -1.2, 3.0)),
    "disk_2": area("DISK", 2.0),
    "ellipse_3x1": area("ELLIPSE", 3.0, 1.0, location=(-1.5, -1.5, 3.0)),
    "square_2_spread_60": area("SQUARE", 2.0, spread=math.radians(60.0)),
    "square_2_unnormalized": area("SQUARE", 2.0, energy=30.0, normalize=False),
    "square_2_facing_away": area("SQUARE", 2.0, target=(0.0, 0.0, 10.0)),
    "square_2_floor_baked": area("SQUARE", 2.0, location=(1.2, -0.8, 3.4)),
    "sphere_light_0.75_near": sphere_light(0.75, (1.6, -1.4, 2.6), 800.0),
    "sphere_light_0.3_near": sphere_light(0.3, (1.4, -1.2, 2.4), 400.0),
    "sphere_light_1.0_touching": sphere_light(1.0, (1.3, -1.3, 2.2), 800.0),
}
DARK_SCENES = ("square_2_facing_away",)
FLOOR_SCENES = ("square_2_floor_baked",)     # a floor the sphere shadows: the visibility bake at its defaults


def build(name, size, patches):
    from benchmarks import engine_vs_eevee, matched_materials, node_materials, truth_suite

    scene = truth_suite._start(size)
    truth_suite._black_world(scene)
    SCENES[name](scene)
    truth_suite._sphere(node_materials._principled("glossy", Base_Color=(0.8, 0.8, 0.8, 1.0), Roughness=0.3)[0])
    truth_suite._sphere_camera(scene)
    scene.render.film_transparent = True
    if name in FLOOR_SCENES:
        floor = truth_suite._floor()
        matched_materials.match_material(floor.data.materials[0])     # Cycles' node tree of its SG-PRT settings
        engine_vs_eevee.bake_all(name)
    if hasattr(scene.sgprt, "area_light_patches"):     # (a before-run on an older commit has none)
        scene.sgprt.area_light_patches = patches
    return scene


def score(name, size, samples, patches, log=print):
    """One scene's row: SG-PRT against the two-seed Cycles truth (benchmarks/cycles_truth.py)."""
    from benchmarks import cycles_truth

    row = {"scene": name, "size": size, "patches": patches,
           **cycles_truth.score(build(name, size, patches), samples, scores=name not in DARK_SCENES)}
    if "relative_rmse" in row:
        log(f"{name:26s} rmse {row['relative_rmse']:.3f}  bias {row['relative_bias']:+.3f}  noise floor "
            f"{row['noise_floor']:.3f}  SG-PRT {row['engine_seconds']:.2f} s  Cycles {row['cycles_seconds']:.1f} s")
    else:
        log(f"{name:26s} largest pixel {row['largest']:.3g} (Cycles {row['truth_largest']:.3g})")
    return row


def _patched(scene, patches, counts, row):
    """A row to show: sphere lights have no patches, so only their first column has one."""
    return None if scene.startswith("sphere_light") and patches != counts[0] else row


def markdown_section(data, before=None):
    """The section: a row a scene, relative RMSE (bias) at each patch count, beside `before` (the same
    benchmark's JSON from the code before area lights had their shape: a sphere of the light's area)."""
    counts = sorted({row["patches"] for row in data["rows"]})
    scenes = list(dict.fromkeys(row["scene"] for row in data["rows"]))
    by_key = {(row["scene"], row["patches"]): row for row in data["rows"]}
    before_rows = {row["scene"]: row for row in (before or {}).get("rows", [])}

    def cell(row):
        if row is None:
            return ""
        if "relative_rmse" in row:
            return f"{row['relative_rmse']:.3f} ({row['relative_bias']:+.3f})"
        return f"largest pixel {row['largest']:.2g} (Cycles {row['truth_largest']:.2g})"

    lines = [SECTION_TITLE, "", "A glossy sphere (Principled, roughness 0.3) under one light and a black world "
             f"(`benchmarks/area_lights.py`), {data['size']} x {data['size']}, Cycles direct light only, "
             f"{data['cycles_samples']} spp x 2 seeds.  Area lights are one-sided emitters of their shape cut into "
             "patches, about n x n (lighting.lights.area_light_patches; the scene's Area Light Patches, 4 by "
             "default); sphere lights are single SGs with the light tail.  Relative RMSE (mean bias) over the "
             "surfaces' pixels (the floor's too where there is one)." + (" *Before*: the code that made an area light a sphere of its area and power "
                                   "(cf05ec3)." if before_rows else ""), "",
             "| scene |" + (" before |" if before_rows else "") + "".join(f" {n} x {n} |" for n in counts)
             + " noise floor |", "|---|" + ("---|" if before_rows else "") + "---|" * (len(counts) + 1)]
    for scene in scenes:
        rows = [by_key.get((scene, n)) for n in counts]
        noise = next((row["noise_floor"] for row in rows if row is not None and "noise_floor" in row), None)
        lines.append(f"| {scene} |" + (f" {cell(before_rows.get(scene))} |" if before_rows else "")
                     + "".join(f" {cell(_patched(scene, n, counts, row))} |" for n, row in zip(counts, rows))
                     + (f" {noise:.3f} |" if noise is not None else " |"))
    lines += ["", f"Rerun: `.venv/bin/python -m benchmarks.area_lights --size {data['size']} "
              f"--cycles-samples {data['cycles_samples']} --patches {','.join(str(n) for n in counts)}` "
              f"({data['seconds']:.0f} s), then `--update-doc`.", ""]
    return "\n".join(lines)


SPEED_TITLE = "## Area lights' frame time"


def frame_times(size=512, repeats=3, log=print):
    """render() seconds (median of `repeats`, after a warm-up) of square_2_floor_baked at `size` with the area
    light cut into 1 to 6 patches a side, and with a point light of the same power in its place, in one run."""
    import bpy

    from benchmarks import engine_vs_eevee

    scene = build("square_2_floor_baked", size, 1)
    light = bpy.data.objects["Area Light"]
    rows = []
    for label, patches in [("point light", None), ("1 x 1", 1), ("2 x 2", 2), ("4 x 4", 4), ("6 x 6", 6)]:
        if patches is None:
            light.data.type = "POINT"
        else:
            light.data.type = "AREA"
            scene.sgprt.area_light_patches = patches
        engine_vs_eevee.render_seconds()
        seconds = sorted(engine_vs_eevee.render_seconds() for _ in range(repeats))[repeats // 2]
        rows.append({"setting": label, "seconds": seconds})
        log(f"{label:12s} {seconds:.3f} s")
    for row in rows:
        row["ratio"] = row["seconds"] / rows[0]["seconds"]
    return {"size": size, "rows": rows}


def speed_section(data):
    lines = [SPEED_TITLE, "", f"`render()` of the baked sphere over a floor (`benchmarks/area_lights.py`, "
             f"square_2_floor_baked) at {data['size']} x {data['size']}, median of 3 after a warm-up, the SG "
             "technique with SSDF shadows; an area light costs a light a patch.  Ratios to the point light "
             "measured in the same run.", "", "| light | render() | ratio |", "|---|---|---|"]
    lines += [f"| {row['setting']} | {row['seconds']:.3f} s | {row['ratio']:.2f} |" for row in data["rows"]]
    lines += ["", "Rerun: `.venv/bin/python -m benchmarks.area_lights --speed`.", ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--cycles-samples", type=int, default=256)
    parser.add_argument("--patches", default="4", help="patches a side, or a comma-separated list of them")
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--update-doc", action="store_true", help="write the section from the JSON (no run)")
    parser.add_argument("--speed", action="store_true", help="time render() by patch count (docs/PERFORMANCE.md)")
    args = parser.parse_args(argv)
    if args.speed:
        from benchmarks import markdown_sections
        section = speed_section(frame_times())
        markdown_sections.update_file(str(ROOT / "docs" / "PERFORMANCE.md"), SPEED_TITLE, section)
        print(section)
        return
    if args.update_doc:
        from benchmarks import markdown_sections
        before = json.loads(BEFORE_JSON_PATH.read_text()) if BEFORE_JSON_PATH.exists() else None
        markdown_sections.update_file(str(DOC_PATH), SECTION_TITLE,
                                      markdown_section(json.loads(JSON_PATH.read_text()), before))
        print(f"updated {DOC_PATH}")
        return
    started = time.perf_counter()
    rows = [score(name, args.size, args.cycles_samples, int(patches))
            for patches in args.patches.split(",") for name in args.scenes.split(",")]
    data = {"size": args.size, "cycles_samples": args.cycles_samples, "rows": rows,
            "seconds": time.perf_counter() - started}
    # only a run of every scene replaces the committed figures
    path = JSON_PATH if args.scenes == ",".join(SCENES) else ROOT / "out" / "area_lights_partial.json"
    path.parent.mkdir(exist_ok=True)
    path.write_text(json.dumps(data, indent=1))
    print(markdown_section(data))


if __name__ == "__main__":
    main()
