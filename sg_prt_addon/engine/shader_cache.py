"""Compiled shaders of the surfaces (any technique's variants) and of the passes, cached by content.

A technique gives the create-info calls of a variant (techniques.base.Technique.create_info_calls);
the cache compiles them once per content hash, so variant keys that assemble to the same shader share
one compile.  A compile error raises ShaderCompileError naming the variant and quoting the offending
lines of the numbered assembled sources.
"""
import atexit
import collections
import hashlib
import os
import re
import sys
import tempfile

from ..techniques import shader_sources
from ..techniques.shader_sources import numbered


class ShaderCompileError(RuntimeError):
    """A variant failed to compile: the message names the variant and quotes the source lines."""


def _code_only(line):
    """A source line as Blender's log quotes it: comments removed (its preprocessor strips them)."""
    return re.sub(r"/\*.*?\*/|//.*$", "", line).strip()


# "<prefix>|  1176 |   text" (Blender 5) or " 1397 |   text" (Blender 4.2): Blender's copy of a source line
_LOG_SOURCE_LINE = re.compile(r"^(?:.*?\|)?\s*(\d*)\s*\| ?(.*)$")
# ":950:15: Error: ..." (Blender 5) or "| Error: ..." (Blender 4.2)
_LOG_ERROR = re.compile(r"(?:\d+:\d+:|\|)\s*(?:Error|error):\s*(.*)$")


def _error_message(what, log, sources):
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
    return f"SG-PRT shader {what} failed to compile\n" + "\n\n".join(quoted)


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


def create_info(calls):
    """A GPUShaderCreateInfo replaying (method, arguments) calls ("vertex_out": (interface name, its calls))."""
    import gpu

    info = gpu.types.GPUShaderCreateInfo()
    for method, arguments in calls:
        if method == "vertex_out":
            name, interface_calls = arguments
            interface = gpu.types.GPUStageInterfaceInfo(name)
            for interface_method, interface_arguments in interface_calls:
                getattr(interface, interface_method)(*interface_arguments)
            info.vertex_out(interface)
        else:
            getattr(info, method)(*arguments)
    return info


def content_hash(calls):
    """sha256 of everything a shader is made of (its create-info calls): equal hashes, one shader."""
    return hashlib.sha256(repr(calls).encode("utf-8")).hexdigest()


def _stage_sources(calls):
    return [(stage, arguments[0]) for method, arguments in calls for stage in ("fragment", "vertex")
            if method == f"{stage}_source"]


# content hash (surface variants) or ("background", ...) / ("depth",) -> GPUShader, least recently used
# first.  Kept for the process, final renders too (a batch job's later renders skip the compile and
# llvmpipe's JIT); the oldest is dropped past MAX_CACHED_SHADERS, inside the caller's GPU context.
MAX_CACHED_SHADERS = 64
_cache = collections.OrderedDict()
_content_hashes = {}    # (technique name, variant key) -> content hash: the sources are assembled once per key
# Surface shader compiles since the process started (clear_cache does not reset it): tests and
# benchmarks read it to see that keys sharing a content hash share one compile.
compile_count = {"surface": 0}


def get_shader(technique, key):
    """Compiled shader of a technique's variant (cached for the process by content hash; the GPU context
    is Blender's); ShaderCompileError names the variant and quotes the lines the driver rejects."""
    digest = _content_hashes.get((technique.name, key))
    calls = None
    if digest is None:
        calls = technique.create_info_calls(key)
        digest = _content_hashes[(technique.name, key)] = content_hash(calls)
    shader = _cached(digest)
    if shader is None:
        calls = calls or technique.create_info_calls(key)
        shader, error, log = create_capturing_log(create_info(calls))
        if shader is None:
            raise ShaderCompileError(_error_message(f"variant {technique.label} [{key.describe()}]", log,
                                                    _stage_sources(calls))) from error
        _remember(digest, shader)
        compile_count["surface"] += 1
    return shader


def get_fixed_shader(cache_key, calls_of, what):
    """A shader that is not a surface variant (a pass of the engine or of a technique), cached by
    `cache_key` like them; calls_of() gives its create-info calls."""
    shader = _cached(cache_key)
    if shader is None:
        calls = calls_of()
        shader, error, log = create_capturing_log(create_info(calls))
        if shader is None:
            raise ShaderCompileError(_error_message(f"{what} pass", log, _stage_sources(calls))) from error
        _remember(cache_key, shader)
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


def forget_assembled_sources():
    """Assemble each variant's sources again at its next get_shader (the compiled shaders stay, by content hash):
    for a caller that changes what a technique assembles between renders (benchmarks/frame_profile.py)."""
    _content_hashes.clear()


def clear_cache():
    _cache.clear()
    forget_assembled_sources()


# Shaders left in the cache when Python shuts down would be freed while the interpreter tears its modules
# down, after Blender's GPU module may be gone (a crash at exit, measured with pip bpy 5.0): free them first.
atexit.register(clear_cache)


# ----------------------------------------------------------------- the engine's own passes

def background_calls(has_environment):
    """The world behind the surfaces (engine/background.frag.glsl), drawn where no surface is."""
    calls = shader_sources.full_screen_calls("sgprt_background_interface",
                                             {"HAS_ENVIRONMENT": 1} if has_environment else {})
    calls += [("push_constant", ("MAT4", "inverse_view_projection")), ("push_constant", ("FLOAT", "background_alpha")),
              ("uniform_buf", (0, "SceneData", "scene"))]
    if has_environment:
        calls.append(("sampler", (0, "FLOAT_2D", "equirect_texture")))
    calls += [("fragment_out", (index, "VEC4", "out_" + name))
              for index, name in enumerate(shader_sources.output_names(False))]
    calls.append(("fragment_source", ("\n".join([shader_sources.library_source("sg.glsl"),
                                                  shader_sources.engine_source("background.frag.glsl")]),)))
    return calls


def get_background_shader(has_environment):
    return get_fixed_shader(("background", bool(has_environment)), lambda: background_calls(has_environment),
                            "background")


def depth_calls():
    """Position-only shader of the depth pre-pass (engine/depth.vert.glsl)."""
    calls = [("define", (name, str(value))) for name, value in shader_sources.LIMITS.items()]
    calls += [("typedef_source", (shader_sources.typedef_source(),)), ("vertex_in", (0, "VEC3", "position")),
              ("push_constant", ("MAT4", "model_matrix")), ("uniform_buf", (0, "SceneData", "scene")),
              ("fragment_out", (0, "VEC4", "out_unused")),
              ("vertex_source", (shader_sources.engine_source("depth.vert.glsl"),)),
              ("fragment_source", ("void main()\n{\n  out_unused = vec4(0.0);\n}\n",))]
    return calls


def get_depth_shader():
    return get_fixed_shader(("depth",), depth_calls, "depth pre-pass")
