"""Engine-level stress: real bpy scenes with hostile input, rendered by the real engine.

Extreme materials of every model, degenerate geometry, huge and tiny scene scales, NaN and Inf
texels in material textures and in the world's HDRI, lights of zero and huge energy and zero size.
Asserts that every pass (Combined, Diffuse, Specular) is finite everywhere, and that bad input
(NaN/Inf texels, zero normals, missing UVs where textures or UV tangents need them) leaves a
warning in SceneState.warnings naming the object / material / image and what was done.
Small resolutions: the file runs in well under a minute and a half on 2 cores.
"""
import math

import engine_fixtures as fx
import numpy as np
import pytest

SIZE = 48
PASSES = ("Combined", "Diffuse", "Specular")


def _new_scene(name, width, height):
    """fx.new_scene with the engine's defaults, Specular Anti-Aliasing and shadow maps: the footprint's derivatives
    and the maps' lookups meet the degenerate geometry, extreme materials and lights too."""
    scene = fx.new_scene(name, width, height)
    scene.sgprt.specular_anti_aliasing = True
    scene.sgprt.light_shadows = "SHADOW_MAPS"
    return scene


@pytest.fixture(scope="module")
def engine(blender):
    from sg_prt_addon.engine import render_engine

    fx.ensure_registered()
    render_engine.debug["environment_layer_size"] = 16        # prefilter small HDRIs fast
    yield blender
    render_engine.debug["environment_layer_size"] = None


def _render(scene):
    result = fx.render(scene)
    assert "error" not in result, result.get("error")
    passes = result["passes"]
    for name in PASSES:
        bad = ~np.isfinite(passes[name])
        assert not bad.any(), f"{scene.name}: {name} has {int(bad.any(axis=-1).sum())} non-finite pixels"
    return result


def _covered(result):
    return result["passes"]["Diffuse"][..., 3] > 0.5


def _warnings(result):
    return list(result["state"].warnings)


def _warned(result, *words):
    """True when one warning mentions every word (case-insensitive)."""
    return any(all(word.lower() in warning.lower() for word in words) for warning in _warnings(result))


def _set_raw(settings, **values):
    """Set material settings past their UI limits (as scripts and old files can): the ID
    properties directly, which RNA does not clamp on read."""
    for key, value in values.items():
        settings[key] = value


def _uv_sphere(scene, name, location, radius=1.0, segments=16, rings=8):
    """A smooth UV sphere with a UV map (fx.uv_sphere's bmesh has no UV layer, so it has none)."""
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bm.loops.layers.uv.new("UVMap")
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius, calc_uvs=True)
    bm.to_mesh(mesh)
    bm.free()
    assert len(mesh.uv_layers) == 1
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return fx.add_object(scene, obj)


def _hdri(name, height=16, width=32, seed=0):
    rng = np.random.default_rng(seed)
    pixels = np.ones((height, width, 4), np.float32)
    pixels[..., :3] = rng.uniform(0.05, 1.0, (height, width, 3))
    pixels[height - 3, 5, :3] = 500.0            # a sun
    return fx.image(name, pixels)


def _world_image(scene, image, strength=1.0):
    world = fx.world_texture(scene, fx.studio_world_path("courtyard.exr"), strength)
    world.node_tree.nodes["Environment Texture"].image = image
    return world


# --------------------------------------------------------------------------- materials

EXTREMES = {
    # name: raw settings (past the UI limits on purpose)
    "smooth": dict(roughness=1e-4, exponent=1e8, alpha_x=1e-4, alpha_y=1e-4, nu=1e8, nv=1e8, ior=4.0),
    "rough": dict(roughness=1.0, exponent=1e-4, alpha_x=1.0, alpha_y=1.0, nu=1e-4, nv=1e-4, ior=1.0),
    "mixed": dict(roughness=1.0, exponent=1e8, alpha_x=1e-4, alpha_y=1.0, nu=1e8, nv=1e-4, ior=1.0),
    "no_diffuse": dict(diffuse_color=(0.0, 0.0, 0.0)),
    "no_specular": dict(specular_color=(0.0, 0.0, 0.0)),
    "black": dict(diffuse_color=(0.0, 0.0, 0.0), specular_color=(0.0, 0.0, 0.0), roughness=1e-4, exponent=0.0,
                  nu=0.0, nv=0.0),
}


