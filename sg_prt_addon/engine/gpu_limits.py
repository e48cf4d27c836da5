"""The driver's texture limits, asked of Blender's `gpu` module once a process: every texture and target the
engine makes is sized within them (llvmpipe and most desktop GPUs allow 16,384 texels a side, some 8,192).

``SG_PRT_MAX_TEXTURE_SIZE`` lowers the side limit below the driver's, to check a scene against a smaller GPU
(a farm's older cards) on this one; it never raises it.
"""
import os

LIMIT_VARIABLE = "SG_PRT_MAX_TEXTURE_SIZE"
SMALLEST_SIDE = 1024           # OpenGL 3.3's guaranteed side: a lower setting is read as this

_driver_side = None


def driver_texture_size():
    """The driver's largest 2-D texture side (GL_MAX_TEXTURE_SIZE); needs a GPU context."""
    global _driver_side
    if _driver_side is None:
        import gpu
        _driver_side = int(gpu.capabilities.max_texture_size_get())
    return _driver_side


def max_texture_size():
    """The largest side of a texture or target the engine makes: the driver's, or less where
    SG_PRT_MAX_TEXTURE_SIZE says so."""
    side = driver_texture_size()
    forced = os.environ.get(LIMIT_VARIABLE, "").strip()
    if forced:
        try:
            side = min(side, max(SMALLEST_SIDE, int(forced)))
        except ValueError:
            pass            # not a number: the driver's
    return side
