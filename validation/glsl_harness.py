"""Evaluate GLSL functions on many inputs at once, from a plain Python process.

The `gpu` module only works inside a RenderEngine's render() with
bl_use_gpu_context = True (see the design notes), so `run_glsl` stashes a job,
calls bpy.ops.render.render() on a private scene whose engine is
SG_PRT_GLSL_HARNESS, and the engine's render() does the GPU work:

- each input (N rows of up to 4 floats) becomes an RGBA32F texture holding the
  rows in a grid of width <= 1024 (row r at texel (r % width, r // width));
- a full-screen triangle is drawn into an RGBA32F offscreen of the grid's size;
  the fragment shader texelFetch-es its row from every input into a `vec4` of
  the input's name and writes `result`;
- the offscreen is read back into our own numpy array (the multi-dimensional
  Buffer returned by read_color has wrong strides).

Shaders are compiled once per (library, call, inputs, textures) and reused.
N above 1024 x 1024 rows is split into several draws inside one render().

    run_glsl([sg_source], "vec4(one_minus_exp_over_x(a.x))", {"a": x}, 1)
"""
import hashlib
import os
import re

import numpy as np

from sg_prt_addon.engine.shader_cache import create_capturing_log
from sg_prt_addon.techniques import shader_sources

ENGINE_IDNAME = "SG_PRT_GLSL_HARNESS"
SCENE_NAME = "SG_PRT_GLSL_HARNESS"
GRID_WIDTH = 1024
MAX_ROWS_PER_DRAW = GRID_WIDTH * GRID_WIDTH

# One pending job at a time: bpy.ops.render.render() is synchronous.
_job = None
_shader_cache = {}
_engine_class = None


class GlslCompileError(RuntimeError):
    """A harness shader failed to compile; the message quotes the offending source lines."""


VERTEX_SOURCE = """
void main()
{
  gl_Position = vec4(position, 0.0, 1.0);
}
"""


def _fragment_source(library_sources, call, input_names):
    fetches = "\n".join(
        f"  vec4 {name} = texelFetch(harness_input_{name}, texel, 0);" for name in input_names
    )
    # A call that assigns `result` itself is a statement block; otherwise an expression.
    body = call if re.search(r"\bresult\s*=", call) else f"result = {call};"
    return "\n".join(list(library_sources) + [
        "void main()",
        "{",
        "  ivec2 texel = ivec2(gl_FragCoord.xy);",
        f"  int row = texel.y * textureSize(harness_input_{input_names[0]}, 0).x + texel.x;",
        fetches,
        "  " + body,
        "}",
        "",
    ])


def _texture_sampler_type(array):
    if array.ndim == 3:
        return "FLOAT_2D"
    if array.ndim == 4:
        return "FLOAT_2D_ARRAY"
    raise ValueError(f"texture must be (H, W, 4) or (layers, H, W, 4), got shape {array.shape}")


def _compile_error_message(log, source):
    """Quote every source line the driver's log points at (`:line:column: Error`)."""
    lines = source.split("\n")
    messages_by_line = {}
    # Blender 5.x: "<file>:line:column: Error: ..." with line numbers of our source (#line)
    for match in re.finditer(r":(\d+):(\d+): *(?:Error|error)[: ]*(.*)", log):
        number = int(match.group(1))
        if 1 <= number <= len(lines):
            messages_by_line.setdefault(number, []).append(f"column {match.group(2)}: {match.group(3)}")
    if not messages_by_line:
        # Blender 4.x quotes the offending code ("  178 |   code", "      | Error: ...") with
        # numbers of the assembled source: find the quoted code in ours
        code = None
        for log_line in log.split("\n"):
            quoted = re.match(r"\s*\d*\s*\| ?(.*)$", log_line)
            if not quoted:
                continue
            text = quoted.group(1)
            error = re.match(r"\s*(?:Error|error)[: ]*(.*)", text)
            if error and code:
                for number, line in enumerate(lines, 1):
                    if line.strip() == code:
                        messages_by_line.setdefault(number, []).append(error.group(1))
                        break
            elif text.strip() and set(text.strip()) != {"^"}:
                code = text.strip()
    quoted = []
    for number, messages in sorted(messages_by_line.items()):
        context = [f"{n:5d}{'>' if n == number else ' '} {lines[n - 1]}"
                   for n in range(max(1, number - 2), min(len(lines), number + 2) + 1)]
        quoted.append(f"line {number}: " + "; ".join(messages) + "\n" + "\n".join(context))
    if not quoted:
        numbered = "\n".join(f"{n:5d}  {line}" for n, line in enumerate(lines, 1))
        quoted.append("driver log:\n" + log + "\nsource:\n" + numbered)
    return "GLSL compile error\n" + "\n\n".join(quoted)


