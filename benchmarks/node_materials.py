"""Blender's own node materials rendered by SG-PRT (material source: Node Tree) against Cycles.

Each scene is a sphere whose material is built only from Blender's nodes (no SG-PRT settings), under the
courtyard HDRI and a point light; SG-PRT reads the node tree (blender/node_reader.py), Cycles renders the same
tree with direct light only (benchmarks.matched_materials.configure_cycles), two seeds: the truth is their
mean, the noise floor rmse(seed 1 - seed 2) / 2.  A lone sphere has no occluder, so no bake is needed.
Scores over the sphere's pixels (one pixel in from its silhouette): relative RMSE and mean bias.

    .venv/bin/python -m benchmarks.node_materials [--size 128] [--cycles-samples 256] [--update-doc]
"""
from pathlib import Path

from benchmarks.cycles_truth import empty_node_material

ROOT = Path(__file__).resolve().parents[1]
JSON_PATH = ROOT / "docs" / "node_materials.json"
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
SECTION_TITLE = "## Blender node materials against Cycles"
GOLD = (1.0, 0.766, 0.336, 1.0)


def _principled(name, **inputs):
    material, tree, output = empty_node_material(name)
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    for socket, value in inputs.items():
        node.inputs[socket.replace("_", " ")].default_value = value
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material, tree, node


def _image(name, pixels, colorspace):
    import bpy
    import numpy as np

    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True)
    image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.pack()
    return image


def _textured(tree, node, socket, image):
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    tree.links.new(texture.outputs["Color"], node.inputs[socket])
    return texture


def dielectric(roughness):
    def build():
        return _principled(f"dielectric_{roughness}", Base_Color=(0.8, 0.25, 0.1, 1.0), Roughness=roughness)[0]
    return build


def gold():
    return _principled("gold", Base_Color=GOLD, Metallic=1.0, Roughness=0.3)[0]


def black_metal():
    """Metallic 1 of a black base colour: Cycles' metallic Fresnel (F82 tint, white by default: Schlick's) still
    reflects at grazing views."""
    return _principled("black_metal", Base_Color=(0.0, 0.0, 0.0, 1.0), Metallic=1.0, Roughness=0.3)[0]


def textured():
    """A checker Base Color, a striped roughness map (Non-Color) and a bumpy normal map."""
    import numpy as np

    material, tree, node = _principled("textured", Roughness=1.0)
    u, v = np.meshgrid((np.arange(64) + 0.5) / 64, (np.arange(64) + 0.5) / 64)
    checker = ((np.floor(u * 8) + np.floor(v * 4)) % 2)[..., None]
    colour = np.ones((64, 64, 4))
    colour[..., :3] = checker * (0.8, 0.7, 0.2) + (1 - checker) * (0.1, 0.3, 0.6)
    rough = np.ones((64, 64, 4))
    rough[..., :3] = (0.25 + 0.45 * (np.floor(v * 6) % 2))[..., None]
    bumps = np.ones((64, 64, 4))
    bumps[..., 0] = 0.5 + 0.25 * np.sin(2 * np.pi * 8 * u)
    bumps[..., 1] = 0.5
    bumps[..., 2] = np.sqrt(1 - (2 * bumps[..., 0] - 1) ** 2) * 0.5 + 0.5
    _textured(tree, node, "Base Color", _image("checker", colour, "sRGB"))
    _textured(tree, node, "Roughness", _image("stripes", rough, "Non-Color"))
    normal_map = tree.nodes.new("ShaderNodeNormalMap")
    _textured(tree, normal_map, "Color", _image("bumps", bumps, "Non-Color"))
    tree.links.new(normal_map.outputs["Normal"], node.inputs["Normal"])
    return material


