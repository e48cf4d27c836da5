"""Node values against Cycles' own evaluation of them: each case routes a node's output into an Emission shader
on a plane that fills an orthographic view (black world, no lights), so Cycles' image is the socket's value at
every pixel and SG-PRT's is its reading of the same nodes (blender/node_reader.py).  Scores: relative RMSE and
bias over the plane against the mean of two Cycles seeds, and the noise floor (benchmarks/cycles_truth.py).

    .venv/bin/python -m benchmarks.node_values [--size 64] [--cycles-samples 16] [--update-doc]
"""
from pathlib import Path

from benchmarks.cycles_truth import empty_node_material

ROOT = Path(__file__).resolve().parents[1]
JSON_PATH = ROOT / "docs" / "node_values.json"
DOC_PATH = ROOT / "docs" / "ACCURACY.md"
SECTION_TITLE = "## Node values against Cycles' evaluation"
TEXTURE_SIDE = 16
MATH_OPERATIONS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT", "INVERSE_SQRT",
                   "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN", "SIGN", "COMPARE",
                   "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO",
                   "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "SINH", "COSH", "TANH", "ARCSINE",
                   "ARCCOSINE", "ARCTANGENT", "ARCTAN2", "RADIANS", "DEGREES")
MIX_BLENDS = ("SCREEN", "OVERLAY", "DIVIDE", "DIFFERENCE", "EXCLUSION", "DARKEN", "LIGHTEN", "DODGE", "BURN",
              "SOFT_LIGHT", "LINEAR_LIGHT", "SUBTRACT", "HUE", "SATURATION", "VALUE", "COLOR")
COLOUR_ATTRIBUTE = "Col"


def _emitting(name, value_of):
    """A material whose surface is an Emission of Strength 1 whose Color is value_of(tree) (an output socket)."""
    material, tree, output = empty_node_material(name)
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    tree.links.new(value_of(tree), emission.inputs["Color"])
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material


def colour_image(colorspace="sRGB"):
    """A smooth 16 x 16 colour image (three slow waves, one a channel), magnified on the plane."""
    import bpy
    import numpy as np

    name = f"waves_{colorspace}"
    if name in bpy.data.images:
        return bpy.data.images[name]
    u, v = np.meshgrid((np.arange(TEXTURE_SIDE) + 0.5) / TEXTURE_SIDE, (np.arange(TEXTURE_SIDE) + 0.5) / TEXTURE_SIDE)
    pixels = np.ones((TEXTURE_SIDE, TEXTURE_SIDE, 4))
    pixels[..., 0] = 0.5 + 0.4 * np.sin(2 * np.pi * u)
    pixels[..., 1] = 0.5 + 0.4 * np.cos(2 * np.pi * v)
    pixels[..., 2] = 0.2 + 0.6 * u * v
    image = bpy.data.images.new(name, TEXTURE_SIDE, TEXTURE_SIDE, alpha=True)
    image.colorspace_settings.name = colorspace
    image.pixels.foreach_set(np.ascontiguousarray(pixels, np.float32).ravel())
    image.pack()
    return image


def _image_node(tree, colorspace="sRGB"):
    node = tree.nodes.new("ShaderNodeTexImage")
    node.image = colour_image(colorspace)
    return node


def _separate(tree, colour_socket):
    node = tree.nodes.new("ShaderNodeSeparateColor")
    tree.links.new(colour_socket, node.inputs[0])
    return node


def image(tree):
    return _image_node(tree).outputs["Color"]


def image_non_color(tree):
    return _image_node(tree, "Non-Color").outputs["Color"]


def separate_green(tree):
    return _separate(tree, _image_node(tree).outputs["Color"]).outputs["Green"]


def combine_swizzled(tree):
    """Separate Color's channels put back as (blue, red, green) by Combine Color."""
    separate = _separate(tree, _image_node(tree).outputs["Color"])
    combine = tree.nodes.new("ShaderNodeCombineColor")
    for target, source in (("Red", "Blue"), ("Green", "Red"), ("Blue", "Green")):
        tree.links.new(separate.outputs[source], combine.inputs[target])
    return combine.outputs["Color"]


def separate_combine_xyz(tree):
    """Separate XYZ of a Non-Color image, recombined as (z, x, 0.5) by Combine XYZ."""
    separate = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(_image_node(tree, "Non-Color").outputs["Color"], separate.inputs[0])
    combine = tree.nodes.new("ShaderNodeCombineXYZ")
    tree.links.new(separate.outputs["Z"], combine.inputs["X"])
    tree.links.new(separate.outputs["X"], combine.inputs["Y"])
    combine.inputs["Z"].default_value = 0.5
    return combine.outputs["Vector"]


def math_and_mix(tree):
    """Mix (Multiply, factor 0.7) of the image and a colour, times twice the image's red channel (Math)."""
    texture = _image_node(tree)
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 0.7
    tree.links.new(texture.outputs["Color"], mix.inputs["A"])
    mix.inputs["B"].default_value = (0.9, 0.4, 0.7, 1.0)
    red = tree.nodes.new("ShaderNodeMath")
    red.operation = "MULTIPLY"
    tree.links.new(_separate(tree, texture.outputs["Color"]).outputs["Red"], red.inputs[0])
    red.inputs[1].default_value = 2.0
    scale = tree.nodes.new("ShaderNodeMix")
    scale.data_type = "RGBA"
    scale.blend_type = "MULTIPLY"
    scale.inputs["Factor"].default_value = 1.0
    tree.links.new(mix.outputs["Result"], scale.inputs["A"])
    tree.links.new(red.outputs[0], scale.inputs["B"])
    return scale.outputs["Result"]


def muted_and_rerouted(tree):
    """The image through two reroutes and a muted Invert (a muted node passes its input)."""
    texture = _image_node(tree)
    first, second = tree.nodes.new("NodeReroute"), tree.nodes.new("NodeReroute")
    tree.links.new(texture.outputs["Color"], first.inputs[0])
    tree.links.new(first.outputs[0], second.inputs[0])
    invert = tree.nodes.new("ShaderNodeInvert")
    invert.mute = True
    tree.links.new(second.outputs[0], invert.inputs["Color"])
    return invert.outputs["Color"]