def _get_shader(library_sources, call, input_names, textures):
    import gpu
    from gpu_extras.batch import batch_for_shader

    texture_kinds = tuple((name, _texture_sampler_type(array)) for name, array in textures.items())
    key = hashlib.sha256(repr((tuple(library_sources), call, tuple(input_names), texture_kinds))
                         .encode()).hexdigest()
    if key in _shader_cache:
        return _shader_cache[key]
    info = gpu.types.GPUShaderCreateInfo()
    info.vertex_in(0, "VEC2", "position")
    slot = 0
    for name in input_names:
        info.sampler(slot, "FLOAT_2D", f"harness_input_{name}")
        slot += 1
    for name, kind in texture_kinds:
        info.sampler(slot, kind, name)
        slot += 1
    info.fragment_out(0, "VEC4", "result")
    source = _fragment_source(library_sources, call, input_names)
    info.vertex_source(VERTEX_SOURCE)
    info.fragment_source(source)
    shader, error, log = create_capturing_log(info)
    if shader is None:
        raise GlslCompileError(_compile_error_message(log, source)) from error
    # One triangle covering the viewport: no diagonal seam, every texel centre covered once.
    batch = batch_for_shader(shader, "TRIS", {"position": [(-1, -1), (3, -1), (-1, 3)]})
    _shader_cache[key] = (shader, batch)
    return shader, batch


