"""Blender's node materials read by blender/node_reader.py and chosen by material.sgprt.source: the reading
of hand-built trees per node and socket, the default source, one warning per material, saved and reopened."""
import numpy as np
import pytest
import recording_layout

bpy = pytest.importorskip("bpy")


def _material(name):
    material = bpy.data.materials.new(name)
    material.use_fake_user = True              # kept when saved without a user
    if bpy.app.version < (5, 0, 0):
        material.use_nodes = True
    tree = material.node_tree
    for node in list(tree.nodes):
        tree.nodes.remove(node)
    output = tree.nodes.new("ShaderNodeOutputMaterial")
    return material, tree, output


def _principled(tree, output, **inputs):
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    for name, value in inputs.items():
        node.inputs[name.replace("_", " ")].default_value = value
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return node


def _image(name, pixels, colorspace="sRGB"):
    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True)
    image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.pack()
    return image


def _read(material):
    from sg_prt_addon.blender import export
    messages = export.collect_warnings([])
    try:
        params = export.export_material(material)
    finally:
        export.collect_warnings(None)
    return params, messages


def test_principled_dielectric(empty_file):
    material, tree, output = _material("dielectric")
    _principled(tree, output, Base_Color=(0.8, 0.1, 0.05, 1.0), Roughness=0.35, IOR=1.5, Metallic=0.0)
    params, warnings = _read(material)
    assert material.sgprt.source == "NODE_TREE" and params.source == "NODE_TREE"
    assert params.model == "GGX" and params.roughness == pytest.approx(0.35)
    assert params.diffuse_color == pytest.approx((0.8, 0.1, 0.05))
    assert params.specular_color == pytest.approx((0.04,) * 3, abs=1e-6)
    assert params.fresnel == "SCHLICK" and params.multiscatter and params.layered_f0 == pytest.approx(0.04)
    assert warnings == []


def test_principled_metal_textures_and_normal_map(empty_file):
    material, tree, output = _material("gold")
    node = _principled(tree, output, Base_Color=(1.0, 0.77, 0.34, 1.0), Metallic=1.0, Specular_IOR_Level=0.5)
    node.distribution = "GGX"
    colour = _image("base", np.full((4, 4, 4), 0.5))
    rough = _image("rough", np.full((4, 4, 4), 0.4), colorspace="Non-Color")
    bumps = _image("bumps", np.full((4, 4, 4), (0.5, 0.5, 1.0, 1.0)), colorspace="Non-Color")
    for image, socket in ((colour, "Base Color"), (rough, "Roughness")):
        texture = tree.nodes.new("ShaderNodeTexImage")
        texture.image = image
        tree.links.new(texture.outputs["Color"], node.inputs[socket])
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    normal_map.inputs["Strength"].default_value = 0.7
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bumps
    tree.links.new(texture.outputs["Color"], normal_map.inputs["Color"])
    tree.links.new(normal_map.outputs["Normal"], node.inputs["Normal"])
    params, warnings = _read(material)
    assert params.textures == {"specular_color": "base", "roughness": "rough", "normal_map": "bumps"}
    assert params.roughness == pytest.approx(1.0)        # the factor: the texture holds the value
    assert params.diffuse_color == pytest.approx((0.0, 0.0, 0.0)) and params.layered_f0 < 0
    assert params.specular_color == pytest.approx((1.0, 1.0, 1.0)) and not params.multiscatter
    assert params.normal_strength == pytest.approx(0.7)
    assert params.decoded_slots == () and warnings == []
    rough.colorspace_settings.name = "sRGB"              # Blender decodes it: so does the engine
    assert _read(material)[0].decoded_slots == ("roughness",)