@pytest.mark.parametrize("world", ["colour", "hdri"])
@pytest.mark.parametrize("model", ["GGX", "COOK_TORRANCE", "BLINN_PHONG", "WARD_ISO", "WARD_ANISO", "ASHIKHMIN_SHIRLEY",
                                   "BECKMANN"])
def test_extreme_materials(engine, model, world):
    """Each model at roughness 1e-4 and 1, exponents 1e-4 and 1e8, zero diffuse / specular / both,
    lit by a point, a spot, a sun and the world (a colour, or an HDRI with a 500x sun texel)."""
    scene = _new_scene(f"stress_{model}_{world}", SIZE, SIZE)
    if world == "hdri":
        _world_image(scene, _hdri("stress_hdri"))
    else:
        fx.world_colour(scene, (0.2, 0.2, 0.2))
    fx.point_light(scene, f"{scene.name}_point", (1.0, -3.0, 3.0), 1000.0, radius=0.0)
    fx.point_light(scene, f"{scene.name}_spot", (-2.0, -3.0, 2.0), 800.0, radius=0.1, kind="SPOT")
    fx.point_light(scene, f"{scene.name}_sun", (0.0, 0.0, 5.0), 3.0, kind="SUN")
    for index, (name, settings) in enumerate(EXTREMES.items()):
        x = -2.5 + index
        sphere = fx.uv_sphere(scene, f"{scene.name}_{name}", (x, 0.0, 1.0), radius=0.45, segments=16, rings=8)
        material = fx.material(f"{scene.name}_{name}", model=model, lobe_count=3)
        _set_raw(material.sgprt, **settings)
        sphere.data.materials.append(material)
    floor = fx.plane(scene, f"{scene.name}_floor", (0.0, 0.0, 0.5))
    floor.data.materials.append(fx.material(f"{scene.name}_floor", model=model))
    result = _render(scene)
    assert _covered(result).mean() > 0.2
    assert result["passes"]["Specular"][..., :3].max() > 0


def _height_image(name, heights):
    pixels = np.repeat(np.flipud(np.asarray(heights, np.float32))[..., None], 4, axis=-1)
    return fx.image(name, pixels)


@pytest.mark.parametrize("model", ["GGX", "COOK_TORRANCE", "BLINN_PHONG", "WARD_ISO"])
def test_extreme_bi_scale_materials(engine, model):
    """The bi-scale technique (SG_BISCALE) with the extreme settings above on a flat tile, a tile of near-vertical
    walls and a single spike, under the HDRI and the lights: every pass finite."""
    scene = _new_scene(f"stress_biscale_{model}", SIZE, SIZE)
    _world_image(scene, _hdri("stress_biscale_hdri"))
    fx.point_light(scene, f"{scene.name}_point", (1.0, -3.0, 3.0), 1000.0, radius=0.0)
    fx.point_light(scene, f"{scene.name}_sun", (0.0, 0.0, 5.0), 3.0, kind="SUN")
    spike = np.zeros((8, 8))
    spike[3, 4] = 1.0
    walls = (np.add.outer(np.arange(8), np.arange(8)) % 2).astype(float)
    tiles = {"flat": (np.zeros((4, 4)), 1.0), "walls": (walls, 5.0), "spike": (spike, 2.0)}
    for index, (name, settings) in enumerate(EXTREMES.items()):
        tile_name = list(tiles)[index % len(tiles)]
        heights, scale = tiles[tile_name]
        sphere = fx.uv_sphere(scene, f"{scene.name}_{name}", (-2.5 + index, 0.0, 1.0), radius=0.45, segments=16,
                              rings=8)
        material = fx.material(f"{scene.name}_{name}", model=model, technique="SG_BISCALE")
        material.sgprt.biscale.height_image = _height_image(f"{scene.name}_{tile_name}", heights)
        material.sgprt.biscale.height_scale = scale
        material.sgprt.biscale.samples = 512
        material.sgprt.biscale.lobes = 4
        _set_raw(material.sgprt, **settings)
        sphere.data.materials.append(material)
    result = _render(scene)
    techniques_used = {params.technique for name, params in result["state"].materials.items()
                       if name.startswith(scene.name)}
    assert techniques_used == {"SG_BISCALE"}, _warnings(result)
    assert _covered(result).mean() > 0.05
    assert result["passes"]["Specular"][..., :3].max() > 0


