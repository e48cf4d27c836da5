"""The SG-PRT RenderEngine: final renders and the viewport share scene_state + renderer."""
import dataclasses
import time
import traceback

import bpy
import numpy as np

from ..blender import export, properties
from ..techniques.shader_sources import GBUFFER_OUTPUTS, MAX_POINT_LIGHTS, MAX_SUNS
from . import anti_aliasing, gpu_limits, multi_sample, pixel_filter, scene_state
from . import renderer as renderer_module
from .shader_cache import ShaderCompileError

# Debug hooks for tests and benchmarks (no UI): when `capture_gbuffer` is True the next
# final render also writes the shading inputs; every final render leaves its float
# passes, the G-buffer and the SceneState in `last_render`.
# `after_frame(depsgraph, state, renderer, camera)` runs inside the render's GPU context after the
# frame (its result: last_render["after_frame"]), e.g. to time the viewport's redraws or re-uploads;
# `test_break()`, when set, stands in for the RenderEngine's (Esc), which Python cannot override.
debug = {"capture_gbuffer": False, "environment_layer_size": None, "timed_redraws": 0, "after_frame": None,
         "test_break": None}
last_render = {}


class SGPRT_RenderEngine(bpy.types.RenderEngine):
    bl_idname = "SG_PRT"
    bl_label = "SG-PRT"
    bl_use_gpu_context = True
    bl_use_preview = False
    bl_use_eevee_viewport = False
    bl_use_shading_nodes_custom = False

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.viewport_state = None
        self.viewport_frame = None
        self.viewport_error = None

    # ----------------------------------------------------------------- passes

    def update_render_passes(self, scene=None, renderlayer=None):
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        self.register_pass(scene, renderlayer, "Diffuse", 3, "RGB", "COLOR")
        self.register_pass(scene, renderlayer, "Specular", 3, "RGB", "COLOR")

    # ----------------------------------------------------------------- final render

    def render(self, depsgraph):
        scene = depsgraph.scene
        scale = scene.render.resolution_percentage / 100.0
        width = int(scene.render.resolution_x * scale)
        height = int(scene.render.resolution_y * scale)
        if scene.camera is None:
            self.report({"ERROR"}, "SG-PRT: the scene has no camera")
            return
        if getattr(scene.camera.data, "type", None) == "PANO":
            self.report({"ERROR"}, f"SG-PRT: camera '{scene.camera.name}' is panoramic; SG-PRT renders perspective "
                                   "and orthographic cameras only (switch its Type, or render it with Cycles)")
            last_render.clear()
            last_render["error"] = "panoramic camera"
            return
        side = gpu_limits.max_texture_size()
        if max(width, height) > side:
            self.report({"ERROR"}, f"SG-PRT: the render is {width} x {height} pixels, over this GPU's limit of "
                                   f"{side} a side: lower the Resolution or its %")
            last_render.clear()
            last_render["error"] = "render size over the GPU's limit"
            return
        self.update_stats("", "SG-PRT: exporting the scene, drawing")
        try:
            samples = 1 if debug["capture_gbuffer"] else getattr(getattr(scene, "sgprt", None), "render_samples",
                                                                  properties.DEFAULT_RENDER_SAMPLES)
            passes, state, timings = render_frame(depsgraph, width, height, gbuffer=debug["capture_gbuffer"],
                                                  samples=samples,
                                                  cancelled=debug["test_break"] or self.test_break,
                                                  progress=self.update_progress)
        except ShaderCompileError as error:
            print(error)
            # the UI gets the variant and the first located error; the console has every line quoted
            lines = str(error).split("\n")
            self.report({"ERROR"}, ": ".join(lines[:2]) if len(lines) > 1 else lines[0])
            last_render.clear()
            last_render["error"] = str(error)
            return
        except Exception as error:
            traceback.print_exc()
            self.report({"ERROR"}, f"SG-PRT render failed: {type(error).__name__}: {error}")
            last_render.clear()
            last_render["error"] = traceback.format_exc()
            return
        if timings.get("cancelled"):
            self.report({"WARNING"}, "SG-PRT: render cancelled; the image holds the samples taken until then")
        for warning in dict.fromkeys(state.warnings + state.unshadowed_warnings() + pixel_filter_warnings(scene)):
            self.report({"WARNING"}, f"SG-PRT: {warning}")
        for line in state.light_budget_warnings(MAX_POINT_LIGHTS, MAX_SUNS):
            self.report({"WARNING"}, f"SG-PRT: {line}")
        # one render() per view layer: write into the one being rendered; with a render border Blender's result
        # holds the border's pixels only (cropped or not; begin_result counts from the border's corner), so the
        # frame is cut to it
        x0, y0, x1, y1 = border_rect(scene.render, width, height)
        result = self.begin_result(0, 0, x1 - x0, y1 - y0, layer=depsgraph.view_layer.name)
        layer = result.layers[0]
        written = []
        for name in renderer_module.PASS_NAMES:
            render_pass = layer.passes.get(name)
            if render_pass is None:
                continue
            channels = render_pass.channels
            pixels = np.ascontiguousarray(passes[name][y0:y1, x0:x1, :channels]).ravel()
            if len(render_pass.rect) * channels != pixels.size:
                self.end_result(result, cancel=True)
                self.report({"ERROR"}, f"SG-PRT: the render result holds {len(render_pass.rect)} pixels, the "
                                       f"border {x1 - x0} x {y1 - y0}: nothing written")
                last_render.clear()
                last_render["error"] = "render result size mismatch"
                return
            render_pass.rect.foreach_set(pixels)
            written.append(name)
        self.end_result(result)
        last_render.clear()
        last_render.update(passes=passes, state=state, timings=timings, size=(width, height),
                           written_passes=written, after_frame=passes.pop("after_frame", None))

    # ----------------------------------------------------------------- viewport

    def view_update(self, context, depsgraph):
        if self.viewport_state is None:
            self.viewport_state = scene_state.SceneState()
            self.viewport_state.sync(depsgraph)
        else:
            self.viewport_state.update(depsgraph)

    def view_draw(self, context, depsgraph):
        import gpu

        region = context.region
        width, height = region.width, region.height
        if self.viewport_state is None:
            self.view_update(context, depsgraph)
        if self.viewport_frame is None:
            self.viewport_frame = ViewportFrame()
        region_3d = context.region_data
        camera = export.camera_from_view(region_3d.view_matrix, region_3d.window_matrix,
                                         region_3d.is_perspective)
        camera.shading_footprint = anti_aliasing.specular_footprint(
            1, specular_anti_aliasing(depsgraph.scene), scene_pixel_filter(depsgraph.scene).footprint_side())
        camera.texture_footprint = anti_aliasing.texture_footprint(1)
        try:
            self.viewport_frame.update(self.viewport_state, camera, width, height,
                                       0.0 if depsgraph.scene.render.film_transparent else 1.0)
        except ShaderCompileError as error:
            if str(error) != self.viewport_error:
                print(error)
                self.viewport_error = str(error)
            return
        border = viewport_border_rect(context, depsgraph.scene, width, height)
        if border is not None:          # the render region: the frame is shown inside it only
            gpu.state.scissor_test_set(True)
            gpu.state.scissor_set(border[0], border[1], border[2] - border[0], border[3] - border[1])
        gpu.state.blend_set("ALPHA_PREMULT")
        self.bind_display_space_shader(depsgraph.scene)
        draw_texture_2d(self.viewport_frame.texture, width, height)
        self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")
        if border is not None:
            gpu.state.scissor_test_set(False)