def test_mix_add_emission_and_math(empty_file):
    material, tree, output = _material("mix")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 0.25
    math = tree.nodes.new("ShaderNodeMath")
    math.operation = "MULTIPLY"
    math.inputs[1].default_value = 2.0
    tree.links.new(value.outputs[0], math.inputs[0])
    tree.links.new(math.outputs[0], glossy.inputs["Roughness"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.3
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 0.5, 0.0, 1.0)
    emission.inputs["Strength"].default_value = 2.0
    add = tree.nodes.new("ShaderNodeAddShader")
    tree.links.new(mix.outputs[0], add.inputs[0])
    tree.links.new(emission.outputs[0], add.inputs[1])
    tree.links.new(add.outputs[0], output.inputs["Surface"])
    params, warnings = _read(material)
    assert params.diffuse_color == pytest.approx((0.14, 0.28, 0.42))
    assert params.specular_color == pytest.approx((0.27, 0.27, 0.27))
    assert params.roughness == pytest.approx(0.5) and params.fresnel == "NONE" and not params.multiscatter
    assert params.layered_f0 < 0 and params.emission == pytest.approx((2.0, 1.0, 0.0))
    assert warnings == []


def test_unsupported_nodes_give_one_warning_naming_them(empty_file):
    material, tree, output = _material("odd")
    node = _principled(tree, output, Coat_Weight=0.5, Alpha=0.5)
    blackbody = tree.nodes.new("ShaderNodeBlackbody")
    tree.links.new(blackbody.outputs["Color"], node.inputs["Base Color"])
    node.inputs["Base Color"].default_value = (0.3, 0.3, 0.3, 1.0)
    params, warnings = _read(material)
    assert len(warnings) == 1, warnings
    text = warnings[0]
    assert "'odd' (node tree)" in text and "Blackbody" in text and "(0.3, 0.3, 0.3)" in text
    assert "the coat" in text and "transparency: shadows are cast as by an opaque surface" in text
    assert params.diffuse_color == pytest.approx((0.3, 0.3, 0.3))


def test_source_defaults_and_survives_reopening(empty_file, tmp_path):
    node_material, tree, output = _material("nodes")
    _principled(tree, output, Base_Color=(0.1, 0.2, 0.3, 1.0))
    tuned, tree, output = _material("tuned")
    _principled(tree, output)
    tuned.sgprt.model = "WARD_ISO"                     # given SG-PRT settings: they render
    chosen, tree, output = _material("chosen")
    _principled(tree, output)
    chosen.sgprt.diffuse_color = (1.0, 0.0, 0.0)
    chosen.sgprt.source = "NODE_TREE"                  # an explicit choice wins
    assert (node_material.sgprt.source, tuned.sgprt.source, chosen.sgprt.source) == ("NODE_TREE", "SETTINGS",
                                                                                     "NODE_TREE")
    assert _read(tuned)[0].model == "WARD_ISO" and _read(tuned)[0].source == "SETTINGS"
    path = tmp_path / "sources.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    materials = bpy.data.materials
    assert [materials[name].sgprt.source for name in ("nodes", "tuned", "chosen")] == ["NODE_TREE", "SETTINGS",
                                                                                       "NODE_TREE"]
    assert _read(materials["nodes"])[0].diffuse_color == pytest.approx((0.1, 0.2, 0.3))
    assert _read(materials["chosen"])[0].diffuse_color == pytest.approx((0.8, 0.8, 0.8))


def test_panel_and_copy_from_node_tree(empty_file):
    """The material panel shows the source and the copy button for a node material, the settings after the
    copy; the copy writes the reading into the settings, which then render the same parameters."""
    from sg_prt_addon.blender import panels

    material, tree, output = _material("copied")
    _principled(tree, output, Base_Color=(0.6, 0.3, 0.1, 1.0), Roughness=0.45, Metallic=0.0)
    before = _read(material)[0]

    def drawn():
        return recording_layout.draw(panels.SGPRT_PT_material, type("Context", (), {"material": material})())

    calls = drawn()
    assert ("prop", "source") in calls and ("operator", "sgprt.copy_from_node_tree") in calls
    # one Surface panel: the node tree's surface drawn in it, and Blender's own not shown beside it
    assert ("template_node_view", "Surface") in calls and ("prop", "model") not in calls
    assert panels.SGPRT_PT_material.bl_label == "Surface"
    assert panels.ENGINE_ID not in bpy.types.EEVEE_MATERIAL_PT_surface.COMPAT_ENGINES
    with bpy.context.temp_override(material=material):
        assert bpy.ops.sgprt.copy_from_node_tree() == {"FINISHED"}
    assert material.sgprt.source == "SETTINGS" and ("prop", "model") in drawn()
    after = _read(material)[0]
    for name in ("model", "diffuse_color", "specular_color", "roughness", "fresnel", "multiscatter"):
        assert getattr(after, name) == pytest.approx(getattr(before, name)), name
    assert after.layered_f0 == pytest.approx(before.layered_f0, abs=1e-6)


def test_metallic_map_and_texture_factors_compute_textures(empty_file):
    """A metallic map and a Mix Shader's texture factor: the slots are computed per pixel from the images
    (export.slot_pixels: the expression bound to the decoded pixels), equal to the formulas there."""
    from sg_prt_addon.blender import export, images
    from sg_prt_addon.reflectance.texture_expression import Expression

    rng = np.random.default_rng(2)
    base_pixels = np.ones((4, 4, 4), np.float32)
    base_pixels[..., :3] = rng.uniform(0.1, 0.9, (4, 4, 3))
    metal_pixels = np.ones((4, 4, 4), np.float32)
    metal_pixels[..., :3] = rng.integers(0, 2, (4, 4, 1))
    material, tree, output = _material("metal_map")
    node = _principled(tree, output, Roughness=0.3)
    _link_image(tree, _image("pbr_base", base_pixels), node.inputs["Base Color"])
    _link_image(tree, _image("pbr_metal", metal_pixels, "Non-Color"), node.inputs["Metallic"])
    params, warnings = _read(material)
    assert warnings == []
    assert isinstance(params.textures["diffuse_color"], Expression)
    assert params.diffuse_color == (1.0, 1.0, 1.0) and params.specular_color == (1.0, 1.0, 1.0)
    base = export.srgb_to_linear(images.image_pixels(bpy.data.images["pbr_base"])[..., :3])    # as stored: bytes
    metal = images.image_pixels(bpy.data.images["pbr_metal"])[..., :3]
    np.testing.assert_allclose(_at_texels(params.textures["diffuse_color"], "diffuse_color"), base * (1 - metal),
                               atol=1e-6)
    np.testing.assert_allclose(_at_texels(params.textures["specular_color"], "specular_color"),
                               metal * base + (1 - metal) * 0.04, atol=1e-6)

    material, tree, output = _material("mix_map")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.2, 0.4, 0.6, 1.0)
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = tree.nodes.new("ShaderNodeMixShader")
    _link_image(tree, bpy.data.images["pbr_metal"], mix.inputs["Fac"])
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    params, warnings = _read(material)
    assert warnings == []
    np.testing.assert_allclose(_at_texels(params.textures["diffuse_color"], "diffuse_color"),
                               (1 - metal) * (0.2, 0.4, 0.6), atol=1e-6)
    # the factor is a number: the image's red channel on all three
    np.testing.assert_allclose(_at_texels(params.textures["specular_color"], "specular_color"), metal[..., :1] * (1, 1, 1),
                               atol=1e-6)