def test_non_finite_material_settings(engine):
    """NaN / Inf settings stored by a script: the defaults are used, and said."""
    scene = _new_scene("stress_nan_settings", 16, 16)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    fx.point_light(scene, "stress_nan_settings_light", (1.0, -3.0, 3.0), 1000.0)
    material = fx.material("stress_nan_settings", model="WARD_ANISO", lobe_count=2)
    _set_raw(material.sgprt, roughness=math.nan, alpha_x=math.inf, diffuse_color=(math.nan, 0.5, 0.5),
             tangent_axis=(math.nan, 0.0, 0.0))
    _uv_sphere(scene, "stress_nan_settings_sphere", (0.0, 0.0, 1.0), radius=1.5).data.materials.append(material)
    result = _render(scene)
    assert _covered(result).mean() > 0.3
    for name in ("roughness", "alpha_x", "diffuse_color", "tangent_axis"):
        assert _warned(result, "material 'stress_nan_settings'", name, "not finite"), (name, _warnings(result))


# --------------------------------------------------------------------------- geometry

def _mesh_object(scene, name, vertices, faces, location=(0.0, 0.0, 1.0), uv=False):
    import bpy

    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    if uv:
        mesh.uv_layers.new(name="uv")
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    return fx.add_object(scene, obj)


