"""Render Samples (scene.sgprt.render_samples) with the 1-pixel Box filter: final renders average frames moved by
sub-pixel offsets (engine.anti_aliasing.pixel_jitter).  Four samples sample the same points as a render twice as
large, so their average must equal that render box-filtered down; the render panel shows it.
Specular Anti-Aliasing (scene.sgprt.specular_anti_aliasing, sg_shading.glsl shade_footprint): one frame
shading each pixel over its footprint comes close to the box-filtered frames the jitter averages.  Edges Only
(scene.sgprt.sample_edges_only, engine/multi_sample.py): the samples at the edges of a frame shaded at the
pixels' centres, drawn tile by tile, equal every pixel's samples there and leave the rest as that frame."""
import engine_fixtures as fx
import numpy as np
import pytest

from sg_prt_addon.engine import anti_aliasing


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def test_pixel_jitter_patterns():
    grid = anti_aliasing.pixel_jitter(4)
    np.testing.assert_allclose(sorted(map(tuple, grid)), [(-0.25, -0.25), (-0.25, 0.25), (0.25, -0.25), (0.25, 0.25)])
    assert np.array_equal(anti_aliasing.pixel_jitter(1), [[0.0, 0.0]])
    r2 = anti_aliasing.pixel_jitter(7)
    assert r2.shape == (7, 2) and np.all(r2 >= -0.5) and np.all(r2 < 0.5)
    assert np.abs(r2.mean(axis=0)).max() < 1e-12         # centred: every stratum once per axis
    assert len(set(np.round(r2[:, 1], 9))) == 7
    # each jittered frame's shading covers its cell of the pixel: the whole pixel for one frame, none when off
    assert [anti_aliasing.specular_footprint(n) for n in (1, 4, 16)] == [1.0, 0.5, 0.25]
    assert anti_aliasing.specular_footprint(16, enabled=False) == 0.0
    assert anti_aliasing.specular_footprint(1, filter_side=1.44) == 1.44     # one frame: the filter's square
    # textures: the pixel, or a jittered frame's cell of it (its mip level; not the filter's square)
    assert [anti_aliasing.texture_footprint(n) for n in (1, 4, 16)] == [1.0, 0.5, 0.25]


def _scene(name, size, samples, specular_anti_aliasing=False, roughness=0.25, edges_only=False,
           pixel_filter=("BOX", 1.0)):
    """A GGX sphere under a small point light; the 1-pixel Box filter unless told (the sampling's equalities
    below hold for it; tests/gpu/test_pixel_filter_render.py measures the others)."""
    scene = fx.new_scene(name, size, size)
    scene.sgprt.render_samples = samples
    scene.sgprt.pixel_filter_type, scene.render.filter_size = pixel_filter
    scene.sgprt.sample_edges_only = edges_only
    scene.sgprt.specular_anti_aliasing = specular_anti_aliasing
    fx.world_colour(scene, (0.05, 0.05, 0.05))
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=1.0)
    sphere.data.materials.append(fx.material(name + "_m", model="GGX", roughness=roughness,
                                             diffuse_color=(0.3, 0.3, 0.3), specular_color=(0.6, 0.6, 0.6)))
    fx.point_light(scene, name + "_light", (2.0, -3.0, 3.0), 300.0, radius=0.05)
    return scene


def test_four_samples_equal_a_box_filtered_double_size_render(engine):
    small = dict(fx.render(_scene("samples4", 32, 4)))        # last_render is reused by the next render
    assert "error" not in small and small["timings"]["samples"] == 4
    large = fx.render(_scene("samples1_large", 64, 1))
    assert large["timings"]["samples"] == 1
    for name in ("Combined", "Diffuse", "Specular"):
        image = large["passes"][name]
        filtered = image.reshape(32, 2, 32, 2, 4).mean(axis=(1, 3))
        error = np.abs(small["passes"][name] - filtered).max() / np.abs(filtered).max()
        print(f"{name}: max |4 samples - 2x box-filtered| / max = {error:.2e}")
        assert error < 1e-4
    centre = fx.render(_scene("samples1", 32, 1))["passes"]["Combined"]
    assert np.abs(centre - small["passes"]["Combined"]).max() > 1e-2       # the samples did change the image