def _at_texels(value, slot, side=4):
    """A computed slot sampled as the mirrors sample it, at the centres of a side x side image's texels."""
    from sg_prt_addon.blender import export

    centres = (np.arange(side) + 0.5) / side
    uv = np.stack(np.broadcast_arrays(centres[None, :], centres[:, None]), -1).reshape(-1, 2).astype(np.float32)
    return export.slot_pixels(value, slot).sample(uv)[:, :3].reshape(side, side, 3)


def _link_image(tree, image, socket):
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], socket)
    return texture


def test_mapping_node_on_uvs(empty_file):
    """A Mapping node between the UVs and the Image Textures: the material's UV transform (POINT: R S uv + L;
    TEXTURE: its inverse); textures under different mappings are named."""
    material, tree, output = _material("mapped")
    node = _principled(tree, output)
    texture = _link_image(tree, _image("mapped_base", np.full((4, 4, 4), 0.5)), node.inputs["Base Color"])
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (4.0, 2.0, 1.0)
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, np.pi / 2)
    mapping.inputs["Location"].default_value = (0.25, 0.5, 0.0)
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    params, warnings = _read(material)
    assert warnings == []
    np.testing.assert_allclose(params.uv_transform, (0.0, -2.0, 0.25, 4.0, 0.0, 0.5), atol=1e-6)
    mapping.vector_type = "TEXTURE"
    a, b, c, d, e, f = _read(material)[0].uv_transform
    forward = np.array([[0.0, -2.0, 0.25], [4.0, 0.0, 0.5], [0.0, 0.0, 1.0]])
    np.testing.assert_allclose(np.array([[a, b, c], [d, e, f], [0, 0, 1]]) @ forward, np.eye(3), atol=1e-6)
    _link_image(tree, _image("unmapped_rough", np.full((4, 4, 4), 0.5), "Non-Color"), node.inputs["Roughness"])
    params, warnings = _read(material)
    assert len(warnings) == 1 and "different Mapping" in warnings[0]