def test_degenerate_geometry(engine):
    """Zero-area triangles (collapsed to a point and to a line), a fan whose vertices have zero
    normals (every face degenerate), custom split normals of zero length, vertices at NaN / Inf /
    1e30, objects scaled by 0 along one axis and along all three."""
    scene = _new_scene("stress_degenerate", SIZE, SIZE)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    fx.point_light(scene, "stress_degenerate_light", (1.0, -3.0, 3.0), 1000.0)
    material = fx.material("stress_degenerate_material", model="WARD_ANISO", lobe_count=2)
    # a quad strip with collapsed triangles in the middle of good ones
    vertices = [(-1.0, 0.0, 0.0), (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (-1.0, 0.0, 1.0), (0.0, 0.0, 1.0),
                (1.0, 0.0, 1.0), (0.5, 0.0, 0.5), (0.5, 0.0, 0.5), (0.5, 0.0, 0.5), (0.0, 0.0, 0.2),
                (0.5, 0.0, 0.2), (1.0, 0.0, 0.2)]
    faces = [(0, 1, 4, 3), (1, 2, 5, 4), (6, 7, 8), (9, 10, 11)]
    collapsed = _mesh_object(scene, "stress_collapsed", vertices, faces, (-1.0, -1.0, 1.0), uv=True)
    collapsed.data.materials.append(material)
    # every face collapsed: the vertices' normals are zero
    line = _mesh_object(scene, "stress_zero_normals", [(0.0, 0.0, 0.0), (0.3, 0.0, 0.3), (0.6, 0.0, 0.6),
                                                       (0.3, 0.0, 0.3)], [(0, 1, 2), (0, 2, 3)], (1.0, -1.0, 1.2))
    line.data.materials.append(material)
    sphere = _uv_sphere(scene, "stress_custom_normals", (0.0, 0.5, 1.0), radius=0.6, segments=12, rings=6)
    sphere.data.materials.append(material)
    if hasattr(sphere.data, "normals_split_custom_set"):
        sphere.data.normals_split_custom_set([(0.0, 0.0, 0.0)] * len(sphere.data.loops))
    # vertices at NaN / Inf / 1e30 (a script or a broken modifier)
    broken = _uv_sphere(scene, "stress_nan_vertices", (-1.5, 1.0, 1.0), radius=0.6, segments=12, rings=6)
    broken.data.materials.append(material)
    broken.data.vertices[5].co = (math.nan, 0.0, 0.0)
    broken.data.vertices[9].co = (math.inf, 0.0, 1.0)
    broken.data.vertices[20].co = (1e30, -1e30, 0.0)
    # transforms that flatten (scale 0 along y) or collapse an object (scale 0)
    for name, scale in (("stress_flattened", (1.0, 0.0, 1.0)), ("stress_collapsed_scale", (0.0, 0.0, 0.0))):
        flat = _uv_sphere(scene, name, (1.5, 1.0, 1.0), radius=0.6, segments=12, rings=6)
        flat.data.materials.append(material)
        flat.scale = scale
    result = _render(scene)
    assert _covered(result).mean() > 0.05
    state = result["state"]
    assert _warned(result, "object 'stress_nan_vertices'", "2 vertices with NaN/Inf coordinates"), _warnings(result)
    for obj in ("stress_collapsed", "stress_zero_normals", "stress_custom_normals", "stress_nan_vertices"):
        mesh = state.meshes[state.objects[obj].mesh_key]
        for array in (mesh.positions, mesh.normals, mesh.tangents, mesh.uvs, mesh.vertex_normals):
            assert np.all(np.isfinite(array)), obj
        np.testing.assert_allclose(np.linalg.norm(mesh.normals, axis=1), 1.0, atol=1e-5, err_msg=obj)
        np.testing.assert_allclose(np.linalg.norm(mesh.tangents[:, :3], axis=1), 1.0, atol=1e-5, err_msg=obj)
    assert _warned(result, "stress_zero_normals", "normal"), _warnings(result)
    assert not _warned(result, "stress_custom_normals", "normal"), _warnings(result)


def test_missing_uvs(engine):
    """Textures and a UV tangent source on meshes without a UV map: rendered (textures at uv 0,
    object-axis tangents) and reported by object and material."""
    import bmesh
    import bpy

    scene = _new_scene("stress_no_uv", SIZE, SIZE)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    fx.point_light(scene, "stress_no_uv_light", (1.0, -3.0, 3.0), 1000.0)
    pixels = np.ones((8, 8, 4), np.float32)
    pixels[..., 0] = np.linspace(0.0, 1.0, 8)[None, :]
    normal_pixels = np.ones((8, 8, 4), np.float32)
    normal_pixels[..., :3] = (0.6, 0.4, 0.9)
    textured = fx.material("stress_no_uv_textured", model="GGX")
    textured.sgprt.diffuse_color_texture = fx.image("stress_no_uv_colour", pixels)
    textured.sgprt.normal_map = fx.image("stress_no_uv_normal", normal_pixels)
    aniso = fx.material("stress_no_uv_aniso", model="ASHIKHMIN_SHIRLEY", lobe_count=2, tangent_source="UV_MAP")
    for name, material, x in (("stress_no_uv_a", textured, -1.0), ("stress_no_uv_b", aniso, 1.0)):
        mesh = bpy.data.meshes.new(name)
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=12, v_segments=6, radius=0.8, calc_uvs=False)
        bm.to_mesh(mesh)
        bm.free()
        assert len(mesh.uv_layers) == 0
        mesh.materials.append(material)
        fx.add_object(scene, bpy.data.objects.new(name, mesh)).location = (x, 0.0, 1.0)
    result = _render(scene)
    assert _covered(result).mean() > 0.1
    assert _warned(result, "stress_no_uv_a", "stress_no_uv_textured", "uv"), _warnings(result)
    assert _warned(result, "stress_no_uv_b", "stress_no_uv_aniso", "tangent"), _warnings(result)


# --------------------------------------------------------------------------- scales