def pbr_metallic_map():
    """A PBR texture set: Base Color, a Metallic map (metal stripes, Non-Color) and a roughness map."""
    import numpy as np

    material, tree, node = _principled("pbr_metallic_map", Roughness=1.0)
    u, v = np.meshgrid((np.arange(64) + 0.5) / 64, (np.arange(64) + 0.5) / 64)
    metal = (np.floor(u * 6) % 2)[..., None]
    colour = np.ones((64, 64, 4))
    colour[..., :3] = metal * GOLD[:3] + (1 - metal) * (0.6, 0.1, 0.1)
    metallic = np.ones((64, 64, 4))
    metallic[..., :3] = metal
    rough = np.ones((64, 64, 4))
    rough[..., :3] = (0.3 + 0.3 * v)[..., None]
    _textured(tree, node, "Base Color", _image("pbr_colour", colour, "sRGB"))
    _textured(tree, node, "Metallic", _image("pbr_metallic", metallic, "Non-Color"))
    _textured(tree, node, "Roughness", _image("pbr_roughness", rough, "Non-Color"))
    return material


def tiled():
    """A checker Base Color tiled and turned by a Mapping node on the UVs (Scale 3 x 2, Rotation 0.4 about z,
    Location 0.1, 0.2): texture coordinates beyond [0, 1] repeat."""
    import numpy as np

    material, tree, node = _principled("tiled", Roughness=0.5)
    u, v = np.meshgrid((np.arange(32) + 0.5) / 32, (np.arange(32) + 0.5) / 32)
    checker = ((np.floor(u * 2) + np.floor(v * 2)) % 2)[..., None]
    colour = np.ones((32, 32, 4))
    colour[..., :3] = checker * (0.9, 0.8, 0.3) + (1 - checker) * (0.1, 0.2, 0.5)
    texture = _textured(tree, node, "Base Color", _image("tiles", colour, "sRGB"))
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Scale"].default_value = (3.0, 2.0, 1.0)
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, 0.4)
    mapping.inputs["Location"].default_value = (0.1, 0.2, 0.0)
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coordinates.outputs["UV"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    return material


def mix_diffuse_glossy():
    material, tree, output = empty_node_material("mix_diffuse_glossy")
    diffuse = tree.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (0.2, 0.5, 0.8, 1.0)
    glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "GGX"
    glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
    glossy.inputs["Roughness"].default_value = 0.3
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.4
    tree.links.new(diffuse.outputs[0], mix.inputs[1])
    tree.links.new(glossy.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return material


def anisotropic():
    """A brushed metal: anisotropy along the UV map's tangent (a Tangent node; unlinked, Cycles would turn it
    radially about the object's Z, which the engine reads as the UV tangent with a warning)."""
    material, tree, node = _principled("anisotropic", Base_Color=(0.9, 0.9, 0.9, 1.0), Metallic=1.0, Roughness=0.4,
                                       Anisotropic=0.8)
    tangent = tree.nodes.new("ShaderNodeTangent")
    tangent.direction_type = "UV_MAP"
    tree.links.new(tangent.outputs["Tangent"], node.inputs["Tangent"])
    return material


def glossy_anisotropic(anisotropy):
    """A Glossy BSDF (GGX) with Anisotropy along the UV map's tangent: the Glossy node's own mapping (positive:
    the lobe widened across the tangent; negative: along it), not the Principled BSDF's."""
    def build():
        material, tree, output = empty_node_material(f"glossy_anisotropic_{anisotropy:+.1f}")
        glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "GGX"
        glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
        glossy.inputs["Roughness"].default_value = 0.4
        glossy.inputs["Anisotropy"].default_value = anisotropy
        tangent = tree.nodes.new("ShaderNodeTangent")
        tangent.direction_type = "UV_MAP"
        tree.links.new(tangent.outputs["Tangent"], glossy.inputs["Tangent"])
        tree.links.new(glossy.outputs[0], output.inputs["Surface"])
        return material
    return build


def glossy_beckmann(roughness):
    """A Glossy BSDF of the Beckmann distribution, its colour white."""
    def build():
        material, tree, output = empty_node_material(f"glossy_beckmann_{roughness}")
        glossy = tree.nodes.new("ShaderNodeBsdfGlossy")
        glossy.distribution = "BECKMANN"
        glossy.inputs["Color"].default_value = (0.9, 0.9, 0.9, 1.0)
        glossy.inputs["Roughness"].default_value = roughness
        tree.links.new(glossy.outputs[0], output.inputs["Surface"])
        return material
    return build


def bumped():
    """A rough dielectric whose Normal is a Bump node over a Noise Texture (Scale 6, Distance 0.05): a shading
    normal computed per pixel."""
    material, tree, node = _principled("bumped", Base_Color=(0.7, 0.35, 0.15, 1.0), Roughness=0.4)
    noise_node = tree.nodes.new("ShaderNodeTexNoise")
    noise_node.inputs["Scale"].default_value = 6.0
    bump_node = tree.nodes.new("ShaderNodeBump")
    bump_node.inputs["Distance"].default_value = 0.05
    tree.links.new(noise_node.outputs["Fac"], bump_node.inputs["Height"])
    tree.links.new(bump_node.outputs["Normal"], node.inputs["Normal"])
    return material


SCENES = {"principled_r020": dielectric(0.2), "principled_r050": dielectric(0.5), "principled_r080": dielectric(0.8),
          "principled_gold_r030": gold, "principled_black_metal": black_metal, "principled_textured": textured, "principled_pbr_metallic_map": pbr_metallic_map,
          "principled_tiled": tiled, "mix_diffuse_glossy": mix_diffuse_glossy,
          "principled_anisotropic": anisotropic, "glossy_anisotropic": glossy_anisotropic(0.6),
          "glossy_anisotropic_negative": glossy_anisotropic(-0.6), "glossy_beckmann_r030": glossy_beckmann(0.3),
          "principled_bumped": bumped, "no_material": lambda: None}


def build(name, size):
    from benchmarks import truth_suite

    scene = truth_suite._start(size)
    truth_suite._hdri(scene)
    truth_suite._light(scene, "POINT", **truth_suite.POINT_LIGHT)
    truth_suite._sphere(SCENES[name]())
    truth_suite._sphere_camera(scene)
    scene.render.film_transparent = True
    return scene


def score(name, size, samples, log=print):
    """One scene's row: SG-PRT against the two-seed Cycles truth (benchmarks/cycles_truth.py)."""
    from benchmarks import cycles_truth

    row = {"scene": name, "size": size, **cycles_truth.score(build(name, size), samples)}
    log(f"{name:24s} rmse {row['relative_rmse']:.3f}  bias {row['relative_bias']:+.3f}  noise floor "
        f"{row['noise_floor']:.3f}  SG-PRT {row['engine_seconds']:.2f} s  Cycles {row['cycles_seconds']:.1f} s")
    return row


def markdown_section(data):
    lines = [SECTION_TITLE, "", f"Blender materials built only from nodes (`benchmarks/node_materials.py`): a sphere under "
             f"courtyard.exr and a point light, {data['size']} x {data['size']}, Cycles direct light only, "
             f"{data['cycles_samples']} spp x 2 seeds.  SG-PRT reads the node tree (no SG-PRT settings); a lone "
             "sphere needs no bake.  Relative RMSE and bias over the sphere's pixels.", "",
             "| scene | relative RMSE | bias | noise floor |", "|---|---|---|---|"]
    for row in data["rows"]:
        lines.append(f"| {row['scene']} | {row['relative_rmse']:.3f} | {row['relative_bias']:+.3f} | "
                     f"{row['noise_floor']:.3f} |")
    from benchmarks import cycles_truth

    lines += ["", f"Rerun: `.venv/bin/python -m benchmarks.node_materials --size {data['size']} "
              f"--cycles-samples {data['cycles_samples']}` ({data['seconds']:.0f} s), then `--update-doc`."
              + cycles_truth.merged_note(data, "--scenes")]
    return "\n".join(lines)


def main(argv=None):
    from benchmarks import cycles_truth

    cycles_truth.cases_main(argv, __doc__.splitlines()[0], "--scenes", SCENES, 128, 256,
                            score, JSON_PATH, DOC_PATH, SECTION_TITLE, markdown_section)


if __name__ == "__main__":
    main()
