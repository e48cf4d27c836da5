"""One scene scored against Cycles with direct light only: SG-PRT's render against the mean of two Cycles seeds,
the noise floor rmse(seed 1 - seed 2) / 2, over the rendered surfaces' pixels one pixel in from their
silhouettes (film_transparent).  Shared by the benchmarks that build their own small scenes (node materials,
area lights, flat shading); the truth suite (benchmarks/truth_suite.py) has its own, fuller harness."""
import tempfile
import time

SEEDS = (1, 2)


def empty_node_material(name):
    """(material, node tree, Material Output) of a new material whose node tree holds the output alone."""
    import bpy

    material = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    return material, tree, tree.nodes.new("ShaderNodeOutputMaterial")


def render_engine_image(scene):
    """(seconds of the second render, RGB (H, W, 3) row 0 at the top, alpha, warnings)."""
    from benchmarks import engine_vs_eevee
    from sg_prt_addon.engine import render_engine

    scene.render.engine = "SG_PRT"
    engine_vs_eevee.render_seconds()                # warm-up: compile, prefilter, upload
    seconds = engine_vs_eevee.render_seconds()
    combined = render_engine.last_render["passes"]["Combined"][::-1].astype("float64")
    warnings = list(render_engine.last_render["state"].warnings)
    return seconds, combined[..., :3], combined[..., 3], warnings


def score(scene, samples, scores=True):
    """A row: engine_seconds, cycles_seconds, pixels, warnings, largest (SG-PRT's and the truth's largest
    value) and, with `scores`, relative_rmse, relative_bias and noise_floor."""
    import bpy
    import numpy as np
    from scipy import ndimage

    from benchmarks import error_vs_time, matched_materials
    from validation import image_error

    seconds, image, alpha, warnings = render_engine_image(scene)
    mask = ndimage.binary_erosion(alpha > 0.999, iterations=1)
    seeds = []
    with tempfile.TemporaryDirectory() as folder:
        for seed in SEEDS:
            matched_materials.configure_cycles(scene, samples, seed)
            start = time.perf_counter()
            bpy.ops.render.render()
            seeds.append((time.perf_counter() - start, error_vs_time._read_render_result(scene, folder)))
    truth = 0.5 * (seeds[0][1] + seeds[1][1])
    row = {"cycles_samples": samples, "engine_seconds": seconds, "cycles_seconds": seeds[0][0],
           "pixels": int(mask.sum()), "warnings": warnings,
           "largest": float(np.max(image[mask])), "truth_largest": float(np.max(truth[mask]))}
    if scores:
        row.update(relative_rmse=image_error.relative_rmse(image, truth, mask),
                   relative_bias=image_error.relative_mean_bias(image, truth, mask),
                   noise_floor=image_error.relative_rmse(seeds[0][1], seeds[1][1], mask) / 2)
    return row


def cases_main(argv, description, option, cases, size, samples, score_case, json_path, doc_path, title,
               markdown_section):
    """The command line of a benchmark of named cases scored against Cycles: run the cases `option` lists (all
    of `cases` by default) at --size and --cycles-samples through score_case(name, size, samples), write their
    rows to json_path (some of the cases: merged into its rows when they were run at the same size and samples,
    else not written) and print markdown_section(data); or, with --update-doc, write that section from the JSON
    into doc_path under `title`."""
    import argparse
    import json

    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--size", type=int, default=size)
    parser.add_argument("--cycles-samples", type=int, default=samples)
    parser.add_argument(option, default=",".join(cases))
    parser.add_argument("--update-doc", action="store_true", help="write the section from the JSON (no run)")
    args = parser.parse_args(argv)
    if args.update_doc:
        from benchmarks import markdown_sections
        markdown_sections.update_file(str(doc_path), title, markdown_section(json.loads(json_path.read_text())))
        print(f"updated {doc_path}")
        return
    started = time.perf_counter()
    names = getattr(args, option.lstrip("-").replace("-", "_")).split(",")
    rows = [score_case(name, args.size, args.cycles_samples) for name in names]
    data = {"size": args.size, "cycles_samples": args.cycles_samples, "rows": rows,
            "seconds": time.perf_counter() - started}
    if set(names) != set(cases):
        data = _merged(data, json_path, list(cases))
    if data is not None:
        json_path.write_text(json.dumps(data, indent=1))
        print(markdown_section(data))
    else:
        print(f"{json_path} holds another size or sample count: this run of some cases is not written into it")


def merged_note(data, option):
    """The line a section adds for the cases run later into its JSON (_merged), or ""."""
    merged = data.get("merged_cases")
    if not merged:
        return ""
    return (f"  Run later into the table at the same size and samples: {', '.join(merged)} "
            f"(`{option} {','.join(merged)}`).")


def _case_name(row):
    return row.get("case", row.get("scene"))


def _merged(data, json_path, order):
    """A run of some cases put into json_path's earlier run (rows of the same case replaced, the rest kept, in
    the cases' order; its seconds the earlier run's), or None where that run had another size or sample count."""
    import json

    if not json_path.exists():
        return data
    earlier = json.loads(json_path.read_text())
    if (earlier.get("size"), earlier.get("cycles_samples")) != (data["size"], data["cycles_samples"]):
        return None
    rows = {_case_name(row): row for row in earlier["rows"]}
    rows.update({_case_name(row): row for row in data["rows"]})
    rank = {name: index for index, name in enumerate(order)}
    earlier["rows"] = sorted(rows.values(), key=lambda row: rank.get(_case_name(row), len(rank)))
    earlier["merged_cases"] = sorted(set(earlier.get("merged_cases", [])) | {_case_name(row) for row in data["rows"]})
    return earlier
