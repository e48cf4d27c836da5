"""Sub-pixel offsets of the frames a final render averages (Render Samples), and the projection moved by
one: anti-aliasing with a 1-pixel box filter; and the footprint each frame's shading averages its
specular over (Specular Anti-Aliasing).  Pixels: x to the right, y DOWN, as validation/camera.py."""
import numpy as np


def pixel_jitter(samples):
    """(samples, 2) sub-pixel offsets from the pixel centre, in (-0.5, 0.5) pixels: the centres of an
    m x m grid when samples = m^2 (then the average of the frames equals rendering m times larger and
    box-filtering down), else a rank-1 (Fibonacci) lattice, k -> ((k + 1/2) / N, (a k mod N + 1/2) / N)
    with a near N / golden ratio and coprime to N: each axis takes every one of N strata once, so the
    offsets average to the centre exactly.  One sample: the centre itself."""
    samples = max(int(samples), 1)
    side = int(round(np.sqrt(samples)))
    if side * side == samples:
        grid = (np.arange(side) + 0.5) / side - 0.5
        x, y = np.meshgrid(grid, grid)
        return np.stack([x.ravel(), y.ravel()], axis=1)
    step = max(int(round(samples * 0.6180339887498949)), 1)
    while np.gcd(step, samples) != 1:
        step += 1
    k = np.arange(samples)
    return np.stack([(k + 0.5) / samples, (step * k % samples + 0.5) / samples], axis=1) - 0.5


def jittered_projection(projection, offset, width, height):
    """The projection matrix moved by ``offset`` pixels (x right, y DOWN as in this module): clip x and y
    shifted by 2 offset / size times w, so every NDC point moves by that many pixels."""
    shift = np.eye(4)
    shift[0, 3] = 2.0 * float(offset[0]) / float(width)
    shift[1, 3] = -2.0 * float(offset[1]) / float(height)
    return shift @ np.asarray(projection, np.float64).reshape(4, 4)


def specular_footprint(samples, enabled=True):
    """The side, in pixels, of the square each pixel of one frame shades its specular over (the scene
    block's shading_footprint, sg_shading.glsl shade_footprint): the whole pixel for one frame, a cell
    of the 1 / sqrt(samples) grid for each of ``samples`` jittered frames, 0 (the centre alone) when
    Specular Anti-Aliasing is off."""
    return 1.0 / float(np.sqrt(max(int(samples), 1))) if enabled else 0.0