def _upload_texture(array):
    import gpu

    data = np.ascontiguousarray(array, np.float32)
    if data.shape[-1] != 4:
        raise ValueError(f"textures must have 4 channels (RGBA32F), got shape {data.shape}")
    if data.ndim == 3:
        size = (data.shape[1], data.shape[0])
        return gpu.types.GPUTexture(size, format="RGBA32F",
                                    data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))
    size = (data.shape[2], data.shape[1])
    return gpu.types.GPUTexture(size, layers=data.shape[0], format="RGBA32F",
                                data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def _draw(shader, batch, rows_by_name, texture_objects):
    """One draw of up to MAX_ROWS_PER_DRAW rows; returns (rows, 4) float32."""
    import gpu

    count = next(iter(rows_by_name.values())).shape[0]
    width = min(count, GRID_WIDTH)
    height = -(-count // width)
    uploaded = {}
    for name, rows in rows_by_name.items():
        grid = np.zeros((height * width, 4), np.float32)
        grid[:count] = rows
        uploaded[name] = _upload_texture(grid.reshape(height, width, 4))
    offscreen = gpu.types.GPUOffScreen(width, height, format="RGBA32F")
    try:
        with offscreen.bind():
            framebuffer = gpu.state.active_framebuffer_get()
            gpu.state.blend_set("NONE")
            gpu.state.depth_test_set("NONE")
            shader.bind()
            samplers = [(f"harness_input_{name}", texture) for name, texture in uploaded.items()]
            samplers += list(texture_objects.items())
            # slot 0 last: on Blender 5.3 it reads whichever texture was bound last
            for name, texture in reversed(samplers):
                shader.uniform_sampler(name, texture)
            batch.draw(shader)
            out = np.empty((height, width, 4), np.float32)
            framebuffer.read_color(0, 0, width, height, 4, 0, "FLOAT",
                                   data=gpu.types.Buffer("FLOAT", (height, width, 4), out))
    finally:
        offscreen.free()
    return out.reshape(-1, 4)[:count]


def _execute(job):
    shader, batch = _get_shader(job["library_sources"], job["call"],
                                list(job["inputs"]), job["textures"])
    texture_objects = {name: _upload_texture(array) for name, array in job["textures"].items()}
    count = job["count"]
    out = np.empty((count, 4), np.float32)
    for start in range(0, count, MAX_ROWS_PER_DRAW):
        stop = min(count, start + MAX_ROWS_PER_DRAW)
        rows = {name: rows[start:stop] for name, rows in job["inputs"].items()}
        out[start:stop] = _draw(shader, batch, rows, texture_objects)
    return out


def _make_engine_class():
    import bpy

    class SGPRT_GlslHarnessEngine(bpy.types.RenderEngine):
        """Runs the pending run_glsl job; renders nothing into the scene's result."""
        bl_idname = ENGINE_IDNAME
        bl_label = "SG-PRT GLSL harness"
        bl_use_gpu_context = True

        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)

        def render(self, depsgraph):
            global _job
            job = _job
            if job is None or "result" in job or "error" in job:
                return
            try:
                job["result"] = _execute(job)
            except BaseException as exception:  # re-raised in the caller's frame
                job["error"] = exception

    return SGPRT_GlslHarnessEngine


def register():
    """Register the harness engine once per process (safe to call repeatedly)."""
    global _engine_class
    import bpy

    if _engine_class is None:
        _engine_class = _make_engine_class()
    if not getattr(_engine_class, "is_registered", False):
        bpy.utils.register_class(_engine_class)


def unregister():
    import bpy

    if _engine_class is not None and getattr(_engine_class, "is_registered", False):
        bpy.utils.unregister_class(_engine_class)
    _shader_cache.clear()


def _harness_scene():
    """A private scene (camera required by render.render) with the harness engine and a 4x4 result."""
    import bpy

    scene = bpy.data.scenes.get(SCENE_NAME)
    if scene is None:
        scene = bpy.data.scenes.new(SCENE_NAME)
    if scene.camera is None:
        camera = bpy.data.objects.new(SCENE_NAME + "_camera", bpy.data.cameras.new(SCENE_NAME + "_camera"))
        scene.collection.objects.link(camera)
        scene.camera = camera
    scene.render.engine = ENGINE_IDNAME
    scene.render.resolution_x = 4
    scene.render.resolution_y = 4
    scene.render.resolution_percentage = 100
    return scene


def _as_rows(name, array, count):
    rows = np.asarray(array, np.float64)
    if rows.ndim == 1:
        rows = rows[:, None]
    if rows.ndim != 2 or rows.shape[1] > 4:
        raise ValueError(f"input {name!r}: expected (N,) or (N, k<=4), got shape {rows.shape}")
    if count is not None and rows.shape[0] != count:
        raise ValueError(f"input {name!r} has {rows.shape[0]} rows, expected {count}")
    padded = np.zeros((rows.shape[0], 4), np.float32)
    padded[:, :rows.shape[1]] = rows
    return padded


def run_glsl(library_sources, call, inputs, output_components=4, textures=None):
    """Evaluate `call` (a GLSL vec4 expression, or statements assigning `result`)
    for every row of `inputs`.

    library_sources: GLSL sources concatenated in order before main().
    inputs: name -> (N,) or (N, k<=4) array; in GLSL each is a zero-padded
        `vec4 name` (float32). `row` (int) is the row index.
    textures: optional name -> (H, W, 4) (sampler2D) or (layers, H, W, 4)
        (sampler2DArray) float32 array; numpy row 0 is texel row t = 0.
    Returns float32 (N,) if output_components == 1, else (N, output_components).
    Raises GlslCompileError quoting the offending source line.
    """
    global _job
    import bpy

    if not inputs:
        raise ValueError("run_glsl needs at least one input (it sets the row count)")
    for name in list(inputs) + list(textures or {}):
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or name in ("row", "texel", "result"):
            raise ValueError(f"invalid GLSL name {name!r}")
    count = None
    rows = {}
    for name, array in inputs.items():
        rows[name] = _as_rows(name, array, count)
        count = rows[name].shape[0]
    if count == 0:
        return np.zeros((0,) if output_components == 1 else (0, output_components), np.float32)
    register()
    scene = _harness_scene()
    _job = {"library_sources": list(library_sources), "call": call, "inputs": rows,
            "textures": dict(textures or {}), "count": count}
    try:
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(scene=scene.name)
        job = _job
    finally:
        _job = None
    if "error" in job:
        raise job["error"]
    if "result" not in job:
        raise RuntimeError("the harness engine did not run (is the gpu module available here?)")
    out = job["result"][:, :output_components]
    return out[:, 0].copy() if output_components == 1 else out.copy()


def load_library(*file_names):
    """Sources of shaders/lib/<name> in the given order (e.g. "sg.glsl", "hemisphere.glsl")."""
    library_dir = shader_sources.LIB_DIR
    sources = []
    for file_name in file_names:
        with open(os.path.join(library_dir, file_name), encoding="utf-8") as handle:
            sources.append(handle.read())
    return sources