def test_node_tree_chosen_over_tuned_settings_reads_nothing_from_them(empty_file):
    """A material whose settings were tuned, then switched to its node tree: what the nodes do not set takes
    the defaults (a Glossy BSDF has no layered diffuse, no object-axis tangent), not the tuned settings."""
    material, tree, output = _material("switched")
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    tree.links.new(glossy.outputs[0], output.inputs["Surface"])
    settings = material.sgprt
    settings.model, settings.layered_diffuse, settings.ior = "WARD_ANISO", True, 2.0
    settings.tangent_source, settings.tangent_rotation, settings.normal_strength = "OBJECT_AXIS", 0.7, 3.0
    assert _read(material)[0].layered_f0 > 0                      # the settings render them
    settings.source = "NODE_TREE"
    params, warnings = _read(material)
    assert warnings == [] and params.model == "GGX" and params.fresnel == "NONE"
    assert params.layered_f0 < 0 and params.ior == 1.5
    assert (params.tangent_source, params.tangent_rotation, params.normal_strength) == ("UV_MAP", 0.0, 1.0)


def test_a_beckmann_glossy_reads_as_beckmann(empty_file):
    """The Glossy BSDF's Beckmann reads as the Beckmann model at the node's roughness, without a word; an
    anisotropic one as anisotropic Ward, which its warning says."""
    for distribution, anisotropy, model in (("BECKMANN", 0.0, "BECKMANN"), ("GGX", 0.0, "GGX"),
                                            ("BECKMANN", 0.5, "WARD_ANISO")):
        material, tree, output = _material(f"glossy_{distribution.lower()}_{anisotropy}")
        glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = distribution
        glossy.inputs["Roughness"].default_value = 0.4
        glossy.inputs["Anisotropy"].default_value = anisotropy
        tree.links.new(glossy.outputs[0], output.inputs["Surface"])
        params, warnings = _read(material)
        said = [w for w in warnings if "Beckmann" in w]
        assert params.model == model, warnings
        assert len(said) == (1 if model == "WARD_ANISO" else 0), warnings
        if model == "BECKMANN":
            assert params.roughness == pytest.approx(0.4)


