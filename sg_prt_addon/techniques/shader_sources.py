"""GLSL every surface shader shares, and the pieces of its GPUShaderCreateInfo.

shaders/lib: pure kernels mirroring the maths packages (lib/README.md); shaders/engine: the scene block, the vertex
stage and the engine's own passes (depth, background); shaders/techniques/<name>: a technique's own.

The per-vertex rows of a precomputation (an SSDF bake's PCA coefficients, a pass's output laid out
the same way) reach the fragment shader as varyings, one vec4 each, interpolated per pixel.  Their
fetch in the vertex stage and their copy into the technique's arrays in the fragment stage are
generated here from a tuple of PerVertexInput, so no GLSL file is unrolled by hand for a row count.
"""
import os
import re
from dataclasses import dataclass

from ..lighting import shadow_maps


def _shader_dir():
    """shaders/ inside the package (installed extension) or next to it (the repository)."""
    package_dir = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for candidate in (os.path.join(package_dir, "shaders"), os.path.join(package_dir, os.pardir, "shaders")):
        if os.path.isdir(os.path.join(candidate, "engine")):
            return os.path.normpath(candidate)
    return os.path.normpath(os.path.join(package_dir, os.pardir, "shaders"))


SHADER_DIR = _shader_dir()
LIB_DIR = os.path.join(SHADER_DIR, "lib")
ENGINE_DIR = os.path.join(SHADER_DIR, "engine")
TECHNIQUE_DIR = os.path.join(SHADER_DIR, "techniques")

# Sizes of the scene block's arrays (engine/scene_data.glsl, filled by engine.renderer.scene_block)
MAX_POINT_LIGHTS = 128     # an area light is lights.area_grid's patches (16 at the default 4 a side)
MAX_SUNS = 8
MAX_ENV_LOBES = 16
MAX_LAYERS = 48
MAX_SHADOW_MAPS = shadow_maps.MAX_SHADOW_MAPS
LIMITS = {"SGPRT_MAX_POINT_LIGHTS": MAX_POINT_LIGHTS, "SGPRT_MAX_SUNS": MAX_SUNS,
          "SGPRT_MAX_ENV_LOBES": MAX_ENV_LOBES, "SGPRT_MAX_LAYERS": MAX_LAYERS,
          "SGPRT_MAX_SHADOW_MAPS": MAX_SHADOW_MAPS}

GBUFFER_OUTPUTS = ("position", "normal", "tangent", "uv")
# vec4 varyings a surface shader may use where the driver cannot be asked (max_varyings): llvmpipe gives 128
# floats (Mesa 22.3), as desktop GL drivers commonly do; the surface's own take 5 with per-vertex rows
# (surface_calls' interface: position, normal, tangent, texcoord, vertex normal)
MAX_VARYINGS = 32
SURFACE_VARYINGS = 5
_driver_varyings = []