def test_render_panel_shows_the_setting(engine):
    import bpy

    from sg_prt_addon.blender import panels, properties

    assert bpy.types.Scene.bl_rna.properties.get("sgprt") is not None
    assert panels.SGPRT_PT_sampling.is_registered and panels.SGPRT_PT_sampling.bl_context == "render"
    scene = bpy.data.scenes.new("specular_aa_default")
    assert scene.sgprt.specular_anti_aliasing          # on unless turned off
    assert scene.sgprt.render_samples == 16 and scene.sgprt.sample_edges_only
    assert scene.sgprt.edge_threshold == pytest.approx(properties.DEFAULT_EDGE_THRESHOLD)


def _surface_rmse(image, reference, mask):
    return float(np.sqrt(np.mean((image[mask, :3] - reference[mask, :3]) ** 2)) / np.mean(reference[mask, :3]))


def test_specular_anti_aliasing_comes_close_to_the_box_filter(engine):
    """A GGX 0.1 highlight on a 16-pixel sphere is narrower than a pixel: the pixel centres catch or miss it.
    Shading each pixel over its footprint must remove nearly all of that error against 64 jittered frames (the
    box filter of the same shading); a diffuse material is left as it was."""
    renders = {}
    for key, samples, footprint in (("reference", 64, False), ("centre", 1, False), ("footprint", 1, True),
                                    ("footprint 16", 16, True), ("centre 16", 16, False)):
        result = fx.render(_scene(f"specular_aa_{key}", 32, samples, footprint, roughness=0.1))
        assert "error" not in result
        renders[key] = result["passes"]["Combined"].copy()
        if key == "centre":
            mask = result["passes"]["Diffuse"][..., 3] > 0.5      # the sphere's pixels
    errors = {key: _surface_rmse(image, renders["reference"], mask) for key, image in renders.items()
              if key != "reference"}
    print("relative RMSE against 64 jittered frames: " + ", ".join(f"{k} {v:.3f}" for k, v in errors.items()))
    # measured: centre 3.43, footprint 0.031; with 16 frames 0.040 (centre) and 0.131 (footprint: each frame
    # shades its cell of the pixel): the highlight lies within 1/20 of one pixel, where the 8 x 8 reference
    # itself is uncertain by a few percent, which on its value of 16 (the surface's mean is 0.05) is the RMSE
    assert errors["centre"] > 1.0                               # the aliasing is there to remove
    assert errors["footprint"] < 0.05
    assert errors["footprint 16"] < 0.2

    diffuse = {}
    for footprint in (False, True):
        scene = _scene(f"specular_aa_diffuse_{footprint}", 32, 1, footprint)
        scene.objects[f"specular_aa_diffuse_{footprint}_sphere"].data.materials[0].sgprt.specular_color = (0, 0, 0)
        diffuse[footprint] = fx.render(scene)["passes"]["Combined"].copy()
    np.testing.assert_allclose(diffuse[True], diffuse[False], rtol=1e-5, atol=1e-6)     # measured: 2.2e-7


# ----------------------------------------------------------------- Edges Only

