"""Batch render a .blend with the SG-PRT engine through the pip `bpy` module.

    python -m sg_prt_addon.render scene.blend -o out.png [--width 512 --height 512] [--frame 12]

With a Blender binary and the extension installed, the same render is
`blender -b scene.blend -E SG_PRT -f 1`.
"""
import argparse
import sys
import time
from pathlib import Path

ENGINE_ID = "SG_PRT"


class StageClock:
    """Prints one progress line per stage with its duration; keeps the figures for reports."""

    def __init__(self, stream=sys.stdout):
        self.stream = stream
        self.durations = {}

    def run(self, name, function, *args, **kwargs):
        start = time.perf_counter()
        result = function(*args, **kwargs)
        self.durations[name] = time.perf_counter() - start
        print(f"[sg-prt] {name}: {self.durations[name]:.2f} s", file=self.stream, flush=True)
        return result


def open_blend(path):
    import bpy
    if not Path(path).is_file():
        raise FileNotFoundError(f"no such .blend file: {path}")
    bpy.ops.wm.open_mainfile(filepath=str(path))
    return bpy.context.scene


def ensure_registered():
    """Register the add-on once per process (the pip module has no add-on preferences)."""
    import bpy

    import sg_prt_addon
    if not hasattr(bpy.types.Material, "sgprt"):
        sg_prt_addon.register()


def render_to_file(scene, output, width=None, height=None, frame=None):
    import bpy
    if frame is not None:
        scene.frame_set(int(frame))
    scene.render.engine = ENGINE_ID
    if width:
        scene.render.resolution_x = width
    if height:
        scene.render.resolution_y = height
    scene.render.resolution_percentage = 100
    output = Path(output).resolve()
    output.parent.mkdir(parents=True, exist_ok=True)
    scene.render.image_settings.file_format = "OPEN_EXR" if output.suffix.lower() == ".exr" else "PNG"
    scene.render.filepath = str(output)
    bpy.ops.render.render(write_still=True)
    if not output.is_file():
        raise RuntimeError(f"the render did not write {output}; see the messages above")
    return output


def read_float_image(path):
    """(H, W, 3) float32 pixels of an image file (an EXR keeps linear values), row 0 at the top."""
    import bpy
    import numpy as np

    image = bpy.data.images.load(str(path))
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)[::-1, :, :3]


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m sg_prt_addon.render", description=__doc__.splitlines()[0])
    parser.add_argument("blend", help=".blend file to render")
    parser.add_argument("-o", "--output", required=True, help="output image (.png or .exr)")
    parser.add_argument("--width", type=int, help="override the scene's resolution")
    parser.add_argument("--height", type=int, help="override the scene's resolution")
    parser.add_argument("--frame", type=int, help="the frame to render (default: the scene's current frame)")
    arguments = parser.parse_args(argv)

    clock = StageClock()
    clock.run("register add-on", ensure_registered)
    scene = clock.run("open scene", open_blend, arguments.blend)
    output = clock.run("render", render_to_file, scene, arguments.output, arguments.width, arguments.height,
                       arguments.frame)
    print(f"[sg-prt] wrote {output}", flush=True)
    return clock.durations


def exit_process(status):
    """Exit with ``status``.  The pip bpy 4.2 module segfaults at interpreter exit once a
    RenderEngine was registered (4.3+ exits cleanly), so there the process ends at once."""
    import bpy
    sys.stdout.flush()
    sys.stderr.flush()
    if bpy.app.version < (4, 3, 0):
        import os
        os._exit(status)
    sys.exit(status)


if __name__ == "__main__":
    try:
        main()
    except (FileNotFoundError, RuntimeError) as error:
        print(f"python -m sg_prt_addon.render: error: {error}", file=sys.stderr)
        exit_process(1)
    exit_process(0)
