"""Assembly and cache of the surface shader variants.

A variant is keyed by what changes the code (not the values): the BRDF model,
its NDF lobe count, whether lights / an environment texture are present, which
material textures are bound, whether the debug G-buffer is written, and which of
the material's diffuse and specular terms can be non-zero.  A variant leaves out
what its scene does not need: no lights, no light loop; a world colour, no
prefiltered-environment fetch; no visibility bake, no SSDF decode; a zero
specular colour (without its texture), no BRDF slice (NDF lobes, warp, light x
slice products, prefiltered fetch and their SSDF decodes); a zero diffuse
colour (without its texture), no irradiance (environment SG mixture, the lights'
diffuse terms and their decodes).  A skipped term is exactly zero in the full
variant (its colour is zero), so the image does not change.

Compiled shaders are cached by a hash of everything the GPUShaderCreateInfo is
made of (defines, interfaces, samplers, vertex and fragment source):
VariantKeys that assemble to the same shader share one compile (content_hash).

Fragment source = generated header (constants from core/) + the GLSL mirrors
of core/ (shaders/lib/<name>.glsl) + our resources (anisotropic_lobes.glsl,
sg_shading.glsl) + surface.frag.glsl.
A compile error raises ShaderCompileError naming the variant and quoting the
offending lines of the numbered assembled source.
"""
import collections
import hashlib
import os
import re
import sys
import tempfile
from dataclasses import dataclass

import numpy as np

from ..core import ggx_albedo, shading, warp

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
LIBRARY_FILES = ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "clamped_cosine_table.glsl", "lights.glsl",
                 "brdf.glsl", "warp.glsl", "env_prefilter.glsl")
# Our own pieces (shaders/resources/), after the library.
RESOURCE_FILES = ("anisotropic_lobes.glsl", "ggx_two_lobes.glsl", "lobe_visibility.glsl", "sg_shading.glsl")


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
    has_diffuse: bool = True        # False: zero diffuse colour, no texture: no irradiance code
    has_specular: bool = True       # False: zero specular colour, no texture: no BRDF slice code
    # vec4 of broad diffuse lobe visibility a vertex, from the per-vertex pass (0: none, or decoded per pixel)
    diffuse_visibility_rows: int = 0
    # light x slice products take the light's visibility (core.shading.shares_light_visibility; with a bake,
    # lights and a specular term)
    shared_light_visibility: bool = False
    warp_mode: str = warp.DEFAULT_MODE      # of the view slice (MaterialParams.warp_mode); with a specular term

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
        if self.diffuse_visibility_rows:
            parts.append(f"per-vertex diffuse visibility ({self.diffuse_visibility_rows} vec4)")
        if self.shared_light_visibility:
            parts.append("light visibility shared by its products")
        if self.has_specular and self.warp_mode != warp.DEFAULT_MODE:
            parts.append(f"warp {self.warp_mode}")
        if not self.has_diffuse:
            parts.append("no diffuse")
        if not self.has_specular:
            parts.append("no specular")
        return ", ".join(parts)


# Material textures that only the specular term reads (left out of a variant without it)
SPECULAR_ONLY_TEXTURES = ("specular_color", "roughness", "ior", "exponent", "alpha_x", "alpha_y", "nu", "nv")


def material_terms(material_params):
    """(has_diffuse, has_specular) of an export.MaterialParams: False when that colour is zero and no
    texture scales it, so the term (colour x irradiance / pi, colour x radiance) is exactly zero and the
    variant leaves its code out.  A stored lobe fit keeps both (its colours are per texel)."""
    if getattr(material_params, "fitted", None) is not None:
        return True, True

    def present(colour, slot):      # NaN counts as present: the full variant shows it
        return slot in material_params.textures or any(not float(c) == 0.0 for c in tuple(colour)[:3])

    return (present(material_params.diffuse_color, "diffuse_color"),
            present(material_params.specular_color, "specular_color"))


