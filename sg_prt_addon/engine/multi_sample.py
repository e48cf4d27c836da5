"""Render Samples on the GPU: the frames' passes summed in float targets and read back once.

Every pixel sampled: jittered frames, each pixel adding the frame's pixels around it weighted by the pixel filter
(engine/pixel_filter.py frame_weights).  Edges Only: a frame shaded at the pixels' centres, the mask of its edges
(engine/edge_pixels.frag.glsl; mirror anti_aliasing.edge_pixels), and each tile of the image that holds an edge
drawn grid_side times larger, with an apron of the pixels the filter reaches around it, shading only the edge
pixels and their neighbours within that reach (the others fail a near-plane depth), then each edge pixel the
filter-weighted sum of the samples around it (engine/add_edge_tile.frag.glsl): one pass of the objects' vertices
a tile instead of one a sample.  Runs where the `gpu` module works.
"""
import numpy as np

from ..techniques import shader_sources
from . import shader_cache

PASSES = shader_sources.output_names(False)     # ("combined", "diffuse", "specular"): the final render's targets
MAX_TILE_PIXELS = 2048      # side of a supersampled tile's targets (3 RGBA32F + depth: 208 MB at 2048)


def tile_side(grid_side, width, height, max_side=MAX_TILE_PIXELS, reach=0):
    """Image pixels a side of Edges Only's tiles: their supersampled targets, the apron of ``reach`` pixels each
    side included, at most MAX_TILE_PIXELS and max_side (the GPU's) a side, and no larger than the image needs."""
    return max(1, min(min(MAX_TILE_PIXELS, max_side) // grid_side - 2 * reach, max(width, height)))


def _frame_samplers():
    return [("sampler", (index, "FLOAT_2D", "frame_" + name)) for index, name in enumerate(PASSES)]


def _pass_outputs():
    return [("fragment_out", (index, "VEC4", "out_" + name)) for index, name in enumerate(PASSES)]


def edge_pixels_calls():
    """The edges of the centred frame and the sums' first values (engine/edge_pixels.frag.glsl)."""
    calls = shader_sources.full_screen_calls("sgprt_edge_pixels_interface", {})
    calls += [("push_constant", ("FLOAT", "edge_threshold")), ("push_constant", ("FLOAT", "edge_floor"))]
    calls += _frame_samplers() + _pass_outputs()
    calls += [("fragment_out", (len(PASSES), "VEC4", "out_mask")),
              ("fragment_source", (shader_sources.engine_source("edge_pixels.frag.glsl"),))]
    return calls


def pixel_mask_calls():
    """Near-plane depth over a supersampled tile's pixels that the mask leaves out (engine/pixel_mask.frag.glsl)."""
    calls = shader_sources.full_screen_calls("sgprt_pixel_mask_interface", {"FULL_SCREEN_DEPTH": "-1.0"})
    calls += [("push_constant", ("IVEC2", "mask_origin")), ("push_constant", ("INT", "mask_scale")),
              ("push_constant", ("INT", "mask_reach")),
              ("sampler", (0, "FLOAT_2D", "pixel_mask")), ("fragment_out", (0, "VEC4", "out_unused")),
              ("fragment_source", (shader_sources.engine_source("pixel_mask.frag.glsl"),))]
    return calls


# Blender 5.3 binds a full-screen pass's fourth sampler to its first one as well unless the pass declares a
# uniform block (measured: the first read the fourth's texture); the passes of four samplers or more declare the
# scene block, and bind it.
SCENE_BLOCK = ("uniform_buf", (0, "SceneData", "scene"))


def add_frame_calls():
    """A jittered frame's passes, weighted by the pixel filter, into the sums (engine/add_frame.frag.glsl)."""
    calls = shader_sources.full_screen_calls("sgprt_add_frame_interface", {}) + [SCENE_BLOCK]
    calls += _frame_samplers() + [("sampler", (len(PASSES), "FLOAT_2D", "frame_weights"))] + _pass_outputs()
    calls.append(("fragment_source", (shader_sources.engine_source("add_frame.frag.glsl"),)))
    return calls


def add_edge_tile_calls():
    """An edge tile's samples, weighted by the pixel filter, into the sums at the mask's pixels
    (engine/add_edge_tile.frag.glsl)."""
    calls = shader_sources.full_screen_calls("sgprt_add_edge_tile_interface", {}) + [SCENE_BLOCK]
    calls += [("push_constant", ("IVEC2", "tile_origin")), ("push_constant", ("INT", "grid_side"))]
    calls += _frame_samplers()
    calls += [("sampler", (len(PASSES), "FLOAT_2D", "pixel_mask")),
              ("sampler", (len(PASSES) + 1, "FLOAT_2D", "filter_weights"))]
    calls += _pass_outputs()
    calls.append(("fragment_source", (shader_sources.engine_source("add_edge_tile.frag.glsl"),)))
    return calls


def _weights_texture(rows):
    """An R32F texture of (rows, columns) weights."""
    import gpu

    values = np.ascontiguousarray(rows, np.float32)
    return gpu.types.GPUTexture((values.shape[1], values.shape[0]), format="R32F",
                                data=gpu.types.Buffer("FLOAT", values.size, values.ravel().tolist()))


class FrameSums:
    """The sums of a final render's frames (one RGBA32F target a pass), the mask of Edges Only's pixels and
    its supersampled tile.  start() then add() after each jittered frame; or start_at_edges() and
    set_filter_weights() then draw_edge_tile() for each tile of anti_aliasing.edge_tiles; then read()."""

    def __init__(self):
        self.size = None
        self.sums = []                  # GPUTexture a pass, in PASSES' order
        self.mask = None                # GPUTexture R32F: 1 at the pixels Edges Only samples
        self.sums_framebuffer = None
        self.edges_framebuffer = None   # the sums and the mask: written by the edge pass
        self.masked = False             # whether the sums since start are those of start_at_edges
        self.tile_size = None
        self.tile_targets = []          # the supersampled tile's GPUTextures, in PASSES' order
        self.tile_depth = None
        self.tile_framebuffer = None
        self.filter_weights = None      # GPUTexture R32F (n, 1): the pixel filter's weights along an axis
        self.filter_weights_values = None

    def _ensure(self, width, height):
        import gpu

        if self.size == (width, height):
            return
        self.sums = [gpu.types.GPUTexture((width, height), format="RGBA32F") for _ in PASSES]
        self.mask = gpu.types.GPUTexture((width, height), format="R32F")
        self.sums_framebuffer = gpu.types.GPUFrameBuffer(color_slots=self.sums)
        self.edges_framebuffer = gpu.types.GPUFrameBuffer(color_slots=self.sums + [self.mask])
        self.size = (width, height)

    def _ensure_tile(self, side):
        import gpu

        if self.tile_size == side:
            return
        self.tile_targets = [gpu.types.GPUTexture((side, side), format="RGBA32F") for _ in PASSES]
        # kept here: a framebuffer does not keep its attachments alive
        self.tile_depth = gpu.types.GPUTexture((side, side), format="DEPTH_COMPONENT32F")
        self.tile_framebuffer = gpu.types.GPUFrameBuffer(depth_slot=self.tile_depth, color_slots=self.tile_targets)
        self.tile_size = side

    def start(self, width, height):
        """Sums of 0 over every pixel: each jittered frame shades the whole image."""
        self._ensure(width, height)
        with self.sums_framebuffer.bind():
            self.sums_framebuffer.clear(color=(0.0, 0.0, 0.0, 0.0))
        self.masked = False

    def start_at_edges(self, renderer, threshold, floor):
        """After renderer drew the frame shaded at the pixels' centres: the mask of its edges
        (anti_aliasing.edge_pixels(frame, threshold, floor)), and the sums 0 there and that frame elsewhere."""
        import gpu

        width, height = renderer.size
        self._ensure(width, height)
        shader = shader_cache.get_fixed_shader(("edge_pixels",), edge_pixels_calls, "edge pixels")
        with self.edges_framebuffer.bind():
            gpu.state.depth_test_set("NONE")
            gpu.state.blend_set("NONE")
            shader.bind()
            shader.uniform_float("edge_threshold", float(threshold))
            shader.uniform_float("edge_floor", float(floor))
            for name, texture in zip(PASSES, renderer.targets):
                shader.uniform_sampler("frame_" + name, texture)
            renderer.full_screen_batch(shader, "edge_pixels").draw(shader)
        self.masked = True

    def set_filter_weights(self, weights):
        """The pixel filter's weights along an axis for draw_edge_tile (pixel_filter.grid_weights)."""
        values = [float(value) for value in weights]
        if self.filter_weights_values == values:
            return
        self.filter_weights = _weights_texture(np.asarray(values, np.float32)[None, :])
        self.filter_weights_values = values

    def draw_edge_tile(self, renderer, state, tile_camera, origin, tile, grid_side, reach, background_alpha):
        """The tile x tile image pixels from `origin` (x right, y up) and an apron of `reach` pixels around them
        drawn grid_side times larger by tile_camera (anti_aliasing.tile_projection of the tile and its apron),
        shading only the pixels of the edge mask and those within `reach` of one; then each edge pixel of the
        tile the sum of its and its neighbours' samples weighted by set_filter_weights' weights, into the sums
        (which hold 0 there: start_at_edges)."""
        import gpu

        self._ensure_tile((tile + 2 * reach) * grid_side)
        shader = shader_cache.get_fixed_shader(("pixel_mask",), pixel_mask_calls, "pixel mask")

        def mask_pixels():
            # after the depth of the surfaces: the near plane over the pixels left out
            gpu.state.depth_test_set("ALWAYS")
            gpu.state.depth_mask_set(True)
            gpu.state.color_mask_set(False, False, False, False)
            shader.bind()
            shader.uniform_int("mask_origin", (int(origin[0]) - reach, int(origin[1]) - reach))
            shader.uniform_int("mask_scale", int(grid_side))
            shader.uniform_int("mask_reach", int(reach))
            shader.uniform_sampler("pixel_mask", self.mask)
            renderer.full_screen_batch(shader, "pixel_mask").draw(shader)
            gpu.state.color_mask_set(True, True, True, True)
            gpu.state.depth_test_set("LESS_EQUAL")

        renderer.draw(state, tile_camera, background_alpha=background_alpha, framebuffer=self.tile_framebuffer,
                      before_shading=mask_pixels)
        shader = shader_cache.get_fixed_shader(("add_edge_tile",), add_edge_tile_calls, "add edge tile")
        with self.sums_framebuffer.bind():
            gpu.state.viewport_set(int(origin[0]), int(origin[1]), int(tile), int(tile))
            gpu.state.depth_test_set("NONE")
            gpu.state.blend_set("ADDITIVE_PREMULT")
            shader.bind()
            shader.uniform_int("tile_origin", tuple(int(v) for v in origin))
            shader.uniform_int("grid_side", int(grid_side))
            for name, texture in zip(PASSES, self.tile_targets):
                shader.uniform_sampler("frame_" + name, texture)
            shader.uniform_sampler("pixel_mask", self.mask)
            shader.uniform_sampler("filter_weights", self.filter_weights)
            shader.uniform_block("scene", renderer.scene_buffer)
            renderer.full_screen_batch(shader, "add_edge_tile").draw(shader)
            gpu.state.blend_set("NONE")
            gpu.state.viewport_set(0, 0, *self.size)

    def add(self, renderer, weights):
        """Add the renderer's whole frame into the sums, weighted by the pixel filter: ``weights`` (2, 2 reach + 1),
        one frame's pixel_filter.frame_weights."""
        import gpu

        frame_weights = _weights_texture(weights)
        shader = shader_cache.get_fixed_shader(("add_frame",), add_frame_calls, "add frame")
        with self.sums_framebuffer.bind():
            gpu.state.depth_test_set("NONE")
            gpu.state.blend_set("ADDITIVE_PREMULT")
            shader.bind()
            for name, texture in zip(PASSES, renderer.targets):
                shader.uniform_sampler("frame_" + name, texture)
            shader.uniform_sampler("frame_weights", frame_weights)
            shader.uniform_block("scene", renderer.scene_buffer)
            renderer.full_screen_batch(shader, "add_frame").draw(shader)
            gpu.state.blend_set("NONE")

    def read(self):
        """name -> (H, W, 4) float32 of each pass's sum, row 0 at the bottom."""
        return {name: self._read(self.sums_framebuffer, slot, 4) for slot, name in enumerate(PASSES)}

    def read_mask(self):
        """(H, W) bool of the pixels sampled (every pixel, unless started at edges), row 0 at the bottom."""
        if not self.masked:
            return np.ones(self.size[::-1], bool)
        return self._read(self.edges_framebuffer, len(PASSES), 1)[..., 0] > 0.5

    def _read(self, framebuffer, slot, channels):
        import gpu

        width, height = self.size
        out = np.empty((height, width, channels), np.float32)
        with framebuffer.bind():
            # our own array: np.asarray of read_color's multi-dimensional Buffer has wrong strides
            framebuffer.read_color(0, 0, width, height, channels, slot, "FLOAT",
                                   data=gpu.types.Buffer("FLOAT", (height, width, channels), out))
        return out