class ViewportFrame:
    """view_draw's work, which needs no window: the scene is drawn again only when something changed
    (the scene's dirty set, the view, the region's size, the film or the footprints the pixel filter sets);
    otherwise the last image is shown again, a texture blit (Blender redraws the viewport for overlays, cursor
    moves, UI...)."""

    def __init__(self):
        self.renderer = renderer_module.Renderer()
        self.signature = None
        self.draws = 0

    def update(self, state, camera, width, height, background_alpha=1.0):
        """Draw if needed; returns whether it drew."""
        signature = (width, height, float(background_alpha), bool(camera.is_perspective), camera.shading_footprint,
                     camera.texture_footprint,
                     np.asarray(camera.view, np.float64).tobytes(), np.asarray(camera.projection, np.float64).tobytes())
        if signature == self.signature and not state.dirty.any():
            return False
        self.signature = None           # a failed draw (shader error) is tried again on the next redraw
        self.renderer.upload(state, state.consume_dirty(), camera)
        self.renderer.ensure_targets(width, height)
        self.renderer.draw(state, camera, background_alpha=background_alpha)
        self.signature = signature
        self.draws += 1
        return True

    @property
    def texture(self):
        return self.renderer.targets[0]


def draw_texture_2d(texture, width, height):
    """Draw a texture over the region with the bound display-space shader."""
    from gpu_extras.presets import draw_texture_2d as preset
    preset(texture, (0, 0), width, height)


