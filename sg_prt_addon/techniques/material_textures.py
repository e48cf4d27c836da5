"""A material's textured slots in its surface shader: each slot the variant textures (its key's `textures`) is
read as texture_value_<slot>() (shaders/techniques/common/material_textures.glsl reads the images), from the
slot's own image (sampler texture_<slot>), or computed per pixel from a node tree's images, the mesh's colour
attribute, the surface's coordinates and node functions (a reflectance.texture_expression.Expression: the key's
`node_values`; shaders/lib/node_functions.glsl), each image read once a pixel (sampler node_image_<k>), the
colour attribute from the vertex stage (vertex_color), the coordinates as COORDINATE_SOURCES says.  The normal
map is read by surface_io.glsl itself (its mip level too).  The computed slots' numbers are read from a
uniform block (NodeConstants), so a value edited in the node tree assembles the same shader.

A technique's key carries `textures` (slot names) and `node_values` (a NodeValues, from `node_values`);
`samplers`, `bind` and `sources` give its shader the rest, shader_sources.surface_calls the colour stream and
the block (node_constants: len(constant_rows(key)))."""
import functools
from dataclasses import dataclass

import numpy as np

from ..reflectance import node_functions, voronoi
from . import shader_sources

NORMAL_MAP = "normal_map"
MAPPING_TYPES = ("POINT", "TEXTURE", "VECTOR", "NORMAL")
IMAGE_EXTENSIONS = ("REPEAT", "EXTEND", "CLIP", "MIRROR")        # material_textures.glsl's extension index
# The surface's coordinates in GLSL (texture_expression.COORDINATES): object_position is the vertex stage's
# (HAS_OBJECT_POSITION), generated_scale and generated_offset the object's push constants (the mesh's texture
# space, bind_object)
COORDINATE_SOURCES = {
    "UV": "vec3(texcoord, 0.0)",
    "SECOND_UV": "vec3(texcoord_second, 0.0)",
    "OBJECT": "object_position",
    "GENERATED": "(object_position * generated_scale.xyz + generated_offset.xyz)",
    "NORMAL": "normalize(transpose(mat3(model_matrix)) * world_normal)",
    "POSITION": "world_position",
    "WORLD_NORMAL": "normalize(world_normal)",
    "INCOMING": "(scene.camera.w > 0.5 ? normalize(scene.camera.xyz - world_position) : -normalize(scene.camera.xyz))",
}
# What a colour attribute or the second UV map reads where the mesh has none (Cycles: an attribute not found is 0)
MISSING_ATTRIBUTE = "vec3(0.0)"


@dataclass(frozen=True)
class NodeValues:
    """The slots a node tree computes: ((slot, Expression), ...) by slot; vertex_colors: they read a colour
    attribute and the object's mesh has one (its vertex stream); coordinates: the surface coordinates they read
    (texture_expression.COORDINATES); coverage: the surface's alpha is below 1 somewhere (HAS_COVERAGE: dithered
    coverage, and drawn after the depth pre-pass); holdout: some of it is a holdout (HAS_HOLDOUT)."""
    slots: tuple = ()
    vertex_colors: bool = False
    coordinates: tuple = ()
    coverage: bool = False
    holdout: bool = False
    second_uv: bool = False      # they read the second UV map and the object's mesh has one (its vertex stream)

    @property
    def object_position(self):
        """Whether the vertex stage passes the object-space position on."""
        return bool({"OBJECT", "GENERATED"} & set(self.coordinates))

    @property
    def generated(self):
        """Whether the shader takes the object's texture space (push constants generated_scale, _offset)."""
        return "GENERATED" in self.coordinates


def node_values(params, textures, inputs):
    """NodeValues of the slots among `textures` whose value a node tree computes (inputs: base.ObjectInputs)."""
    slots = tuple((slot, params.textures[slot]) for slot in sorted(textures)
                  if not isinstance(params.textures[slot], str))
    reads_attributes = any(expression.attributes for _, expression in slots)
    coordinates = tuple(sorted({name for _, expression in slots for name in expression.coordinate_names}))
    return NodeValues(slots, reads_attributes and inputs.vertex_colors, coordinates,
                      coverage=has_coverage(params, textures), holdout=params.holdout > 0.0 or "holdout" in textures,
                      second_uv="SECOND_UV" in coordinates and inputs.second_uv)


def has_coverage(params, textures=None):
    """Whether a material's surface is drawn over less than all of a pixel somewhere (its alpha slot)."""
    return params.alpha < 1.0 or "alpha" in (params.textures if textures is None else textures)


def bind_object(shader, key, context):
    """The object's own values a variant reads: its mesh's texture space (DrawContext.generated_transform)."""
    node_values = getattr(key, "node_values", None)
    if node_values is not None and node_values.generated:
        scale, offset = context.generated_transform
        shader.uniform_float("generated_scale", scale)
        shader.uniform_float("generated_offset", offset)


