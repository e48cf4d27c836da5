"""Flat-shaded and low-poly objects baked and rendered by SG-PRT against Cycles.

Each scene is one object standing on a floor under courtyard.exr, both baked by the visibility bake at its
defaults: an 8-vertex cube (flat faces), the same cube cut into 8 x 8 flat quads a face, a flat-shaded
cylinder, and a smooth sphere (one normal a vertex: rows per vertex, as before).  Where a vertex has corners of
several normals the bake is made per corner, each with its face's hemisphere (visibility.per_vertex.
split_points); before it was made per vertex with the averaged normal.  Cycles renders the same file with
direct light only, two seeds (benchmarks/cycles_truth.py).

    .venv/bin/python -m benchmarks.flat_shading [--size 128] [--cycles-samples 256] [--update-doc]
"""
import argparse
import json
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
JSON_PATH = ROOT / "docs" / "flat_shading.json"
BEFORE_JSON_PATH = ROOT / "docs" / "flat_shading_before.json"    # the same run on cf05ec3 (bakes per vertex)
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
SECTION_TITLE = "## Flat-shaded objects against Cycles"


def _cube(subdivisions=0):
    def build():
        import bpy

        bpy.ops.mesh.primitive_cube_add(size=1.5, location=(0.0, 0.0, 0.75), rotation=(0.0, 0.0, 0.5))
        cube = bpy.context.active_object
        if subdivisions:
            modifier = cube.modifiers.new("Subdivision", "SUBSURF")
            modifier.subdivision_type, modifier.levels = "SIMPLE", subdivisions
            bpy.ops.object.modifier_apply(modifier=modifier.name)
        return cube
    return build


def _cylinder():
    import bpy

    bpy.ops.mesh.primitive_cylinder_add(vertices=12, radius=0.8, depth=1.6, location=(0.0, 0.0, 0.8))
    return bpy.context.active_object


def _smooth_sphere():
    import bpy

    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.8, location=(0.0, 0.0, 0.8))
    sphere = bpy.context.active_object
    sphere.data.shade_smooth()
    return sphere


SCENES = {"cube_8_vertices": _cube(), "cube_8x8_quads": _cube(3), "cylinder_flat": _cylinder,
          "sphere_smooth": _smooth_sphere}


def build(name, size):
    from benchmarks import engine_vs_eevee, matched_materials, truth_suite

    scene = truth_suite._start(size)
    truth_suite._hdri(scene)
    floor = truth_suite._floor()
    obj = SCENES[name]()
    obj.data.materials.append(truth_suite._lambert("Object", 0.7))
    for material in (floor.data.materials[0], obj.data.materials[0]):
        matched_materials.match_material(material)      # Cycles' node tree of its SG-PRT settings
    truth_suite._sphere_camera(scene)
    scene.render.film_transparent = True
    engine_vs_eevee.bake_all(name)
    return scene


def score(name, size, samples, log=print):
    from benchmarks import cycles_truth

    row = {"scene": name, "size": size, **cycles_truth.score(build(name, size), samples)}
    log(f"{name:18s} rmse {row['relative_rmse']:.3f}  bias {row['relative_bias']:+.3f}  noise floor "
        f"{row['noise_floor']:.3f}")
    return row


def markdown_section(data, before=None):
    before_rows = {row["scene"]: row for row in (before or {}).get("rows", [])}

    def cell(row):
        return f"{row['relative_rmse']:.3f} ({row['relative_bias']:+.3f})" if row else ""
    lines = [SECTION_TITLE, "", f"One object on a floor under courtyard.exr, both baked at the visibility bake's "
             f"defaults (`benchmarks/flat_shading.py`), {data['size']} x {data['size']}, Cycles direct light only, "
             f"{data['cycles_samples']} spp x 2 seeds.  Relative RMSE (mean bias) over the surfaces' pixels.  "
             "*Per vertex* is the bake before it was made per corner where a vertex has several normals "
             "(cf05ec3: the averaged normal's hemisphere, the vertex on any surface it touches).", "",
             "| scene | per vertex | now | noise floor |", "|---|---|---|---|"]
    for row in data["rows"]:
        lines.append(f"| {row['scene']} | {cell(before_rows.get(row['scene']))} | {cell(row)} | "
                     f"{row['noise_floor']:.3f} |")
    lines += ["", f"Rerun: `.venv/bin/python -m benchmarks.flat_shading --size {data['size']} --cycles-samples "
              f"{data['cycles_samples']}` ({data['seconds']:.0f} s), then `--update-doc`.", ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--cycles-samples", type=int, default=256)
    parser.add_argument("--scenes", default=",".join(SCENES))
    parser.add_argument("--output", default=str(JSON_PATH))
    parser.add_argument("--update-doc", action="store_true", help="write the section from the JSON (no run)")
    args = parser.parse_args(argv)
    if args.update_doc:
        from benchmarks import markdown_sections
        before = json.loads(BEFORE_JSON_PATH.read_text()) if BEFORE_JSON_PATH.exists() else None
        markdown_sections.update_file(str(DOC_PATH), SECTION_TITLE,
                                      markdown_section(json.loads(JSON_PATH.read_text()), before))
        print(f"updated {DOC_PATH}")
        return
    started = time.perf_counter()
    rows = [score(name, args.size, args.cycles_samples) for name in args.scenes.split(",")]
    data = {"size": args.size, "cycles_samples": args.cycles_samples, "rows": rows,
            "seconds": time.perf_counter() - started}
    Path(args.output).write_text(json.dumps(data, indent=1))
    print(markdown_section(data))


if __name__ == "__main__":
    main()
