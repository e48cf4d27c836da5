"""Final renders reconstruct with the scene's pixel filter (scene.sgprt.pixel_filter_type at the film's Filter
Size; engine/pixel_filter.py), Blackman-Harris 1.5 px by default as Cycles: scored against the same scene drawn
eight times larger at the cells' centres and filtered down exactly (pixel_filter.filter_supersampled), every
pixel's jittered frames and Edges Only's tiles come close; the 1-pixel box the engine used before does not."""
import engine_fixtures as fx
import numpy as np
import pytest

from sg_prt_addon.engine.pixel_filter import PixelFilter, filter_supersampled

SIZE = 32
SCALE = 8           # the reference: SCALE x SCALE samples a pixel


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _scene(name, size, samples, edges_only, pixel_filter, specular_anti_aliasing=True):
    """A GGX 0.3 sphere whose highlight spans a few pixels, over a dark world: sub-pixel detail at its
    silhouette and highlight, where the filter's shape shows."""
    scene = fx.new_scene(name, size, size)
    scene.sgprt.render_samples = samples
    scene.sgprt.sample_edges_only = edges_only
    scene.sgprt.specular_anti_aliasing = specular_anti_aliasing
    scene.sgprt.pixel_filter_type, scene.render.filter_size = pixel_filter
    fx.world_colour(scene, (0.05, 0.05, 0.05))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(fx.material(name + "_m", model="GGX", roughness=0.3,
                                             diffuse_color=(0.3, 0.3, 0.3), specular_color=(0.6, 0.6, 0.6)))
    fx.point_light(scene, name + "_light", (2.0, -3.0, 3.0), 300.0, radius=0.25)
    return scene


def _combined(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return np.array(result["passes"]["Combined"]), dict(result["timings"])


def _relative_rmse(image, reference, mask):
    """RMS of the difference over the RMS of the reference: the highlight's pixels weigh as they show."""
    return float(np.sqrt(np.mean((image[mask, :3] - reference[mask, :3]) ** 2) / np.mean(reference[mask, :3] ** 2)))


def test_renders_match_the_exactly_filtered_image(engine):
    harris = ("BLACKMAN_HARRIS", 1.5)
    large, _ = _combined(_scene("filter_reference", SIZE * SCALE, 1, False, harris, specular_anti_aliasing=False))
    reference = filter_supersampled(large, PixelFilter(*harris), SCALE)
    box_reference = filter_supersampled(large, PixelFilter("BOX", 1.0), SCALE)
    mask = np.ones(reference.shape[:2], bool)
    errors, edge_fraction = {}, None
    for key, samples, edges_only, pixel_filter in (("every pixel", 16, False, harris),
                                                   ("Edges Only", 16, True, harris),
                                                   ("one sample", 1, False, harris),
                                                   ("box, every pixel", 16, False, ("BOX", 1.0)),
                                                   ("box, Edges Only", 16, True, ("BOX", 1.0))):
        image, timings = _combined(_scene(f"filter_{key}", SIZE, samples, edges_only, pixel_filter))
        errors[key] = _relative_rmse(image, reference, mask)
        if key == "Edges Only":
            edge_fraction = timings["edge_pixels"]
    print(f"edge pixels {edge_fraction:.1%}; relative RMSE against Blackman-Harris 1.5 of {SCALE}x{SCALE} "
          f"samples: " + ", ".join(f"{key} {value:.4f}" for key, value in errors.items())
          + f"; the two references differ by {_relative_rmse(box_reference, reference, mask):.4f}")
    # measured: every pixel 0.0025, Edges Only 0.0019 (17% of the pixels), one sample (its specular over the
    # filter's footprint) 0.051; the 1-pixel box 0.199 either way
    assert errors["every pixel"] < 0.006 and errors["Edges Only"] < 0.006 and errors["one sample"] < 0.08
    assert min(errors["box, every pixel"], errors["box, Edges Only"]) > 10 * max(errors["every pixel"],
                                                                                 errors["Edges Only"])


def test_the_default_is_cycles_filter_and_the_film_panel_shows_it(engine):
    import bpy

    from sg_prt_addon.blender import panels
    from sg_prt_addon.engine import pixel_filter, render_engine

    scene = bpy.data.scenes.new("filter_defaults")
    assert scene.sgprt.pixel_filter_type == "BLACKMAN_HARRIS" and scene.render.filter_size == pytest.approx(1.5)
    assert render_engine.scene_pixel_filter(scene) == PixelFilter("BLACKMAN_HARRIS", 1.5)
    assert panels.SGPRT_PT_film.is_registered and panels.SGPRT_PT_film.bl_context == "render"
    identifiers = [item.identifier for item in scene.sgprt.bl_rna.properties["pixel_filter_type"].enum_items]
    assert identifiers == list(pixel_filter.KINDS)
    assert render_engine.pixel_filter_warnings(scene) == []
    scene.render.filter_size = 4.0
    warnings = render_engine.pixel_filter_warnings(scene)
    assert len(warnings) == 1 and "cuts it at 3 px" in warnings[0]


def test_a_wide_filter_renders_through_its_apron(engine, monkeypatch):
    """A Gaussian of Filter Size 1.5 reaches 2 pixels: Edges Only's tiles draw that apron, the tiles join (tiles
    of 12 pixels and their aprons give what one tile gives), and Edges Only comes close to every pixel's frames."""
    from sg_prt_addon.engine import multi_sample

    gaussian = ("GAUSSIAN", 1.5)
    whole, timings = _combined(_scene("filter_gaussian_whole", SIZE, 16, True, gaussian))
    assert timings["edge_tiles"] == 1
    every, _ = _combined(_scene("filter_gaussian_every", SIZE, 16, False, gaussian))
    monkeypatch.setattr(multi_sample, "MAX_TILE_PIXELS", 64)    # (12 + 2 x 2) x 4 samples a side
    tiled, timings = _combined(_scene("filter_gaussian_tiled", SIZE, 16, True, gaussian))
    assert timings["edge_tiles"] > 1
    np.testing.assert_allclose(tiled, whole, atol=2e-4)
    mask = np.ones(every.shape[:2], bool)
    error = _relative_rmse(whole, every, mask)
    print(f"Gaussian 1.5, Edges Only against every pixel: relative RMSE {error:.4f}")
    assert error < 0.006            # measured: 0.0025
