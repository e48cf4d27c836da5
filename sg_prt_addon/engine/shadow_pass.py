"""The lights' shadow maps on the GPU: the plan of a frame (lighting.shadow_maps) from the drawn objects' bounds,
its rows of the scene block, and the depth atlas drawn from the lights (drawn again only when the plan or what
is drawn changed: a viewport redraw that moves the view alone reuses it)."""
import numpy as np

from ..lighting import shadow_maps
from ..techniques import shader_sources
from ..techniques.shader_sources import MAX_POINT_LIGHTS, MAX_SHADOW_MAPS, MAX_SUNS
from . import shader_cache


def world_corners(matrices, boxes):
    """(N, 8, 3) world corners of local boxes (N, 2, 3) under matrices (N, 4, 4)."""
    corners = shadow_maps.box_corners(boxes)
    matrices = np.asarray(matrices, np.float64).reshape(-1, 4, 4)
    return np.einsum("nij,nkj->nki", matrices[:, :3, :3], corners) + matrices[:, None, :3, 3]


def world_bounds(entries, mesh_buffers):
    """(2, 3) box of every object's mesh (ObjectEntry, MeshBuffers by mesh key) in the world, or None."""
    matrices, boxes = [], []
    for entry in entries:
        buffers = mesh_buffers.get(entry.mesh_key)
        if buffers is not None and buffers.bounds is not None:
            matrices.append(entry.matrix_world)
            boxes.append(buffers.bounds)
    if not boxes:
        return None
    world = world_corners(matrices, boxes)
    world = world[np.all(np.isfinite(world), axis=(1, 2))]
    if not len(world):
        return None
    return np.stack([world.min(axis=(0, 1)), world.max(axis=(0, 1))])


def scene_rows(shadow_plan, light_data):
    """The scene block's shadow rows (engine/scene_data.glsl, after shading_footprint) as (R, 4) float32."""
    points, suns = len(light_data.point_radius), len(light_data.sun_sharpness)
    atlas = np.zeros((1, 4), np.float32)
    slots = np.zeros((MAX_SHADOW_MAPS // 4, 4), np.float32)
    point_rows = np.zeros((MAX_POINT_LIGHTS, 4), np.float32)
    point_rows[:, 0] = -1.0
    sun_rows = np.zeros((MAX_SUNS, 4), np.float32)
    sun_rows[:, 0] = -1.0
    sun_frames = np.zeros((3 * MAX_SUNS, 4), np.float32)
    sun_radius = np.zeros((MAX_SUNS, 4), np.float32)
    if shadow_plan is not None and shadow_plan.active:
        atlas[0] = shadow_plan.size, shadow_plan.columns, shadow_plan.inner, len(shadow_plan.slot_lights)
        slots.ravel()[:len(shadow_plan.slot_lights)] = shadow_plan.slot_lights
        point_rows[:points] = np.stack([shadow_plan.point_slot, shadow_plan.point_first_tile,
                                        shadow_plan.point_near_far[:, 0], shadow_plan.point_near_far[:, 1]], 1)
        sun_rows[:suns] = np.stack([shadow_plan.sun_slot, shadow_plan.sun_tile, shadow_plan.sun_texel,
                                    shadow_plan.sun_range], 1)
        sun_frames[:3 * suns] = shadow_plan.sun_rows.reshape(-1, 4)
        sun_radius[:suns, 0] = shadow_plan.sun_tan_radius
    return np.concatenate([atlas, slots, point_rows, sun_rows, sun_frames, sun_radius])


def shadow_calls():
    """Depth from a light (engine/shadow.vert.glsl): the model matrix and the tile's world -> clip."""
    return [("vertex_in", (0, "VEC3", "position")), ("push_constant", ("MAT4", "model_matrix")),
            ("push_constant", ("MAT4", "tile_matrix")), ("fragment_out", (0, "VEC4", "out_unused")),
            ("vertex_source", (shader_sources.engine_source("shadow.vert.glsl"),)),
            ("fragment_source", ("void main()\n{\n  out_unused = vec4(0.0);\n}\n",))]


def _object_corners(objects):
    """(N, 8, 3) world box corners of draw()'s objects; an object without bounds gets NaN (always drawn)."""
    corners = np.full((len(objects), 8, 3), np.nan)
    known = [index for index, item in enumerate(objects) if item[3] is not None]
    if known:
        corners[known] = world_corners([objects[i][2] for i in known], [objects[i][3] for i in known])
    return corners


class ShadowAtlas:
    """The depth texture of a frame's shadow maps, drawn by draw()."""

    def __init__(self):
        self.texture = None
        self.framebuffer = None
        self.signature = None
        self.draw_count = 0         # atlases drawn (tests: a view change alone draws none)

    def draw(self, shadow_plan, objects):
        """Draw every tile of shadow_plan with `objects`, [(model matrix (16 floats, column-major), [GPUBatch],
        (4, 4) matrix_world, (2, 3) local bounds or None)], each in the tiles its box may reach, unless the plan and
        the objects are those of the last atlas."""
        import gpu

        signature = (shadow_plan.size, shadow_plan.columns, shadow_plan.rows,
                     tuple((tile, matrix.tobytes()) for tile, matrix in shadow_plan.tiles),
                     tuple((tuple(matrix), tuple(id(batch) for batch in batches)) for matrix, batches, *_ in objects))
        if signature == self.signature:
            return
        self.signature = None
        shape = shadow_plan.atlas_shape
        if self.texture is None or (self.texture.width, self.texture.height) != shape:
            self.texture = gpu.types.GPUTexture(shape, format="DEPTH_COMPONENT32F")
            self.framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.texture)
        shader = shader_cache.get_fixed_shader(("shadow",), shadow_calls, "shadow map")
        with self.framebuffer.bind():
            self.framebuffer.clear(depth=1.0)
            gpu.state.depth_test_set("LESS_EQUAL")
            gpu.state.depth_mask_set(True)
            gpu.state.face_culling_set("NONE")
            gpu.state.color_mask_set(False, False, False, False)
            shader.bind()
            corners = _object_corners(objects)
            for tile, matrix in shadow_plan.tiles:
                x, y = shadow_plan.tile_origin(tile)
                gpu.state.viewport_set(x, y, shadow_plan.size, shadow_plan.size)
                shader.uniform_float("tile_matrix", np.asarray(matrix, np.float32).T.ravel().tolist())
                for index in np.nonzero(shadow_maps.in_tile(matrix, corners))[0]:
                    model_matrix, batches = objects[index][:2]
                    shader.uniform_float("model_matrix", model_matrix)
                    for batch in batches:
                        batch.draw(shader)
            gpu.state.color_mask_set(True, True, True, True)
            gpu.state.depth_test_set("NONE")
            gpu.state.depth_mask_set(False)
        self.signature = signature
        self.draw_count += 1

    def read(self):
        """(H, W) float32 window depths, row 0 at the bottom (the tests' mirror reads them)."""
        # through a list: np.asarray of a multi-dimensional gpu Buffer has the wrong strides (renderer.read)
        return np.asarray(self.texture.read().to_list(), np.float32).reshape(self.texture.height, self.texture.width)