def test_a_shader_inside_a_group_and_the_output_eevee_renders(empty_file):
    """A Principled BSDF inside a node group reads as if it were in the material's tree (its notes name it by
    its path), with the group node's own input values; of an output for Cycles and one for EEVEE, EEVEE's."""
    material, tree, cycles_output = _material("grouped")
    cycles_output.target = "CYCLES"
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    tree.links.new(diffuse.outputs[0], cycles_output.inputs["Surface"])
    eevee_output = tree.nodes.new("ShaderNodeOutputMaterial")
    eevee_output.target = "EEVEE"
    group = bpy.data.node_groups.new("Shell", "ShaderNodeTree")
    group.interface.new_socket("Roughness", in_out="INPUT", socket_type="NodeSocketFloat").default_value = 0.5
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    group_input, group_output = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    principled = group.nodes.new("ShaderNodeBsdfPrincipled")
    group.links.new(group_input.outputs["Roughness"], principled.inputs["Roughness"])
    blackbody = group.nodes.new("ShaderNodeBlackbody")
    group.links.new(blackbody.outputs["Color"], principled.inputs["Base Color"])
    group.links.new(principled.outputs[0], group_output.inputs["Shader"])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    node.name = "Outer"
    node.inputs["Roughness"].default_value = 0.2
    tree.links.new(node.outputs["Shader"], eevee_output.inputs["Surface"])
    params, warnings = _read(material)
    assert params.roughness == pytest.approx(0.2) and params.specular_color != (0.0, 0.0, 0.0)
    assert len(warnings) == 1 and "'Outer/Blackbody' (Blackbody)" in warnings[0], warnings


def test_colour_attributes_export_per_corner_and_non_finite_ones_are_named(empty_file):
    """The mesh's default colour attribute is exported per corner (a point attribute at each corner's vertex); a
    NaN in it becomes 0 and the warning names the attribute."""
    from sg_prt_addon.blender import export
    from sg_prt_addon.blender.export.meshes import export_mesh_data

    mesh = bpy.data.meshes.new("coloured")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    attribute = mesh.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    attribute.data.foreach_set("color", np.array([1, 0, 0, 1, 0, 1, 0, 1, np.nan, 0, 1, 1], np.float32))
    messages = export.collect_warnings([])
    try:
        exported = export_mesh_data(mesh, "coloured")
    finally:
        export.collect_warnings(None)
    np.testing.assert_allclose(exported.colors, [[1, 0, 0, 1], [0, 1, 0, 1], [0, 0, 1, 1]])
    assert len(messages) == 1 and "'Col'" in messages[0] and "non-finite" in messages[0], messages
    assert export_mesh_data(bpy.data.meshes.new("plain"), "plain").colors is None


def _mixed(name, first, second, factor):
    """A material whose surface is a Mix Shader (Fac `factor`) of a `first` and a `second` shader node; returns
    (material, first node, second node)."""
    material, tree, output = _material(name)
    nodes = [tree.nodes.new(kind) for kind in (first, second)]
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = factor
    for k, node in enumerate(nodes, start=1):
        tree.links.new(node.outputs[0], mix.inputs[k])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return material, *nodes


