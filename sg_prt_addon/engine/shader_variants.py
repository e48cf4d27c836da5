"""Assembly and cache of the surface shader variants.

A variant is keyed by what changes the code (not the values): the BRDF model,
its NDF lobe count, whether lights / an environment texture are present, which
material textures are bound, and whether the debug G-buffer is written.

Fragment source = generated header (constants from core/) + the GLSL mirrors
of core/ (shaders/lib/<name>.glsl) + our resources (anisotropic_lobes.glsl,
sg_shading.glsl) + surface.frag.glsl.
A compile error raises ShaderCompileError naming the variant and quoting the
offending lines of the numbered assembled source.
"""
import os
import re
import sys
import tempfile
from dataclasses import dataclass

import numpy as np

def _shader_dir():
    """shaders/ inside the package (installed extension) or next to it (the repository)."""
    package_dir = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    for candidate in (os.path.join(package_dir, "shaders"), os.path.join(package_dir, os.pardir, "shaders")):
        if os.path.isdir(os.path.join(candidate, "resources")):
            return os.path.normpath(candidate)
    return os.path.normpath(os.path.join(package_dir, os.pardir, "shaders"))


SHADER_DIR = _shader_dir()
LIB_DIR = os.path.join(SHADER_DIR, "lib")
RESOURCE_DIR = os.path.join(SHADER_DIR, "resources")

MAX_POINT_LIGHTS = 32
MAX_SUNS = 8
MAX_ENV_LOBES = 16
MAX_LAYERS = 48
LIMITS = {"SGPRT_MAX_POINT_LIGHTS": MAX_POINT_LIGHTS, "SGPRT_MAX_SUNS": MAX_SUNS,
          "SGPRT_MAX_ENV_LOBES": MAX_ENV_LOBES, "SGPRT_MAX_LAYERS": MAX_LAYERS}

TEXTURE_SLOTS = ("diffuse_color", "specular_color", "roughness", "ior", "exponent",
                 "alpha_x", "alpha_y", "nu", "nv", "normal_map")
ANISOTROPIC_MODELS = ("WARD_ANISO", "ASHIKHMIN_SHIRLEY")
# Variant model of materials rendered from their stored lobe fit (blender.lobe_fit, export.FittedLobes)
FITTED_MODEL = "FITTED"
GBUFFER_OUTPUTS = ("position", "normal", "tangent", "uv")
# Library files in dependency order; env_prefilter only with an environment texture.
LIBRARY_FILES = ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "lights.glsl", "brdf.glsl", "warp.glsl", "env_prefilter.glsl")
# Our own pieces (shaders/resources/), after the library.
RESOURCE_FILES = ("anisotropic_lobes.glsl", "ggx_two_lobes.glsl", "sg_shading.glsl")


def output_names(gbuffer):
    """Colour attachments in slot order.  Framebuffers take at most 6, so the G-buffer variant
    leaves Combined out (the caller adds Diffuse + Specular, the same float32 sum)."""
    return (("diffuse", "specular") + GBUFFER_OUTPUTS) if gbuffer else ("combined", "diffuse", "specular")


class ShaderCompileError(RuntimeError):
    """A variant failed to compile: the message names the variant and quotes the source lines."""


@dataclass(frozen=True)
class VariantKey:
    model: str = "GGX"
    ndf_lobes: int = 1
    has_lights: bool = False
    has_environment: bool = False
    textures: tuple = ()            # sorted names from TEXTURE_SLOTS
    gbuffer: bool = False
    visibility_layers: int = 0      # vec4 of SSDF coefficients per vertex (0: no visibility bake)
    shadowing_components: int = 0   # model FITTED: PCA components of the stored shadowing

    @property
    def has_visibility(self):
        return self.visibility_layers > 0

    def describe(self):
        parts = [self.model, f"{self.ndf_lobes} lobe(s)", "lights" if self.has_lights else "no lights",
                 "environment texture" if self.has_environment else "world colour"]
        if self.textures:
            parts.append("textures: " + ", ".join(self.textures))
        if self.gbuffer:
            parts.append("G-buffer")
        if self.model == FITTED_MODEL:
            parts.append(f"{self.shadowing_components} shadowing component(s)")
        if self.visibility_layers:
            parts.append(f"visibility ({self.visibility_layers} coefficient vec4)")
        return ", ".join(parts)