def border_rect(render_settings, width, height):
    """(x0, y0, x1, y1) pixels of the frame a final render writes, y from the bottom: the render border when
    it is on (Blender truncates border * size), else the whole frame."""
    if not render_settings.use_border:
        return 0, 0, width, height
    x0, x1 = int(render_settings.border_min_x * width), int(render_settings.border_max_x * width)
    y0, y1 = int(render_settings.border_min_y * height), int(render_settings.border_max_y * height)
    x0, y0 = min(max(x0, 0), width), min(max(y0, 0), height)
    return x0, y0, max(min(x1, width), x0), max(min(y1, height), y0)


def viewport_border_rect(context, scene, width, height):
    """(x0, y0, x1, y1) region pixels, y from the bottom, of a 3D view's render region (View > Render Region),
    or None without one: in camera view the scene's render border placed on the camera's frame as the view
    shows it, else the view's own region border."""
    space, region_3d = context.space_data, context.region_data
    if region_3d.view_perspective == "CAMERA":
        if not scene.render.use_border or scene.camera is None or scene.camera.type != "CAMERA":
            return None
        from bpy_extras.view3d_utils import location_3d_to_region_2d

        corners = [location_3d_to_region_2d(context.region, region_3d, scene.camera.matrix_world @ corner)
                   for corner in scene.camera.data.view_frame(scene=scene)]
        if any(corner is None for corner in corners):
            return None
        xs, ys = [corner.x for corner in corners], [corner.y for corner in corners]
        left, bottom, frame_width, frame_height = min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)
        render = scene.render
        box = (left + render.border_min_x * frame_width, bottom + render.border_min_y * frame_height,
               left + render.border_max_x * frame_width, bottom + render.border_max_y * frame_height)
    else:
        if not getattr(space, "use_render_border", False):
            return None
        box = (space.render_border_min_x * width, space.render_border_min_y * height,
               space.render_border_max_x * width, space.render_border_max_y * height)
    x0, y0 = (min(max(int(round(v)), 0), size) for v, size in zip(box[:2], (width, height)))
    x1, y1 = (min(max(int(round(v)), 0), size) for v, size in zip(box[2:], (width, height)))
    return x0, y0, max(x1, x0), max(y1, y0)


def specular_anti_aliasing(scene):
    """The scene's Specular Anti-Aliasing setting (on where the add-on's settings are absent)."""
    return bool(getattr(getattr(scene, "sgprt", None), "specular_anti_aliasing", True))


def scene_pixel_filter(scene):
    """The pixel filter of the scene's Film: its type (scene.sgprt.pixel_filter_type, Blackman-Harris where the
    add-on's settings are absent) at Blender's Filter Size (scene.render.filter_size)."""
    kind = getattr(getattr(scene, "sgprt", None), "pixel_filter_type", pixel_filter.DEFAULT_KIND)
    return pixel_filter.PixelFilter(kind, float(scene.render.filter_size))


def pixel_filter_warnings(scene):
    """What the render cannot honour of the scene's pixel filter."""
    chosen = scene_pixel_filter(scene)
    if not chosen.truncated:
        return []
    return [f"the {chosen.kind.replace('_', '-').title()} filter of Filter Size {chosen.width:g} px reaches "
            f"{chosen.full_radius:g} px from a pixel; SG-PRT cuts it at {pixel_filter.MAX_RADIUS:g} px"]


def edge_sampling(scene):
    """(Edges Only, its threshold, the difference floor) of the scene's Render Samples: the floor, in the
    scene's linear units, is EDGE_FLOOR of the display's white, which the view's exposure moves."""
    settings = getattr(scene, "sgprt", None)
    exposure = float(getattr(getattr(scene, "view_settings", None), "exposure", 0.0))
    return (bool(getattr(settings, "sample_edges_only", True)),
            float(getattr(settings, "edge_threshold", properties.DEFAULT_EDGE_THRESHOLD)),
            anti_aliasing.EDGE_FLOOR * 2.0 ** -exposure)


