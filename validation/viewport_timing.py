"""The viewport's redraw timed as view_draw runs it, less the window (tests and benchmarks)."""
import time

from sg_prt_addon.engine.render_engine import ViewportFrame


def time_viewport_redraws(state, camera, width, height, count, edit=None):
    """Seconds of a new viewport's first draw and of `count` redraws, each one the ViewportFrame update
    plus the blit of its image into a target of the region's size (one pixel read back, so the GPU has
    finished): view_draw's work minus the window.  edit(state), if given, runs before every redraw
    (nothing changes without it).  Returns (first, [redraw seconds], scene draws, the image)."""
    import gpu
    from gpu_extras.presets import draw_texture_2d as preset_draw_texture_2d
    from mathutils import Matrix

    state.mark_all_dirty()                 # a new viewport uploads everything
    frame = ViewportFrame()
    offscreen = gpu.types.GPUOffScreen(width, height, format="RGBA16F")
    times = []
    try:
        for index in range(count + 1):
            if index and edit is not None:
                edit(state)
            start = time.perf_counter()
            frame.update(state, camera, width, height)
            with offscreen.bind(), gpu.matrix.push_pop(), gpu.matrix.push_pop_projection():
                gpu.matrix.load_identity()
                gpu.matrix.load_projection_matrix(Matrix.Identity(4))
                gpu.state.blend_set("ALPHA_PREMULT")
                preset_draw_texture_2d(frame.texture, (-1.0, -1.0), 2.0, 2.0)    # the whole target
                gpu.state.blend_set("NONE")
                gpu.state.active_framebuffer_get().read_color(0, 0, 1, 1, 4, 0, "FLOAT")
            times.append(time.perf_counter() - start)
        image = frame.renderer.read_output("combined")
    finally:
        offscreen.free()
    return times[0], times[1:], frame.draws, image
