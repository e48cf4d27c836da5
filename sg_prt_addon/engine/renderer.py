"""GPU side: uploads a SceneState and draws it with each material's technique (techniques/).

Used by both the final render (into our float offscreen framebuffer) and the
viewport (view_draw draws the same framebuffer's Combined texture).  Only
what SceneState marks dirty is re-uploaded.  Must run where the `gpu` module
works: inside render() with bl_use_gpu_context, or in view_update/view_draw.
"""

import collections

import numpy as np

from .. import techniques
from ..blender.export import COLOUR_SLOTS, texture_sources
from ..lighting import shadow_maps
from ..spherical import clamped_cosine, texture_mips
from ..techniques import material_textures, shader_sources, surface_layering
from ..techniques.shader_sources import MAX_ENV_LOBES, MAX_LAYERS, MAX_POINT_LIGHTS, MAX_SUNS
from ..visibility import per_vertex as per_vertex_layout  # the layout of every per-vertex texture
from . import disk_cache, gpu_limits, multi_sample, scene_state, shader_cache, shadow_pass

PASS_NAMES = ("Combined", "Diffuse", "Specular")

# GPU copies of scene_state's environment cache entries (one EnvironmentData object per pixels and
# layer size): a later render's new Renderer finds them here instead of uploading the map again.
# id(EnvironmentData) -> (EnvironmentData, prefiltered layers, equirect map), least recently used first.
ENVIRONMENT_TEXTURE_CACHE_SIZE = 2
_environment_textures = collections.OrderedDict()


def _column_major(matrix):
    return np.asarray(matrix, np.float32).T.ravel().tolist()


