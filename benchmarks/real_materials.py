"""Real material files made by others against Cycles (direct light only) and EEVEE: the corpus' glTF 2 files
(scripts/fetch_corpus.sh: the test models of the Open Asset Import Library) through Blender's own importer, the
camera framing their meshes as the real-files tier frames them (validation/real_files.py), under courtyard.exr
and a sun; each baked at Bake Visibility's defaults (the files under 60,000 vertices), then rendered by SG-PRT
(Render Samples 16), Cycles (two seeds) and EEVEE (16 samples).  Relative RMSE, bias and HDR-FLIP against the
mean of the Cycles seeds over the meshes' pixels one pixel in from their silhouettes; the noise floor is
rmse(seed 1 - seed 2) / 2.

--addon-tree DIR renders SG-PRT from another tree's sg_prt_addon (an earlier commit's `git archive`): the
before of the doc's table.

    .venv/bin/python -m benchmarks.real_materials [--size 128] [--cycles-samples 128] [--json FILE]
        [--addon-tree DIR]
    .venv/bin/python -m benchmarks.real_materials --update-doc     # docs/ACCURACY.md from the two JSON files
"""
import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
JSON_PATH = ROOT / "docs" / "real_materials.json"
BEFORE_PATH = ROOT / "docs" / "real_materials_before.json"
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
SECTION_TITLE = "## Real material files against Cycles"
FILES = ("glTF2/BoxTextured-glTF/BoxTextured.gltf", "glTF2/BoxTextured-glTF-pbrSpecularGlossiness/BoxTextured.gltf",
         "glTF2/ClearCoat-glTF/ClearCoatTest.gltf", "glTF2/BoxTexcoords-glTF/boxTexcoords.gltf",
         "glTF2/textureTransform/TextureTransformTest.gltf",
         "glTF2/glTF-Sample-Models/AnimatedMorphCube-glTF/AnimatedMorphCube.gltf",
         "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb", "glTF2/BoxBadNormals-glTF-Binary/BoxBadNormals.glb",
         "glTF2/simple_skin/simple_skin.gltf", "glTF2/cameras/Cameras.gltf")
BAKE_VERTEX_LIMIT = 60000
SUN = dict(rotation=(0.7, 0.2, 0.9), energy=3.0)


def _light(scene):
    import bpy

    from benchmarks import truth_suite

    truth_suite._hdri(scene)
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = SUN["energy"]
    sun.rotation_euler = SUN["rotation"]
    scene.collection.objects.link(sun)


def _rendered(scene, folder):
    import bpy

    from benchmarks import error_vs_time

    bpy.ops.render.render()
    return error_vs_time._read_render_result(scene, folder)


def score_file(models, relative, size, samples, eevee_samples):
    """One file's row: SG-PRT's and EEVEE's scores against the two-seed Cycles truth."""
    import numpy as np
    from scipy import ndimage

    from benchmarks import matched_materials, truth_suite
    from validation import image_error, real_files

    scene = real_files.load(models, relative)
    real_files.prepare(scene)
    scene.render.resolution_x = scene.render.resolution_y = size
    scene.sgprt.render_samples = 16
    scene.render.film_transparent = True
    _light(scene)
    row = {"file": relative}
    if real_files.rendered_vertices(scene) <= BAKE_VERTEX_LIMIT:
        row["bake"] = real_files.bake(scene)[0]
    error, combined, warnings = real_files.render(scene)
    if error is not None:
        return {**row, "error": error}
    engine = combined[::-1].astype(np.float64)
    row["warnings"] = warnings
    with tempfile.TemporaryDirectory() as folder:
        seeds = []
        for seed in (1, 2):
            matched_materials.configure_cycles(scene, samples, seed)
            seeds.append(_rendered(scene, folder))
        matched_materials.configure_eevee(scene, eevee_samples)
        _rendered(scene, folder)                # its shaders compiled first
        eevee = _rendered(scene, folder)
    truth = 0.5 * (seeds[0] + seeds[1])
    mask = ndimage.binary_erosion(engine[..., 3] > 0.999, iterations=1)
    row["pixels"] = int(mask.sum())
    if not row["pixels"]:
        return {**row, "error": "no surface pixels"}
    for name, image in (("sgprt", engine[..., :3]), ("eevee", eevee)):
        row[name] = {"relative_rmse": image_error.relative_rmse(image, truth, mask),
                     "relative_bias": image_error.relative_mean_bias(image, truth, mask),
                     "hdr_flip": truth_suite.hdr_flip(truth, image, mask)}
    row["noise_floor"] = image_error.relative_rmse(seeds[0], seeds[1], mask) / 2
    scene.render.engine = "SG_PRT"
    print(f"{relative:64s} SG-PRT {row['sgprt']['relative_rmse']:.3f}  EEVEE {row['eevee']['relative_rmse']:.3f}  "
          f"noise floor {row['noise_floor']:.3f}", flush=True)
    return row