def variant_key(material_params, has_lights, has_environment, gbuffer=False, visibility_layers=0):
    """VariantKey of an export.MaterialParams in a scene (visibility_layers: of the object's bake, 0 without)."""
    from ..core.shading import GGX_NDF_LOBES

    fitted = getattr(material_params, "fitted", None)
    if fitted is not None:      # the stored lobe fit: its lobes, shadowing and base; only a normal map applies
        textures = ("normal_map",) if "normal_map" in material_params.textures else ()
        return VariantKey(FITTED_MODEL, int(fitted.lobe_count), bool(has_lights), bool(has_environment), textures,
                          bool(gbuffer), int(visibility_layers), int(fitted.components))
    model = material_params.model
    lobes = int(material_params.lobe_count) if model in ANISOTROPIC_MODELS else 1
    if model == "GGX":
        lobes = GGX_NDF_LOBES
    textures = tuple(sorted(name for name in material_params.textures if name in TEXTURE_SLOTS))
    return VariantKey(model, lobes, bool(has_lights), bool(has_environment), textures, bool(gbuffer),
                      int(visibility_layers))


def _read(path):
    with open(path, encoding="utf-8") as handle:
        return handle.read()


def library_source(file_name):
    return _read(os.path.join(LIB_DIR, file_name))


def _float_literal(value):
    text = repr(float(value))
    return text if ("e" in text or "." in text) else text + ".0"


def _constants_source(key):
    """Constants taken from core/ at assembly time, so GLSL and numpy cannot drift apart."""
    from ..core import brdf

    rf0 = brdf.AshikhminShirley.__dataclass_fields__["rf0"].default
    from ..core import shading
    return (f"const float BRDF_AS_RF0 = {_float_literal(rf0)};\n"
            f"const float VISIBILITY_SKIP_FRACTION = {_float_literal(shading.VISIBILITY_SKIP_FRACTION)};\n")


def warp_mode():
    """(GLSL function, lobes per NDF lobe) of core.warp's default mode, which the mirror uses."""
    from ..core import warp
    mode = warp.DEFAULT_MODE
    nodes = 1 if mode == "paper" else len(warp.SPLIT_RULES[mode][0])
    return f"warp_lobes_{mode}", nodes