def images(key):
    """The images the computed slots read, sorted: node_image_<k> is the k-th."""
    return tuple(sorted({name for _, expression in key.node_values.slots for name in expression.images}))


def samplers(key):
    computed = {slot for slot, _ in key.node_values.slots}
    out = [("FLOAT_2D", "texture_" + name) for name in key.textures if name not in computed]
    return out + [("FLOAT_2D", f"node_image_{k}") for k in range(len(images(key)))]


def bind(shader, key, context):
    """The slots' images (DrawContext.image), the computed slots' (DrawContext.node_image) and their numbers
    (DrawContext.material_uniforms)."""
    rows = constant_rows(key)
    if len(rows):
        shader.uniform_block("node_constants", context.material_uniforms(rows))
    computed = {slot for slot, _ in key.node_values.slots}
    for name in key.textures:
        if name not in computed:
            shader.uniform_sampler("texture_" + name, context.image(name))
    for k, name in enumerate(images(key)):
        shader.uniform_sampler(f"node_image_{k}", context.node_image(name))


class NodeConstants:
    """The numbers of a material's computed slots (the terms' coefficients, the factors' scales and offsets),
    gathered as their GLSL is written: the GLSL reads them from the NodeConstants block (node_constants.values[k],
    bound per material: bind), so a value edited in a node tree changes the block, not the shader.  Without
    `uniform`, they are written as literals."""

    def __init__(self, uniform=True):
        self.uniform = uniform
        self.rows = []

    def vec3(self, rgb):
        if not self.uniform:
            return f"vec3({', '.join(shader_sources.float_literal(c) for c in rgb)})"
        self.rows.append((*(float(c) for c in rgb), 0.0))
        return f"node_constants.values[{len(self.rows) - 1}].xyz"

    def affine(self, scale, offset, value):
        """offset + scale x value (a GLSL expression)."""
        if not self.uniform:
            literal = shader_sources.float_literal
            return f"({literal(offset)} + {literal(scale)} * {value})"
        self.rows.append((float(scale), float(offset), 0.0, 0.0))
        row = f"node_constants.values[{len(self.rows) - 1}]"
        return f"({row}.y + {row}.x * {value})"


def expression_source(expression, rgb_of, helpers, sampler_of=None, constants=None):
    """An Expression as a GLSL vec3 expression; rgb_of(factor): the GLSL vec3 of its image or attribute at the
    pixel; helpers: {settings: (name, GLSL)} of the helper functions it calls (a Color Ramp's), added to;
    sampler_of(image name): the sampler an image read at coordinates of its own is read from; constants: the
    NodeConstants its numbers go to (None: literals)."""
    constants = constants or NodeConstants(uniform=False)

    def factor_source(factor):
        value = function_source(factor.function, rgb_of, helpers, sampler_of, constants) \
            if factor.function is not None else rgb_of(factor)
        value += "" if factor.channel is None else "." + "rgb"[factor.channel] * 3
        if factor.scale == 1.0 and factor.offset == 0.0:
            return value
        return constants.affine(factor.scale, factor.offset, value)

    terms = [" * ".join([constants.vec3(coefficient)] + [factor_source(factor) for factor in factors])
             for coefficient, factors in expression.terms]
    return " + ".join(terms)


def function_source(function, rgb_of, helpers, sampler_of=None, constants=None):
    """A texture_expression.Function as a GLSL vec3 expression (shaders/lib/node_functions.glsl's node_<name>,
    a Color Ramp's helper, an image at coordinates of its own: material_textures.glsl's material_texture_at)."""
    args = [expression_source(arg, rgb_of, helpers, sampler_of, constants) for arg in function.args]
    name, settings = function.name, function.settings
    if name == "image":
        value = f"material_texture_at({sampler_of(settings[0])}, ({args[0]}).xy, {IMAGE_EXTENSIONS.index(settings[1])})"
        return f"vec3({value}.a)" if settings[2] == "Alpha" else f"{value}.rgb"
    if name == "color_ramp":
        helper = _ramp_helper(settings[:3], helpers)
        value = f"{helper}(({args[0]}).r)"
        return f"{value}.rgb" if settings[3] == "Color" else f"vec3({value}.a)"
    if name == "curves":
        return f"{_curves_helper(settings, helpers)}({', '.join(args)})"
    glsl_name, flags = _GLSL_CALLS[name](settings) if name in _GLSL_CALLS else (f"node_{name}", ())
    return f"{glsl_name}({', '.join([*args, *flags])})"


def _bool(value):
    return "true" if value else "false"


def _index(names, name):
    return str(names.index(name))


