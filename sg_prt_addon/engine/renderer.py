"""GPU side: uploads a SceneState and draws it with the SG surface shaders.

Used by both the final render (into our float offscreen framebuffer) and the
viewport (view_draw draws the same framebuffer's Combined texture).  Only
what SceneState marks dirty is re-uploaded.  Must run where the `gpu` module
works: inside render() with bl_use_gpu_context, or in view_update/view_draw.
"""

import collections

import numpy as np

from ..core import clamped_cosine, clamped_cosine_table, ggx_albedo, shading
from . import shader_variants
from .shader_variants import GBUFFER_OUTPUTS, MAX_ENV_LOBES, MAX_LAYERS, MAX_POINT_LIGHTS, MAX_SUNS

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


def _texture_2d_array(layers):
    import gpu
    data = np.ascontiguousarray(layers, np.float32)
    return gpu.types.GPUTexture((data.shape[2], data.shape[1]), layers=data.shape[0], format="RGBA32F",
                                data=gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def _texture_key(image_name, slot):
    from ..blender.export import COLOUR_SLOTS
    return image_name, slot in COLOUR_SLOTS


def _uniform_buffer(data):
    import gpu
    data = np.ascontiguousarray(data, np.float32)
    return gpu.types.GPUUniformBuf(gpu.types.Buffer("FLOAT", data.size, data.ravel()))


def scene_block(camera, light_data, environment):
    """SceneData (resources/scene_data.glsl) as float32 words, std140 (all vec4)."""
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
        vec4_array(MAX_POINT_LIGHTS, np.pad(light_data.point_intensity, ((0, 0), (0, 1))) if points else []),
        vec4_array(MAX_POINT_LIGHTS, np.concatenate([light_data.spot_direction,
                                                     light_data.spot_size[:, None]], 1) if points else []),
        vec4_array(MAX_POINT_LIGHTS, np.pad(light_data.spot_blend[:, None], ((0, 0), (0, 3)))
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
    ]
    return np.concatenate(parts, axis=0)


def material_block(params, material_id=0):
    """MaterialData of an export.MaterialParams as (6, 4) float32; material_id goes to the G-buffer."""
    return np.array([
        list(params.diffuse_color) + [1.0],
        list(params.specular_color) + [1.0],
        [params.roughness, params.ior, params.exponent, params.alpha_x],
        [params.alpha_y, params.nu, params.nv, params.normal_strength],
        list(params.tangent_axis) + [params.tangent_rotation],
        [1.0 if params.tangent_source == "OBJECT_AXIS" else 0.0, float(material_id), 0.0, 0.0],
    ], np.float32)


VISIBILITY_TEXTURE_WIDTH = 4096     # texels a row of the coefficient texture (a multiple of the layers is used)


MAX_TEXTURE_SIZE = 16384              # GPUTexture side limit measured here (DESIGN.md)


def vertices_per_row(layers):
    """Vertices a row of the per-vertex textures of a bake with `layers` coefficient vec4 a vertex (the
    coefficient texture, and the normal and per-vertex visibility textures in the same rows)."""
    return max(1, VISIBILITY_TEXTURE_WIDTH // layers)


def visibility_texture_shape(vertex_count, layers):
    """(rows, texels a row) of the coefficient texture of vertex_count vertices."""
    per_row = vertices_per_row(layers)
    return max(1, -(-vertex_count // per_row)), per_row * layers


def per_vertex_texture(values, texels_per_vertex, per_row):
    """(rows, per_row * texels_per_vertex, 4) float32 texture of per-vertex values (V, 4 * texels_per_vertex):
    vertex v's texel k at (column (v % per_row) * texels_per_vertex + k, row v // per_row)."""
    count = values.shape[0]
    rows = max(1, -(-count // per_row))
    out = np.zeros((rows * per_row, texels_per_vertex, 4), np.float32)
    out[:count] = np.asarray(values, np.float32).reshape(count, texels_per_vertex, 4)
    return out.reshape(rows, per_row * texels_per_vertex, 4)


def visibility_texture_rows(packed, layers):
    """(H, W, 4) float32 texture of per-vertex coefficient rows (V, 4 layers): vertex v's vec4 k at texel
    (column (v % per_row) * layers + k, row v // per_row), per_row = vertices_per_row(layers)
    (mesh.vert.glsl reads it back with texelFetch)."""
    return per_vertex_texture(packed, layers, vertices_per_row(layers))


class MeshBuffers:
    """Vertex buffer + one index buffer per material range of a MeshExport; with a usable visibility
    bake (scene_state.VisibilityData) also the corners' mesh vertex index and SSDF normal attributes,
    the per-vertex coefficient texture, the vertex normal texture (one texel a vertex, in the same rows)
    and the basis texture."""

    def __init__(self, mesh, visibility=None):
        import gpu

        self.batches = []               # (material slot index, first triangle, GPUBatch)
        self.visibility_layers = 0
        self.coefficient_texture = None
        self.normal_texture = None
        self.basis_texture = None
        self.bounds = None              # (2, 3) local box, for core.shading.shares_light_visibility
        if len(mesh.triangles) == 0:     # empty meshes, curves without fill: nothing to draw
            return
        self.bounds = np.stack([mesh.positions.min(axis=0), mesh.positions.max(axis=0)])
        if visibility is not None:
            # scene_state.VisibilityData.from_bake checked this; check again right before the upload:
            # texelFetch must never read past the rows uploaded
            if (mesh.corner_vertex is None or len(mesh.corner_vertex) != len(mesh.positions)
                    or visibility.packed.shape[0] != mesh.vertex_count
                    or (len(mesh.corner_vertex) and int(mesh.corner_vertex.max()) >= visibility.packed.shape[0])
                    or visibility_texture_shape(visibility.packed.shape[0], visibility.layers)[0] > MAX_TEXTURE_SIZE):
                visibility = None
        fmt = gpu.types.GPUVertFormat()
        fmt.attr_add(id="position", comp_type="F32", len=3, fetch_mode="FLOAT")
        fmt.attr_add(id="normal", comp_type="F32", len=3, fetch_mode="FLOAT")
        fmt.attr_add(id="tangent", comp_type="F32", len=4, fetch_mode="FLOAT")
        fmt.attr_add(id="uv", comp_type="F32", len=2, fetch_mode="FLOAT")
        if visibility is not None:
            fmt.attr_add(id="vertex_index", comp_type="I32", len=1, fetch_mode="INT")
            fmt.attr_add(id="ssdf_normal", comp_type="F32", len=3, fetch_mode="FLOAT")
        vertices = gpu.types.GPUVertBuf(fmt, len(mesh.positions))
        vertices.attr_fill("position", mesh.positions)
        vertices.attr_fill("normal", mesh.normals)
        vertices.attr_fill("tangent", mesh.tangents)
        vertices.attr_fill("uv", mesh.uvs)
        if visibility is not None:
            vertices.attr_fill("vertex_index", np.ascontiguousarray(mesh.corner_vertex, np.int32))
            vertices.attr_fill("ssdf_normal", np.ascontiguousarray(
                mesh.vertex_normals[mesh.corner_vertex.astype(np.int64)], np.float32))
            self.visibility_layers = visibility.layers
            self.coefficient_texture = _texture_2d(visibility_texture_rows(visibility.packed, visibility.layers))
            normals = np.zeros((visibility.packed.shape[0], 4), np.float32)
            normals[:, :3] = mesh.vertex_normals
            self.normal_texture = _texture_2d(per_vertex_texture(normals, 1, vertices_per_row(visibility.layers)))
            self.basis_texture = _texture_2d_array(visibility.basis_texture)
        for material_index, first, count in mesh.material_ranges:
            indices = gpu.types.GPUIndexBuf(type="TRIS", seq=mesh.triangles[first:first + count])
            self.batches.append((material_index, first, gpu.types.GPUBatch(type="TRIS", buf=vertices, elem=indices)))
        self.vertices = vertices


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
    entry = (environment, _texture_2d_array(padded), _texture_2d(rgba))
    _environment_textures[id(environment)] = entry
    while len(_environment_textures) > ENVIRONMENT_TEXTURE_CACHE_SIZE:
        _environment_textures.popitem(last=False)        # freed here, in the caller's GPU context
    return entry[1], entry[2]


class Renderer:
    """Owns the GPU resources of one SceneState and draws it."""

    depth_prepass = True        # False: shade every surface in draw order (benchmarks compare the two)

    def __init__(self, gbuffer=False):
        self.gbuffer = gbuffer
        self.mesh_buffers = {}          # mesh key -> MeshBuffers
        self.material_buffers = {}      # material name -> GPUUniformBuf
        self.material_ids = {}          # material name -> id written to the G-buffer (uv.z)
        self.textures = {}              # (image name, slot is a colour) -> GPUTexture
        self.fitted_textures = {}       # material name -> (layers, shadowing table) of its lobe fit
        self.scene_buffer = None
        self.environment_texture = None
        self.equirect_texture = None
        self.environment_source = None
        self.anisotropy_tables = {}     # lobe count -> GPUTexture
        self.ggx_texture = None
        self.ggx_albedo_texture = None
        self.clamped_cosine_texture = None
        self.framebuffer = None
        self.targets = []
        self.size = None
        self.uploads = {"meshes": 0, "materials": 0}
        self.background_batch = None
        self.vertex_visibility = {}     # object key -> (GPUTexture, GPUFrameBuffer) of the per-vertex pass
        self.vertex_visibility_batch = None

    # ----------------------------------------------------------------- uploads

    def upload(self, state, dirty, camera):
        import bpy

        for key in dirty.meshes:
            if key in state.meshes:
                self.mesh_buffers[key] = MeshBuffers(state.meshes[key], state.visibility.get(key))
                self.uploads["meshes"] += 1
        for key in list(self.mesh_buffers):
            if key not in state.meshes:
                del self.mesh_buffers[key]
        for key in [key for key in self.textures if key[0] in dirty.images]:
            del self.textures[key]
        for name, params in state.materials.items():      # materials whose image changed reload it
            if name not in dirty.materials and any(image in dirty.images for image in params.textures.values()):
                dirty.materials.add(name)
        for name in dirty.materials:
            params = state.materials.get(name)
            if params is None:
                continue
            material_id = self.material_ids.setdefault(name, len(self.material_ids))
            self.material_buffers[name] = _uniform_buffer(material_block(params, material_id))
            self.uploads["materials"] += 1
            self.fitted_textures.pop(name, None)
            if params.fitted is not None:
                self.fitted_textures[name] = (_texture_2d_array(params.fitted.layers),
                                              _texture_2d(params.fitted.table))
            for slot, image_name in params.textures.items():
                key = _texture_key(image_name, slot)
                if key not in self.textures and image_name in bpy.data.images:
                    from ..blender import export
                    self.textures[key] = _texture_2d(export.texture_pixels(bpy.data.images[image_name], slot))
        if state.environment.prefiltered is not None and self.environment_source is not state.environment:
            self.environment_texture, self.equirect_texture = environment_textures(state.environment,
                                                                                   state.world.equirect)
            self.environment_source = state.environment
        block = scene_block(camera, state.light_data(), state.environment)
        if self.scene_buffer is None:
            self.scene_buffer = _uniform_buffer(block)
        else:
            self.scene_buffer.update(gpu_buffer(block))

    def _anisotropy_texture(self, lobe_count):
        texture = self.anisotropy_tables.get(lobe_count)
        if texture is None:
            texture = _texture_2d(shader_variants.anisotropy_table(lobe_count))
            self.anisotropy_tables[lobe_count] = texture
        return texture

    # ----------------------------------------------------------------- targets

    def ensure_targets(self, width, height):
        import gpu

        if self.size == (width, height):
            return
        count = len(shader_variants.output_names(self.gbuffer))
        self.targets = [gpu.types.GPUTexture((width, height), format="RGBA32F") for _ in range(count)]
        self.depth = gpu.types.GPUTexture((width, height), format="DEPTH_COMPONENT32F")
        self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.depth, color_slots=self.targets)
        self.size = (width, height)

    # ----------------------------------------------------------------- drawing

    def draw(self, state, camera, background_alpha=1.0):
        """Draw every object, then the world behind them, into our framebuffer (call ensure_targets
        first).  background_alpha: alpha of the world pixels (0 for a transparent film)."""
        import gpu

        light_data = state.light_data()
        has_lights = light_data.count > 0
        has_environment = state.environment.prefiltered is not None
        diffuse_rows = shader_variants.diffuse_visibility_rows(state.environment)
        self._draw_vertex_visibility(state, diffuse_rows, has_lights, has_environment)
        with self.framebuffer.bind():
            self.framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0), depth=1.0)
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            gpu.state.face_culling_set("NONE")
            gpu.state.blend_set("NONE")
            if self.depth_prepass:
                self._draw_depth(state)
                gpu.state.depth_mask_set(False)     # the shading pass tests against the final depth
            else:       # holdouts shade nothing but occlude: their depth alone, first
                self._draw_depth(state, holdouts_only=True)
            for object_index, (object_key, entry) in enumerate(state.objects.items()):
                buffers = self.mesh_buffers.get(entry.mesh_key)
                if buffers is None or entry.holdout:       # a holdout's pixels keep the clear: (0, 0, 0, 0)
                    continue
                model = _column_major(entry.matrix_world)
                shared_light_visibility = bool(buffers.visibility_layers and has_lights) and \
                    shading.shares_light_visibility(light_data, shading.world_bounds(buffers.bounds, entry.matrix_world))
                for slot, first_triangle, batch in buffers.batches:
                    name, params = _slot_material(state, entry, slot)
                    if name not in self.material_buffers:
                        name = ""
                    key = shader_variants.variant_key(params, has_lights, has_environment, self.gbuffer,
                                                      buffers.visibility_layers, diffuse_rows, shared_light_visibility)
                    shader = shader_variants.get_shader(key)
                    shader.bind()
                    shader.uniform_float("model_matrix", model)
                    if self.gbuffer:
                        shader.uniform_int("gbuffer_object_index", object_index)
                        shader.uniform_int("gbuffer_triangle_offset", first_triangle)
                    if key.visibility_layers:
                        shader.uniform_sampler("visibility_coefficients", buffers.coefficient_texture)
                        shader.uniform_sampler("visibility_basis", buffers.basis_texture)
                    if key.diffuse_visibility_rows:
                        shader.uniform_sampler("diffuse_visibility", self.vertex_visibility[object_key][0])
                    shader.uniform_block("scene", self.scene_buffer)
                    shader.uniform_block("material", self.material_buffers[name])
                    if has_environment:
                        shader.uniform_sampler("environment_texture", self.environment_texture)
                        if key.has_specular:
                            shader.uniform_sampler("equirect_texture", self.equirect_texture)
                    if key.model in shader_variants.ANISOTROPIC_MODELS:
                        shader.uniform_sampler("anisotropy_table", self._anisotropy_texture(key.ndf_lobes))
                    if shader_variants.uses_clamped_cosine_table(key):
                        if self.clamped_cosine_texture is None:
                            self.clamped_cosine_texture = _texture_2d(clamped_cosine_table.clamped_cosine_table())
                        shader.uniform_sampler("clamped_cosine_table", self.clamped_cosine_texture)
                    if shader_variants.uses_ggx_table(key):
                        if self.ggx_texture is None:
                            self.ggx_texture = _texture_2d(shader_variants.ggx_table())
                        shader.uniform_sampler("ggx_table", self.ggx_texture)
                        if self.ggx_albedo_texture is None:
                            albedo = np.repeat(ggx_albedo.albedo_table()[..., None], 4, axis=-1)
                            self.ggx_albedo_texture = _texture_2d(albedo)
                        shader.uniform_sampler("ggx_albedo_table", self.ggx_albedo_texture)
                    if key.model == shader_variants.FITTED_MODEL:
                        layers, table = self.fitted_textures[params.name if params.name in self.fitted_textures
                                                             else name]
                        shader.uniform_sampler("fitted_layers", layers)
                        shader.uniform_sampler("fitted_shadowing", table)
                    for texture_name in key.textures:
                        shader.uniform_sampler("texture_" + texture_name, self.textures[
                            _texture_key(params.textures[texture_name], texture_name)])
                    batch.draw(shader)
            if not self.gbuffer:
                self._draw_background(camera, has_environment, background_alpha)
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)

    def _draw_vertex_visibility(self, state, rows, has_lights, has_environment):
        """The broad diffuse lobes' visibility at the vertices of every object with a bake whose variants
        read it (a diffuse term; resources/vertex_visibility.frag.glsl): one texel a vertex and vec4."""
        import gpu
        from gpu_extras.batch import batch_for_shader

        for object_key in [key for key in self.vertex_visibility if key not in state.objects]:
            del self.vertex_visibility[object_key]
        for object_key, entry in state.objects.items():
            buffers = self.mesh_buffers.get(entry.mesh_key)
            if buffers is None or not buffers.visibility_layers or not rows or not any(
                    shader_variants.variant_key(_slot_material(state, entry, slot)[1], has_lights, has_environment,
                                                self.gbuffer, buffers.visibility_layers, rows).diffuse_visibility_rows
                    for slot, _first, _batch in buffers.batches):
                self.vertex_visibility.pop(object_key, None)
                continue
            # one texel a vertex and vec4, in the coefficient texture's rows
            size = (vertices_per_row(buffers.visibility_layers) * rows, buffers.coefficient_texture.height)
            target = self.vertex_visibility.get(object_key)
            if target is None or (target[0].width, target[0].height) != size:
                texture = gpu.types.GPUTexture(size, format="RGBA32F")
                target = self.vertex_visibility[object_key] = (texture, gpu.types.GPUFrameBuffer(color_slots=texture))
            shader = shader_variants.get_vertex_visibility_shader(buffers.visibility_layers, rows, has_environment)
            if self.vertex_visibility_batch is None:
                self.vertex_visibility_batch = batch_for_shader(
                    shader, "TRIS", {"position": [(-1, -1), (3, -1), (-1, 3)]})
            with target[1].bind():
                gpu.state.depth_test_set("NONE")
                gpu.state.blend_set("NONE")
                shader.bind()
                shader.uniform_float("model_matrix", _column_major(entry.matrix_world))
                shader.uniform_block("scene", self.scene_buffer)
                shader.uniform_sampler("visibility_coefficients", buffers.coefficient_texture)
                shader.uniform_sampler("vertex_normals", buffers.normal_texture)
                shader.uniform_sampler("visibility_basis", buffers.basis_texture)
                self.vertex_visibility_batch.draw(shader)

    def _draw_depth(self, state, holdouts_only=False):
        """Depth of every surface, no colour: the surface shaders then shade each pixel once instead of
        every surface drawn over it (they are the frame's whole cost; the pre-pass is vertex work).
        holdouts_only: the holdouts' depth alone (without the pre-pass the shading pass writes the rest)."""
        import gpu

        shader = shader_variants.get_depth_shader()
        shader.bind()
        shader.uniform_block("scene", self.scene_buffer)
        gpu.state.color_mask_set(False, False, False, False)
        for entry in state.objects.values():
            buffers = self.mesh_buffers.get(entry.mesh_key)
            if buffers is None or (holdouts_only and not entry.holdout):
                continue
            shader.uniform_float("model_matrix", _column_major(entry.matrix_world))
            for _slot, _first_triangle, batch in buffers.batches:
                batch.draw(shader)
        gpu.state.color_mask_set(True, True, True, True)

    def _draw_background(self, camera, has_environment, alpha):
        """Full-screen triangle at the far plane: only where no surface was drawn (depth test)."""
        import gpu
        from gpu_extras.batch import batch_for_shader

        shader = shader_variants.get_background_shader(has_environment)
        if self.background_batch is None:
            self.background_batch = batch_for_shader(shader, "TRIS", {"position": [(-1, -1), (3, -1), (-1, 3)]})
        gpu.state.depth_mask_set(False)
        shader.bind()
        shader.uniform_float("background_alpha", float(alpha))
        shader.uniform_block("scene", self.scene_buffer)
        if has_environment:      # (the world-colour variant has no use for the view ray)
            shader.uniform_float("inverse_view_projection",
                                 _column_major(np.linalg.inv(camera.projection @ camera.view)))
            shader.uniform_sampler("equirect_texture", self.equirect_texture)
        self.background_batch.draw(shader)
        gpu.state.depth_mask_set(True)

    def read_output(self, name):
        """(H, W, 4) float32 of output `name` ("combined", "diffuse", "position"...), row 0 at the bottom."""
        names = shader_variants.output_names(self.gbuffer)
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
        self.fitted_textures.clear()
        self.vertex_visibility.clear()
        self.targets = []
        self.framebuffer = None
        self.size = None


def gpu_buffer(block):
    import gpu
    data = np.ascontiguousarray(block, np.float32)
    return gpu.types.Buffer("FLOAT", data.size, data.ravel())