def _scaled_scene(scale):
    scene = _new_scene(f"stress_scale_{scale:g}", SIZE, SIZE)
    fx.world_colour(scene, (0.1, 0.1, 0.1))
    scene.camera.location = tuple(scale * c for c in scene.camera.location)
    scene.camera.data.clip_start = 0.1 * scale
    scene.camera.data.clip_end = 100.0 * scale
    # same irradiance at the same relative place: power ~ distance^2
    fx.point_light(scene, f"{scene.name}_point", (scale * 1.0, scale * -3.0, scale * 3.0), 1000.0 * scale ** 2,
                   radius=0.1 * scale)
    spot = fx.point_light(scene, f"{scene.name}_spot", (scale * -2.0, scale * -3.0, scale * 2.0),
                          500.0 * scale ** 2, radius=0.0, kind="SPOT")
    spot.rotation_euler = (math.radians(60.0), 0.0, math.radians(-30.0))
    area = fx.point_light(scene, f"{scene.name}_area", (0.0, scale * -2.0, scale * 3.0), 300.0 * scale ** 2,
                          kind="AREA")
    area.data.size = 0.5 * scale
    for model, x in (("GGX", -1.0), ("BLINN_PHONG", 1.0)):
        sphere = fx.uv_sphere(scene, f"{scene.name}_{model}", (scale * x, 0.0, scale * 1.0), radius=0.8 * scale,
                              segments=16, rings=8)
        sphere.data.materials.append(fx.material(f"{scene.name}_{model}", model=model, roughness=0.2))
    fx.plane(scene, f"{scene.name}_floor", (0.0, 0.0, 0.0), size=6.0 * scale)
    return scene


def test_scene_scales(engine):
    """The same scene at scale 1e-4, 1 and 1e4 (objects, camera, lights; light power ~ scale^2):
    finite, and the same picture up to float32 rounding of the geometry."""
    images = {}
    for scale in (1e-4, 1.0, 1e4):
        result = _render(_scaled_scene(scale))
        images[scale] = result["passes"]["Combined"][..., :3]
        assert _covered(result).mean() > 0.3
    reference = images[1.0]
    for scale in (1e-4, 1e4):
        difference = np.abs(images[scale] - reference)
        # silhouette pixels may flip; the rest agrees closely
        assert np.median(difference) < 1e-3 * reference.max(), scale
        assert np.mean(difference) < 0.02 * reference.mean(), scale


# --------------------------------------------------------------------------- NaN / Inf texels

def _poisoned(height, width, base, seed, count_nan, count_inf, channels=3):
    rng = np.random.default_rng(seed)
    pixels = np.ones((height, width, 4), np.float32)
    pixels[..., :3] = base
    flat = pixels.reshape(-1, 4)
    where = rng.choice(height * width, count_nan + count_inf, replace=False)
    channel = rng.integers(0, channels, count_nan + count_inf)
    flat[where[:count_nan], channel[:count_nan]] = np.nan
    flat[where[count_nan:], channel[count_nan:]] = np.where(rng.random(count_inf) < 0.5, np.inf, -np.inf)
    return pixels


@pytest.mark.parametrize("model", ["GGX", "WARD_ANISO"])
def test_nan_inf_texels(engine, model):
    """NaN and +-Inf texels in the diffuse colour, roughness (alpha_x) and normal map textures and in
    the world's HDRI: finite passes and a warning per image with its count."""
    scene = _new_scene(f"stress_texels_{model}", SIZE, SIZE)
    world_pixels = _poisoned(16, 32, 0.5, 1, 5, 4)
    world_pixels[13, 5, :3] = 200.0
    world_pixels[2, 7:9, :3] = 3e38                 # finite, but two of them overflow the prefilter's sums
    _world_image(scene, fx.image(f"stress_world_{model}", world_pixels))
    fx.point_light(scene, f"{scene.name}_light", (1.0, -3.0, 3.0), 1000.0)
    material = fx.material(f"stress_texels_{model}", model=model, lobe_count=2)
    images = {
        "diffuse_color_texture": fx.image(f"stress_diffuse_{model}", _poisoned(16, 16, 0.8, 2, 6, 3)),
        ("roughness_texture" if model == "GGX" else "alpha_x_texture"):
            fx.image(f"stress_rough_{model}", _poisoned(16, 16, 0.5, 3, 4, 4, channels=1)),
        "normal_map": fx.image(f"stress_normal_{model}", _poisoned(16, 16, (0.5, 0.5, 1.0), 4, 3, 5)),
    }
    for slot, image in images.items():
        setattr(material.sgprt, slot, image)
    sphere = _uv_sphere(scene, f"{scene.name}_sphere", (0.0, 0.0, 1.0), radius=1.2, segments=24, rings=12)
    sphere.data.materials.append(material)
    result = _render(scene)
    assert _covered(result).mean() > 0.2
    expected = {images["diffuse_color_texture"].name: 9, f"stress_world_{model}": 9,
                images["normal_map"].name: 8}
    for slot, image in images.items():
        if slot not in ("diffuse_color_texture", "normal_map"):
            expected[image.name] = 8
    for name, count in expected.items():
        assert _warned(result, f"'{name}'", f"{count} NaN/Inf texels replaced by 0"), (name, _warnings(result))
    assert _warned(result, f"world 'stress_texels_{model}_world'", f"'stress_world_{model}'", "2 texels beyond 1e+30 clamped")
    # the environment built from the repaired HDRI is finite too
    environment = result["state"].environment
    assert np.all(np.isfinite(environment.prefiltered.layers))
    assert np.all(np.isfinite(environment.lobe_amplitude))


