"""Textures seen smaller than their texels are filtered (spherical/texture_mips.py): a floor under a 1-texel
checker and a bumpy normal map, rendered at one sample a pixel, against the same scene drawn eight times larger
and box-filtered down (the average over each pixel, which minified texels would otherwise alias into moire).  A
minified normal map's normals average shorter: their spread widens the NDF lobes (surface_common.glsl
normal_spread), or the averaged, flatter normal would show a sharp highlight the bumps scatter."""
import engine_fixtures as fx
import numpy as np
import pytest

from sg_prt_addon.engine.pixel_filter import PixelFilter, filter_supersampled

SIZE = 48
SCALE = 8
TEXELS = 256


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _checker(cell=1):
    """A checker of cell x cell texels."""
    cells = (np.add.outer(np.arange(TEXELS) // cell, np.arange(TEXELS) // cell) % 2).astype(np.float32)
    pixels = np.ones((TEXELS, TEXELS, 4), np.float32)
    pixels[..., :3] = (0.1 + 0.8 * cells)[..., None]
    return pixels


def _bumps():
    """A normal map of random tilts up to about 35 degrees, one a texel (tangent space, encoded in [0, 1])."""
    rng = np.random.default_rng(5)
    tilt = rng.uniform(-0.7, 0.7, (TEXELS, TEXELS, 2))
    normal = np.concatenate([tilt, np.ones((TEXELS, TEXELS, 1))], axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    pixels = np.ones((TEXELS, TEXELS, 4), np.float32)
    pixels[..., :3] = 0.5 + 0.5 * normal
    return pixels


def _render(name, size, kind, samples=1, edges_only=False):
    scene = fx.new_scene(name, size, size)
    scene.sgprt.render_samples, scene.sgprt.sample_edges_only = samples, edges_only
    scene.camera.location = (0.0, -5.0, 1.5)
    fx.world_colour(scene, (0.3, 0.3, 0.3))
    floor = fx.plane(scene, name + "_floor", (0.0, 0.0, 0.0), size=8.0)
    if kind in ("checker", "coarse checker"):
        material = fx.material(name, diffuse_color=(1.0, 1.0, 1.0), specular_color=(0.0, 0.0, 0.0),
                               diffuse_color_texture=fx.image(name + "_checker", _checker(1 if kind == "checker"
                                                                                          else 8)))
    else:
        material = fx.material(name, model="GGX", roughness=0.3, diffuse_color=(0.2, 0.2, 0.2),
                               specular_color=(0.6, 0.6, 0.6), normal_map=fx.image(name + "_bumps", _bumps()))
        fx.point_light(scene, name + "_light", (0.0, 3.0, 2.0), 400.0, radius=0.1)
    floor.data.materials.append(material)
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    return np.array(result["passes"]["Combined"])


# measured: checker 0.057 / -0.013 (bilinear in the image alone: 0.243); bumps 0.339 / +0.041 (bilinear in the
# image: 1.66 / -0.018, aliased; the mip levels without the spread: 2.27 / +0.43, the flattened highlight), what
# is left the reference's glints, bumps resolved at 8 x 8 samples a pixel
@pytest.mark.parametrize("kind, rmse_bound, bias_bound", [("checker", 0.08, 0.03), ("bumps", 0.45, 0.1)])
def test_minified_textures_are_filtered(engine, kind, rmse_bound, bias_bound):
    image = _render(f"minified_{kind}", SIZE, kind)
    reference = filter_supersampled(_render(f"minified_{kind}_large", SIZE * SCALE, kind), PixelFilter("BOX", 1.0),
                                    SCALE)
    floor = reference[..., :3].max(axis=-1) > 0.0
    floor &= np.abs(reference[..., :3] - 0.3).max(axis=-1) > 1e-3       # not the world
    difference = image[floor, :3] - reference[floor, :3]
    rmse = float(np.sqrt(np.mean(difference ** 2) / np.mean(reference[floor, :3] ** 2)))
    bias = float(difference.mean() / reference[floor, :3].mean())
    print(f"{kind}: {floor.mean():.0%} of the pixels, relative RMSE {rmse:.4f}, bias {bias:+.4f} against "
          f"{SCALE}x{SCALE} samples a pixel")
    assert rmse < rmse_bound and abs(bias) < bias_bound


def test_jittered_frames_and_edge_tiles_read_textures_at_their_own_footprint(engine):
    """16 samples of every pixel read a checker of 8-texel cells (2 to 6 pixels on the floor) at a quarter of a
    pixel each (anti_aliasing.texture_footprint), as Edges Only's tiles drawn 4 times larger do: both come close to
    the 8 x 8 reference filtered by the same Blackman-Harris (measured 0.021 every pixel, 0.033 Edges Only, whose
    pixels off the edges read the texture at the whole pixel; reading at the whole pixel, the jittered frames
    blurred the cells twice: 0.128)."""
    kind = "coarse checker"
    reference = filter_supersampled(_render("coarse_checker_reference", SIZE * SCALE, kind),
                                    PixelFilter("BLACKMAN_HARRIS", 1.5), SCALE)
    every = _render("coarse_checker_every", SIZE, kind, 16)
    edges = _render("coarse_checker_edges", SIZE, kind, 16, edges_only=True)
    floor = np.abs(reference[..., :3] - 0.3).max(axis=-1) > 1e-3
    errors = {key: float(np.sqrt(np.mean((image[floor, :3] - reference[floor, :3]) ** 2)
                                 / np.mean(reference[floor, :3] ** 2))) for key, image in (("every", every),
                                                                                          ("edges", edges))}
    print(f"relative RMSE against {SCALE}x{SCALE} samples, Blackman-Harris: every pixel {errors['every']:.4f}, "
          f"Edges Only {errors['edges']:.4f}")
    assert errors["every"] < 0.04 and errors["edges"] < 0.05