def _cell(scores):
    if not scores:
        return "|"
    flip = scores.get("hdr_flip")
    return (f"{scores['relative_rmse']:.3f} | {scores['relative_bias']:+.3f} | "
            f"{'' if flip is None else f'{flip:.3f}'}")


def markdown_section(data, before):
    rows_before = {row["file"]: row for row in (before or {}).get("rows", [])}
    lines = [SECTION_TITLE, "", "glTF 2 files of the corpus (`scripts/fetch_corpus.sh`: made by others, the test models "
             "of the Open Asset Import Library), imported by Blender's importer into an empty file, framed by the "
             f"real-files tier's camera, under courtyard.exr and a sun, baked at the defaults; {data['size']} x "
             f"{data['size']}, Cycles direct light {data['cycles_samples']} spp x 2 seeds, SG-PRT at Render Samples "
             f"16, EEVEE at {data['eevee_samples']} samples (`benchmarks/real_materials.py`).  Relative RMSE, bias and "
             "HDR-FLIP against Cycles over the meshes' pixels.  Before: SG-PRT of the tree "
             f"{(before or {}).get('addon_tree_commit', '(none)')}, before the node materials' work.", "",
             "| file | before: RMSE | bias | HDR-FLIP | SG-PRT: RMSE | bias | HDR-FLIP | EEVEE: RMSE | bias | "
             "HDR-FLIP | noise floor |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for row in data["rows"]:
        if "error" in row:
            lines.append(f"| {row['file']} | {row['error']} | | | | | | | | | |")
            continue
        earlier = rows_before.get(row["file"], {}).get("sgprt")
        name = row["file"] if "bake" in row else f"{row['file']} (not baked: over {BAKE_VERTEX_LIMIT} vertices)"
        lines.append(f"| {name} | {_cell(earlier)} | {_cell(row['sgprt'])} | "
                     f"{_cell(row['eevee'])} | {row['noise_floor']:.3f} |")
    lines += ["", "Rerun: `.venv/bin/python -m benchmarks.real_materials` (this tree) and, for the before column, "
              "`git archive` of that commit unpacked into a folder, then `.venv/bin/python -m "
              "benchmarks.real_materials --addon-tree FOLDER --json docs/real_materials_before.json`; then "
              "`--update-doc`."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--cycles-samples", type=int, default=128)
    parser.add_argument("--eevee-samples", type=int, default=16)
    parser.add_argument("--json", type=Path, default=JSON_PATH)
    parser.add_argument("--addon-tree", help="render SG-PRT from this tree's sg_prt_addon")
    parser.add_argument("--commit", default="", help="the commit the addon tree was archived from (for the doc)")
    parser.add_argument("--update-doc", action="store_true")
    args = parser.parse_args(argv)
    if args.update_doc:
        from benchmarks import markdown_sections
        before = json.loads(BEFORE_PATH.read_text()) if BEFORE_PATH.exists() else None
        markdown_sections.update_file(str(DOC_PATH), SECTION_TITLE,
                                      markdown_section(json.loads(JSON_PATH.read_text()), before))
        print(f"updated {DOC_PATH}")
        return
    if args.addon_tree:
        sys.path.insert(0, os.path.abspath(args.addon_tree))
    import sg_prt_addon
    from sg_prt_addon import render
    from validation import real_files

    render.ensure_registered()
    print(f"sg_prt_addon from {os.path.dirname(os.path.dirname(sg_prt_addon.__file__))}", flush=True)
    models = real_files.corpus_models()
    rows = [score_file(models, relative, args.size, args.cycles_samples, args.eevee_samples) for relative in FILES]
    data = {"size": args.size, "cycles_samples": args.cycles_samples, "eevee_samples": args.eevee_samples,
            "addon_tree_commit": args.commit, "rows": rows}
    args.json.write_text(json.dumps(data, indent=1))
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