def test_a_udim_image_is_named(engine):
    """A UDIM set of tiles: its first tile is read over every UV, and the render says so (Cycles reads them
    all); a single-tile image says nothing."""
    import bpy

    scene = _new_scene("stress_udim", 16, 16)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    sphere = _uv_sphere(scene, "stress_udim_sphere", (0.0, 0.0, 1.0), segments=8, rings=4)
    image = bpy.data.images.new("stress_udim", 4, 4, tiled=True)
    material = fx.material("stress_udim", model="GGX", diffuse_color_texture=image)
    sphere.data.materials.append(material)
    assert not any("UDIM" in line for line in _warnings(_render(scene)))
    image.tiles.new(tile_number=1002)
    assert _warned(_render(scene), "image 'stress_udim': a UDIM set of 2 tiles, of which SG-PRT reads tile 1001 "
                                   "alone over every UV"), _warnings(_render(scene))


def test_warnings_reset_per_render(engine):
    """A second render of a repaired scene does not keep the first one's warnings twice, and a
    clean scene has none."""
    scene = _new_scene("stress_clean", 16, 16)
    fx.world_colour(scene, (0.2, 0.2, 0.2))
    _uv_sphere(scene, "stress_clean_sphere", (0.0, 0.0, 1.0), segments=8, rings=4)
    assert _warnings(_render(scene)) == []
    material = fx.material("stress_once", model="GGX")
    material.sgprt.diffuse_color_texture = fx.image("stress_once_image", _poisoned(4, 4, 0.5, 5, 1, 0))
    scene.objects["stress_clean_sphere"].data.materials.append(material)
    first = _warnings(_render(scene))
    second = _warnings(_render(scene))
    assert first == second and len(first) == 1, (first, second)


# --------------------------------------------------------------------------- lights

def test_light_extremes(engine):
    """Point, spot, area and sun lights of zero energy, huge energy (1e20 W) and zero size, one of them
    inside the sphere and one at the shading point of the floor."""
    scene = _new_scene("stress_lights", SIZE, SIZE)
    fx.world_colour(scene, (0.0, 0.0, 0.0))
    lights = [
        ("zero_point", "POINT", (1.0, -3.0, 3.0), 0.0, 0.0),
        ("huge_point", "POINT", (-1.0, -3.0, 3.0), 1e20, 0.0),
        ("inside_point", "POINT", (0.0, 0.0, 1.0), 1e6, 0.0),
        ("on_floor", "POINT", (1.5, 0.0, 0.0), 1e3, 0.0),
        ("huge_on_floor", "POINT", (-1.5, 0.5, 0.0), 1e20, 0.0),
        ("zero_spot", "SPOT", (0.0, -3.0, 4.0), 0.0, 0.0),
        ("huge_spot", "SPOT", (0.0, -2.0, 4.0), 1e20, 0.0),
        ("zero_area", "AREA", (2.0, -2.0, 3.0), 1e3, 0.0),
        ("zero_sun", "SUN", (0.0, 0.0, 5.0), 0.0, 0.0),
        ("huge_sun", "SUN", (0.0, 0.0, 5.0), 1e20, 0.0),
        ("max_point", "POINT", (0.5, -3.0, 2.0), 3e38, 0.0),
    ]
    for name, kind, location, energy, radius in lights:
        light = fx.point_light(scene, f"stress_{name}", location, energy, radius=radius, kind=kind)
        if kind == "SPOT":
            light.data.spot_size = 0.0 if name.startswith("zero") else math.pi
        if kind == "AREA":
            light.data.size = 0.0
        if kind == "SUN":
            light.data.angle = 0.0
    for model, x in (("GGX", -1.0), ("ASHIKHMIN_SHIRLEY", 1.0)):
        sphere = fx.uv_sphere(scene, f"stress_lights_{model}", (x, 0.0, 1.0), radius=0.8, segments=16, rings=8)
        sphere.data.materials.append(fx.material(f"stress_lights_{model}", model=model, lobe_count=2))
    floor = fx.plane(scene, "stress_lights_floor", (0.0, 0.0, 0.0))
    mirror = fx.material("stress_lights_mirror", model="GGX")
    _set_raw(mirror.sgprt, roughness=1e-4)
    floor.data.materials.append(mirror)
    result = _render(scene)
    assert _covered(result).mean() > 0.3
    assert result["passes"]["Combined"][..., :3].max() > 1e10
    assert _warned(result, "light 'stress_max_point'", "clamped to +-1e+20"), _warnings(result)


