"""What widens a sun's shadow edge: the floor's tessellation (per-vertex interpolation), the SSDF bake
resolution, or the PCA terms.

    .venv/bin/python -m benchmarks.shadow_edge [--update-doc]

A diffuse sphere over a floor under a sun of angle 0.05 rad (black world, 96 x 96), baked with
visibility.pipeline at each setting (tests/gpu/engine_fixtures.bake_objects: every mesh occludes), rendered
by the engine and by the Monte Carlo reference at pixel centres (32 samples; the engine samples pixel
centres too, so no anti-aliasing enters).  Scores over the floor pixels, and over the band of floor
pixels within 3 pixels of the reference's lit/shadowed boundary; "penumbra pixels": pixels of that band
between 10% and 90% of the lit level, in the engine's image and in the reference (the edge's width).
``--update-doc`` writes the table into docs/ACCURACY.md under "## Shadow edge (sun)".
"""
import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for path in (ROOT, ROOT / "tests" / "gpu"):
    if str(path) not in sys.path:
        sys.path.insert(0, str(path))

SECTION_TITLE = "## Shadow edge (sun)"
SIZE = 96
SETTINGS = (            # (floor segments, SSDF resolution, PCA terms: None = the error target's choice)
    (64, 32, None), (64, 32, 47), (256, 32, None), (256, 32, 47), (256, 64, 47), (64, 16, None),
)


def measure(segments, resolution, terms):
    import bpy  # noqa: F401  (the engine and the fixtures need it loaded)
    import engine_fixtures as fx
    import numpy as np
    from scipy import ndimage

    from sg_prt_addon.visibility.raytrace import RayTracer
    from validation import image_error
    from validation.reference import render_reference
    from validation.reference_scene import reference_inputs

    fx.ensure_registered()
    name = f"shadow_edge_{segments}_{resolution}_{terms}"
    scene = fx.new_scene(name, SIZE, SIZE)
    scene.camera.location = (0.0, -5.0, 3.0)
    scene.camera.rotation_euler = (math.radians(60), 0.0, 0.0)
    fx.world_colour(scene, (0.0, 0.0, 0.0))
    material = fx.material(name + "_m", model="GGX", roughness=0.5, diffuse_color=(0.7, 0.7, 0.7),
                           specular_color=(0.0, 0.0, 0.0))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=0.8, segments=48, rings=24)
    sphere.data.materials.append(material)
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=8.0, segments=segments)
    floor.data.materials.append(material)
    sun = fx.point_light(scene, name + "_sun", (0.0, 0.0, 5.0), 3.0, kind="SUN")
    sun.data.angle = 0.05
    sun.rotation_euler = (math.radians(35), 0.0, math.radians(30))
    try:
        bakes = fx.bake_objects(scene, [sphere, floor], resolution=resolution, terms=terms)
        result = fx.render(scene)
    finally:
        fx.clear_bakes()
    image = result["passes"]["Combined"][::-1, :, :3]
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    reference_scene, camera = reference_inputs(depsgraph, SIZE, SIZE)
    reference, error = render_reference(reference_scene, camera, 32, seed=2, pixel_centres=True)
    tracer = RayTracer(reference_scene.vertices, reference_scene.triangles)
    origins, directions = camera.primary_rays()
    hits = tracer.intersect(origins.reshape(-1, 3), directions.reshape(-1, 3))
    tracer.close()
    height = (origins.reshape(-1, 3) + directions.reshape(-1, 3) * hits.distance[:, None])[:, 2]
    floor_mask = (hits.hit & (np.abs(height) < 1e-3)).reshape(SIZE, SIZE)
    level = np.percentile(reference.mean(-1)[floor_mask], 90)
    lit = reference.mean(-1) > 0.5 * level
    band = floor_mask & ndimage.binary_dilation(lit, iterations=3) & ndimage.binary_dilation(~lit, iterations=3)

    def penumbra(values):
        v = values.mean(-1)[band] / level
        return int(((v > 0.1) & (v < 0.9)).sum())

    return {"segments": segments, "resolution": resolution, "terms": terms,
            "floor_terms": int(bakes[floor.name].terms),
            "floor_rmse": image_error.relative_rmse(image, reference, floor_mask),
            "floor_noise": image_error.rmse_noise_floor(error, reference, floor_mask),
            "band_rmse": image_error.relative_rmse(image, reference, band),
            "band_noise": image_error.rmse_noise_floor(error, reference, band), "band_pixels": int(band.sum()),
            "penumbra_engine": penumbra(image), "penumbra_reference": penumbra(reference)}


def markdown(results):
    lines = [SECTION_TITLE, "",
             "`.venv/bin/python -m benchmarks.shadow_edge` (benchmarks/shadow_edge.py says how): a diffuse sphere "
             "over a floor, sun angle 0.05 rad, 96 x 96, the pixel-centre Monte Carlo reference (32 samples).", "",
             "| floor segments | SSDF resolution | PCA terms (floor's) | floor RMSE (noise) | edge band RMSE (noise) "
             "| penumbra pixels, engine / reference |", "|---|---|---|---|---|---|"]
    for r in results:
        terms = "error target" if r["terms"] is None else str(r["terms"])
        lines.append(f"| {r['segments']} | {r['resolution']} | {terms} ({r['floor_terms']}) | {r['floor_rmse']:.4f} "
                     f"({r['floor_noise']:.4f}) | {r['band_rmse']:.4f} ({r['band_noise']:.4f}) | "
                     f"{r['penumbra_engine']} / {r['penumbra_reference']} |")
    lines += ["", "Read: the PCA truncation costs the edge most error (all 47 terms take 30% off the band's "
              "RMSE) but does not widen it; the width, 1.5-1.8 x the reference's penumbra, stays whatever the "
              "floor's tessellation, the SSDF resolution or the terms: it comes from the visibility product "
              "itself (the SSDF's distance and fh's smooth profile for the light's SG, against the sun's "
              "hard-edged disc), not from the per-vertex interpolation."]
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update-doc", action="store_true", help="write the table into docs/ACCURACY.md")
    args = parser.parse_args(argv)
    results = []
    for setting in SETTINGS:
        results.append(measure(*setting))
        print(results[-1], flush=True)
    section = markdown(results)
    print(section)
    if args.update_doc:
        from benchmarks import markdown_sections
        markdown_sections.update_file(str(ROOT / "docs" / "ACCURACY.md"), SECTION_TITLE, section)
    return results


if __name__ == "__main__":
    main()