def test_transparency_and_holdout_read_as_coverage(empty_file):
    """Principled Alpha: the BSDF drawn whole over a coverage of alpha (its colours unscaled); an image's Alpha
    output read per pixel; a Transparent BSDF in a Mix Shader: the coverage is the other shader's share, which
    is drawn whole; a tinted one is named; a Holdout's share of the drawn surface."""
    material, tree, output = _material("alpha_constant")
    _principled(tree, output, Base_Color=(0.8, 0.4, 0.2, 1.0), Alpha=0.25)
    params, warnings = _read(material)
    assert params.alpha == pytest.approx(0.25) and params.diffuse_color == pytest.approx((0.8, 0.4, 0.2))
    assert len(warnings) == 1 and warnings[0].endswith("transparency: shadows are cast as by an opaque surface")

    pixels = np.ones((4, 4, 4), np.float32)
    pixels[..., 3] = np.linspace(0.0, 1.0, 16).reshape(4, 4)
    image = _image("alpha_ramp", pixels, "Non-Color")
    material, tree, output = _material("alpha_texture")
    texture = _link_image(tree, image, _principled(tree, output).inputs["Base Color"])
    tree.links.new(texture.outputs["Alpha"], tree.nodes["Principled BSDF"].inputs["Alpha"])
    params, _ = _read(material)
    assert params.alpha == 1.0 and params.textures["diffuse_color"] == "alpha_ramp"
    np.testing.assert_allclose(_at_texels(params.textures["alpha"], "alpha")[..., 0], pixels[..., 3], atol=1e-6)

    material, transparent, emission = _mixed("transparent_mix", "ShaderNodeBsdfTransparent", "ShaderNodeEmission", 0.7)
    params, warnings = _read(material)
    assert params.alpha == pytest.approx(0.7) and params.emission == pytest.approx((1.0, 1.0, 1.0))
    transparent.inputs["Color"].default_value = (1.0, 0.5, 0.0, 1.0)
    params, warnings = _read(material)
    assert params.alpha == pytest.approx(1.0 - 0.3 * 0.5) and "a tinted Transparent BSDF" in warnings[0]

    material, _, _ = _mixed("holdout", "ShaderNodeEmission", "ShaderNodeHoldout", 0.4)
    params, warnings = _read(material)
    assert params.alpha == 1.0 and params.holdout == pytest.approx(0.4) and warnings == []
    assert params.emission == pytest.approx((0.6, 0.6, 0.6))


def test_a_bump_node_on_the_normal_is_a_computed_shading_normal(empty_file):
    """A Bump node over a texture feeds the shading_normal slot (a function of the height, the surface normal
    and position); over a constant height it bumps nothing and no slot is made; nothing is named."""
    material, tree, output = _material("bumped")
    node = _principled(tree, output)
    bump = tree.nodes.new("ShaderNodeBump")
    tree.links.new(bump.outputs["Normal"], node.inputs["Normal"])
    params, warnings = _read(material)
    assert "shading_normal" not in params.textures and warnings == []
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    params, warnings = _read(material)
    normal = params.textures["shading_normal"]
    assert warnings == [] and normal.terms[0][1][0].function.name == "bump"
    assert set(normal.coordinate_names) == {"GENERATED", "POSITION", "WORLD_NORMAL"}


def test_a_uv_map_node_naming_the_second_uv_map_reads_it(empty_file):
    """A UV Map node naming each mesh's second UV map reads it (SECOND_UV coordinates, an image read there per
    pixel), which the mesh export carries; one naming a map that is neither is named and reads the render UV map."""
    from sg_prt_addon.blender import export

    material, tree, output = _material("second_uv")
    texture = _link_image(tree, _image("second_uv_image", np.ones((2, 2, 4), np.float32)),
                          _principled(tree, output).inputs["Base Color"])
    uv_map = tree.nodes.new("ShaderNodeUVMap")
    tree.links.new(uv_map.outputs["UV"], texture.inputs["Vector"])
    mesh = bpy.data.meshes.new("second_uv_mesh")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    first, second = mesh.uv_layers.new(name="First"), mesh.uv_layers.new(name="Second")
    second.data.foreach_set("uv", [0.5, 0.25] * 4)
    mesh.uv_layers.active = first
    mesh.materials.append(material)
    uv_map.uv_map = "Second"
    params, warnings = _read(material)
    assert warnings == [] and params.textures["diffuse_color"].coordinate_names == ("SECOND_UV",)
    exported = export.export_mesh_data(mesh)
    np.testing.assert_array_equal(exported.second_uvs, np.tile([0.5, 0.25], (4, 1)))
    uv_map.uv_map = "Third"
    params, warnings = _read(material)
    assert params.textures["diffuse_color"] == "second_uv_image" and "UV map 'Third'" in warnings[0]