def _sampled_passes(scene, state, renderer, camera, samples, background_alpha, timings, cancelled, progress):
    """The passes of Render Samples > 1, summed on the GPU (engine/multi_sample.py), reconstructed with the
    scene's pixel filter.  Every pixel: `samples` frames, each with the projection moved by a sub-pixel offset
    (anti_aliasing.pixel_jitter's strata), each pixel the filter-weighted sum of the frames' pixels it reaches.
    Edges Only: a frame at the pixels' centres (its specular over the filter's footprint); where it shows an
    edge (passes["edge_pixels"]; timings["edge_pixels"]: their fraction), the filter-weighted sum of a grid_side
    x grid_side grid of samples a pixel over the pixel and the neighbours the filter reaches, drawn tile by tile
    (timings["edge_tiles"]).  cancelled() is asked between frames or tiles: when it says so (Esc), the frames so
    far, their weights made whole, or the tiles not drawn keep the centred frame (timings["cancelled"]);
    progress(fraction) is told after each."""
    width, height = renderer.size
    sums = renderer.frame_sums
    edges_only, threshold, floor = edge_sampling(scene)
    chosen_filter = scene_pixel_filter(scene)
    if not edges_only:
        sums.start(width, height)
        offsets = chosen_filter.jitter_offsets(anti_aliasing.pixel_jitter(samples))
        weights = chosen_filter.frame_weights(offsets)
        coverage_offsets = anti_aliasing.coverage_offsets(len(offsets))
        for done, offset in enumerate(offsets):
            if done and cancelled():
                timings["cancelled"] = True
                summed = sums.read()
                # the frames so far, their weights made whole
                taken = float(np.sum(weights[:done, 0].sum(axis=1) * weights[:done, 1].sum(axis=1)))
                return {name: summed[name.lower()] * np.float32(1.0 / taken) for name in renderer_module.PASS_NAMES}
            # the view-projection is in the scene block: upload it moved (the shadow maps keep the centred plan)
            frame_camera = dataclasses.replace(
                camera, projection=anti_aliasing.jittered_projection(camera.projection, offset, width, height),
                coverage_offset=float(coverage_offsets[done]))
            renderer.upload(state, state.consume_dirty(), frame_camera, shadow_camera=camera)
            renderer.draw(state, frame_camera, background_alpha=background_alpha)
            sums.add(renderer, weights[done])
            progress((done + 1) / len(offsets))
        summed = sums.read()
        return {name: summed[name.lower()] for name in renderer_module.PASS_NAMES}
    # a sample's specular footprint: the filter's at the centre, a grid cell (one pixel of a tile) in the grid
    specular_aa = camera.shading_footprint > 0.0
    centred = dataclasses.replace(
        camera, shading_footprint=anti_aliasing.specular_footprint(1, specular_aa, chosen_filter.footprint_side()),
        texture_footprint=anti_aliasing.texture_footprint(1))
    renderer.upload(state, state.consume_dirty(), centred)
    renderer.draw(state, centred, background_alpha=background_alpha)
    sums.start_at_edges(renderer, threshold, floor)
    edges = sums.read_mask()
    side = anti_aliasing.grid_side(samples)
    reach = chosen_filter.reach
    sums.set_filter_weights(chosen_filter.grid_weights(side))
    tile = multi_sample.tile_side(side, width, height, gpu_limits.max_texture_size(), reach)
    tiles = anti_aliasing.edge_tiles(edges, tile)
    cell = anti_aliasing.specular_footprint(1, specular_aa)
    drawn = 0
    for origin in tiles:
        if cancelled():
            timings["cancelled"] = True
            break
        apron_origin = (origin[0] - reach, origin[1] - reach)
        tile_camera = dataclasses.replace(
            camera, projection=anti_aliasing.tile_projection(camera.projection, apron_origin, tile + 2 * reach,
                                                             width, height),
            shading_footprint=cell, texture_footprint=1.0,
            footprint_grid_limit=anti_aliasing.footprint_grid_limit(side))
        renderer.upload(state, state.consume_dirty(), tile_camera, shadow_camera=camera)
        sums.draw_edge_tile(renderer, state, tile_camera, origin, tile, side, reach, background_alpha)
        drawn += 1
        progress(drawn / len(tiles))
    timings["edge_pixels"] = float(edges.mean())
    timings["edge_tiles"] = drawn
    summed = sums.read()
    passes = {name: summed[name.lower()] for name in renderer_module.PASS_NAMES}
    if drawn < len(tiles):      # cancelled: the tiles not drawn keep the centred frame (the renderer's targets)
        undrawn = np.zeros_like(edges)
        for x0, y0 in tiles[drawn:]:
            undrawn[y0:y0 + tile, x0:x0 + tile] = True
        undrawn &= edges
        for name in renderer_module.PASS_NAMES:
            passes[name][undrawn] = renderer.read_output(name.lower())[undrawn]
    passes["edge_pixels"] = edges        # (H, W) bool, row 0 at the bottom: for tests and benchmarks
    return passes