# name -> settings -> (the node_functions.glsl function, the arguments after the inputs that pass the settings)
_GLSL_CALLS = {
    "math": lambda settings: (f"node_math_{settings[0].lower()}", ()),
    "clamp": lambda settings: ("node_clamp_range" if settings[0] == "RANGE" else "node_clamp", ()),
    "map_range": lambda settings: ("node_map_range", (_index(node_functions.MAP_RANGE_INTERPOLATIONS, settings[0]),
                                                      _bool(settings[1]))),
    "mix": lambda settings: (f"node_mix_{settings[0].lower()}", ()),
    "mapping": lambda settings: ("node_mapping", (_index(MAPPING_TYPES, settings[0]),)),
    "vector_math": lambda settings: (f"node_vector_{settings[0].lower()}", ()),
    "tex_checker": lambda settings: ("node_tex_checker", (_bool(settings[0] == "Color"),)),
    "tex_gradient": lambda settings: ("node_tex_gradient", (_index(node_functions.GRADIENTS, settings[0]),)),
    "tex_noise": lambda settings: ("node_tex_noise", (_index(node_functions.NOISE_TYPES, settings[0]),
                                                      _bool(settings[1]), _bool(settings[2] == "Color"))),
    "tex_wave": lambda settings: ("node_tex_wave", ("0" if settings[0] == "BANDS" else "1",
                                                    _index(node_functions.WAVE_DIRECTIONS, settings[1]),
                                                    _index(node_functions.WAVE_DIRECTIONS, settings[2]),
                                                    _index(node_functions.WAVE_PROFILES, settings[3]))),
    "tex_magic": lambda settings: ("node_tex_magic", (str(int(settings[0])), _bool(settings[1] == "Color"))),
    "tex_white_noise": lambda settings: ("node_tex_white_noise", (_index(node_functions.NOISE_DIMENSIONS, settings[0]),
                                                                  _bool(settings[1] == "Color"))),
    "layer_weight": lambda settings: ("node_layer_weight", (_bool(settings[0] == "Fresnel"),)),
    "tex_brick": lambda settings: ("node_tex_brick", (shader_sources.float_literal(settings[0]), str(int(settings[1])),
                                                      shader_sources.float_literal(settings[2]), str(int(settings[3])),
                                                      _bool(settings[4] == "Color"))),
    "tex_voronoi": lambda settings: ("node_tex_voronoi", (_index(voronoi.FEATURES, settings[0]),
                                                          _index(voronoi.METRICS, settings[1]), _bool(settings[2]),
                                                          _index(voronoi.OUTPUTS, settings[3]))),
    "bump": lambda settings: ("node_bump", (_bool(settings[0]),)),
}


def _ramp_helper(settings, helpers):
    """The name of the GLSL function giving a Color Ramp's RGBA at x (node_functions.color_ramp), added to
    helpers once for each ramp."""
    if settings in helpers:
        return helpers[settings][0]
    literal = shader_sources.float_literal
    interpolation, positions, colours = settings
    name = f"node_ramp_{len(helpers)}"
    lines = [f"vec4 {name}(float x)", "{", "  x = clamp(x, 0.0, 1.0);",
             f"  vec4 value = vec4({', '.join(literal(c) for c in colours[0])});", "  float t;"]
    for k in range(1, len(positions)):
        low, high = positions[k - 1], positions[k]
        if interpolation == "CONSTANT" or high <= low:
            lines.append(f"  t = step({literal(high)}, x);")
        else:
            lines.append(f"  t = clamp((x - {literal(low)}) / {literal(high - low)}, 0.0, 1.0);")
            if interpolation == "EASE":
                lines.append("  t = t * t * (3.0 - 2.0 * t);")
        lines.append(f"  value = mix(value, vec4({', '.join(literal(c) for c in colours[k])}), t);")
    lines += ["  return value;", "}"]
    helpers[settings] = (name, "\n".join(lines))
    return name


def _curves_helper(settings, helpers):
    """The name of the GLSL function (fac, value) of a curves node (node_functions.curves): its table as a
    constant array, added to helpers once for each table."""
    if settings in helpers:
        return helpers[settings][0]
    literal = shader_sources.float_literal
    min_x, max_x, extrapolate, table = settings
    name, last = f"node_curves_{len(helpers)}", len(table) - 1
    rows = ",\n  ".join(f"vec3({', '.join(literal(v) for v in row)})" for row in table)
    lines = [f"const vec3 {name}_table[{len(table)}] = vec3[{len(table)}](\n  {rows});",
             f"float {name}_channel(int k, float f)", "{"]
    if extrapolate:
        lines += ["  if (f < 0.0) {",
                  f"    return {name}_table[0][k] + ({name}_table[0][k] - {name}_table[1][k]) * -f * {literal(last)};",
                  "  }", "  if (f > 1.0) {",
                  f"    return {name}_table[{last}][k] + ({name}_table[{last}][k] - {name}_table[{last - 1}][k]) * "
                  f"(f - 1.0) * {literal(last)};", "  }"]
    lines += [f"  float scaled = clamp(f, 0.0, 1.0) * {literal(last)};", f"  int i = clamp(int(scaled), 0, {last});",
              "  float t = scaled - float(i);", f"  float low = {name}_table[i][k];",
              f"  return t > 0.0 ? (1.0 - t) * low + t * {name}_table[min(i + 1, {last})][k] : low;", "}",
              f"vec3 {name}(vec3 fac, vec3 value)", "{",
              f"  vec3 relative = (value - vec3({literal(min_x)})) / {literal(max_x - min_x)};",
              f"  vec3 curved = vec3({name}_channel(0, relative.x), {name}_channel(1, relative.y), "
              f"{name}_channel(2, relative.z));",
              "  return (1.0 - fac.x) * value + fac.x * curved;", "}"]
    helpers[settings] = (name, "\n".join(lines))
    return name