def _passes(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return {name: np.array(image) for name, image in result["passes"].items() if isinstance(image, np.ndarray)}, \
        dict(result["timings"])


def test_edges_only_samples_the_edges_and_keeps_the_centred_frame_elsewhere(engine):
    """Edges Only: where the frame at the pixels' centres shows an edge (the GLSL edge pass, as its mirror
    anti_aliasing.edge_pixels finds them), the 4 x 4 grid of a supersampled tile gives what 16 jittered frames
    of every pixel give there; every other pixel is the one-sample render's (to float32 rounding: the sums
    blend)."""
    from sg_prt_addon.blender import properties

    one, _ = _passes(_scene("edges_one", 48, 1))
    every, _ = _passes(_scene("edges_every", 48, 16))
    edged, timings = _passes(_scene("edges_only", 48, 16, edges_only=True))
    edges = edged["edge_pixels"]
    mirror = anti_aliasing.edge_pixels(one["Combined"], properties.DEFAULT_EDGE_THRESHOLD)
    print(f"edge pixels {edges.mean():.1%} in {timings['edge_tiles']} tile(s); the mirror disagrees on "
          f"{np.mean(mirror != edges):.2%}")
    assert 0.02 < edges.mean() < 0.5 and timings["edge_tiles"] == 1 and timings["edge_pixels"] == edges.mean()
    assert np.mean(mirror != edges) < 1e-3                  # measured: 0
    for name in ("Combined", "Diffuse", "Specular"):
        # measured: 6e-8; two renders of equal scenes differ by up to 1.3e-5 at a highlight's pixel (bpy 5.3)
        np.testing.assert_allclose(edged[name][~edges], one[name][~edges], rtol=1e-4, atol=1e-6)
        difference = edged[name][edges] - every[name][edges]
        rms = float(np.sqrt(np.mean(difference ** 2)) / np.mean(np.abs(every[name][edges])))
        print(f"{name}: relative RMS of Edges Only - every pixel over the edges {rms:.2e}")
        # the same samples, drawn through a cropped projection rather than a jittered one: the rasterizer snaps
        # vertices to 1/256 of a pixel of each, so a sample that close to a triangle's edge may fall on its other
        # side (1/16 of the pixel; measured: 0.001 Combined, 0.015 Diffuse, whose alpha is the coverage)
        assert rms < 0.05
    # the approximation: what Edges Only leaves out of every pixel's samples, beside what one sample leaves out
    surface = every["Diffuse"][..., 3] > 0.0
    left_out = {key: _surface_rmse(image["Combined"], every["Combined"], surface) for key, image in
                (("one sample", one), ("Edges Only", edged))}
    print("relative RMSE against 16 samples of every pixel: " + ", ".join(f"{k} {v:.4f}" for k, v in left_out.items()))
    assert left_out["Edges Only"] < 0.01 and left_out["Edges Only"] < 0.25 * left_out["one sample"]   # 0.003, 2.8
    changed = np.abs(edged["Combined"] - one["Combined"]).max(axis=-1) > 1e-3
    # the samples did change the edges (measured: half of them; both sides of an edge are marked, and a pixel the
    # surface covers whole may change little)
    assert changed[edges].mean() > 0.25


def test_edges_only_tiles_join_and_a_high_threshold_samples_nothing(engine, monkeypatch):
    from sg_prt_addon.engine import multi_sample

    whole, timings = _passes(_scene("edges_whole", 48, 16, edges_only=True))
    assert timings["edge_tiles"] == 1
    monkeypatch.setattr(multi_sample, "MAX_TILE_PIXELS", 64)        # tiles of 16 pixels: 9 over the image
    tiled, timings = _passes(_scene("edges_tiled", 48, 16, edges_only=True))
    assert 1 < timings["edge_tiles"] <= 9
    for name in ("Combined", "Diffuse", "Specular"):
        # the tiles' projections put a sample within the rasterizer's 1/256 pixel of a triangle's edge on one
        # side or the other (measured: under 0.1% of the values moved, by one sample's share); nothing else moves
        moved = np.abs(tiled[name] - whole[name]) > 1e-5 * (1.0 + np.abs(whole[name]))
        print(f"{name}: tiled - whole, {moved.mean():.2%} of the values moved, by at most "
              f"{np.abs(tiled[name] - whole[name]).max():.4f}")
        assert moved.mean() < 0.005 and np.abs(tiled[name] - whole[name]).max() < 0.1 * np.abs(whole[name]).max()
    monkeypatch.undo()
    scene = _scene("edges_none", 48, 16, edges_only=True)
    scene.sgprt.edge_threshold = 1.0                # no difference passes it: the centred frame alone
    nothing, timings = _passes(scene)
    one, _ = _passes(_scene("edges_none_one", 48, 1))
    assert timings["edge_tiles"] == 0 and not nothing["edge_pixels"].any()
    np.testing.assert_allclose(nothing["Combined"], one["Combined"], rtol=1e-4, atol=1e-6)   # measured: 1.3e-5


def test_edge_pass_matches_its_mirror_on_hostile_frames(engine):
    """engine/edge_pixels.frag.glsl against anti_aliasing.edge_pixels on frames of random, huge, negative,
    NaN and infinite values; the sums' first values: 0 at the edges, the frame elsewhere."""
    from types import SimpleNamespace

    from sg_prt_addon.engine import multi_sample, render_engine
    from sg_prt_addon.engine import renderer as renderer_module

    rng = np.random.default_rng(7)
    height, width = 64, 96
    frames = []
    for _ in range(3):
        # flat 8 x 8 blocks (edges at their borders only), some of them noise, some of them nearly equal
        blocks = rng.uniform(0.0, 1.0, (height // 8, width // 8, 4)).astype(np.float32)
        blocks[rng.random(blocks.shape[:2]) < 0.3] = blocks[0, 0] * np.float32(1.1)
        frame = np.repeat(np.repeat(blocks, 8, axis=0), 8, axis=1)
        noisy = np.repeat(np.repeat(rng.random(blocks.shape[:2]) < 0.2, 8, axis=0), 8, axis=1)
        frame[noisy] *= rng.uniform(0.7, 1.3, (int(noisy.sum()), 4)).astype(np.float32)
        spots = rng.random((height, width)) < 0.005
        frame[spots, 0] = rng.choice(np.array([np.nan, np.inf, -np.inf, 1e30, -5.0], np.float32), spots.sum())
        frames.append(frame)

    def edge_pass(depsgraph, state, renderer, camera):
        textures = [renderer_module._texture_2d(frame) for frame in frames]
        sums = multi_sample.FrameSums()
        sums.start_at_edges(SimpleNamespace(size=(width, height), targets=textures,
                                            full_screen_batch=renderer.full_screen_batch), 0.2, 0.03)
        return sums.read_mask(), sums.read()

    render_engine.debug["after_frame"] = edge_pass
    try:
        result = fx.render(_scene("edge_pass_mirror", 8, 1))
    finally:
        render_engine.debug["after_frame"] = None
    mask, starts = result["after_frame"]
    mirror = anti_aliasing.edge_pixels(frames[0], 0.2, 0.03)
    print(f"edges {mask.mean():.1%}; GLSL and mirror disagree on {np.mean(mask != mirror):.3%}")
    assert 0.2 < mask.mean() < 0.95 and np.mean(mask != mirror) < 1e-3          # measured: 0
    for name, frame in zip(multi_sample.PASSES, frames):
        assert not starts[name][mask].any()
        np.testing.assert_array_equal(starts[name][~mask], frame[~mask])


def test_objects_outside_the_view_are_not_drawn(engine):
    """renderer.in_view keeps the draws whose world box may reach the view (an edge tile sees a part of it), and
    those it cannot tell: no bounds, or a non-finite transform."""
    from types import SimpleNamespace

    from sg_prt_addon.engine import renderer as renderer_module

    def draw(name, location, bounds=((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5))):
        matrix = np.eye(4)
        matrix[:3, 3] = location
        return (0, name, SimpleNamespace(matrix_world=matrix), SimpleNamespace(
            buffers=SimpleNamespace(bounds=None if bounds is None else np.array(bounds))), [])

    draws = [draw("inside", (0.0, 0.0, 0.0)), draw("beyond x", (5.0, 0.0, 0.0)), draw("straddles", (1.2, 0.0, 0.0)),
             draw("behind", (0.0, 0.0, -3.0)), draw("no bounds", (9.0, 9.0, 9.0), bounds=None),
             draw("not finite", (np.nan, 0.0, 0.0))]
    kept = [name for _index, name, *_ in renderer_module.in_view(draws, np.eye(4))]    # clip = world: [-1, 1]^3
    assert kept == ["inside", "straddles", "no bounds", "not finite"]
    assert renderer_module.in_view([], np.eye(4)) == []


def test_esc_keeps_the_samples_taken(engine, monkeypatch):
    """Esc between an Edges Only tile and the next: the tiles drawn keep their samples, the others the centred
    frame; between jittered frames of every pixel: the mean of those drawn.  The render reports it."""
    from sg_prt_addon.engine import multi_sample, render_engine

    monkeypatch.setattr(multi_sample, "MAX_TILE_PIXELS", 64)        # tiles of 16 pixels
    finished, timings = _passes(_scene("esc_finished", 48, 16, edges_only=True))
    centred, _ = _passes(_scene("esc_centred", 48, 1))
    assert timings["edge_tiles"] > 3
    asked = []

    def test_break():
        asked.append(True)
        return len(asked) > 2                   # Esc after two tiles (or frames)

    monkeypatch.setitem(render_engine.debug, "test_break", test_break)
    result = fx.render(_scene("esc_edges", 48, 16, edges_only=True))
    assert "error" not in result and result["timings"]["cancelled"] and result["timings"]["edge_tiles"] == 2
    image, edges = result["passes"]["Combined"], result["passes"]["edge_pixels"]
    kept = np.isclose(image, finished["Combined"], rtol=1e-4, atol=1e-5).all(axis=-1)
    fell_back = np.isclose(image, centred["Combined"], rtol=1e-4, atol=1e-5).all(axis=-1)
    print(f"edge pixels sampled before Esc {np.mean(kept[edges] & ~fell_back[edges]):.0%}, left at the centred "
          f"frame {np.mean(fell_back[edges] & ~kept[edges]):.0%}")
    assert (kept | fell_back).mean() > 0.999
    assert (edges & kept & ~fell_back).any() and (edges & fell_back & ~kept).any()

    asked.clear()
    result = fx.render(_scene("esc_every", 48, 16))
    assert result["timings"]["cancelled"] and "error" not in result
    image = result["passes"]["Combined"]
    assert np.isfinite(image).all() and abs(float(image[..., 3].mean()) - 1.0) < 1e-5   # the mean of 2 frames


def test_edges_only_on_a_transparent_film(engine):
    """A transparent film: the silhouette is an edge of alpha alone (the world is (0, 0, 0, 0)), and Edges Only
    averages its coverage as every pixel's samples do."""
    images = {}
    for key, samples, edges_only in (("one", 1, False), ("every", 16, False), ("edges", 16, True)):
        scene = _scene(f"film_{key}", 48, samples, edges_only=edges_only)
        scene.render.film_transparent = True
        images[key], _ = _passes(scene)
    edges = images["edges"]["edge_pixels"]
    alpha = {key: passes["Combined"][..., 3] for key, passes in images.items()}
    partial = (alpha["every"] > 0.01) & (alpha["every"] < 0.99)         # the silhouette's pixels
    print(f"silhouette pixels {partial.sum()}, of them marked {edges[partial].mean():.0%}; edge alpha "
          f"|Edges Only - every pixel| max {np.abs(alpha['edges'] - alpha['every'])[edges].max():.4f}")
    assert partial.sum() > 20 and edges[partial].all()
    assert set(np.unique(alpha["one"])) <= {0.0, 1.0}                    # one sample: covered or not
    # the same coverage, but for samples the rasterizer's 1/256-pixel snap puts on the other side of an edge
    assert np.abs(alpha["edges"] - alpha["every"])[edges].max() <= 2.0 / 16 + 1e-6
    np.testing.assert_allclose(alpha["edges"][~edges], alpha["one"][~edges], atol=1e-6)
