"""Bad input met (and repaired) while exporting, sent to the list of the thread that collects it."""
import threading

import numpy as np

# --------------------------------------------------------------------------- bad input

# Bad input met (and repaired) while exporting: NaN/Inf texels, zero-length normals, textures or UV
# tangents on meshes without UVs.  The messages go to the list given to collect_warnings() in the
# calling thread: SceneState.sync() gives its SceneState.warnings, so the texture reads of the upload
# that follows in the same render add to it too (the final render and the viewport run in different
# threads, each with its own list).
_warning_target = threading.local()


def collect_warnings(messages):
    """Send this thread's export warnings to the list `messages` (returned); None stops collecting."""
    _warning_target.messages = messages
    return messages


def warn(message):
    messages = getattr(_warning_target, "messages", None)
    if messages is not None and message not in messages:
        messages.append(message)


# Texel values beyond this magnitude are clamped to it: a few float32 texels near 3e38 summed by the
# environment prefilter (or scaled by the lighting) overflow to Inf.
MAX_TEXEL_VALUE = 1e30


def finite_texels(pixels, what):
    """pixels (..., C) with every texel holding a NaN or +-Inf set to 0 (all channels) and values
    beyond +-MAX_TEXEL_VALUE clamped (a copy only when needed), with a warning each:
    `what: N NaN/Inf texels replaced by 0`, `what: N texels beyond 1e+30 clamped`."""
    if pixels.size == 0 or (pixels.max() <= MAX_TEXEL_VALUE and pixels.min() >= -MAX_TEXEL_VALUE):
        return pixels                                        # (a NaN fails both comparisons)
    bad = ~np.isfinite(pixels).all(axis=-1)
    huge = ~bad & (np.abs(pixels) > MAX_TEXEL_VALUE).any(axis=-1)
    pixels = np.where(bad[..., None], np.float32(0.0), pixels)
    pixels = np.clip(pixels, -MAX_TEXEL_VALUE, MAX_TEXEL_VALUE).astype(np.float32)
    if bad.any():
        warn(f"{what}: {int(np.count_nonzero(bad))} NaN/Inf texels replaced by 0")
    if huge.any():
        warn(f"{what}: {int(np.count_nonzero(huge))} texels beyond {MAX_TEXEL_VALUE:g} clamped")
    return pixels
