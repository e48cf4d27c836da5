"""The engine's GLSL against its numpy mirror (techniques/sg/sg_shading.py) on the same pixels.

One render per scene writes the G-buffer (position, normal, tangent input, uv, material id);
techniques.sg.sg_shading.shade_fragments shades those pixels from the same material, lights and
environment data, and the two must agree to float32 round-off (max relative error 1e-3).
"""
import engine_fixtures as fx
import numpy as np
import pytest

TOLERANCE = 1e-3


@pytest.fixture(scope="module")
def engine(blender):
    fx.ensure_registered()
    return blender


def _mirror(result, textures_by_material=None, use_visibility=True, use_shadow_maps=True):
    """Numpy shading of every covered pixel; returns (expected, actual) diffuse/specular and mask.  With shadow
    maps, their lookups (lighting.shadow_maps.light_visibility) read the frame's atlas."""
    from sg_prt_addon import techniques
    from sg_prt_addon.lighting import shadow_maps

    passes, state = result["passes"], result["state"]
    camera = passes["camera"]
    uv = passes["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    material_of_id = {i: name for name, i in passes["material_ids"].items()}
    expected = {"Diffuse": np.zeros(uv.shape[:2] + (3,), np.float32),
                "Specular": np.zeros(uv.shape[:2] + (3,), np.float32)}
    light_data = state.light_data()
    object_of_pixel = np.rint(passes["gbuffer_normal"][..., 3]).astype(int)     # object index + 1
    for material_id in np.unique(uv[covered][:, 2]).astype(int):
        name = material_of_id[material_id]
        for object_index in np.unique(object_of_pixel[covered]):
            mask = covered & (np.abs(uv[..., 2] - material_id) < 0.25) & (object_of_pixel == object_index)
            if not mask.any():
                continue
            view_origin = camera.position if camera.is_perspective else camera.forward
            light_shadow = None
            if "shadow_atlas" in passes and use_shadow_maps:
                light_shadow = shadow_maps.light_visibility(passes["shadow_atlas"], passes["shadow_plan"], light_data,
                                                            passes["gbuffer_position"][mask][:, :3],
                                                            passes["gbuffer_normal"][mask][:, :3])
            params = state.materials[name]
            diffuse, specular = techniques.for_material(params).mirror(
                params, (textures_by_material or {}).get(name, {}),
                passes["gbuffer_position"][mask][:, :3], passes["gbuffer_normal"][mask][:, :3],
                passes["gbuffer_tangent"][mask], fx.mirror_uv(uv[mask]), view_origin, camera.is_perspective,
                light_data, state.environment,
                visibility=fx.pixel_visibility(result, mask) if use_visibility else None, light_shadow=light_shadow)
            expected["Diffuse"][mask] = diffuse
            expected["Specular"][mask] = specular
    return expected, covered


def _check(result, textures_by_material=None, minimum_coverage=0.2):
    assert "error" not in result, result.get("error")
    expected, covered = _mirror(result, textures_by_material)
    assert covered.mean() > minimum_coverage
    errors = {}
    for name in ("Diffuse", "Specular"):
        actual = result["passes"][name][..., :3][covered]
        reference = expected[name][covered]
        assert np.all(np.isfinite(actual))
        assert reference.max() > 0, f"{name}: the scene must light the pixels"
        errors[name] = float(fx.relative_error(actual, reference).max())
    combined = result["passes"]["Combined"][..., :3][covered]
    np.testing.assert_allclose(combined, (result["passes"]["Diffuse"] + result["passes"]["Specular"])[..., :3][covered],
                               rtol=1e-6, atol=1e-6)
    print("max relative error", errors)
    for name, error in errors.items():
        assert error <= TOLERANCE, f"{name}: max relative error {error:.2e} > {TOLERANCE}"
    return errors


def test_isotropic_models_lights_and_world_colour(engine):
    """GGX (with Fresnel, multiscatter and a layered diffuse: reflectance.layering), Cook-Torrance, Blinn-Phong
    and Ward on four spheres, point + spot + sun + area lights."""
    scene = fx.new_scene("mirror_isotropic", 256, 256)
    fx.world_colour(scene, (0.05, 0.07, 0.1))
    models = [("GGX", dict(roughness=0.35, fresnel="SCHLICK", multiscatter=True, layered_diffuse=True)), ("COOK_TORRANCE", dict(roughness=0.25, ior=1.6)),
              ("BLINN_PHONG", dict(exponent=60.0)), ("WARD_ISO", dict(alpha_x=0.15))]
    for index, (model, settings) in enumerate(models):
        x = -2.25 + 1.5 * index
        sphere = fx.uv_sphere(scene, f"sphere_{model}", (x, 0.0, 1.0), radius=0.7)
        sphere.data.materials.append(fx.material(f"mat_{model}", model=model, diffuse_color=(0.6, 0.4, 0.3),
                                                 specular_color=(0.5, 0.5, 0.5), **settings))
    fx.plane(scene, "floor", (0.0, 0.0, 0.3))      # no material: the defaults
    fx.point_light(scene, "point", (2.0, -3.0, 3.0), 800.0, radius=0.1)
    spot = fx.point_light(scene, "spot", (-2.0, -3.0, 4.0), 1500.0, radius=0.2, colour=(1.0, 0.8, 0.6), kind="SPOT")
    spot.rotation_euler = (0.6, -0.4, 0.0)
    spot.data.spot_size = 1.0
    spot.data.spot_blend = 0.3
    sun = fx.point_light(scene, "sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.rotation_euler = (0.5, 0.3, 0.0)
    sun.data.angle = 0.1
    area = fx.point_light(scene, "area", (0.0, -2.0, 3.0), 300.0, kind="AREA")
    area.data.size = 0.5
    result = fx.render(scene, gbuffer=True)
    _check(result)


def test_beckmann(engine):
    """The Glossy BSDF's Beckmann (alpha = roughness^2, Walter's Smith Lambda) on a sphere over the floor, a point
    light and a sun."""
    scene = fx.new_scene("mirror_beckmann", 128, 128)
    fx.world_colour(scene, (0.05, 0.07, 0.1))
    sphere = fx.uv_sphere(scene, "sphere_beckmann", (0.0, 0.0, 1.0), radius=0.8)
    sphere.data.materials.append(fx.material("mat_beckmann", model="BECKMANN", roughness=0.4,
                                             diffuse_color=(0.3, 0.3, 0.3), specular_color=(0.7, 0.7, 0.7)))
    fx.plane(scene, "floor", (0.0, 0.0, 0.2))
    fx.point_light(scene, "point", (2.0, -3.0, 3.0), 800.0, radius=0.1)
    sun = fx.point_light(scene, "sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.rotation_euler = (0.5, 0.3, 0.0)
    _check(fx.render(scene, gbuffer=True))


def test_anisotropic_models_textures_and_normal_map(engine):
    """Ward anisotropic and Ashikhmin-Shirley with textured parameters, a normal map and both tangent sources."""
    rng = np.random.default_rng(3)
    scene = fx.new_scene("mirror_textures", 192, 192)
    fx.world_colour(scene, (0.2, 0.2, 0.25))
    colour = np.ones((16, 16, 4), np.float32)
    colour[..., :3] = rng.uniform(0.2, 1.0, (16, 16, 3))
    scalar = np.ones((8, 8, 4), np.float32)
    scalar[..., 0] = rng.uniform(0.5, 1.5, (8, 8))
    bumps = np.ones((16, 16, 4), np.float32)
    bumps[..., :2] = rng.uniform(0.35, 0.65, (16, 16, 2))
    bumps[..., 2] = 0.9
    images = {"colour": fx.image("tex_colour", colour), "scalar": fx.image("tex_scalar", scalar),
              "bumps": fx.image("tex_bumps", bumps)}
    ward = fx.material("mat_ward", model="WARD_ANISO", alpha_x=0.3, alpha_y=0.08, lobe_count=4,
                       diffuse_color=(0.5, 0.5, 0.5), specular_color=(0.6, 0.6, 0.6), tangent_rotation=0.4)
    ward.sgprt.diffuse_color_texture = images["colour"]
    ward.sgprt.alpha_x_texture = images["scalar"]
    ward.sgprt.normal_map = images["bumps"]
    ward.sgprt.normal_strength = 0.8
    shirley = fx.material("mat_as", model="ASHIKHMIN_SHIRLEY", nu=50.0, nv=800.0, lobe_count=3,
                          tangent_source="OBJECT_AXIS", tangent_axis=(0.0, 0.0, 1.0))
    shirley.sgprt.specular_color_texture = images["colour"]
    shirley.sgprt.nv_texture = images["scalar"]
    fx.uv_sphere(scene, "ward", (-1.1, 0.0, 1.0), radius=0.9).data.materials.append(ward)
    fx.uv_sphere(scene, "shirley", (1.1, 0.0, 1.0), radius=0.9).data.materials.append(shirley)
    fx.point_light(scene, "point", (1.0, -3.0, 3.0), 1000.0, radius=0.05)
    result = fx.render(scene, gbuffer=True)
    from sg_prt_addon.blender import export
    textures = {
        "mat_ward": {"diffuse_color": colour, "alpha_x": scalar, "normal_map": bumps},
        "mat_as": {"specular_color": colour, "nv": scalar},
    }
    # the engine uploads exactly what export.image_pixels reads
    np.testing.assert_array_equal(export.texture_pixels(images["colour"], "diffuse_color"), colour)
    # the spheres carry a UV map: the lookups cover many texels, not one
    uv = result["passes"]["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    texels = np.unique(np.floor(uv[covered][:, :2] * 16).astype(int), axis=0)
    assert len(texels) > 100, len(texels)
    _check(result, textures)


def test_environment_texture(engine):
    """Prefiltered environment (specular) and SG mixture (diffuse) from a world Environment Texture."""
    import bpy

    # Blender's courtyard, box-filtered to 128 x 64 so the prefilter takes a moment, as a float image
    source = bpy.data.images.load(fx.studio_world_path("courtyard.exr"), check_existing=True)
    width, height = source.size
    pixels = np.empty(width * height * 4, np.float32)
    source.pixels.foreach_get(pixels)
    small = pixels.reshape(64, height // 64, 128, width // 128, 4).mean(axis=(1, 3))
    scene = fx.new_scene("mirror_environment", 160, 160)
    world = fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    world.node_tree.nodes["Environment Texture"].image = fx.image("courtyard_small", small)
    glossy = fx.material("mat_env_ggx", model="GGX", roughness=0.25, diffuse_color=(0.3, 0.3, 0.3),
                         specular_color=(0.8, 0.8, 0.8))
    shirley = fx.material("mat_env_as", model="ASHIKHMIN_SHIRLEY", nu=30.0, nv=300.0, lobe_count=2)
    # lobes broader than the broadest prefiltered level: the lookup blends to the mean radiance
    rough = fx.material("mat_env_rough", model="GGX", roughness=1.0)
    fx.uv_sphere(scene, "glossy", (-1.2, 0.0, 1.0), radius=0.7).data.materials.append(glossy)
    fx.uv_sphere(scene, "brushed", (0.4, 0.0, 1.0), radius=0.7).data.materials.append(shirley)
    fx.uv_sphere(scene, "rough", (1.6, 0.0, 1.4), radius=0.5).data.materials.append(rough)
    result = fx.render(scene, gbuffer=True, environment_layer_size=32)
    assert result["state"].environment.prefiltered is not None
    _check(result)


def test_orthographic_camera(engine):
    """The orthographic view direction (the camera's forward, not towards a position)."""
    scene = fx.new_scene("mirror_ortho", 96, 96)
    scene.camera.data.type = "ORTHO"
    scene.camera.data.ortho_scale = 3.0
    fx.world_colour(scene, (0.1, 0.1, 0.1))
    fx.uv_sphere(scene, "ortho_sphere", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(
        fx.material("mat_ortho", model="COOK_TORRANCE", roughness=0.2, ior=1.8))
    fx.point_light(scene, "ortho_light", (2.0, -3.0, 2.0), 600.0, radius=0.3)
    result = fx.render(scene, gbuffer=True)
    assert not result["passes"]["camera"].is_perspective
    _check(result)


def _shadow_scene(name, size):
    """A sphere over a 24 x 24 floor, both baked (the sphere shadows the floor and itself)."""
    scene = fx.new_scene(name, size, size)
    scene.camera.location = (0.0, -5.0, 3.0)
    scene.camera.rotation_euler = (1.05, 0.0, 0.0)
    sphere = fx.uv_sphere(scene, name + "_sphere", (0.0, 0.0, 1.0), radius=0.8, segments=24, rings=12)
    sphere.data.materials.append(fx.material(name + "_ggx", model="GGX", roughness=0.3,
                                             diffuse_color=(0.6, 0.5, 0.4), specular_color=(0.5, 0.5, 0.5)))
    floor = fx.grid(scene, name + "_floor", (0.0, 0.0, 0.0), size=5.0, segments=24)
    floor.data.materials.append(fx.material(name + "_floor_mat", model="COOK_TORRANCE", roughness=0.3,
                                            diffuse_color=(0.7, 0.7, 0.7), specular_color=(0.2, 0.2, 0.2)))
    return scene, sphere, floor


def test_visibility_lights_and_world_colour(engine, bakes):
    """SSDF shadows (HAS_VISIBILITY variant): point light + sun + world colour, both objects baked."""
    scene, sphere, floor = _shadow_scene("mirror_shadow_lights", 128)
    fx.world_colour(scene, (0.1, 0.12, 0.15))
    fx.point_light(scene, "shadow_point", (1.5, -1.0, 3.5), 1500.0, radius=0.4)
    sun = fx.point_light(scene, "shadow_sun", (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.rotation_euler = (0.4, -0.5, 0.0)
    sun.data.angle = 0.3
    bakes(scene, [sphere, floor], resolution=12)
    result = fx.render(scene, gbuffer=True)
    state = result["state"]
    assert len(state.visibility) == 2, state.visibility_status
    _check(result)
    _assert_shadows(result)


@pytest.mark.parametrize("view_warp", ["PAPER", "SPLIT2"])
def test_view_warps_with_visibility(engine, bakes, view_warp):
    """A material's view warp (material.sgprt.sg.view_warp: one or two lobes per NDF lobe instead of three)
    reaches the shader (WARP_FUNCTION / WARP_NODES of its variant) and the mirror alike, shadows included."""
    from sg_prt_addon.spherical import warp

    scene, sphere, floor = _shadow_scene("mirror_warp_" + view_warp.lower(), 96)
    fx.world_colour(scene, (0.1, 0.12, 0.15))
    fx.point_light(scene, "warp_point_" + view_warp, (1.5, -1.0, 3.5), 1500.0, radius=0.1)
    sphere.data.materials[0] = fx.material("mirror_warp_as_" + view_warp, model="ASHIKHMIN_SHIRLEY", nu=40.0,
                                           nv=400.0, lobe_count=3, tangent_source="OBJECT_AXIS",
                                           tangent_axis=(0.0, 0.0, 1.0), sg={"view_warp": view_warp})
    floor.data.materials[0].sgprt.sg.view_warp = view_warp
    bakes(scene, [sphere, floor], resolution=12)
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True)
    assert {key.warp_mode for key in keys} == {view_warp.lower()}
    assert {int(fx.variant_defines(key)["WARP_NODES"]) for key in keys} == {warp.nodes_per_lobe(view_warp.lower())}
    assert all(material.warp_mode == view_warp.lower() for material in result["state"].materials.values()
               if material.name)
    _check(result)


def _assert_shadows(result, unshadowed_scene=False):
    """The visibility variant really shadows: many pixels lose over 20% of their diffuse light (against the mirror
    without visibility, or, unshadowed_scene, without the shadow maps too)."""
    shadowed, covered = _mirror(result)
    unshadowed, _ = _mirror(result, use_visibility=False, use_shadow_maps=not unshadowed_scene)
    darker = shadowed["Diffuse"][covered].sum(-1) < 0.8 * unshadowed["Diffuse"][covered].sum(-1)
    print("pixels darkened by the shadows", darker.mean())
    assert darker.mean() > 0.05


def test_visibility_environment(engine, bakes):
    """SSDF shadows of the environment SG mixture (eq. 39) and the prefiltered specular (eq. 41)."""
    import bpy

    source = bpy.data.images.load(fx.studio_world_path("courtyard.exr"), check_existing=True)
    width, height = source.size
    pixels = np.empty(width * height * 4, np.float32)
    source.pixels.foreach_get(pixels)
    small = pixels.reshape(64, height // 64, 128, width // 128, 4).mean(axis=(1, 3))
    scene, sphere, floor = _shadow_scene("mirror_shadow_env", 96)
    world = fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    world.node_tree.nodes["Environment Texture"].image = fx.image("courtyard_small_shadow", small)
    bakes(scene, [sphere, floor], resolution=12)
    result = fx.render(scene, gbuffer=True, environment_layer_size=32)
    assert len(result["state"].visibility) == 2
    _check(result)
    _assert_shadows(result)


def test_node_material_with_computed_textures(engine):
    """A Principled BSDF over a PBR texture set with a metallic map (its colours are textures computed from
    two images: export.slot_pixels) and a roughness map, read from its node tree: shader against mirror."""
    import bpy

    from benchmarks import node_materials
    from sg_prt_addon.blender import export
    from sg_prt_addon.reflectance.texture_expression import Expression

    scene = fx.new_scene("mirror_nodes", 160, 160)
    fx.world_colour(scene, (0.2, 0.22, 0.25))
    material = node_materials.pbr_metallic_map()
    fx.uv_sphere(scene, "pbr_sphere", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(material)
    fx.point_light(scene, "point", (1.5, -3.0, 3.0), 900.0, radius=0.1)
    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    params = result["state"].materials[material.name]
    assert params.source == "NODE_TREE" and isinstance(params.textures["diffuse_color"], Expression)
    textures = {slot: export.slot_pixels(value, slot, True if slot in params.decoded_slots else None)
                for slot, value in params.textures.items()}
    assert set(textures) == {"diffuse_color", "specular_color", "roughness"} and bpy.data.images["pbr_metallic"]
    _check(result, {material.name: textures})


def test_node_material_with_channels_products_and_functions(engine):
    """A Principled BSDF whose Base Color is an image's channels recombined (Separate and Combine Color) and
    overlaid on the image (Mix, Overlay), and whose Roughness is a Color Ramp's colour (read as its luminance)
    of a product of two channels (Math): each slot's GLSL (material_textures, node_functions.glsl) against the
    Expression sampled per pixel (texture_expression.BoundExpression, node_functions.py)."""
    import bpy

    from benchmarks import node_values
    from sg_prt_addon.blender import export

    scene = fx.new_scene("mirror_node_channels", 96, 96)
    fx.world_colour(scene, (0.2, 0.22, 0.25))
    material = bpy.data.materials.new("node_channels")
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    principled = next(node for node in tree.nodes if node.type == "BSDF_PRINCIPLED")
    tree.links.new(node_values.mix_blend("OVERLAY")(tree), principled.inputs["Base Color"])
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    tree.links.new(node_values._image_node(tree, "Non-Color").outputs["Color"], separate.inputs[0])
    product = tree.nodes.new("ShaderNodeMath")
    product.operation = "MULTIPLY"
    tree.links.new(separate.outputs["Red"], product.inputs[0])
    tree.links.new(separate.outputs["Blue"], product.inputs[1])
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.interpolation = "EASE"
    ramp.color_ramp.elements[0].color = (0.1, 0.2, 0.15, 1.0)
    ramp.color_ramp.elements[1].position = 0.4
    ramp.color_ramp.elements[1].color = (0.8, 0.6, 0.7, 1.0)
    tree.links.new(product.outputs[0], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], principled.inputs["Roughness"])
    fx.uv_sphere(scene, "channels_sphere", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(material)
    fx.point_light(scene, "point", (1.5, -3.0, 3.0), 900.0, radius=0.1)
    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    params = result["state"].materials[material.name]
    assert not isinstance(params.textures["diffuse_color"], str) and not isinstance(params.textures["roughness"], str)
    textures = {slot: export.slot_pixels(value, slot, True if slot in params.decoded_slots else None)
                for slot, value in params.textures.items()}
    _check(result, {material.name: textures})


def test_anisotropic_ggx_with_its_tails(engine):
    """Anisotropic GGX (the Principled BSDF's anisotropy) under courtyard.exr and a point light: its table
    lobes, the light tail, the environment tail from GGX's albedo at the equivalent roughness, and the layer."""
    scene = fx.new_scene("mirror_ggx_aniso", 128, 128)
    fx.world_texture(scene, fx.studio_world_path("courtyard.exr"))
    brushed = fx.material("mat_ggx_aniso", model="GGX_ANISO", alpha_x=0.35, alpha_y=0.06, lobe_count=4,
                          diffuse_color=(0.1, 0.1, 0.1), specular_color=(0.9, 0.8, 0.6), tangent_rotation=0.3,
                          fresnel="SCHLICK", multiscatter=True)
    fx.uv_sphere(scene, "ggx_aniso", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(brushed)
    fx.point_light(scene, "point", (1.0, -3.0, 3.0), 900.0, radius=0.05)
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True, environment_layer_size=32)
    assert {key.model for key in keys} == {"GGX_ANISO"}
    assert "ENVIRONMENT_TAIL" in fx.variant_defines(next(iter(keys)))
    _check(result)


def test_node_material_with_tiled_uvs(engine):
    """An Image Texture behind a Mapping node (scale 3 x 2, a turn, an offset): texture coordinates beyond
    [0, 1] repeat through the manual bilinear fetch (material_texture), against the mirror's wrapped fetch."""
    from benchmarks import node_materials
    from sg_prt_addon.blender import export

    scene = fx.new_scene("mirror_tiled", 128, 128)
    fx.world_colour(scene, (0.3, 0.3, 0.35))
    material = node_materials.tiled()
    fx.uv_sphere(scene, "tiled_sphere", (0.0, 0.0, 1.0), radius=1.2).data.materials.append(material)
    fx.point_light(scene, "point", (1.5, -3.0, 3.0), 600.0, radius=0.1)
    result = fx.render(scene, gbuffer=True)
    assert "error" not in result, result.get("error")
    params = result["state"].materials[material.name]
    assert params.uv_transform != (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    uv = result["passes"]["gbuffer_uv"]
    covered = uv[..., 3] > 0.5
    assert uv[covered][:, :2].max() > 2.0 and uv[covered][:, :2].min() < 0.0       # tiled beyond [0, 1]
    _check(result, {material.name: {"diffuse_color": export.slot_pixels(params.textures["diffuse_color"],
                                                                        "diffuse_color")}})


@pytest.mark.parametrize("baked", [False, True])
def test_shadow_maps(engine, bakes, baked):
    """Light Shadows = Shadow Maps: a point light, a spot and a sun, each with a map (lighting.shadow_maps), and a
    wide sphere light without one (SSDF, or unshadowed unbaked); the mirror's lookups read the frame's atlas.  With a
    bake the wide light and the maps' softness blend in the SSDF; without one the maps alone shadow."""
    scene, sphere, floor = _shadow_scene("mirror_shadow_maps_" + str(baked), 96)
    scene.sgprt.light_shadows = "SHADOW_MAPS"
    scene.sgprt.shadow_map_size = 256
    fx.world_colour(scene, (0.05, 0.06, 0.08))
    fx.point_light(scene, "maps_point_" + str(baked), (1.5, -1.0, 3.5), 800.0, radius=0.1)
    spot = fx.point_light(scene, "maps_spot_" + str(baked), (-1.5, -1.5, 3.0), 900.0, radius=0.05, kind="SPOT")
    spot.rotation_euler = (0.5, -0.4, 0.0)
    fx.point_light(scene, "maps_wide_" + str(baked), (-2.0, 1.0, 2.0), 300.0, radius=1.0)
    sun = fx.point_light(scene, "maps_sun_" + str(baked), (0.0, 0.0, 5.0), 2.0, kind="SUN")
    sun.rotation_euler = (0.4, -0.5, 0.0)
    sun.data.angle = 0.05
    if baked:
        bakes(scene, [sphere, floor], resolution=12)
    with fx.recorded_variant_keys() as keys:
        result = fx.render(scene, gbuffer=True)
    assert all(key.shadow_maps for key in keys)
    plan = result["passes"]["shadow_plan"]
    assert sorted(plan.slot_lights) == [0, 1, 3], plan.slot_lights     # the point, the spot and the sun (index 3)
    assert len(result["state"].visibility) == (2 if baked else 0)
    _check(result)
    if not baked:
        _assert_shadows(result, unshadowed_scene=True)