def defines(key):
    out = dict(LIMITS)
    out["WARP_FUNCTION"], out["WARP_NODES"] = warp_mode()
    out["MODEL_" + key.model] = 1
    out["NDF_LOBES"] = key.ndf_lobes
    if key.has_lights:
        out["HAS_LIGHTS"] = 1
    if key.has_environment:
        out["HAS_ENVIRONMENT"] = 1
        out["ENV_PREFILTER_MAX_LAYERS"] = MAX_LAYERS
    for name in key.textures:
        out["HAS_NORMAL_MAP" if name == "normal_map" else "HAS_TEXTURE_" + name.upper()] = 1
    if key.gbuffer:
        out["GBUFFER"] = 1
    if key.model == FITTED_MODEL:
        out["FITTED_COMPONENTS"] = key.shadowing_components
        out["FITTED_SHADOWING_LAYERS"] = -(-key.shadowing_components // 4)
    if key.visibility_layers:
        out["HAS_VISIBILITY"] = 1
        out["SSDF_MAX_LAYERS"] = key.visibility_layers
    return out


def typedef_source():
    source = _read(os.path.join(RESOURCE_DIR, "scene_data.glsl"))
    for name, value in LIMITS.items():          # typedefs may be emitted before the defines
        source = re.sub(rf"\b{name}\b", str(value), source)
    return source


def fragment_source(key):
    parts = [_constants_source(key)]
    for file_name in LIBRARY_FILES:
        if file_name == "env_prefilter.glsl" and not key.has_environment:
            continue
        parts.append(library_source(file_name))
    if key.visibility_layers:
        parts.append(library_source("ssdf.glsl"))
    for file_name in RESOURCE_FILES:
        if file_name == "anisotropic_lobes.glsl" and key.model not in ANISOTROPIC_MODELS:
            continue
        if file_name == "ggx_two_lobes.glsl" and not uses_ggx_table(key):
            continue
        parts.append(_read(os.path.join(RESOURCE_DIR, file_name)))
    parts.append(_read(os.path.join(SHADER_DIR, "surface.frag.glsl")))
    return "\n".join(parts)


def vertex_source(key=None):
    return _read(os.path.join(SHADER_DIR, "mesh.vert.glsl"))


def numbered(source):
    return "\n".join(f"{n:5d}  {line}" for n, line in enumerate(source.split("\n"), 1))


def _code_only(line):
    """A source line as Blender's log quotes it: comments removed (its preprocessor strips them)."""
    return re.sub(r"/\*.*?\*/|//.*$", "", line).strip()


# "<prefix>|  1176 |   text" (Blender 5) or " 1397 |   text" (Blender 4.2): Blender's copy of a source line
_LOG_SOURCE_LINE = re.compile(r"^(?:.*?\|)?\s*(\d*)\s*\| ?(.*)$")
# ":950:15: Error: ..." (Blender 5) or "| Error: ..." (Blender 4.2)
_LOG_ERROR = re.compile(r"(?:\d+:\d+:|\|)\s*(?:Error|error):\s*(.*)$")


def _error_message(key, log, sources):
    """Quote, in our numbered assembled sources, the lines the driver log complains about.

    Blender prints each error under a copy of the offending source text (`| 1176 |   text`)
    with line numbers of its own full source (its preamble included), so the text is looked
    up in our sources to give line numbers a reader can find in the files we assemble.
    """
    quoted, seen = [], set()
    last_text = None
    for raw in log.splitlines():
        error_match = _LOG_ERROR.search(raw)
        if not error_match:
            source_match = _LOG_SOURCE_LINE.search(raw)
            text = source_match.group(2).strip() if source_match else ""
            # not the caret line under the source text, nor a warning
            if text.strip("^~ ") and not re.match(r"(?::?\d+:\d+:)?\s*[Ww]arning", text):
                last_text = text
            continue
        message = error_match.group(1).strip()
        location = "unknown line"
        context = ""
        if last_text:
            for stage, source in sources:
                lines = source.split("\n")
                hits = [n for n, line in enumerate(lines, 1) if _code_only(line) == _code_only(last_text)]
                if hits:
                    number = hits[0]
                    location = f"{stage} line {number}"
                    context = "\n".join(f"{k:5d}{'>' if k == number else ' '} {lines[k - 1]}"
                                        for k in range(max(1, number - 2), min(len(lines), number + 2) + 1))
                    break
        if (location, message) in seen:
            continue
        seen.add((location, message))
        quoted.append(f"{location}: {message}" + (f"\n{context}" if context else ""))
    if not quoted:
        quoted = ["driver log:\n" + log.strip()] + [f"{stage} source:\n{numbered(source)}" for stage, source in sources]
    return f"SG-PRT shader variant [{key.describe()}] failed to compile\n" + "\n\n".join(quoted)


def create_capturing_log(info):
    """create_from_info prints the driver log on the C stdio streams: capture it for the error."""
    import gpu

    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as capture:
        os.dup2(capture.fileno(), 1)
        os.dup2(capture.fileno(), 2)
        try:
            shader, error = gpu.shader.create_from_info(info), None
        except Exception as exception:  # Blender raises a bare Exception
            shader, error = None, exception
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
        capture.seek(0)
        log = capture.read().decode("utf-8", "replace")
    return shader, error, log


def create_info(key):
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for name, value in defines(key).items():
        info.define(name, str(value))
    info.typedef_source(typedef_source())
    info.vertex_in(0, "VEC3", "position")
    info.vertex_in(1, "VEC3", "normal")
    info.vertex_in(2, "VEC4", "tangent")
    info.vertex_in(3, "VEC2", "uv")
    if key.visibility_layers:
        info.vertex_in(4, "INT", "vertex_index")
        info.vertex_in(5, "VEC3", "ssdf_normal")
    interface = gpu.types.GPUStageInterfaceInfo(f"sgprt_surface_interface_{key.visibility_layers}")
    interface.smooth("VEC3", "world_position")
    interface.smooth("VEC3", "world_normal")
    interface.smooth("VEC4", "world_tangent")
    interface.smooth("VEC2", "texcoord")
    if key.visibility_layers:
        # the SSDF frame's normal and the vertex's PCA coefficients, interpolated per pixel (wang2009 5.3)
        interface.smooth("VEC3", "world_ssdf_normal")
        for layer in range(key.visibility_layers):
            interface.smooth("VEC4", f"ssdf_coefficients_{layer}")
    info.vertex_out(interface)
    info.push_constant("MAT4", "model_matrix")
    if key.gbuffer:
        info.push_constant("INT", "gbuffer_object_index")
        info.push_constant("INT", "gbuffer_triangle_offset")
    info.uniform_buf(0, "SceneData", "scene")
    info.uniform_buf(1, "MaterialData", "material")
    slot = 0
    if key.has_environment:
        info.sampler(slot, "FLOAT_2D_ARRAY", "environment_texture")
        slot += 1
    if key.model in ANISOTROPIC_MODELS:
        info.sampler(slot, "FLOAT_2D", "anisotropy_table")
        slot += 1
    if uses_ggx_table(key):
        info.sampler(slot, "FLOAT_2D", "ggx_table")
        slot += 1
    if key.model == FITTED_MODEL:
        info.sampler(slot, "FLOAT_2D_ARRAY", "fitted_layers")     # texelFetch: the nearest texel
        slot += 1
        info.sampler(slot, "FLOAT_2D", "fitted_shadowing")
        slot += 1
    for name in key.textures:
        info.sampler(slot, "FLOAT_2D", "texture_" + name)
        slot += 1
    if key.visibility_layers:
        info.sampler(slot, "FLOAT_2D", "visibility_coefficients")       # read in the vertex shader
        slot += 1
        info.sampler(slot, "FLOAT_2D_ARRAY", "visibility_basis")
        slot += 1
    for index, name in enumerate(output_names(key.gbuffer)):
        info.fragment_out(index, "VEC4", "out_" + name)
    info.vertex_source(vertex_source())
    info.fragment_source(fragment_source(key))
    return info


_cache = {}


def get_shader(key):
    """Compiled shader of a variant (cached for the process; the GPU context is Blender's)."""
    shader = _cache.get(key)
    if shader is None:
        shader, error, log = create_capturing_log(create_info(key))
        if shader is None:
            raise ShaderCompileError(_error_message(
                key, log, [("fragment", fragment_source(key)), ("vertex", vertex_source())])) from error
        _cache[key] = shader
    return shader


def clear_cache():
    _cache.clear()


def uses_ggx_table(key):
    return key.model == "GGX" and key.ndf_lobes == 2


def ggx_table():
    """ndf_fit's two-lobe GGX table as an (A, 2, 4) float32 texture: texel (k, row) =
    (log alpha, sharpness * alpha^2, amplitude / D(n), 0)."""
    from ..core import ndf_fit
    alphas, table = ndf_fit.ggx_two_lobe_table()
    out = np.zeros((len(alphas), 2, 4), np.float32)
    out[..., 0] = np.log(alphas)[:, None]
    out[..., 1:3] = table
    return out


def anisotropy_table(lobe_count):
    """ndf_fit's table as an (R, K, 4) float32 texture: texel (k, row)."""
    from ..core import ndf_fit
    return np.ascontiguousarray(ndf_fit.anisotropy_table_array(lobe_count), np.float32)


def background_create_info(has_environment):
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for name, value in LIMITS.items():
        info.define(name, str(value))
    if has_environment:
        info.define("HAS_ENVIRONMENT", "1")
    info.typedef_source(typedef_source())
    info.vertex_in(0, "VEC2", "position")
    interface = gpu.types.GPUStageInterfaceInfo("sgprt_background_interface")
    interface.smooth("VEC2", "ndc")
    info.vertex_out(interface)
    info.push_constant("MAT4", "inverse_view_projection")
    info.push_constant("FLOAT", "background_alpha")
    info.uniform_buf(0, "SceneData", "scene")
    if has_environment:
        info.sampler(0, "FLOAT_2D", "equirect_texture")
    for index, name in enumerate(output_names(False)):
        info.fragment_out(index, "VEC4", "out_" + name)
    info.vertex_source(_read(os.path.join(RESOURCE_DIR, "background.vert.glsl")))
    info.fragment_source("\n".join([library_source("sg.glsl"),
                                    _read(os.path.join(RESOURCE_DIR, "background.frag.glsl"))]))
    return info


def get_background_shader(has_environment):
    """Shader drawing the world behind the surfaces (cached like the surface variants)."""
    key = ("background", bool(has_environment))
    shader = _cache.get(key)
    if shader is None:
        info = background_create_info(has_environment)
        shader, error, log = create_capturing_log(info)
        if shader is None:
            raise ShaderCompileError(f"SG-PRT background shader failed to compile\n{log.strip()}") from error
        _cache[key] = shader
    return shader


def get_depth_shader():
    """Position-only shader of the depth pre-pass (resources/depth.vert.glsl), cached like the others."""
    import gpu

    key = ("depth",)
    shader = _cache.get(key)
    if shader is None:
        info = gpu.types.GPUShaderCreateInfo()
        for name, value in LIMITS.items():
            info.define(name, str(value))
        info.typedef_source(typedef_source())
        info.vertex_in(0, "VEC3", "position")
        info.push_constant("MAT4", "model_matrix")
        info.uniform_buf(0, "SceneData", "scene")
        info.fragment_out(0, "VEC4", "out_unused")
        info.vertex_source(_read(os.path.join(RESOURCE_DIR, "depth.vert.glsl")))
        info.fragment_source("void main()\n{\n  out_unused = vec4(0.0);\n}\n")
        shader, error, log = create_capturing_log(info)
        if shader is None:
            raise ShaderCompileError(f"SG-PRT depth pre-pass shader failed to compile\n{log.strip()}") from error
        _cache[key] = shader
    return shader