def _texture_2d(pixels):
    import gpu
    data = np.ascontiguousarray(pixels, np.float32)
    return gpu.types.GPUTexture((data.shape[1], data.shape[0]), format="RGBA32F",
                                data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def within_side(pixels, side):
    """(pixels, factor): an (H, W, C) image no larger than `side` a side, box-averaged by the smallest whole
    factor that fits it (edge texels repeated to fill the last box); factor 1: the image as it is."""
    height, width = pixels.shape[:2]
    factor = -(-max(height, width) // side)
    if factor <= 1:
        return pixels, 1
    rows, columns = -(-height // factor), -(-width // factor)
    padded = np.pad(pixels, ((0, rows * factor - height), (0, columns * factor - width), (0, 0)), mode="edge")
    boxes = padded.reshape(rows, factor, columns, factor, -1).mean(axis=(1, 3), dtype=np.float64)
    return boxes.astype(np.float32), factor


def _texture_2d_array(layers):
    import gpu
    data = np.ascontiguousarray(layers, np.float32)
    return gpu.types.GPUTexture((data.shape[2], data.shape[1]), layers=data.shape[0], format="RGBA32F",
                                data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def _texture_key(value, slot, params):
    """(image name, decoded from sRGB: a colour slot, or a data slot a node tree reads decoded as Blender does,
    a normal map: its normals made unit) of a slot's own image."""
    return value, slot in COLOUR_SLOTS or slot in params.decoded_slots, slot == "normal_map"


def _node_image_key(name):
    """The texture key of an image a node tree's computed slot reads (decoded as Blender decodes it)."""
    return name, True, False


def _texture_keys(value, slot, params):
    """The texture keys a slot reads: its image's, or (an Expression) each of its images'."""
    if isinstance(value, str):
        return [_texture_key(value, slot, params)]
    return [_node_image_key(name) for name in value.images]


def _uniform_buffer(data):
    import gpu
    data = np.ascontiguousarray(data, np.float32)
    return gpu.types.GPUUniformBuf(gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def scene_block(camera, light_data, environment, shadow_plan=None):
    """SceneData (shaders/engine/scene_data.glsl) as float32 words, std140 (all vec4); shadow_plan: the
    lights' lighting.shadow_maps.ShadowPlan, or None (no maps)."""
    def vec4_array(count, rows):
        block = np.zeros((count, 4), np.float32)
        rows = np.asarray(rows, np.float32).reshape(-1, 4) if len(rows) else np.zeros((0, 4), np.float32)
        block[:len(rows)] = rows[:count]
        return block

    points = len(light_data.point_radius)
    suns = len(light_data.sun_sharpness)
    if points > MAX_POINT_LIGHTS or suns > MAX_SUNS:
        raise ValueError(f"SG-PRT draws at most {MAX_POINT_LIGHTS} point/spot/area and {MAX_SUNS} sun lights")
    camera_vec = (list(camera.position) + [1.0]) if camera.is_perspective else (list(camera.forward) + [0.0])
    prefiltered = environment.prefiltered
    mean_radiance = getattr(prefiltered, "mean_radiance", None) if prefiltered is not None else None
    world_colour = (list(np.asarray(mean_radiance, np.float32).ravel()[:3]) + [1.0]) if mean_radiance is not None \
        else (list(environment.colour[:3]) + [0.0])
    env_lobes = min(len(environment.lobe_sharpness), MAX_ENV_LOBES) if prefiltered is not None else 0
    layer_count = len(prefiltered.sharpness) if prefiltered is not None else 0
    if layer_count > MAX_LAYERS:
        raise ValueError(f"the prefiltered environment has {layer_count} layers, at most {MAX_LAYERS}")
    counts = np.array([points, suns, env_lobes, layer_count], np.int32).view(np.float32)
    info = [prefiltered.log2_min_sharpness, prefiltered.levels_per_octave, layer_count - 1, 0.0] \
        if prefiltered is not None else [0.0, 1.0, 0.0, 0.0]
    scale_offset = np.stack([prefiltered.texcoord_scale, prefiltered.texcoord_offset,
                             np.zeros(layer_count), np.zeros(layer_count)], axis=1) if layer_count else []
    parts = [
        np.array([camera_vec], np.float32),
        np.array([world_colour], np.float32),
        counts[None],
        np.array([info], np.float32),
        vec4_array(MAX_LAYERS, scale_offset),
        vec4_array(MAX_POINT_LIGHTS, np.concatenate([light_data.point_position, light_data.point_radius[:, None]], 1)
                   if points else []),
        vec4_array(MAX_POINT_LIGHTS, np.concatenate([light_data.point_intensity, light_data.soft_falloff[:, None]], 1)
                   if points else []),
        vec4_array(MAX_POINT_LIGHTS, np.concatenate([light_data.spot_direction,
                                                     light_data.spot_size[:, None]], 1) if points else []),
        vec4_array(MAX_POINT_LIGHTS, np.concatenate([light_data.spot_blend[:, None], light_data.point_emitter], 1)
                   if points else []),
        vec4_array(MAX_SUNS, np.concatenate([light_data.sun_axis, light_data.sun_sharpness[:, None]], 1)
                   if suns else []),
        vec4_array(MAX_SUNS, np.pad(light_data.sun_amplitude, ((0, 0), (0, 1))) if suns else []),
        vec4_array(MAX_ENV_LOBES, np.concatenate([environment.lobe_axis, environment.lobe_sharpness[:, None]], 1)
                   [:env_lobes] if env_lobes else []),
        vec4_array(MAX_ENV_LOBES, np.pad(environment.lobe_amplitude, ((0, 0), (0, 1)))[:env_lobes]
                   if env_lobes else []),
        # the diffuse lobes' clamped-cosine terms of lambda alone: once a frame, not once a pixel
        vec4_array(2 * MAX_ENV_LOBES, clamped_cosine.sharpness_terms(environment.lobe_sharpness[:env_lobes], np.float32)
                   if env_lobes else []),
        np.asarray(_column_major(camera.projection @ camera.view), np.float32).reshape(4, 4),   # mat4 columns
        np.array([[camera.shading_footprint, camera.footprint_grid_limit, camera.texture_footprint,
                   camera.coverage_offset]], np.float32),
        shadow_pass.scene_rows(shadow_plan, light_data),
    ]
    return np.concatenate(parts, axis=0)


def material_block(params, material_id=0):
    """MaterialData of an export.MaterialParams as (9, 4) float32; material_id goes to the G-buffer."""
    return np.array([
        list(params.diffuse_color) + [params.layered_f0],
        list(params.specular_color) + [1.0],
        [params.roughness, params.ior, params.exponent, params.alpha_x],
        [params.alpha_y, params.nu, params.nv, params.normal_strength],
        list(params.tangent_axis) + [params.tangent_rotation],
        [1.0 if params.tangent_source == "OBJECT_AXIS" else 0.0, float(material_id),
         surface_layering.layer_roughness(params), params.alpha],
        list(params.emission) + [params.holdout],
        list(params.uv_transform[:3]) + [0.0],
        list(params.uv_transform[3:]) + [0.0],
    ], np.float32)


def per_vertex_refusal(mesh, data, max_side):
    """Why visibility.per_vertex data cannot be uploaded for a MeshExport, or None: scene_state checked the
    counts when it read it; checked again right before the upload, since texelFetch must never read past the
    rows uploaded, and against the GPU's texture side."""
    if mesh.corner_vertex is None or len(mesh.corner_vertex) != len(mesh.positions):
        return "stale bake: the mesh's corners changed"
    rows = data.corner_rows(mesh.corner_vertex)
    expected = len(mesh.positions) if data.domain == "CORNER" else mesh.vertex_count
    if data.rows.shape[0] != expected or (len(rows) and int(rows.max()) >= data.rows.shape[0]):
        return f"stale bake: {data.rows.shape[0]} rows for {expected}"
    return per_vertex_layout.texture_refusal(data.rows.shape[0], max_side,
                                             "corners" if data.domain == "CORNER" else "vertices")


def row_normals(mesh, data):
    """(rows, 3) the local frames' normals of per-vertex data's rows: the vertex normals, or for rows per
    corner the corners' (split) normals (visibility.per_vertex)."""
    return mesh.normals if data.domain == "CORNER" else mesh.vertex_normals


class PerVertexBuffers:
    """GPU copy of one kind of per-vertex data (visibility.per_vertex.PerVertexData): its rows texture, the
    vertex normal texture in the same rows (one texel a vertex) and the basis texture."""

    def __init__(self, mesh, data, per_row):
        self.data = data                # the numpy PerVertexData (base.ObjectInputs.per_vertex_data)
        self.layers = data.layers
        self.vertices_per_row = per_row  # every texture and target of the mesh's per-vertex layout
        self.rows_texture = _texture_2d(per_vertex_layout.texture_of(data.rows, data.layers, per_row))
        normals = np.zeros((data.rows.shape[0], 4), np.float32)
        normals[:, :3] = row_normals(mesh, data)
        self.normal_texture = _texture_2d(per_vertex_layout.texture_of(normals, 1, per_row))
        self.basis_texture = _texture_2d_array(data.basis_texture)


class MeshBuffers:
    """Vertex buffer + one index buffer per material range of a MeshExport; with per-vertex data
    (scene_state.per_vertex) also the corners' mesh vertex index and vertex normal attributes, and a
    PerVertexBuffers of each kind."""

    def __init__(self, mesh, per_vertex=None):
        import gpu

        self.batches = []               # (material slot index, first triangle, GPUBatch)
        self.per_vertex = {}            # kind -> PerVertexBuffers
        self.refused = {}               # kind -> why its per-vertex data was not uploaded (the render says so)
        self.bounds = None              # (2, 3) local box
        self.has_colors = False         # a colour attribute (MeshExport.colors) in the vertex buffer
        self.has_second_uv = False      # the second UV map (MeshExport.second_uvs) in the vertex buffer
        # object space -> Generated coordinates: (co - location) / (2 size) + 1/2 of the mesh's texture space
        location, size = (np.asarray(v, np.float64) for v in mesh.texture_space)
        size = np.where(size != 0.0, size, 1.0)
        self.generated_transform = (list(0.5 / size) + [0.0], list(0.5 - location * 0.5 / size) + [0.0])
        if len(mesh.triangles) == 0:     # empty meshes, curves without fill: nothing to draw
            return
        self.bounds = np.stack([mesh.positions.min(axis=0), mesh.positions.max(axis=0)])
        max_side = gpu_limits.max_texture_size()
        usable = {}
        for kind, data in (per_vertex or {}).items():
            reason = per_vertex_refusal(mesh, data, max_side)
            if reason is None:
                usable[kind] = data
            else:
                self.refused[kind] = reason
        if len({data.domain for data in usable.values()}) > 1:
            # the corners read every kind's rows by one index: the kinds must agree on vertices or corners
            # (scene_state warns of the kind left out); the visibility bake wins
            first = "ssdf" if "ssdf" in usable else next(iter(usable))
            usable = {kind: data for kind, data in usable.items() if data.domain == usable[first].domain}
        per_row = per_vertex_layout.vertices_per_row(max_side)
        for kind, data in usable.items():
            try:
                self.per_vertex[kind] = PerVertexBuffers(mesh, data, per_row)
            except RuntimeError as error:       # the driver's own refusal (memory): the mesh drawn without them
                self.refused[kind] = f"the GPU could not make its per-vertex textures ({error})"
        usable = {kind: data for kind, data in usable.items() if kind in self.per_vertex}
        fmt = gpu.types.GPUVertFormat()
        fmt.attr_add(id="position", comp_type="F32", len=3, fetch_mode="FLOAT")
        fmt.attr_add(id="normal", comp_type="F32", len=3, fetch_mode="FLOAT")
        fmt.attr_add(id="tangent", comp_type="F32", len=4, fetch_mode="FLOAT")
        fmt.attr_add(id="uv", comp_type="F32", len=2, fetch_mode="FLOAT")
        self.has_colors = mesh.colors is not None
        if self.has_colors:
            fmt.attr_add(id="color", comp_type="F32", len=4, fetch_mode="FLOAT")
        self.has_second_uv = mesh.second_uvs is not None
        if self.has_second_uv:
            fmt.attr_add(id="second_uv", comp_type="F32", len=2, fetch_mode="FLOAT")
        if usable:
            fmt.attr_add(id="vertex_index", comp_type="I32", len=1, fetch_mode="INT")
            fmt.attr_add(id="vertex_normal", comp_type="F32", len=3, fetch_mode="FLOAT")
        vertices = gpu.types.GPUVertBuf(fmt, len(mesh.positions))
        vertices.attr_fill("position", mesh.positions)
        vertices.attr_fill("normal", mesh.normals)
        vertices.attr_fill("tangent", mesh.tangents)
        vertices.attr_fill("uv", mesh.uvs)
        if self.has_colors:
            vertices.attr_fill("color", mesh.colors)
        if self.has_second_uv:
            vertices.attr_fill("second_uv", mesh.second_uvs)
        if usable:
            data = next(iter(usable.values()))
            rows = data.corner_rows(mesh.corner_vertex)
            vertices.attr_fill("vertex_index", np.ascontiguousarray(rows, np.int32))
            vertices.attr_fill("vertex_normal", np.ascontiguousarray(row_normals(mesh, data)[rows], np.float32))
        for material_index, first, count in mesh.material_ranges:
            indices = gpu.types.GPUIndexBuf(type="TRIS", seq=mesh.triangles[first:first + count])
            self.batches.append((material_index, first, gpu.types.GPUBatch(type="TRIS", buf=vertices, elem=indices)))
        self.vertices = vertices

    def per_vertex_layers(self):
        """kind -> vec4 rows a vertex of the uploaded per-vertex data (base.ObjectInputs.per_vertex)."""
        return {kind: buffers.layers for kind, buffers in self.per_vertex.items()}

    def per_vertex_data(self):
        """kind -> the uploaded visibility.per_vertex.PerVertexData (base.ObjectInputs.per_vertex_data)."""
        return {kind: buffers.data for kind, buffers in self.per_vertex.items()}


def _slot_material(state, entry, slot):
    """(material name, export.MaterialParams) of an object's material slot; an empty slot: the default."""
    name = entry.material_names[slot] if slot < len(entry.material_names) else ""
    return name, state.materials.get(name) or state.materials[""]


def environment_textures(environment, equirect):
    """(prefiltered layers, equirect map) GPU textures of an EnvironmentData and the map it was made of,
    shared by every Renderer while the environment cache keeps the EnvironmentData."""
    entry = _environment_textures.get(id(environment))
    if entry is not None and entry[0] is environment:
        _environment_textures.move_to_end(id(environment))
        return entry[1], entry[2]
    layers = environment.prefiltered.layers
    padded = np.ones(layers.shape[:3] + (4,), np.float32)
    padded[..., :layers.shape[3]] = layers
    # the map itself for the background, in Blender's row order (texture t = 0 at the bottom)
    rgba = np.ones(equirect.shape[:2] + (4,), np.float32)
    rgba[..., :3] = equirect[::-1]
    entry = (environment, _texture_2d_array(padded), _texture_2d(within_side(rgba, gpu_limits.max_texture_size())[0]))
    _environment_textures[id(environment)] = entry
    while len(_environment_textures) > ENVIRONMENT_TEXTURE_CACHE_SIZE:
        _environment_textures.popitem(last=False)        # freed here, in the caller's GPU context
    return entry[1], entry[2]


class _DrawContext(techniques.DrawContext):
    """The renderer's side of the technique seam for one object (and, in bind, one material slot)."""

    def __init__(self, renderer, object_key, entry, buffers, inputs):
        self.renderer = renderer
        self.object_key = object_key
        self.buffers = buffers
        self.inputs = inputs
        self.model_matrix = _column_major(entry.matrix_world)
        self.scene_buffer = renderer.scene_buffer
        self.material_buffer = None
        self.material_name = ""
        self.params = None

    def for_material(self, name, params):
        self.material_name, self.params = name, params
        self.material_buffer = self.renderer.material_buffers[name]
        return self

    def per_vertex(self, kind):
        return self.buffers.per_vertex[kind]

    @property
    def generated_transform(self):
        return self.buffers.generated_transform

    def environment_textures(self):
        return self.renderer.environment_texture, self.renderer.equirect_texture

    def shadow_atlas(self):
        return self.renderer.shadow_atlas.texture

    def table(self, name, build):
        tables = self.renderer.tables
        if name not in tables:
            # of the code alone, so the same in every process: kept on disk for the next one's first frame
            array = disk_cache.load_or_build("table", (name,), lambda: {"table": build()})["table"]
            tables[name] = _texture(array)
        return tables[name]

    def cached_arrays(self, kind, key, build):
        return disk_cache.load_or_build(kind, key, build)

    def environment_table(self, name, build):
        environment = self.inputs.environment
        entry = self.renderer.environment_tables.get(name)
        if entry is None or entry[0] is not environment:
            entry = self.renderer.environment_tables[name] = (environment, _texture(build()))
        return entry[1]

    def material_table(self, name, build):
        tables = self.renderer.material_tables.setdefault(self.params.name or self.material_name, {})
        if name not in tables:
            tables[name] = _texture(build())
        return tables[name]

    def material_uniforms(self, rows):
        tables = self.renderer.material_tables.setdefault(self.params.name or self.material_name, {})
        rows = np.ascontiguousarray(rows, np.float32)
        key = ("uniforms", rows.tobytes())
        if key not in tables:
            tables[key] = _uniform_buffer(rows)
        return tables[key]

    def image(self, slot):
        return self.renderer.textures[_texture_key(self.params.textures[slot], slot, self.params)]

    def node_image(self, name):
        return self.renderer.textures[_node_image_key(name)]

    def object_target(self, name, size, sources=()):
        import gpu

        targets = self.renderer.object_targets.setdefault(self.object_key, {})
        target = targets.get(name)
        if target is None or (target[0].width, target[0].height) != tuple(size):
            texture = gpu.types.GPUTexture(tuple(size), format="RGBA32F")
            target = (texture, gpu.types.GPUFrameBuffer(color_slots=texture), None)
        drawn_from = target[2]
        current = bool(sources) and drawn_from is not None and len(drawn_from) == len(sources) and all(
            a is b for a, b in zip(drawn_from, sources))
        # not current: forgotten until object_target_drawn, so a pass that fails is drawn again next time
        targets[name] = target if current else (target[0], target[1], None)
        return target[0], target[1], current

    def object_target_drawn(self, name, sources):
        target = self.renderer.object_targets.get(self.object_key, {}).get(name)
        if target is not None:
            self.renderer.object_targets[self.object_key][name] = (target[0], target[1], tuple(sources))

    def object_table(self, name, sources, build):
        tables = self.renderer.object_tables.setdefault(self.object_key, {})
        entry = tables.get(name)
        if entry is None or len(entry[0]) != len(sources) or any(a is not b for a, b in zip(entry[0], sources)):
            entry = tables[name] = (tuple(sources), _texture(build()))
        return entry[1]

    def object_texture(self, name):
        target = self.renderer.object_targets.get(self.object_key, {}).get(name)
        return None if target is None else target[0]

    def fixed_shader(self, cache_key, calls_of):
        return shader_cache.get_fixed_shader(cache_key, calls_of, f"technique {cache_key[0]}")

    def full_screen_batch(self, shader, name):
        return self.renderer.full_screen_batch(shader, name)


def _texture(array):
    """A float RGBA GPU texture of an (H, W, 4) or (L, H, W, 4) array."""
    return _texture_2d_array(array) if np.ndim(array) == 4 else _texture_2d(array)


class Renderer:
    """Owns the GPU resources of one SceneState and draws it."""

    depth_prepass = True        # False: shade every surface in draw order (benchmarks compare the two)

    def __init__(self, gbuffer=False):
        self.gbuffer = gbuffer
        self.mesh_buffers = {}          # mesh key -> MeshBuffers
        self.material_buffers = {}      # material name -> GPUUniformBuf
        self.material_ids = {}          # material name -> id written to the G-buffer (uv.z)
        self.textures = {}              # _texture_key -> GPUTexture
        self.texture_warnings = {}      # image name -> why it was uploaded smaller than it is
        self.tables = {}                # a technique's tables (DrawContext.table): name -> GPUTexture
        self.environment_tables = {}    # name -> (EnvironmentData, GPUTexture) (DrawContext.environment_table)
        self.material_tables = {}       # material name -> {name: GPUTexture} (DrawContext.material_table)
        self.object_targets = {}        # object key -> {name: (GPUTexture, GPUFrameBuffer, sources)} of techniques' passes
        self.object_tables = {}         # object key -> {name: (sources, GPUTexture)} (DrawContext.object_table)
        self.scene_buffer = None
        self.environment_texture = None
        self.equirect_texture = None
        self.environment_source = None
        self.framebuffer = None
        self.targets = []
        self.size = None
        self.uploads = {"meshes": 0, "materials": 0}
        self.shadow_plan = None         # lighting.shadow_maps.ShadowPlan of the frame (None: no maps)
        self.shadow_atlas = shadow_pass.ShadowAtlas()
        self.frame_sums = multi_sample.FrameSums()     # Render Samples' sums, Edges Only's mask and tile
        self._full_screen_batches = {}  # pass name -> GPUBatch of a full-screen triangle

    # ----------------------------------------------------------------- uploads

    def upload(self, state, dirty, camera, shadow_camera=None):
        """Upload what `dirty` names of `state`, and the scene block of `camera`; the shadow maps planned for
        shadow_camera's view when given (a jittered frame keeps its centred frame's plan, and so the atlas)."""
        for key in dirty.meshes:
            if key in state.meshes:
                self.mesh_buffers[key] = MeshBuffers(state.meshes[key], state.per_vertex.get(key))
                self.uploads["meshes"] += 1
        for key in list(self.mesh_buffers):
            if key not in state.meshes:
                del self.mesh_buffers[key]
        for key in [key for key in self.textures if key[0] in dirty.images]:
            del self.textures[key]
        for name, params in state.materials.items():      # materials whose image changed reload it
            if name not in dirty.materials and any(image in dirty.images for value in params.textures.values()
                                                   for image in texture_sources(value)):
                dirty.materials.add(name)
        for name in dirty.materials:
            params = state.materials.get(name)
            if params is None:
                continue
            material_id = self.material_ids.setdefault(name, len(self.material_ids))
            self.material_buffers[name] = _uniform_buffer(material_block(params, material_id))
            self.uploads["materials"] += 1
            self.material_tables.pop(params.name or name, None)
            self._upload_images(state, params)
        if state.environment.prefiltered is not None and self.environment_source is not state.environment:
            self.environment_texture, self.equirect_texture = environment_textures(state.environment,
                                                                                   state.world.equirect)
            self.environment_source = state.environment
            height, width = state.world.equirect.shape[:2]
            if self.equirect_texture.width < width:
                self.texture_warnings["world"] = (
                    f"the world's map is {width} x {height}, over this GPU's limit of "
                    f"{gpu_limits.max_texture_size()} texels a side: its background and reflections are drawn "
                    f"from a {self.equirect_texture.width} x {self.equirect_texture.height} copy")
        light_data = state.light_data()
        self.shadow_plan = self._plan_shadows(state, light_data, shadow_camera or camera)
        block = scene_block(camera, light_data, state.environment, self.shadow_plan)
        if self.scene_buffer is None:
            self.scene_buffer = _uniform_buffer(block)
        else:
            self.scene_buffer.update(gpu_buffer(block))

    def _upload_images(self, state, params):
        """The images a material's slots read that are not uploaded yet."""
        for slot, value in params.textures.items():
            for key in _texture_keys(value, slot, params):
                pixels = state.texture_pixels(key[0], slot, key[1]) if key not in self.textures else None
                if pixels is not None:
                    self.textures[key] = self._image_texture(pixels, key[0], key[2])

    def _image_texture(self, pixels, name, normal_map=False):
        """The GPU texture of an image's mip levels (spherical/texture_mips.py's atlas, half as wide again as the
        image; a normal map's normals made unit first), the image made smaller where that atlas would pass the
        GPU's side (said once)."""
        if normal_map:
            pixels = texture_mips.unit_normals(pixels)
        side = gpu_limits.max_texture_size()
        fitted, factor = within_side(pixels, side * 2 // 3)
        if factor > 1:
            self.texture_warnings[name] = (f"image '{name}' is {pixels.shape[1]} x {pixels.shape[0]}, over this "
                                           f"GPU's limit of {side} texels a side (with its mip levels): rendered "
                                           f"at 1/{factor} of its size")
        return _texture_2d(texture_mips.atlas(fitted))

    def upload_warnings(self, state):
        """The render report's lines for objects whose per-vertex data the upload refused (MeshBuffers.refused):
        each object once a kind, naming why."""
        lines, seen = [], set()
        for entry in state.objects.values():
            buffers = self.mesh_buffers.get(entry.mesh_key)
            for kind, reason in (buffers.refused.items() if buffers is not None else ()):
                if (entry.mesh_key, kind) not in seen:
                    seen.add((entry.mesh_key, kind))
                    lines.append(f"object '{entry.name.split('#')[0]}' renders without its "
                                 f"{scene_state.BAKE_NAMES.get(kind, kind)}: {reason}")
        return lines + list(self.texture_warnings.values())

    def _plan_shadows(self, state, light_data, camera):
        """The frame's lighting.shadow_maps.ShadowPlan over the uploaded objects (a sun's tile over what the camera
        sees of them), or None (no maps)."""
        if not state.shadow_map_size or not light_data.count:
            return None
        bounds = shadow_pass.world_bounds(state.objects.values(), self.mesh_buffers)
        view = None
        if bounds is not None and len(light_data.sun_sharpness):
            view = shadow_maps.view_corners(camera.projection @ camera.view, bounds)
        shadow_plan = shadow_maps.plan(light_data, bounds, state.shadow_map_size, view, gpu_limits.max_texture_size())
        return shadow_plan if shadow_plan.active else None

    # ----------------------------------------------------------------- targets

    def ensure_targets(self, width, height):
        import gpu

        if self.size == (width, height):
            return
        count = len(shader_sources.output_names(self.gbuffer))
        self.targets = [gpu.types.GPUTexture((width, height), format="RGBA32F") for _ in range(count)]
        self.depth = gpu.types.GPUTexture((width, height), format="DEPTH_COMPONENT32F")
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=self.targets)
        self.size = (width, height)

    def full_screen_batch(self, shader, name):
        """One triangle covering any target, for the full-screen pass `name` (position in NDC): a batch
        for each pass, made with its shader."""
        from gpu_extras.batch import batch_for_shader

        batch = self._full_screen_batches.get(name)
        if batch is None:
            batch = self._full_screen_batches[name] = batch_for_shader(
                shader, "TRIS", {"position": [(-1, -1), (3, -1), (-1, 3)]})
        return batch

    # ----------------------------------------------------------------- drawing

    def object_draws(self, state):
        """[(object index, object key, ObjectEntry, DrawContext, [(first triangle, GPUBatch, material name,
        params, technique, variant key)])] of every drawable object, in draw order (the index counts every
        object of the state: the G-buffer's object id)."""
        light_data = state.light_data()
        draws = []
        # (technique name, material, MeshBuffers) -> a variant key made without reading the object's transform:
        # the same for every object drawing that mesh and material (ObjectInputs.matrix_world_read)
        shared_keys = {}
        for object_index, (object_key, entry) in enumerate(state.objects.items()):
            buffers = self.mesh_buffers.get(entry.mesh_key)
            if buffers is None:
                continue
            inputs = techniques.ObjectInputs(light_data, state.environment, self.gbuffer,
                                             buffers.per_vertex_layers(), buffers.bounds, entry.matrix_world,
                                             buffers.per_vertex_data(), self.shadow_plan is not None,
                                             buffers.has_colors, buffers.has_second_uv)
            slots = []
            for slot, first_triangle, batch in buffers.batches:
                name, params = _slot_material(state, entry, slot)
                if name not in self.material_buffers:
                    name = ""
                technique = techniques.for_material(params)
                shared = (technique.name, name, id(params), buffers)       # params: the state's, alive all frame
                key = shared_keys.get(shared)
                if key is None:
                    key = technique.variant_key(params, inputs)
                    if not inputs.matrix_world_read:
                        shared_keys[shared] = key
                slots.append((first_triangle, batch, name, params, technique, key))
            draws.append((object_index, object_key, entry, _DrawContext(self, object_key, entry, buffers, inputs),
                          slots))
        return draws

    def draw(self, state, camera, background_alpha=1.0, framebuffer=None, before_shading=None):
        """Draw every object the view may see (all of them cast into the shadow maps), then the world behind
        them, into our framebuffer (call ensure_targets first) or `framebuffer` (its colour slots as ours).
        background_alpha: alpha of the world pixels (0
        for a transparent film); before_shading(): run with the framebuffer bound after the depth of the
        surfaces is in (multi_sample's pixel mask)."""
        import gpu

        draws = self.object_draws(state)
        self._prepare_objects(draws)
        if self.shadow_plan is not None:        # holdouts cast too, as in Cycles; objects whose Shadow is off do not
            self.shadow_atlas.draw(self.shadow_plan, [(context.model_matrix,
                                                       [batch for *_, batch in context.buffers.batches],
                                                       entry.matrix_world, context.buffers.bounds)
                                                      for _index, _key, entry, context, _slots in draws
                                                      if entry.casts_shadow])
        draws = in_view(draws, camera.projection @ camera.view)     # an edge tile sees a part of the view
        framebuffer = framebuffer or self.framebuffer
        with framebuffer.bind():
            framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            gpu.state.face_culling_set("NONE")
            gpu.state.blend_set("NONE")
            if self.depth_prepass:
                self._draw_depth(draws)
            else:       # holdouts shade nothing but occlude: their depth alone, first
                self._draw_depth(draws, holdouts_only=True)
            if before_shading is not None:
                before_shading()
            if self.depth_prepass:
                gpu.state.depth_mask_set(False)     # the shading pass tests against the final depth
            self._draw_surfaces(draws)
            # surfaces with a coverage below 1 last, writing the depth of the samples they keep (the pre-pass
            # left them out: its depth would hide what shows through them)
            gpu.state.depth_mask_set(True)
            self._draw_surfaces(draws, covered=True)
            if not self.gbuffer:
                self._draw_background(camera, state.environment.prefiltered is not None, background_alpha)
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)

    def _draw_surfaces(self, draws, covered=False):
        """The shading pass over the opaque materials' slots, or (covered) those with a coverage below 1
        (material_textures.has_coverage).  A run of draws with one variant and material binds the shader and
        the technique's resources once (a uniform block and texture binding per run, not per object), unless
        the technique's bind reads the object's own (Technique.bind_reads_object): then per object."""
        bound = None        # (shader, variant key, material name) of the bindings in place
        for object_index, _object_key, entry, context, slots in draws:
            if entry.holdout:       # a holdout's pixels keep the clear: (0, 0, 0, 0)
                continue
            for first_triangle, batch, name, params, technique, key in slots:
                if material_textures.has_coverage(params) != covered:
                    continue
                shader = shader_cache.get_shader(technique, key)
                in_place = bound is not None and shader is bound[0] and name == bound[2] and (
                    key is bound[1] or key == bound[1])
                if not in_place or technique.bind_reads_object(key):
                    shader.bind()
                    technique.bind(shader, key, context.for_material(name, params))
                    bound = (shader, key, name)
                shader.uniform_float("model_matrix", context.model_matrix)
                technique.bind_object(shader, key, context)
                if self.gbuffer:
                    shader.uniform_int("gbuffer_object_index", object_index)
                    shader.uniform_int("gbuffer_triangle_offset", first_triangle)
                batch.draw(shader)

    def _prepare_objects(self, draws):
        """Each technique's own passes for the objects that use it (Technique.prepare_object), before the
        surfaces; the targets of objects gone are dropped."""
        live = {object_key for _index, object_key, *_ in draws}
        for object_key in [key for key in self.object_targets if key not in live]:
            del self.object_targets[object_key]
        for object_key in [key for key in self.object_tables if key not in live]:
            del self.object_tables[object_key]
        for _index, _object_key, entry, context, slots in draws:
            if entry.holdout:
                continue
            by_technique = {}
            for *_, technique, key in slots:
                by_technique.setdefault(technique.name, (technique, []))[1].append(key)
            for technique, keys in by_technique.values():
                technique.prepare_object(keys, context)

    def _draw_depth(self, draws, holdouts_only=False):
        """Depth of every opaque surface of object_draws' `draws` (a holdout object's all), no colour: the
        surface shaders then shade each pixel once instead of every surface drawn over it (they are the frame's
        whole cost; the pre-pass is vertex work).  holdouts_only: the holdouts' depth alone (without the
        pre-pass the shading pass writes the rest)."""
        import gpu

        shader = shader_cache.get_depth_shader()
        shader.bind()
        shader.uniform_block("scene", self.scene_buffer)
        gpu.state.color_mask_set(False, False, False, False)
        for _index, _object_key, entry, context, slots in draws:
            if holdouts_only and not entry.holdout:
                continue
            shader.uniform_float("model_matrix", context.model_matrix)
            for _first_triangle, batch, _name, params, *_ in slots:
                if entry.holdout or not material_textures.has_coverage(params):
                    batch.draw(shader)
        gpu.state.color_mask_set(True, True, True, True)

    def _draw_background(self, camera, has_environment, alpha):
        """Full-screen triangle at the far plane: only where no surface was drawn (depth test)."""
        import gpu

        shader = shader_cache.get_background_shader(has_environment)
        gpu.state.depth_mask_set(False)
        shader.bind()
        shader.uniform_float("background_alpha", float(alpha))
        shader.uniform_block("scene", self.scene_buffer)
        if has_environment:      # (the world-colour variant has no use for the view ray)
            shader.uniform_float("inverse_view_projection",
                                 _column_major(np.linalg.inv(camera.projection @ camera.view)))
            shader.uniform_sampler("equirect_texture", self.equirect_texture)
        self.full_screen_batch(shader, "background").draw(shader)
        gpu.state.depth_mask_set(True)

    def read_output(self, name):
        """(H, W, 4) float32 of output `name` ("combined", "diffuse", "position"...), row 0 at the bottom."""
        names = shader_sources.output_names(self.gbuffer)
        if name == "combined" and name not in names:
            combined = self.read(names.index("diffuse")) + self.read(names.index("specular"))
            combined[..., 3] = np.minimum(combined[..., 3], 1.0)
            return combined
        return self.read(names.index(name))

    def read(self, slot):
        """(H, W, 4) float32 of colour target `slot`, row 0 at the bottom (Blender's order)."""
        import gpu

        width, height = self.size
        out = np.empty((height, width, 4), np.float32)
        with self.framebuffer.bind():
            # our own array: np.asarray of read_color's multi-dimensional Buffer has wrong strides
            self.framebuffer.read_color(0, 0, width, height, 4, slot, "FLOAT",
                                        data=gpu.types.Buffer("FLOAT", (height, width, 4), out))
        return out

    def free(self):
        self.mesh_buffers.clear()
        self.material_buffers.clear()
        self.textures.clear()
        self.tables.clear()
        self.environment_tables.clear()
        self.material_tables.clear()
        self.object_targets.clear()
        self.object_tables.clear()
        self.shadow_plan = None
        self.shadow_atlas = shadow_pass.ShadowAtlas()
        self.frame_sums = multi_sample.FrameSums()
        self.targets = []
        self.framebuffer = None
        self.size = None


def in_view(draws, view_projection):
    """Renderer.object_draws' `draws` whose world box may reach the view of world -> clip `view_projection`
    (shadow_maps.in_tile's test); an object without bounds is kept."""
    known = [index for index, draw in enumerate(draws) if draw[3].buffers.bounds is not None]
    keep = np.ones(len(draws), bool)
    if known:
        corners = shadow_pass.world_corners([draws[i][2].matrix_world for i in known],
                                            [draws[i][3].buffers.bounds for i in known])
        keep[known] = shadow_maps.in_tile(view_projection, corners)
    return [draw for draw, kept in zip(draws, keep) if kept]


def gpu_buffer(block):
    import gpu
    data = np.ascontiguousarray(block, np.float32)
    return gpu.types.Buffer("FLOAT", data.size, data.ravel())