def _group(name, build_inside, inputs):
    """A shader node group: its interface `inputs` ((name, socket type, default)) and a Color output, which
    build_inside(tree, group_input) returns the socket of."""
    import bpy

    group = bpy.data.node_groups.new(name, "ShaderNodeTree")
    for socket_name, socket_type, default in inputs:
        item = group.interface.new_socket(socket_name, in_out="INPUT", socket_type=socket_type)
        item.default_value = default
    group.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    group_input = group.nodes.new("NodeGroupInput")
    group_output = group.nodes.new("NodeGroupOutput")
    group.links.new(build_inside(group, group_input), group_output.inputs["Color"])
    return group


def nested_groups(tree):
    """The image into a group that scales it by its Float input (unlinked: the group node's 0.8, not the
    interface's 0.5) and passes it through an inner group adding a colour."""
    def inner_build(group, group_input):
        add = group.nodes.new("ShaderNodeMix")
        add.data_type = "RGBA"
        add.blend_type = "ADD"
        add.inputs["Factor"].default_value = 1.0
        group.links.new(group_input.outputs["Color"], add.inputs["A"])
        add.inputs["B"].default_value = (0.1, 0.2, 0.05, 1.0)
        return add.outputs["Result"]

    inner = _group("add_tint", inner_build, [("Color", "NodeSocketColor", (0.5, 0.5, 0.5, 1.0))])

    def outer_build(group, group_input):
        scale = group.nodes.new("ShaderNodeMix")
        scale.data_type = "RGBA"
        scale.blend_type = "MULTIPLY"
        scale.inputs["Factor"].default_value = 1.0
        group.links.new(group_input.outputs["Color"], scale.inputs["A"])
        group.links.new(group_input.outputs["Scale"], scale.inputs["B"])
        inner_node = group.nodes.new("ShaderNodeGroup")
        inner_node.node_tree = inner
        group.links.new(scale.outputs["Result"], inner_node.inputs["Color"])
        return inner_node.outputs["Color"]

    outer = _group("scaled_tint", outer_build, [("Color", "NodeSocketColor", (0.5, 0.5, 0.5, 1.0)),
                                               ("Scale", "NodeSocketFloat", 0.5)])
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = outer
    node.inputs["Scale"].default_value = 0.8
    tree.links.new(_image_node(tree).outputs["Color"], node.inputs["Color"])
    return node.outputs["Color"]


def principled_emission_texture(name):
    """A black Principled BSDF (nothing to reflect here) whose Emission Color is the image, Strength 3."""
    material, tree, output = empty_node_material(name)
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    node.inputs["Emission Strength"].default_value = 3.0
    tree.links.new(_image_node(tree).outputs["Color"], node.inputs["Emission Color"])
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def emission_strength_texture(name):
    """An Emission of a constant colour whose Strength is four times the image's red channel."""
    material, tree, output = empty_node_material(name)
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 0.5, 0.2, 1.0)
    strength = tree.nodes.new("ShaderNodeMath")
    strength.operation = "MULTIPLY"
    tree.links.new(_separate(tree, _image_node(tree).outputs["Color"]).outputs["Red"], strength.inputs[0])
    strength.inputs[1].default_value = 4.0
    tree.links.new(strength.outputs[0], emission.inputs["Strength"])
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material


def grouped_shader(name):
    """A Principled BSDF inside a node group (as asset libraries and some glTF exporters make them): black base,
    the image as its emission through the group's Color input."""
    def build(group, group_input):
        node = group.nodes.new("ShaderNodeBsdfPrincipled")
        node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        node.inputs["Emission Strength"].default_value = 1.0
        group.links.new(group_input.outputs["Color"], node.inputs["Emission Color"])
        return node.outputs[0]

    import bpy

    group = bpy.data.node_groups.new("emitting_principled", "ShaderNodeTree")
    item = group.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    item.default_value = (0.5, 0.5, 0.5, 1.0)
    group.interface.new_socket("Shader", in_out="OUTPUT", socket_type="NodeSocketShader")
    group_input, group_output = group.nodes.new("NodeGroupInput"), group.nodes.new("NodeGroupOutput")
    group.links.new(build(group, group_input), group_output.inputs["Shader"])
    material, tree, output = empty_node_material(name)
    node = tree.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    tree.links.new(_image_node(tree).outputs["Color"], node.inputs["Color"])
    tree.links.new(node.outputs["Shader"], output.inputs["Surface"])
    return material