@pytest.mark.parametrize("world", ["colour", "hdri"])
def test_non_finite_light_and_world_settings(engine, world):
    """NaN light power, colour, radius, spot size / blend, area size, sun angle, a light at a NaN
    location, a NaN world colour and strength (Blender stores what scripts set): finite, warned."""
    import bpy

    scene = _new_scene(f"stress_nan_lights_{world}", 32, 32)
    if world == "hdri":
        world_data = _world_image(scene, _hdri("stress_nan_lights_hdri"))
    else:
        world_data = fx.world_colour(scene, (0.2, 0.2, 0.2))
    uses_nodes = world_data.node_tree is not None and (bpy.app.version >= (5, 0, 0) or world_data.use_nodes)
    if uses_nodes:
        background = next(node for node in world_data.node_tree.nodes if node.type == "BACKGROUND")
        if world == "colour":
            background.inputs["Color"].default_value = (math.nan, 0.2, 0.2, 1.0)
        background.inputs["Strength"].default_value = math.nan
    else:                                   # Blender 4.x without world nodes: the world colour
        world_data.color = (math.nan, 0.2, 0.2)
    name = scene.name
    fx.point_light(scene, f"{name}_ok", (1.0, -3.0, 3.0), 1000.0)
    fx.point_light(scene, f"{name}_power", (-1.0, -3.0, 3.0), math.nan)
    fx.point_light(scene, f"{name}_colour", (-1.0, -3.0, 2.0), 100.0, colour=(math.nan, 1.0, 1.0))
    fx.point_light(scene, f"{name}_radius", (0.0, -3.0, 3.0), 100.0, radius=math.nan)
    spot = fx.point_light(scene, f"{name}_spot", (0.0, -3.0, 4.0), 100.0, kind="SPOT")
    spot.data.spot_size = math.nan
    spot.data.spot_blend = math.nan
    area = fx.point_light(scene, f"{name}_area", (2.0, -2.0, 3.0), 100.0, kind="AREA")
    area.data.size = math.nan
    sun = fx.point_light(scene, f"{name}_sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.data.angle = math.nan
    fx.point_light(scene, f"{name}_nowhere", (math.nan, 0.0, 3.0), 100.0)
    _uv_sphere(scene, f"{name}_sphere", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(
        fx.material(f"{name}_material", model="GGX"))
    result = _render(scene)
    assert _covered(result).mean() > 0.15
    expected = [(f"light '{name}_power'", "clamped"), (f"light '{name}_colour'", "clamped"),
                (f"light '{name}_radius'", "radius nan not finite"), (f"light '{name}_spot'", "spot size nan"),
                (f"light '{name}_spot'", "spot blend nan"), (f"light '{name}_area'", "size nan"),
                (f"light '{name}_sun'", "angle nan"), (f"light '{name}_nowhere'", "transform not finite")]
    if uses_nodes:
        expected.append((f"world '{world_data.name}'", "strength nan not finite"))
    if world == "colour":
        expected.append((f"world '{world_data.name}'", "colour", "not finite"))
    for words in expected:
        assert _warned(result, *words), (words, _warnings(result))