def _functions_used(key):
    """The names of the node functions the computed slots call, inside other functions' inputs too."""
    def functions_in(expression):
        for _, factors in expression.terms:
            for factor in factors:
                if factor.function is not None:
                    yield factor.function.name
                    for arg in factor.function.args:
                        yield from functions_in(arg)

    return {name for _, expression in key.node_values.slots for name in functions_in(expression)}


def values_source(key):
    """GLSL: each computed slot's image read once a pixel (node_image_<k>_rgb()), and texture_value_<slot>() of
    every textured slot but the normal map (a colour attribute: the vertex stage's vertex_color, or
    MISSING_ATTRIBUTE where the mesh has none), after the helpers they call; their numbers from the
    NodeConstants block (constant_rows)."""
    return _values(key)[0]


def constant_rows(key):
    """The NodeConstants block's rows of a variant ((k, 4) float32; k may be 0): its material's numbers in the
    order values_source's GLSL reads them."""
    return _values(key)[1]


@functools.lru_cache(maxsize=256)
def _values(key):
    names = images(key)
    lines = ["/* The material's textured slots (techniques/material_textures.py) */"]
    for k in range(len(names)):
        lines += [f"vec3 node_image_{k}_value = vec3(0.0);", f"bool node_image_{k}_read = false;",
                  f"vec3 node_image_{k}_rgb()", "{", f"  if (!node_image_{k}_read) {{",
                  f"    node_image_{k}_value = material_texture(node_image_{k}).rgb;",
                  f"    node_image_{k}_read = true;", "  }", f"  return node_image_{k}_value;", "}"]
    computed = dict(key.node_values.slots)
    attribute = "vertex_color.rgb" if key.node_values.vertex_colors else MISSING_ATTRIBUTE

    def rgb_of(factor):
        if factor.coordinates == "SECOND_UV" and not key.node_values.second_uv:
            return MISSING_ATTRIBUTE
        if factor.coordinates is not None:
            return COORDINATE_SOURCES[factor.coordinates]
        return attribute if factor.attribute else f"node_image_{names.index(factor.image)}_rgb()"

    helpers, slots, constants = {}, [], NodeConstants()
    for slot in key.textures:
        if slot == NORMAL_MAP:
            continue
        slots += [f"vec4 texture_value_{slot}()", "{"]
        if slot in computed:
            value = expression_source(computed[slot], rgb_of, helpers, lambda image: f"node_image_{names.index(image)}",
                                      constants)
            slots.append(f"  return vec4({value}, 1.0);")
        else:
            slots.append(f"  return material_texture(texture_{slot});")
        slots.append("}")
    source = "\n".join(lines + [source for _, source in helpers.values()] + slots) + "\n"
    return source, np.asarray(constants.rows, np.float32).reshape(-1, 4)


def noise_offsets_source():
    """The Noise Texture's five random offsets (node_functions.random_float3_offset) as the GLSL constant
    node_functions.glsl reads: computed here, so GLSL and numpy read the same float32 values."""
    literal = shader_sources.float_literal
    offsets = ", ".join("vec3(" + ", ".join(literal(v) for v in node_functions.random_float3_offset(seed)) + ")"
                        for seed in range(5))
    return f"const vec3 NODE_NOISE_OFFSETS[5] = vec3[5]({offsets});\n"


def sources(key):
    """The surface shader's sources from surface_common.glsl to surface_io.glsl, the slots' values between."""
    used = _functions_used(key)
    library = [noise_offsets_source(), shader_sources.library_source("node_functions.glsl")] if used else []
    if "tex_voronoi" in used:
        library.append(shader_sources.library_source("voronoi.glsl"))
    return [shader_sources.technique_source("common", "surface_common.glsl"),
            shader_sources.technique_source("common", "material_textures.glsl"), *library, values_source(key),
            shader_sources.technique_source("common", "surface_io.glsl")]