def max_varyings():
    """vec4 varyings a surface shader may use: the driver's (gpu.capabilities, asked once inside a GPU context;
    Metal and some GL drivers give fewer than 128 floats), else MAX_VARYINGS."""
    if not _driver_varyings:
        try:
            from gpu import capabilities  # answers only in Blender's GPU context
            _driver_varyings.append(int(capabilities.max_varying_floats_get()) // 4)
        except (ImportError, AttributeError, SystemError):  # no GPU context (background without one, the maths' tests)
            return MAX_VARYINGS
    return _driver_varyings[0]


def shadow_map_constants():
    """The SHADOW_* constants shaders/lib/shadow_maps.glsl reads, from lighting.shadow_maps."""
    return (f"const float SHADOW_MARGIN = {float_literal(shadow_maps.MARGIN)};\n"
            f"const int SHADOW_SEARCH_TAPS = {shadow_maps.SEARCH_TAPS};\n"
            f"const int SHADOW_FILTER_TAPS = {shadow_maps.FILTER_TAPS};\n"
            f"const float SHADOW_DEPTH_BIAS = {float_literal(shadow_maps.DEPTH_BIAS)};\n"
            f"const float SHADOW_NORMAL_OFFSET = {float_literal(shadow_maps.NORMAL_OFFSET)};\n")


def output_names(gbuffer):
    """Colour attachments in slot order.  Framebuffers take at most 6, so the G-buffer variant
    leaves Combined out (the caller adds Diffuse + Specular, the same float32 sum)."""
    return (("diffuse", "specular") + GBUFFER_OUTPUTS) if gbuffer else ("combined", "diffuse", "specular")


def read(path):
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def library_source(file_name):
    return read(os.path.join(LIB_DIR, file_name))


def engine_source(file_name):
    return read(os.path.join(ENGINE_DIR, file_name))


def technique_source(technique_dir, file_name):
    return read(os.path.join(TECHNIQUE_DIR, technique_dir, file_name))


def float_literal(value):
    text = repr(float(value))
    return text if ("e" in text or "." in text) else text + ".0"


def numbered(source):
    return "\n".join(f"{n:5d}  {line}" for n, line in enumerate(source.split("\n"), 1))


def typedef_source():
    source = engine_source("scene_data.glsl")
    for name, value in LIMITS.items():          # typedefs may be emitted before the defines
        source = re.sub(rf"\b{name}\b", str(value), source)
    return source


@dataclass(frozen=True)
class PerVertexInput:
    """Rows of one per-vertex texture, read by the vertex stage and interpolated to the fragments.

    sampler: the texture (vertex v's row k at texel ((v % per_row) * rows + k, v // per_row),
    per_row = its width / rows); rows: vec4 a vertex (visibility.per_vertex.MAX_ROWS at most); varying: the varyings' name prefix (varying_0...);
    array: the fragment stage's vec4 array the technique declares and the rows are copied into."""
    sampler: str
    rows: int
    varying: str
    array: str


def per_vertex_fetch_source(inputs):
    """Vertex-stage function fetch_per_vertex_rows() filling the varyings of `inputs`."""
    lines = ["void fetch_per_vertex_rows()", "{", "  int per_row, row, column;"]
    for item in inputs:
        lines += [f"  per_row = textureSize({item.sampler}, 0).x / {item.rows};",
                  "  row = vertex_index / per_row;",
                  f"  column = (vertex_index - row * per_row) * {item.rows};"]
        lines += [f"  {item.varying}_{k} = texelFetch({item.sampler}, ivec2(column + {k}, row), 0);"
                  for k in range(item.rows)]
    return "\n".join(lines + ["}", ""])


def per_vertex_copy_source(inputs):
    """Fragment-stage function load_per_vertex_rows() copying the varyings into the technique's arrays."""
    lines = ["void load_per_vertex_rows()", "{"]
    for item in inputs:
        lines += [f"  {item.array}[{k}] = {item.varying}_{k};" for k in range(item.rows)]
    return "\n".join(lines + ["}", ""])


def vertex_source(per_vertex=()):
    """The surface vertex stage (engine/mesh.vert.glsl) with the fetch of `per_vertex` (PerVertexInput)."""
    source = engine_source("mesh.vert.glsl")
    return (per_vertex_fetch_source(per_vertex) + source) if per_vertex else source


def surface_calls(defines, fragment_source, samplers, gbuffer, per_vertex=(), push_constants=(), node_values=None,
                  node_constants=0):
    """The create-info calls of a surface shader (see base.Technique.create_info_calls): `defines` (name ->
    value, the scene limits added), the vertex stage with `per_vertex`'s fetch (PER_VERTEX_ROWS defined;
    the fragment source calls per_vertex_copy_source's load_per_vertex_rows), what the material's computed
    values read (node_values: techniques.material_textures.NodeValues): the mesh's colour attribute as the
    vertex_color varying (HAS_VERTEX_COLOR), the object-space position as object_position
    (HAS_OBJECT_POSITION), the mesh's second UV map as texcoord_second (HAS_SECOND_UV), the texture space's push
    constants, the coverage and holdout (HAS_COVERAGE, HAS_HOLDOUT); the scene and material blocks at bindings
    0 and 1, `samplers` ((kind, name) in slot order), the technique's own push_constants ((type, name)) after
    the model matrix, the NodeConstants block of `node_constants` rows at binding 2 where there are any
    (techniques.material_textures.constant_rows), and the outputs of output_names."""
    vertex_colors = node_values is not None and node_values.vertex_colors
    object_position = node_values is not None and node_values.object_position
    second_uv = node_values is not None and node_values.second_uv
    coverage = node_values is not None and node_values.coverage
    holdout = node_values is not None and node_values.holdout
    defines = {**LIMITS, **defines, **({"PER_VERTEX_ROWS": 1} if per_vertex else {}),
               **({"HAS_VERTEX_COLOR": 1} if vertex_colors else {}),
               **({"HAS_OBJECT_POSITION": 1} if object_position else {}),
               **({"HAS_COVERAGE": 1} if coverage else {}), **({"HAS_HOLDOUT": 1} if holdout else {}),
               **({"HAS_SECOND_UV": 1} if second_uv else {})}
    calls = [("define", (name, str(value))) for name, value in sorted(defines.items())]
    typedefs = typedef_source()
    if node_constants:
        typedefs += f"struct NodeConstants {{\n  vec4 values[{node_constants}];\n}};\n"
    calls.append(("typedef_source", (typedefs,)))
    calls += [("vertex_in", (0, "VEC3", "position")), ("vertex_in", (1, "VEC3", "normal")),
              ("vertex_in", (2, "VEC4", "tangent")), ("vertex_in", (3, "VEC2", "uv"))]
    if per_vertex:
        calls += [("vertex_in", (4, "INT", "vertex_index")), ("vertex_in", (5, "VEC3", "vertex_normal"))]
    if vertex_colors:
        calls.append(("vertex_in", (6, "VEC4", "color")))
    if second_uv:
        calls.append(("vertex_in", (7, "VEC2", "second_uv")))
    interface = [("smooth", ("VEC3", "world_position")), ("smooth", ("VEC3", "world_normal")),
                 ("smooth", ("VEC4", "world_tangent")), ("smooth", ("VEC2", "texcoord"))]
    if per_vertex:
        # the vertex's smooth normal (a bake's frame) and its rows, interpolated per pixel (wang2009 5.3)
        interface.append(("smooth", ("VEC3", "world_vertex_normal")))
        interface += [("smooth", ("VEC4", f"{item.varying}_{k}")) for item in per_vertex for k in range(item.rows)]
    if vertex_colors:
        interface.append(("smooth", ("VEC4", "vertex_color")))
    if object_position:
        interface.append(("smooth", ("VEC3", "object_position")))
    if second_uv:
        interface.append(("smooth", ("VEC2", "texcoord_second")))
    interface_name = "sgprt_surface_interface" + "".join(f"_{item.varying}{item.rows}" for item in per_vertex) \
        + ("_color" if vertex_colors else "") + ("_object" if object_position else "") \
        + ("_second_uv" if second_uv else "")
    calls.append(("vertex_out", (interface_name, tuple(interface))))
    calls.append(("push_constant", ("MAT4", "model_matrix")))
    calls += [("push_constant", constant) for constant in push_constants]
    if node_values is not None and node_values.generated:
        calls += [("push_constant", ("VEC4", "generated_scale")), ("push_constant", ("VEC4", "generated_offset"))]
    if gbuffer:
        calls += [("push_constant", ("INT", "gbuffer_object_index")),
                  ("push_constant", ("INT", "gbuffer_triangle_offset"))]
    calls += [("uniform_buf", (0, "SceneData", "scene")), ("uniform_buf", (1, "MaterialData", "material"))]
    if node_constants:
        calls.append(("uniform_buf", (2, "NodeConstants", "node_constants")))
    calls += [("sampler", (slot, kind, name)) for slot, (kind, name) in enumerate(samplers)]
    calls += [("fragment_out", (index, "VEC4", "out_" + name)) for index, name in enumerate(output_names(gbuffer))]
    calls.append(("vertex_source", (vertex_source(per_vertex),)))
    calls.append(("fragment_source", (fragment_source,)))
    return calls


def full_screen_calls(interface_name, defines):
    """Create-info calls of a full-screen triangle (engine/background.vert.glsl, `ndc` out) with the scene
    block's typedefs, the limits and `defines` (FULL_SCREEN_DEPTH: NDC z, the far plane unless given): the
    caller adds the rest."""
    calls = [("define", (name, str(value))) for name, value in {**LIMITS, "FULL_SCREEN_DEPTH": "1.0",
                                                                **defines}.items()]
    calls += [("typedef_source", (typedef_source(),)), ("vertex_in", (0, "VEC2", "position")),
              ("vertex_out", (interface_name, (("smooth", ("VEC2", "ndc")),))),
              ("vertex_source", (engine_source("background.vert.glsl"),))]
    return calls