def mix_shader_textured_factor(name):
    """Two Emissions (red; the image) mixed by the image's green channel."""
    material, tree, output = empty_node_material(name)
    red, textured = tree.nodes.new("ShaderNodeEmission"), tree.nodes.new("ShaderNodeEmission")
    red.inputs["Color"].default_value = (1.0, 0.1, 0.1, 1.0)
    texture = _image_node(tree)
    tree.links.new(texture.outputs["Color"], textured.inputs["Color"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(_separate(tree, texture.outputs["Color"]).outputs["Green"], mix.inputs["Fac"])
    tree.links.new(red.outputs[0], mix.inputs[1])
    tree.links.new(textured.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return material


def color_attribute(tree):
    node = tree.nodes.new("ShaderNodeVertexColor")
    node.layer_name = COLOUR_ATTRIBUTE
    return node.outputs["Color"]


def attribute_fac(tree):
    """The Attribute node's Fac of the colour attribute (the mean of its channels)."""
    node = tree.nodes.new("ShaderNodeAttribute")
    node.attribute_name = COLOUR_ATTRIBUTE
    return node.outputs["Fac"]


def image_times_color_attribute(tree):
    """The image times the colour attribute (Mix, Multiply), as glTF's importer joins COLOR_0 and a texture."""
    mix = tree.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.blend_type = "MULTIPLY"
    mix.inputs["Factor"].default_value = 1.0
    tree.links.new(_image_node(tree).outputs["Color"], mix.inputs["A"])
    tree.links.new(color_attribute(tree), mix.inputs["B"])
    return mix.outputs["Result"]


def add_colour_attribute(mesh, domain="POINT", data_type="FLOAT_COLOR"):
    """A smooth colour attribute over the grid (a function of each point's position)."""
    import numpy as np

    attribute = mesh.color_attributes.new(COLOUR_ATTRIBUTE, data_type, domain)
    positions = np.array([vertex.co[:2] for vertex in mesh.vertices])
    if domain == "CORNER":
        positions = positions[[loop.vertex_index for loop in mesh.loops]]
    x, y = positions[:, 0], positions[:, 1]
    colours = np.stack([0.5 + 0.4 * np.sin(np.pi * x), 0.5 + 0.4 * np.cos(np.pi * y), 0.3 + 0.2 * x * y,
                        np.ones_like(x)], axis=-1)
    attribute.data.foreach_set("color", np.ascontiguousarray(colours, np.float32).ravel())


def _three_inputs(tree):
    """Three values over the plane from the Non-Color image: a = 4 red - 2 (-1.6..1.6), b = 2 green (0.2..1.8),
    c = blue (0.2..0.8)."""
    separate = _separate(tree, _image_node(tree, "Non-Color").outputs["Color"])
    a = _math_node(tree, "MULTIPLY_ADD", separate.outputs["Red"], 4.0, -2.0)
    b = _math_node(tree, "MULTIPLY", separate.outputs["Green"], 2.0)
    return a, b, separate.outputs["Blue"]


def _math_node(tree, operation, *inputs):
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    for socket, value in zip(node.inputs, inputs):
        if isinstance(value, float):
            socket.default_value = value
        else:
            tree.links.new(value, socket)
    return node.outputs[0]


# inputs moved off a pole: the base of a logarithm past 1, tan's argument within (-pi/2, pi/2), 1/sqrt's past 0
SHIFTED_INPUTS = {"LOGARITHM": (0.0, 1.0), "TANGENT": (-0.5, 0.0), "INVERSE_SQRT": (1.7, 0.0)}


def math_operation(operation):
    """The Math node's `operation` of the three inputs, made positive (Absolute) for the emission."""
    def value_of(tree):
        a, b, c = _three_inputs(tree)
        shift_a, shift_b = SHIFTED_INPUTS.get(operation, (0.0, 0.0))
        if operation == "TANGENT":
            a = _math_node(tree, "MULTIPLY", a, 0.8)
        elif shift_a:
            a = _math_node(tree, "ADD", a, shift_a)
        if shift_b:
            b = _math_node(tree, "ADD", b, shift_b)
        return _math_node(tree, "ABSOLUTE", _math_node(tree, operation, a, b, c))
    return value_of


def clamp_node(clamp_type):
    def value_of(tree):
        a, b, c = _three_inputs(tree)
        node = tree.nodes.new("ShaderNodeClamp")
        node.clamp_type = clamp_type
        tree.links.new(a, node.inputs["Value"])
        tree.links.new(_math_node(tree, "SUBTRACT", b, 1.0), node.inputs["Min"])
        tree.links.new(c, node.inputs["Max"])
        return _math_node(tree, "ABSOLUTE", node.outputs[0])
    return value_of


def map_range_node(interpolation):
    def value_of(tree):
        a, b, c = _three_inputs(tree)
        node = tree.nodes.new("ShaderNodeMapRange")
        node.interpolation_type = interpolation
        tree.links.new(a, node.inputs["Value"])
        node.inputs["From Min"].default_value = -1.0
        tree.links.new(b, node.inputs["From Max"])
        tree.links.new(c, node.inputs["To Min"])
        node.inputs["To Max"].default_value = 1.5
        if interpolation == "STEPPED":
            node.inputs["Steps"].default_value = 3.0
        return node.outputs["Result"]
    return value_of


def color_ramp_node(interpolation, output="Color", color_mode="RGB"):
    """A four-stop ramp (stops at 0.1, 0.35, 0.6, 0.9) of the image's red channel."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeValToRGB")
        ramp = node.color_ramp
        ramp.color_mode = color_mode
        ramp.interpolation = interpolation
        stops = [(0.1, (0.9, 0.1, 0.1, 1.0)), (0.35, (0.1, 0.8, 0.2, 0.5)), (0.6, (0.2, 0.3, 0.9, 0.8)),
                 (0.9, (1.0, 0.9, 0.3, 0.2))]
        ramp.elements[0].position, ramp.elements[0].color = stops[0]
        ramp.elements[1].position, ramp.elements[1].color = stops[-1]
        for position, colour in stops[1:-1]:
            ramp.elements.new(position).color = colour
        separate = _separate(tree, _image_node(tree, "Non-Color").outputs["Color"])
        tree.links.new(separate.outputs["Red"], node.inputs["Fac"])
        return node.outputs[output]
    return value_of


def mix_blend(blend):
    """The image (A) and its channels turned (B; for the HSV blends, whose saturation and value a turn keeps, a
    colour) blended by `blend` at a factor of its blue channel."""
    def value_of(tree):
        texture = _image_node(tree)
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        node.blend_type = blend
        tree.links.new(_separate(tree, texture.outputs["Color"]).outputs["Blue"], node.inputs["Factor"])
        tree.links.new(texture.outputs["Color"], node.inputs["A"])
        if blend in ("HUE", "SATURATION", "VALUE", "COLOR"):
            node.inputs["B"].default_value = (0.9, 0.35, 0.1, 1.0)
        else:
            tree.links.new(combine_swizzled(tree), node.inputs["B"])
        return node.outputs["Result"]
    return value_of


def colour_node(kind):
    """Hue/Saturation/Value, Gamma, Brightness/Contrast or RGB to BW of the image, their other inputs from its
    channels."""
    def value_of(tree):
        texture = _image_node(tree)
        separate = _separate(tree, texture.outputs["Color"])
        node = tree.nodes.new({"hue_saturation_value": "ShaderNodeHueSaturation", "gamma": "ShaderNodeGamma",
                               "brightness_contrast": "ShaderNodeBrightContrast", "rgb_to_bw": "ShaderNodeRGBToBW"}[kind])
        tree.links.new(texture.outputs["Color"], node.inputs["Color"])
        if kind == "hue_saturation_value":
            tree.links.new(separate.outputs["Red"], node.inputs["Hue"])
            node.inputs["Saturation"].default_value = 1.4
            tree.links.new(_math_node(tree, "ADD", separate.outputs["Green"], 0.5), node.inputs["Value"])
            node.inputs["Fac"].default_value = 0.8
        elif kind == "gamma":
            tree.links.new(_math_node(tree, "MULTIPLY", separate.outputs["Green"], 3.0), node.inputs["Gamma"])
        elif kind == "brightness_contrast":
            tree.links.new(_math_node(tree, "SUBTRACT", separate.outputs["Red"], 0.4), node.inputs["Bright"])
            node.inputs["Contrast"].default_value = 0.6
        return node.outputs[0]
    return value_of


def _shape_curve(curve, points):
    """A curve's points set to `points` ((x, y), ...), the first two moved, the rest added."""
    for k, (x, y) in enumerate(points):
        if k < len(curve.points):
            curve.points[k].location = (x, y)
        else:
            curve.points.new(x, y)


def curves_node(kind, extend="EXTRAPOLATED"):
    """RGB Curves of the image (an S on the combined curve, red lifted, Fac 0.9), Vector Curves of the Object
    coordinates (x bent, y inverted) or a Float Curve of the image's red channel (a bump), with the mapping's
    `extend`: the values past the points' span (Object x reaches -1 and 1) test it."""
    def value_of(tree):
        node = tree.nodes.new({"rgb": "ShaderNodeRGBCurve", "vector": "ShaderNodeVectorCurve",
                               "float": "ShaderNodeFloatCurve"}[kind])
        mapping = node.mapping
        mapping.extend = extend
        if kind == "rgb":
            _shape_curve(mapping.curves[3], [(0.0, 0.0), (1.0, 1.0), (0.3, 0.2), (0.7, 0.85)])
            _shape_curve(mapping.curves[0], [(0.0, 0.15), (1.0, 1.0)])
            node.inputs["Fac"].default_value = 0.9
            tree.links.new(_image_node(tree).outputs["Color"], node.inputs["Color"])
        elif kind == "vector":
            _shape_curve(mapping.curves[0], [(-0.5, -0.8), (0.5, 0.9), (0.0, 0.3)])
            _shape_curve(mapping.curves[1], [(-1.0, 1.0), (1.0, -1.0)])
            tree.links.new(_coordinates(tree, "Object"), node.inputs["Vector"])
        else:
            _shape_curve(mapping.curves[0], [(0.1, 0.2), (0.9, 0.3), (0.5, 0.9)])
            separate = _separate(tree, _image_node(tree, "Non-Color").outputs["Color"])
            tree.links.new(separate.outputs["Red"], node.inputs["Value"])
        mapping.update()
        output = node.outputs[0]
        return _vector_math(tree, "ABSOLUTE", output) if kind == "vector" else output
    return value_of


def _coordinates(tree, output, node_type="ShaderNodeTexCoord"):
    return tree.nodes.new(node_type).outputs[output]


def _vector_math(tree, operation, a, b=None):
    node = tree.nodes.new("ShaderNodeVectorMath")
    node.operation = operation
    tree.links.new(a, node.inputs[0])
    if b is not None:
        tree.links.new(b, node.inputs[1])
    return node.outputs["Value" if operation in ("DOT_PRODUCT", "DISTANCE", "LENGTH") else "Vector"]


def coordinates_case(output, node_type="ShaderNodeTexCoord"):
    """A Texture Coordinate (or Geometry) output as the colour, made positive (Vector Math, Absolute)."""
    def value_of(tree):
        return _vector_math(tree, "ABSOLUTE", _coordinates(tree, output, node_type))
    return value_of


def checker(vector_output=None, scale=5.0, output="Color"):
    """The Checker texture (its default Generated coordinates, or a Texture Coordinate output)."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexChecker")
        node.inputs["Scale"].default_value = scale
        node.inputs["Color1"].default_value = (0.9, 0.6, 0.2, 1.0)
        node.inputs["Color2"].default_value = (0.1, 0.3, 0.7, 1.0)
        if vector_output is not None:
            tree.links.new(_coordinates(tree, vector_output), node.inputs["Vector"])
        return node.outputs[output]
    return value_of


def _mapping_node(tree, mapping_type, vector):
    node = tree.nodes.new("ShaderNodeMapping")
    node.vector_type = mapping_type
    tree.links.new(vector, node.inputs["Vector"])
    if "Location" in node.inputs:
        node.inputs["Location"].default_value = (0.1, 0.2, 0.0)
    node.inputs["Rotation"].default_value = (0.3, 0.5, 0.7)
    node.inputs["Scale"].default_value = (1.5, 0.8, 1.2)
    return node.outputs["Vector"]


def gradient(gradient_type):
    """The Gradient texture of the Object coordinates (centred on the plane) turned and scaled by a Mapping."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexGradient")
        node.gradient_type = gradient_type
        tree.links.new(_mapping_node(tree, "POINT", _coordinates(tree, "Object")), node.inputs["Vector"])
        return node.outputs["Color"]
    return value_of


def mapping_case(mapping_type):
    def value_of(tree):
        return _vector_math(tree, "ABSOLUTE", _mapping_node(tree, mapping_type, _coordinates(tree, "Generated")))
    return value_of


def vector_math_case(operation):
    """Vector Math of the Object and Generated coordinates, made positive."""
    def value_of(tree):
        value = _vector_math(tree, operation, _coordinates(tree, "Object"), _coordinates(tree, "Generated"))
        return _math_node(tree, "ABSOLUTE", value) if operation in ("DOT_PRODUCT", "DISTANCE", "LENGTH") \
            else _vector_math(tree, "ABSOLUTE", value)
    return value_of


def noise(noise_type="FBM", output="Fac", distortion=0.0, vector_output=None):
    """The Noise Texture (Scale 4, Detail 3.5, its other inputs at their defaults) of its default Generated
    coordinates or a Texture Coordinate output."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexNoise")
        node.noise_type = noise_type
        node.inputs["Scale"].default_value = 4.0
        node.inputs["Detail"].default_value = 3.5
        node.inputs["Distortion"].default_value = distortion
        if vector_output is not None:
            tree.links.new(_coordinates(tree, vector_output), node.inputs["Vector"])
        value = node.outputs[output]
        # the multifractal types pass 1 and go below 0: scaled into the emission's range
        return value if noise_type == "FBM" else _math_node(tree, "ABSOLUTE", _math_node(tree, "MULTIPLY", value, 0.25))
    return value_of


def white_noise(dimensions, output):
    """The White Noise Texture of Generated coordinates (moved by 0.1, so that none lies on a cell's edge, where
    a rounding sends the snap either way) snapped to cells a quarter of the plane wide, its W (1D, 4D) the
    snapped x: one random value a cell (of every sample inside it), as it is used to colour cells."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexWhiteNoise")
        node.noise_dimensions = dimensions
        moved = _vector_math(tree, "ADD", _coordinates(tree, "Generated"))
        moved.node.inputs[1].default_value = (0.1, 0.1, 0.1)
        snapped = _vector_math(tree, "SNAP", moved)
        snapped.node.inputs[1].default_value = (0.25, 0.25, 0.25)
        if dimensions != "1D":
            tree.links.new(snapped, node.inputs["Vector"])
        if dimensions in ("1D", "4D"):
            separate = tree.nodes.new("ShaderNodeSeparateXYZ")
            tree.links.new(snapped, separate.inputs[0])
            tree.links.new(separate.outputs["X"], node.inputs["W"])
        return node.outputs[output]
    return value_of


def voronoi(feature="F1", output="Distance", metric="EUCLIDEAN", detail=0.0, normalize=False):
    """The Voronoi Texture in 3D of the Object coordinates (Scale 3, Randomness 0.9, Smoothness 0.6, Exponent
    1.5); a Position made positive (Vector Math Absolute)."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexVoronoi")
        node.feature, node.distance, node.normalize = feature, metric, normalize
        node.inputs["Scale"].default_value = 3.0
        node.inputs["Randomness"].default_value = 0.9
        for name, value in (("Smoothness", 0.6), ("Exponent", 1.5), ("Detail", detail)):
            if name in node.inputs:
                node.inputs[name].default_value = value
        tree.links.new(_coordinates(tree, "Object"), node.inputs["Vector"])
        socket = node.outputs[output]
        return _vector_math(tree, "ABSOLUTE", socket) if output == "Position" else socket
    return value_of


def brick(output="Color", offset_frequency=2, squash=1.0, squash_frequency=2, smooth=0.3):
    """The Brick Texture of the Object coordinates (Scale 2.3, Mortar Size 0.06: lines two pixels wide, which
    Edges Only's first frame at the pixels' centres sees; its colours the defaults'), rows offset and squashed
    by the node's settings."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexBrick")
        node.offset_frequency, node.squash, node.squash_frequency = offset_frequency, squash, squash_frequency
        node.inputs["Scale"].default_value = 2.3
        node.inputs["Mortar Size"].default_value = 0.06
        node.inputs["Mortar Smooth"].default_value = smooth
        node.inputs["Bias"].default_value = 0.1
        tree.links.new(_coordinates(tree, "Object"), node.inputs["Vector"])
        return node.outputs[output]
    return value_of


def wave(wave_type="BANDS", direction="X", profile="SIN", distortion=3.0):
    """The Wave Texture (Scale 2, its distortion's noise at Detail 2) of the Object coordinates."""
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexWave")
        node.wave_type = wave_type
        if wave_type == "BANDS":
            node.bands_direction = direction
        else:
            node.rings_direction = direction
        node.wave_profile = profile
        node.inputs["Scale"].default_value = 2.0
        node.inputs["Distortion"].default_value = distortion
        tree.links.new(_coordinates(tree, "Object"), node.inputs["Vector"])
        return node.outputs["Color"]
    return value_of


def magic(depth, output="Color"):
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeTexMagic")
        node.turbulence_depth = depth
        node.inputs["Scale"].default_value = 3.0
        return node.outputs[output]
    return value_of


def image_extended(extension):
    """The image over UVs a Mapping spreads to [-0.5, 1.5] (Scale 2, Location -0.5), past its edges as
    `extension` says."""
    def value_of(tree):
        node = _image_node(tree)
        node.extension = extension
        mapping = tree.nodes.new("ShaderNodeMapping")
        mapping.inputs["Scale"].default_value = (2.0, 2.0, 1.0)
        mapping.inputs["Location"].default_value = (-0.5, -0.5, 0.0)
        tree.links.new(_coordinates(tree, "UV"), mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], node.inputs["Vector"])
        return node.outputs["Color"]
    return value_of


def image_at(vector_of):
    """The image at the coordinates vector_of(tree) gives."""
    def value_of(tree):
        node = _image_node(tree)
        tree.links.new(vector_of(tree), node.inputs["Vector"])
        return node.outputs["Color"]
    return value_of


def uv_transformed_by_math(tree):
    """glTF's texture transform as its importer builds it: the UV's x and y through Math into Combine XYZ."""
    separate = tree.nodes.new("ShaderNodeSeparateXYZ")
    tree.links.new(_coordinates(tree, "UV"), separate.inputs[0])
    combine = tree.nodes.new("ShaderNodeCombineXYZ")
    tree.links.new(_math_node(tree, "MULTIPLY_ADD", separate.outputs["X"], 1.5, 0.2), combine.inputs["X"])
    tree.links.new(_math_node(tree, "MULTIPLY", separate.outputs["Y"], 0.7), combine.inputs["Y"])
    return combine.outputs["Vector"]


def bump(strength=1.0, distance=0.2, invert=False):
    """The Bump node's Normal over a Noise Texture's Fac (Scale 3), as a colour: normal x 0.5 + 0.5."""
    def value_of(tree):
        noise_node = tree.nodes.new("ShaderNodeTexNoise")
        noise_node.inputs["Scale"].default_value = 3.0
        node = tree.nodes.new("ShaderNodeBump")
        node.invert = invert
        node.inputs["Strength"].default_value = strength
        node.inputs["Distance"].default_value = distance
        tree.links.new(noise_node.outputs["Fac"], node.inputs["Height"])
        shift = tree.nodes.new("ShaderNodeVectorMath")
        shift.operation = "MULTIPLY_ADD"
        tree.links.new(node.outputs["Normal"], shift.inputs[0])
        shift.inputs[1].default_value = (0.5, 0.5, 0.5)
        shift.inputs[2].default_value = (0.5, 0.5, 0.5)
        return shift.outputs["Vector"]
    return value_of


def fresnel_node(ior=1.45):
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeFresnel")
        node.inputs["IOR"].default_value = ior
        return node.outputs["Fac"]
    return value_of


def layer_weight(output, blend):
    def value_of(tree):
        node = tree.nodes.new("ShaderNodeLayerWeight")
        node.inputs["Blend"].default_value = blend
        return node.outputs[output]
    return value_of


def mix_shader_by_fresnel(name):
    """Two Emissions (blue; the image) mixed by Layer Weight's Fresnel: the rim takes the image."""
    material, tree, output = empty_node_material(name)
    blue, textured = tree.nodes.new("ShaderNodeEmission"), tree.nodes.new("ShaderNodeEmission")
    blue.inputs["Color"].default_value = (0.1, 0.2, 0.9, 1.0)
    tree.links.new(_image_node(tree).outputs["Color"], textured.inputs["Color"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(layer_weight("Fresnel", 0.4)(tree), mix.inputs["Fac"])
    tree.links.new(blue.outputs[0], mix.inputs[1])
    tree.links.new(textured.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return material


def _transparent_or_image(name, factor_of):
    """A Transparent BSDF mixed with an Emission of the image by factor_of(tree, image node) (an output)."""
    material, tree, output = empty_node_material(name)
    texture = _image_node(tree)
    emission, transparent = tree.nodes.new("ShaderNodeEmission"), tree.nodes.new("ShaderNodeBsdfTransparent")
    tree.links.new(texture.outputs["Color"], emission.inputs["Color"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    tree.links.new(factor_of(tree, texture), mix.inputs["Fac"])
    tree.links.new(transparent.outputs[0], mix.inputs[1])
    tree.links.new(emission.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return material


def unlit(name):
    """glTF's unlit material as its importer builds it: Light Path's Is Camera Ray mixing a Transparent BSDF and
    an Emission of the image."""
    return _transparent_or_image(name, lambda tree, _: tree.nodes.new("ShaderNodeLightPath").outputs["Is Camera Ray"])


def alpha_image():
    """A 16 x 16 image whose alpha is a ramp across u (0.1 to 0.9) and a wave along v, its colour the waves'."""
    import bpy
    import numpy as np

    if "alpha_waves" in bpy.data.images:
        return bpy.data.images["alpha_waves"]
    source = colour_image()
    pixels = np.empty(TEXTURE_SIDE * TEXTURE_SIDE * 4, np.float32)
    source.pixels.foreach_get(pixels)
    pixels = pixels.reshape(TEXTURE_SIDE, TEXTURE_SIDE, 4)
    u, v = np.meshgrid((np.arange(TEXTURE_SIDE) + 0.5) / TEXTURE_SIDE, (np.arange(TEXTURE_SIDE) + 0.5) / TEXTURE_SIDE)
    pixels[..., 3] = np.clip(0.1 + 0.8 * u + 0.1 * np.sin(2 * np.pi * v), 0.0, 1.0)
    image = bpy.data.images.new("alpha_waves", TEXTURE_SIDE, TEXTURE_SIDE, alpha=True)
    image.pixels.foreach_set(np.ascontiguousarray(pixels).ravel())
    image.pack()
    return image


def _emitting_principled(tree, colour_socket=None):
    """A black Principled BSDF emitting the image (or colour_socket's value), Strength 1."""
    node = tree.nodes.new("ShaderNodeBsdfPrincipled")
    node.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    node.inputs["Emission Strength"].default_value = 1.0
    tree.links.new(colour_socket or _image_node(tree).outputs["Color"], node.inputs["Emission Color"])
    return node


def alpha_constant(name):
    """The emitting Principled BSDF at Alpha 0.4 over the backdrop (BACKDROP_CASES)."""
    material, tree, output = empty_node_material(name)
    node = _emitting_principled(tree)
    node.inputs["Alpha"].default_value = 0.4
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def alpha_texture(name):
    """The emitting Principled BSDF whose Alpha is an image's Alpha output (glTF's alpha blend and mask)."""
    material, tree, output = empty_node_material(name)
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = alpha_image()
    node = _emitting_principled(tree, texture.outputs["Color"])
    tree.links.new(texture.outputs["Alpha"], node.inputs["Alpha"])
    tree.links.new(node.outputs[0], output.inputs["Surface"])
    return material


def transparent_mix(name):
    """A Transparent BSDF mixed with an Emission of the image by the image's green channel."""
    return _transparent_or_image(name, lambda tree, texture: _separate(tree, texture.outputs["Color"]).outputs["Green"])


SECOND_UV_MAP = "Second"


def add_second_uv_map(mesh):
    """A second UV map on the mesh: its first UV map turned a quarter and scaled 1.5 times."""
    import numpy as np

    first = mesh.uv_layers[0]
    uvs = np.empty(len(first.data) * 2, np.float32)
    first.data.foreach_get("uv", uvs)
    uvs = uvs.reshape(-1, 2)
    second = mesh.uv_layers.new(name=SECOND_UV_MAP)
    second.data.foreach_set("uv", np.ascontiguousarray(np.stack([1.5 * uvs[:, 1], 1.5 * (1.0 - uvs[:, 0])], -1)).ravel())
    mesh.uv_layers.active = first
    first.active_render = True


def image_second_uv(tree):
    """The image read over the mesh's second UV map (a UV Map node naming it)."""
    node = _image_node(tree)
    uv_map = tree.nodes.new("ShaderNodeUVMap")
    uv_map.uv_map = SECOND_UV_MAP
    tree.links.new(uv_map.outputs["UV"], node.inputs["Vector"])
    return node.outputs["Color"]


def _backdrop_material():
    """The backdrop's: an Emission of (0.1, 0.3, 0.8)."""
    import bpy

    if "backdrop" in bpy.data.materials:
        return bpy.data.materials["backdrop"]
    material, tree, output = empty_node_material("backdrop")
    emission = tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (0.1, 0.3, 0.8, 1.0)
    tree.links.new(emission.outputs[0], output.inputs["Surface"])
    return material


def _socket_case(value_of):
    return lambda name: _emitting(name, value_of)


CASES = {"image": _socket_case(image), "image_non_color": _socket_case(image_non_color),
         "separate_color": _socket_case(separate_green), "combine_color": _socket_case(combine_swizzled),
         "separate_combine_xyz": _socket_case(separate_combine_xyz), "math_and_mix": _socket_case(math_and_mix),
         "muted_and_rerouted": _socket_case(muted_and_rerouted), "nested_groups": _socket_case(nested_groups),
         "principled_emission_texture": principled_emission_texture,
         "emission_strength_texture": emission_strength_texture, "grouped_shader": grouped_shader,
         "mix_shader_textured_factor": mix_shader_textured_factor, "color_attribute": _socket_case(color_attribute),
         "color_attribute_corners": _socket_case(color_attribute), "attribute_fac": _socket_case(attribute_fac),
         "image_times_color_attribute": _socket_case(image_times_color_attribute),
         "color_attribute_missing": _socket_case(color_attribute),
         **{f"math_{operation.lower()}": _socket_case(math_operation(operation)) for operation in MATH_OPERATIONS},
         "clamp_minmax": _socket_case(clamp_node("MINMAX")), "clamp_range": _socket_case(clamp_node("RANGE")),
         **{f"map_range_{kind.lower()}": _socket_case(map_range_node(kind))
            for kind in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")},
         **{f"color_ramp_{kind.lower()}": _socket_case(color_ramp_node(kind)) for kind in ("LINEAR", "EASE", "CONSTANT")},
         "color_ramp_alpha": _socket_case(color_ramp_node("LINEAR", "Alpha")),
         "color_ramp_b_spline": _socket_case(color_ramp_node("B_SPLINE")),
         "color_ramp_cardinal": _socket_case(color_ramp_node("CARDINAL")),
         "color_ramp_cardinal_alpha": _socket_case(color_ramp_node("CARDINAL", "Alpha")),
         "color_ramp_hsv": _socket_case(color_ramp_node("LINEAR", color_mode="HSV")),
         "color_ramp_hsl_ease": _socket_case(color_ramp_node("EASE", color_mode="HSL")),
         **{f"mix_{blend.lower()}": _socket_case(mix_blend(blend)) for blend in MIX_BLENDS},
         "rgb_curves": _socket_case(curves_node("rgb")), "vector_curves": _socket_case(curves_node("vector")),
         "vector_curves_horizontal": _socket_case(curves_node("vector", "HORIZONTAL")),
         "float_curve": _socket_case(curves_node("float")),
         **{kind: _socket_case(colour_node(kind))
            for kind in ("hue_saturation_value", "gamma", "brightness_contrast", "rgb_to_bw")},
         **{f"coordinates_{output.lower()}": _socket_case(coordinates_case(output))
            for output in ("Generated", "Object", "Normal", "UV")},
         "geometry_position": _socket_case(coordinates_case("Position", "ShaderNodeNewGeometry")),
         "checker": _socket_case(checker()), "checker_object_fac": _socket_case(checker("Object", 3.0, "Fac")),
         **{f"gradient_{kind.lower()}": _socket_case(gradient(kind))
            for kind in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "RADIAL", "QUADRATIC_SPHERE", "SPHERICAL")},
         **{f"mapping_{kind.lower()}": _socket_case(mapping_case(kind)) for kind in ("POINT", "TEXTURE", "VECTOR", "NORMAL")},
         **{f"vector_math_{operation.lower()}": _socket_case(vector_math_case(operation))
            for operation in ("CROSS_PRODUCT", "PROJECT", "REFLECT", "DOT_PRODUCT", "DISTANCE", "LENGTH", "NORMALIZE",
                              "MODULO", "SNAP")},
         "noise_fac": _socket_case(noise()), "noise_color": _socket_case(noise(output="Color")),
         "noise_distorted_object": _socket_case(noise(output="Color", distortion=1.5, vector_output="Object")),
         **{f"noise_{kind.lower()}": _socket_case(noise(kind))
            for kind in ("MULTIFRACTAL", "HYBRID_MULTIFRACTAL", "RIDGED_MULTIFRACTAL", "HETERO_TERRAIN")},
         "wave_bands_sin": _socket_case(wave()), "wave_bands_diagonal_saw": _socket_case(wave("BANDS", "DIAGONAL", "SAW")),
         "wave_rings_tri": _socket_case(wave("RINGS", "SPHERICAL", "TRI")),
         "wave_rings_z_sin_plain": _socket_case(wave("RINGS", "Z", "SIN", 0.0)),
         **{f"white_noise_{dimensions.lower()}_{output.lower()}": _socket_case(white_noise(dimensions, output))
            for dimensions, output in (("1D", "Value"), ("2D", "Color"), ("3D", "Color"), ("4D", "Color"),
                                       ("3D", "Value"))},
         "voronoi_f1": _socket_case(voronoi()), "voronoi_f1_color": _socket_case(voronoi(output="Color")),
         "voronoi_f1_position": _socket_case(voronoi(output="Position")),
         "voronoi_f2_manhattan": _socket_case(voronoi("F2", metric="MANHATTAN")),
         "voronoi_f1_minkowski": _socket_case(voronoi(metric="MINKOWSKI")),
         "voronoi_smooth_f1": _socket_case(voronoi("SMOOTH_F1")),
         "voronoi_smooth_f1_color": _socket_case(voronoi("SMOOTH_F1", "Color")),
         "voronoi_distance_to_edge": _socket_case(voronoi("DISTANCE_TO_EDGE")),
         "voronoi_n_sphere_radius": _socket_case(voronoi("N_SPHERE_RADIUS", "Radius")),
         "voronoi_fractal": _socket_case(voronoi(detail=2.5, normalize=True)),
         "voronoi_fractal_edge": _socket_case(voronoi("DISTANCE_TO_EDGE", detail=1.5, normalize=True)),
         "brick": _socket_case(brick()), "brick_fac_hard_mortar": _socket_case(brick("Fac", smooth=0.0)),
         "brick_squashed": _socket_case(brick(offset_frequency=3, squash=0.6, squash_frequency=2)),
         "magic_depth_2": _socket_case(magic(2)), "magic_depth_5_fac": _socket_case(magic(5, "Fac")),
         **{f"image_{extension.lower()}": _socket_case(image_extended(extension))
            for extension in ("REPEAT", "EXTEND", "CLIP", "MIRROR")},
         "image_generated": _socket_case(image_at(lambda tree: _coordinates(tree, "Generated"))),
         "image_uv_by_math": _socket_case(image_at(uv_transformed_by_math)),
         "image_turned_about_x": _socket_case(image_at(lambda tree: _mapping_node(tree, "POINT",
                                                                                 _coordinates(tree, "UV")))),
         "bump": _socket_case(bump()), "bump_inverted_half": _socket_case(bump(0.5, 0.4, True)),
         "fresnel": _socket_case(fresnel_node()), "fresnel_ior_3": _socket_case(fresnel_node(3.0)),
         "layer_weight_fresnel": _socket_case(layer_weight("Fresnel", 0.3)),
         "layer_weight_facing": _socket_case(layer_weight("Facing", 0.3)),
         "layer_weight_facing_0_8": _socket_case(layer_weight("Facing", 0.8)),
         "mix_shader_by_fresnel": mix_shader_by_fresnel, "unlit": unlit,
         "image_second_uv_map": _socket_case(image_second_uv),
         "alpha_constant": alpha_constant, "alpha_texture": alpha_texture, "transparent_mix": transparent_mix}
# the cases on a sphere (what depends on the view's angle to the surface) in place of the plane
SPHERE_CASES = ("fresnel", "fresnel_ior_3", "layer_weight_fresnel", "layer_weight_facing", "layer_weight_facing_0_8",
                "mix_shader_by_fresnel")
# the cases over a backdrop: a second plane behind, which shows through their transparency
BACKDROP_CASES = ("alpha_constant", "alpha_texture", "transparent_mix")
# cases whose truth is 0 everywhere (scored by their largest values)
ZERO_TRUTH = ("color_attribute_missing",)
# the cases whose grid has the colour attribute: (domain, data type)
COLOURED = {"color_attribute": ("POINT", "FLOAT_COLOR"), "color_attribute_corners": ("CORNER", "BYTE_COLOR"),
            "attribute_fac": ("POINT", "FLOAT_COLOR"), "image_times_color_attribute": ("POINT", "FLOAT_COLOR")}


def build(name, size):
    """The case's plane (2 m, 8 x 8 faces, its UVs over [0, 1]; the colour attribute where the case has one)
    under an orthographic camera that it fills; a sphere in the plane's place for SPHERE_CASES; a larger plane
    behind it for BACKDROP_CASES."""
    import bpy

    from benchmarks import truth_suite
    from examples import build_scenes

    scene = truth_suite._start(size)
    truth_suite._black_world(scene)
    if name in SPHERE_CASES:
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=0.95)
        bpy.context.active_object.data.shade_smooth()
    else:
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=8, size=2.0)
    plane = bpy.context.active_object
    if name in COLOURED:
        add_colour_attribute(plane.data, *COLOURED[name])
    if name == "image_second_uv_map":
        add_second_uv_map(plane.data)
    plane.data.materials.append(CASES[name](name))
    if name in BACKDROP_CASES:
        bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0.0, 0.0, -0.5))
        bpy.context.active_object.data.materials.append(_backdrop_material())
    camera = build_scenes._add_camera(scene, location=(0.0, 0.0, 3.0), target=(0.0, 0.0, 0.0))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 2.0
    scene.render.film_transparent = True
    return scene


def score(name, size, samples, log=print, scores=True):
    """One case's row (benchmarks/cycles_truth.score); without `scores`, the largest values alone (a case whose
    truth is 0 has no relative error)."""
    from benchmarks import cycles_truth

    row = {"case": name, "size": size, **cycles_truth.score(build(name, size), samples, scores)}
    if scores:
        log(f"{name:28s} rmse {row['relative_rmse']:.4f}  bias {row['relative_bias']:+.4f}  noise floor "
            f"{row['noise_floor']:.4f}")
    else:
        log(f"{name:28s} largest {row['largest']:.4g}  truth's largest {row['truth_largest']:.4g}")
    return row


def markdown_section(data):
    lines = [SECTION_TITLE, "", "Each node's output routed into an Emission on a plane filling an orthographic view "
             f"(`benchmarks/node_values.py`), {data['size']} x {data['size']}, Cycles {data['cycles_samples']} spp x "
             "2 seeds: Cycles' image is the socket's value.  SG-PRT reads the same nodes.  Relative RMSE and bias "
             "over the plane.  The cases of an 8-bit sRGB image keep a bias of +0.5-0.8%: Cycles filters the "
             "encoded texels and decodes the result, the GPU (SG-PRT, EEVEE) decodes the texels before it filters; "
             "the same image as Non-Color has none.  The transparency cases (alpha_constant, alpha_texture, "
             "transparent_mix) lie over a plane emitting (0.1, 0.3, 0.8) that shows through them: SG-PRT's dithered "
             "coverage at Edges Only's 4 x 4 grid against Cycles' samples.", "",
             "| case | relative RMSE | bias | noise floor |", "|---|---|---|---|"]
    for row in data["rows"]:
        if "relative_rmse" in row:
            lines.append(f"| {row['case']} | {row['relative_rmse']:.4f} | {row['relative_bias']:+.4f} | "
                         f"{row['noise_floor']:.4f} |")
        else:
            lines.append(f"| {row['case']} | largest {row['largest']:.3g}, Cycles' {row['truth_largest']:.3g} | | |")
    from benchmarks import cycles_truth

    lines += ["", f"Rerun: `.venv/bin/python -m benchmarks.node_values --size {data['size']} --cycles-samples "
              f"{data['cycles_samples']}` ({data['seconds']:.0f} s), then `--update-doc`."
              + cycles_truth.merged_note(data, "--cases")]
    return "\n".join(lines)


def main(argv=None):
    from benchmarks import cycles_truth

    def score_case(name, size, samples):
        return score(name, size, samples, scores=name not in ZERO_TRUTH)

    cycles_truth.cases_main(argv, __doc__.splitlines()[0], "--cases", CASES, 64, 16, score_case, JSON_PATH, DOC_PATH,
                            SECTION_TITLE, markdown_section)


if __name__ == "__main__":
    main()