def render_frame(depsgraph, width, height, gbuffer=False, state=None, renderer=None, samples=1,
                 cancelled=lambda: False, progress=lambda fraction: None):
    """Export, upload, draw and read back one frame; with ``samples`` > 1 the average of that many draws,
    each with the projection moved by anti_aliasing.pixel_jitter's sub-pixel offset (anti-aliasing), at the
    edges alone with Edges Only (_sampled_passes).

    Returns (passes: name -> (H, W, 4) float32 with row 0 at the bottom, the SceneState, timings).
    """
    timings = {}
    start = time.perf_counter()
    scene = depsgraph.scene
    if state is None:
        state = scene_state.SceneState(environment_layer_size=debug.get("environment_layer_size"))
        state.sync(depsgraph)
    camera_object = scene.camera.evaluated_get(depsgraph)
    camera = export.export_camera(camera_object, depsgraph, width, height,
                                  scene.render.pixel_aspect_x, scene.render.pixel_aspect_y)
    # the G-buffer the mirrors read is shaded at the pixels' centres
    camera.shading_footprint = anti_aliasing.specular_footprint(
        samples, specular_anti_aliasing(scene) and not gbuffer, scene_pixel_filter(scene).footprint_side())
    camera.texture_footprint = anti_aliasing.texture_footprint(samples)
    timings["export"] = time.perf_counter() - start
    renderer = renderer or renderer_module.Renderer(gbuffer=gbuffer)
    start = time.perf_counter()
    renderer.upload(state, state.consume_dirty(), camera)
    renderer.ensure_targets(width, height)
    timings["upload"] = time.perf_counter() - start
    start = time.perf_counter()
    background_alpha = 0.0 if scene.render.film_transparent else 1.0
    if samples > 1:
        passes = _sampled_passes(scene, state, renderer, camera, samples, background_alpha, timings, cancelled,
                                 progress)
    else:
        renderer.draw(state, camera, background_alpha=background_alpha)
        passes = {name: renderer.read_output(name.lower()) for name in renderer_module.PASS_NAMES}
    timings["samples"] = samples
    if gbuffer:
        for name in GBUFFER_OUTPUTS:
            passes["gbuffer_" + name] = renderer.read_output(name)
        if renderer.shadow_plan is not None:        # the mirror's shadow-map lookups read the same atlas
            passes["shadow_atlas"], passes["shadow_plan"] = renderer.shadow_atlas.read(), renderer.shadow_plan
    timings["draw_and_read"] = time.perf_counter() - start
    # steady-state frame cost (shaders compiled and JIT-ed, data uploaded): draw + read the passes
    frame_times = []
    for _ in range(int(debug.get("timed_redraws") or 0)):
        start = time.perf_counter()
        renderer.upload(state, state.consume_dirty(), camera)
        renderer.draw(state, camera, background_alpha=0.0 if scene.render.film_transparent else 1.0)
        for name in renderer_module.PASS_NAMES:
            renderer.read_output(name.lower())
        frame_times.append(time.perf_counter() - start)
    if frame_times:
        timings["frames"] = frame_times
    if debug.get("after_frame") is not None:
        passes["after_frame"] = debug["after_frame"](depsgraph, state, renderer, camera)
    passes["camera"] = camera
    passes["material_ids"] = dict(renderer.material_ids)
    # what the upload could not make within the GPU's limits, said with the export's warnings
    state.warnings.extend(line for line in renderer.upload_warnings(state) if line not in state.warnings)
    return passes, state, timings