def diffuse_visibility_rows(environment):
    """vec4 a vertex of the per-vertex pass (resources/vertex_visibility.frag.glsl) for a
    core.shading.EnvironmentData: its diffuse SG lobes four to a vec4, or the constant world's one lobe."""
    if environment.prefiltered is None:
        return 1
    return -(-min(len(environment.lobe_sharpness), MAX_ENV_LOBES) // 4)


def variant_key(material_params, has_lights, has_environment, gbuffer=False, visibility_layers=0,
                diffuse_rows=0, shared_light_visibility=False):
    """VariantKey of an export.MaterialParams in a scene (visibility_layers: of the object's bake, 0 without;
    diffuse_rows: diffuse_visibility_rows of the scene, used with a bake and a diffuse term;
    shared_light_visibility: core.shading.shares_light_visibility of the object, used with a bake, lights
    and a specular term)."""
    from ..core.shading import GGX_NDF_LOBES

    fitted = getattr(material_params, "fitted", None)
    if fitted is not None:      # the stored lobe fit: its lobes, shadowing and base; only a normal map applies
        textures = ("normal_map",) if "normal_map" in material_params.textures else ()
        return VariantKey(FITTED_MODEL, int(fitted.lobe_count), bool(has_lights), bool(has_environment), textures,
                          bool(gbuffer), int(visibility_layers), int(fitted.components),
                          diffuse_visibility_rows=int(diffuse_rows) if visibility_layers else 0,
                          shared_light_visibility=bool(shared_light_visibility and visibility_layers and has_lights),
                          warp_mode=_warp_mode_of(material_params))
    model = material_params.model
    lobes = int(material_params.lobe_count) if model in ANISOTROPIC_MODELS else 1
    if model == "GGX":
        lobes = GGX_NDF_LOBES
    has_diffuse, has_specular = material_terms(material_params)
    textures = tuple(sorted(name for name in material_params.textures if name in TEXTURE_SLOTS
                            and (has_specular or name not in SPECULAR_ONLY_TEXTURES)))
    return VariantKey(model, lobes, bool(has_lights), bool(has_environment), textures, bool(gbuffer),
                      int(visibility_layers), has_diffuse=has_diffuse, has_specular=has_specular,
                      diffuse_visibility_rows=int(diffuse_rows) if visibility_layers and has_diffuse else 0,
                      shared_light_visibility=bool(shared_light_visibility and visibility_layers and has_lights
                                                   and has_specular),
                      warp_mode=_warp_mode_of(material_params) if has_specular else warp.DEFAULT_MODE)


def _warp_mode_of(material_params):
    """The material's core.warp mode (MaterialParams.warp_mode; objects without it: the default)."""
    mode = getattr(material_params, "warp_mode", warp.DEFAULT_MODE)
    if mode not in warp.MODES:
        raise ValueError(f"unknown view warp {mode!r} (core.warp.MODES: {', '.join(warp.MODES)})")
    return mode


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


def warp_mode(mode):
    """(GLSL function, lobes per NDF lobe) of a core.warp mode (the mirror warps with the same)."""
    return f"warp_lobes_{mode}", warp.nodes_per_lobe(mode)


def defines(key):
    out = dict(LIMITS)
    if key.has_specular:        # the model only shapes the BRDF slice
        out["HAS_SPECULAR"] = 1
        out["WARP_FUNCTION"], out["WARP_NODES"] = warp_mode(key.warp_mode)
        out["MODEL_" + key.model] = 1
        out["NDF_LOBES"] = key.ndf_lobes
    if key.has_diffuse:
        out["HAS_DIFFUSE"] = 1
    if key.has_lights:
        out["HAS_LIGHTS"] = 1
    if key.has_environment:
        out["HAS_ENVIRONMENT"] = 1
        if key.has_specular:    # the prefiltered fetch; diffuse reads the SG mixture in the scene block
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
    if key.diffuse_visibility_rows:
        out["DIFFUSE_VISIBILITY_ROWS"] = key.diffuse_visibility_rows
    if key.shared_light_visibility:
        out["SHARED_LIGHT_VISIBILITY"] = 1
    if uses_ggx_table(key):     # GGX's energy beyond its two lobes, from its albedo table (core.ggx_albedo)
        out["ENVIRONMENT_TAIL"] = 1
        out["GGX_ALBEDO_SIZE"] = ggx_albedo.TABLE_SIZE
        out["TAIL_SHARPNESS_RATIO"] = f"{shading.TAIL_SHARPNESS_RATIO!r}"
    return out


def typedef_source():
    source = _read(os.path.join(RESOURCE_DIR, "scene_data.glsl"))
    for name, value in LIMITS.items():          # typedefs may be emitted before the defines
        source = re.sub(rf"\b{name}\b", str(value), source)
    return source


def library_files(key):
    """shaders/lib files of a variant, in dependency order: the BRDF, warp and prefiltered environment
    only for the specular term, the lights only with lights, the SSDF decode only with a bake."""
    files = []
    for file_name in LIBRARY_FILES:
        if file_name in ("brdf.glsl", "warp.glsl") and not key.has_specular:
            continue
        if file_name == "lights.glsl" and not key.has_lights:
            continue
        if file_name == "clamped_cosine_table.glsl" and not uses_clamped_cosine_table(key):
            continue
        if file_name == "env_prefilter.glsl" and not (key.has_environment and key.has_specular):
            continue
        files.append(file_name)
    if key.visibility_layers:
        files.append("ssdf.glsl")
    return files


def fragment_source(key):
    parts = [_constants_source(key)]
    for file_name in library_files(key):
        parts.append(library_source(file_name))
    for file_name in RESOURCE_FILES:
        if file_name == "anisotropic_lobes.glsl" and (key.model not in ANISOTROPIC_MODELS or not key.has_specular):
            continue
        if file_name == "ggx_two_lobes.glsl" and not uses_ggx_table(key):
            continue
        if file_name == "lobe_visibility.glsl" and not key.visibility_layers:
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


def create_info_calls(key):
    """What a variant's GPUShaderCreateInfo is made of, as (method, arguments) calls in order
    ("vertex_out": (interface name, its (method, arguments) calls)).  create_info replays them;
    content_hash hashes them."""
    calls = [("define", (name, str(value))) for name, value in sorted(defines(key).items())]
    calls.append(("typedef_source", (typedef_source(),)))
    calls += [("vertex_in", (0, "VEC3", "position")), ("vertex_in", (1, "VEC3", "normal")),
              ("vertex_in", (2, "VEC4", "tangent")), ("vertex_in", (3, "VEC2", "uv"))]
    if key.visibility_layers:
        calls += [("vertex_in", (4, "INT", "vertex_index")), ("vertex_in", (5, "VEC3", "ssdf_normal"))]
    interface = [("smooth", ("VEC3", "world_position")), ("smooth", ("VEC3", "world_normal")),
                 ("smooth", ("VEC4", "world_tangent")), ("smooth", ("VEC2", "texcoord"))]
    if key.visibility_layers:
        # the SSDF frame's normal and the vertex's PCA coefficients, interpolated per pixel (wang2009 5.3)
        interface.append(("smooth", ("VEC3", "world_ssdf_normal")))
        interface += [("smooth", ("VEC4", f"ssdf_coefficients_{layer}")) for layer in range(key.visibility_layers)]
        interface += [("smooth", ("VEC4", f"diffuse_fractions_{row}")) for row in range(key.diffuse_visibility_rows)]
    calls.append(("vertex_out", (f"sgprt_surface_interface_{key.visibility_layers}_{key.diffuse_visibility_rows}",
                                 tuple(interface))))
    calls.append(("push_constant", ("MAT4", "model_matrix")))
    if key.gbuffer:
        calls += [("push_constant", ("INT", "gbuffer_object_index")),
                  ("push_constant", ("INT", "gbuffer_triangle_offset"))]
    calls += [("uniform_buf", (0, "SceneData", "scene")), ("uniform_buf", (1, "MaterialData", "material"))]
    samplers = []
    if key.has_environment:
        samplers.append(("FLOAT_2D_ARRAY", "environment_texture"))
        if key.has_specular:        # the map itself, for slice lobes sharper than the top prefiltered layer
            samplers.append(("FLOAT_2D", "equirect_texture"))
    if key.model in ANISOTROPIC_MODELS:
        samplers.append(("FLOAT_2D", "anisotropy_table"))
    if uses_ggx_table(key):
        samplers.append(("FLOAT_2D", "ggx_table"))
        samplers.append(("FLOAT_2D", "ggx_albedo_table"))      # ENVIRONMENT_TAIL
    if uses_clamped_cosine_table(key):
        samplers.append(("FLOAT_2D", "clamped_cosine_table"))
    if key.model == FITTED_MODEL:
        samplers.append(("FLOAT_2D_ARRAY", "fitted_layers"))     # texelFetch: the nearest texel
        samplers.append(("FLOAT_2D", "fitted_shadowing"))
    samplers += [("FLOAT_2D", "texture_" + name) for name in key.textures]
    if key.visibility_layers:
        samplers.append(("FLOAT_2D", "visibility_coefficients"))       # read in the vertex shader
        samplers.append(("FLOAT_2D_ARRAY", "visibility_basis"))
    if key.diffuse_visibility_rows:
        samplers.append(("FLOAT_2D", "diffuse_visibility"))             # read in the vertex shader
    calls += [("sampler", (slot, kind, name)) for slot, (kind, name) in enumerate(samplers)]
    calls += [("fragment_out", (index, "VEC4", "out_" + name)) for index, name in enumerate(output_names(key.gbuffer))]
    calls.append(("vertex_source", (vertex_source(),)))
    calls.append(("fragment_source", (fragment_source(key),)))
    return calls


def create_info(key):
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for method, arguments in create_info_calls(key):
        if method == "vertex_out":
            name, interface_calls = arguments
            interface = gpu.types.GPUStageInterfaceInfo(name)
            for interface_method, interface_arguments in interface_calls:
                getattr(interface, interface_method)(*interface_arguments)
            info.vertex_out(interface)
        else:
            getattr(info, method)(*arguments)
    return info


def content_hash(key):
    """sha256 of everything a variant's shader is made of (create_info_calls): equal hashes, one shader."""
    return hashlib.sha256(repr(create_info_calls(key)).encode("utf-8")).hexdigest()


# content hash (surface variants) or ("background", ...) / ("depth",) -> GPUShader, least recently used
# first.  Kept for the process, final renders too (a batch job's later renders skip the compile and
# llvmpipe's JIT); the oldest is dropped past MAX_CACHED_SHADERS, inside the caller's GPU context.
MAX_CACHED_SHADERS = 64
_cache = collections.OrderedDict()
_content_hashes = {}    # VariantKey -> content_hash(key): the sources are assembled once per key
# Surface shader compiles since the process started (clear_cache does not reset it): tests and
# benchmarks read it to see that keys sharing a content hash share one compile.
compile_count = {"surface": 0}


def get_shader(key):
    """Compiled shader of a variant (cached for the process by content hash; the GPU context is Blender's)."""
    digest = _content_hashes.get(key)
    if digest is None:
        digest = _content_hashes[key] = content_hash(key)
    shader = _cached(digest)
    if shader is None:
        shader, error, log = create_capturing_log(create_info(key))
        if shader is None:
            raise ShaderCompileError(_error_message(
                key, log, [("fragment", fragment_source(key)), ("vertex", vertex_source())])) from error
        _remember(digest, shader)
        compile_count["surface"] += 1
    return shader


def _cached(key):
    shader = _cache.get(key)
    if shader is not None:
        _cache.move_to_end(key)
    return shader


def _remember(key, shader):
    _cache[key] = shader
    while len(_cache) > MAX_CACHED_SHADERS:
        _cache.popitem(last=False)


def clear_cache():
    _cache.clear()
    _content_hashes.clear()


def uses_clamped_cosine_table(key):
    """Whether a variant integrates lobes of per-pixel sharpness against the clamped cosine (lights,
    slice lobes, their products): those read core.clamped_cosine_table."""
    return key.has_lights or key.has_specular


def uses_ggx_table(key):
    return key.model == "GGX" and key.ndf_lobes == 2 and key.has_specular


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


def _full_screen_create_info(interface_name, extra_defines):
    """Create info of a full-screen triangle (resources/background.vert.glsl, `ndc` out) with the scene
    block's typedefs, the limits and `extra_defines`: the caller adds the rest."""
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for name, value in {**LIMITS, **extra_defines}.items():
        info.define(name, str(value))
    info.typedef_source(typedef_source())
    info.vertex_in(0, "VEC2", "position")
    interface = gpu.types.GPUStageInterfaceInfo(interface_name)
    interface.smooth("VEC2", "ndc")
    info.vertex_out(interface)
    info.vertex_source(_read(os.path.join(RESOURCE_DIR, "background.vert.glsl")))
    return info


def background_create_info(has_environment):
    info = _full_screen_create_info("sgprt_background_interface", {"HAS_ENVIRONMENT": 1} if has_environment else {})
    info.push_constant("MAT4", "inverse_view_projection")
    info.push_constant("FLOAT", "background_alpha")
    info.uniform_buf(0, "SceneData", "scene")
    if has_environment:
        info.sampler(0, "FLOAT_2D", "equirect_texture")
    for index, name in enumerate(output_names(False)):
        info.fragment_out(index, "VEC4", "out_" + name)
    info.fragment_source("\n".join([library_source("sg.glsl"),
                                    _read(os.path.join(RESOURCE_DIR, "background.frag.glsl"))]))
    return info


def _cached_fixed_shader(key, create_info_of, what):
    """A shader that is not a surface variant (cached by `key` like them); create_info_of() builds it."""
    shader = _cached(key)
    if shader is None:
        shader, error, log = create_capturing_log(create_info_of())
        if shader is None:
            raise ShaderCompileError(f"SG-PRT {what} shader failed to compile\n{log.strip()}") from error
        _remember(key, shader)
    return shader


def get_background_shader(has_environment):
    """Shader drawing the world behind the surfaces."""
    return _cached_fixed_shader(("background", bool(has_environment)),
                                lambda: background_create_info(has_environment), "background")


def depth_create_info():
    """Position-only shader of the depth pre-pass (resources/depth.vert.glsl)."""
    import gpu

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
    return info


def get_depth_shader():
    return _cached_fixed_shader(("depth",), depth_create_info, "depth pre-pass")


def vertex_visibility_create_info(visibility_layers, rows, has_environment):
    """The per-vertex pass of the broad diffuse lobes (resources/vertex_visibility.frag.glsl), drawn as
    one full-screen triangle over its target (one texel a vertex and vec4)."""
    defines = {"HAS_VISIBILITY": 1, "SSDF_MAX_LAYERS": visibility_layers, "DIFFUSE_VISIBILITY_ROWS": rows}
    if has_environment:
        defines["HAS_ENVIRONMENT"] = 1
    info = _full_screen_create_info("sgprt_vertex_visibility_interface", defines)
    info.push_constant("MAT4", "model_matrix")
    info.uniform_buf(0, "SceneData", "scene")
    info.sampler(0, "FLOAT_2D", "visibility_coefficients")
    info.sampler(1, "FLOAT_2D", "vertex_normals")
    info.sampler(2, "FLOAT_2D_ARRAY", "visibility_basis")
    info.fragment_out(0, "VEC4", "out_fractions")
    info.fragment_source("\n".join([library_source(name) for name in
                                    ("sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "ssdf.glsl")]
                                   + [_read(os.path.join(RESOURCE_DIR, name)) for name in
                                      ("lobe_visibility.glsl", "vertex_visibility.frag.glsl")]))
    return info


def get_vertex_visibility_shader(visibility_layers, rows, has_environment):
    return _cached_fixed_shader(("vertex_visibility", int(visibility_layers), int(rows), bool(has_environment)),
                                lambda: vertex_visibility_create_info(visibility_layers, rows, has_environment),
                                "per-vertex visibility")
