"""Sub-pixel offsets of the frames a final render averages (Render Samples): strata of the pixel, whose samples
the pixel filter weighs (engine/pixel_filter.py frame_weights); the projection moved by one; and the footprint
each frame's shading averages its specular and reads its textures over (Specular Anti-Aliasing, the textures' mip
level).  Pixels: x to the right, y DOWN, as validation/camera.py.

Edges Only (engine/multi_sample.py draws it): which pixels of a frame shaded at the pixels' centres are
edges (edge_pixels, the mirror of engine/edge_pixels.frag.glsl), the grid of samples an edge pixel takes,
the tiles holding edges and the projection that draws a tile larger (there pixels count x right, y UP, as
the read-back mask's rows)."""
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


def coverage_offsets(samples):
    """(samples,) offsets of the dithered coverage's thresholds (surface_io.glsl surface_coverage), one a jittered
    frame: k times the golden ratio, mod 1.  A pixel keeps the surface in the frames whose thresholds fall below
    its alpha, a run of these offsets; k / samples would make that run adjacent rows of pixel_jitter's grid, whose
    pixel-filter weights differ, where the golden ratio spreads it over the grid."""
    return np.mod(np.arange(max(int(samples), 1)) * 0.6180339887498949, 1.0)


def coverage_threshold(x, y, offset):
    """The threshold of pixel (x, y) (integers) in a frame of coverage offset `offset`: interleaved gradient
    noise moved by the offset (mirror of surface_io.glsl surface_coverage; a sample keeps the surface where
    its alpha exceeds it)."""
    noise = np.mod(52.9829189 * np.mod(0.06711056 * np.asarray(x, np.float64) + 0.00583715 * np.asarray(y), 1.0),
                   1.0)
    return np.mod(noise + offset, 1.0)


def jittered_projection(projection, offset, width, height):
    """The projection matrix moved by ``offset`` pixels (x right, y DOWN as in this module): clip x and y
    shifted by 2 offset / size times w, so every NDC point moves by that many pixels."""
    shift = np.eye(4)
    shift[0, 3] = 2.0 * float(offset[0]) / float(width)
    shift[1, 3] = -2.0 * float(offset[1]) / float(height)
    return shift @ np.asarray(projection, np.float64).reshape(4, 4)


def specular_footprint(samples, enabled=True, filter_side=1.0):
    """The side, in pixels, of the square each pixel of one frame shades its specular over (the scene
    block's shading_footprint.x, sg_shading.glsl shade_footprint): for one frame, the square of the pixel
    filter's variance (``filter_side``: pixel_filter.PixelFilter.footprint_side, 1 for a 1-pixel box); a cell
    of the 1 / sqrt(samples) grid for each of ``samples`` jittered frames; 0 (the centre alone) when
    Specular Anti-Aliasing is off."""
    if not enabled:
        return 0.0
    samples = max(int(samples), 1)
    return float(filter_side) if samples == 1 else 1.0 / float(np.sqrt(samples))


def texture_footprint(samples):
    """The side, in pixels, of the square a pixel's material textures are read over (the scene block's
    shading_footprint.z, surface_io.glsl material_texture picks their mip level by it): the pixel for one frame,
    a cell of the 1 / sqrt(samples) grid for each of ``samples`` jittered frames.  Not the filter's square: a
    trilinear level is already wider than the box of its footprint (measured on suzanne_courtyard's tiles, Edges
    Only against 16 samples of every pixel: 0.0042 at 1 pixel, 0.0129 at Blackman-Harris 1.5's 1.44)."""
    return 1.0 / float(np.sqrt(max(int(samples), 1)))


# Render Samples' Edges Only: a pixel pair differs when a channel differs by more than the threshold times the
# brighter pixel's largest channel plus EDGE_FLOOR of the display's white (at the view's exposure): a dark
# pixel's small differences, which neither a relative error nor the eye sees, stay out.
EDGE_FLOOR = 0.03


def edge_pixels(frame, threshold, floor=EDGE_FLOOR):
    """(H, W) bool: the pixels of a frame shaded at the pixels' centres ((H, W, 4) RGBA) whose colour or alpha
    differs from one of their 8 neighbours' (both pixels of such a pair), where more samples change the pixel:
    silhouettes, shadow, texture and highlight edges.  Colours differ when a channel's difference passes
    ``threshold`` times (the brighter pixel's largest channel + ``floor``), alphas when theirs passes
    ``threshold``.  A non-finite pixel is an edge, and compared as black.  (Mirror of
    engine/edge_pixels.frag.glsl.)"""
    frame = np.asarray(frame, np.float32)
    finite = np.isfinite(frame).all(axis=-1)
    frame = np.where(finite[..., None], frame, np.float32(0.0))
    colour, alpha = frame[..., :3], frame[..., 3]
    brightness = colour.max(axis=-1)
    edges = ~finite
    height, width = brightness.shape
    # each neighbour pair once: right, up, and the two diagonals; a pair that differs marks both
    for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
        a = (slice(0, height - dy), slice(max(-dx, 0), width - max(dx, 0)))
        b = (slice(dy, height), slice(max(dx, 0), width - max(-dx, 0)))
        difference = np.abs(colour[a] - colour[b]).max(axis=-1)
        differs = (difference > np.float32(threshold) * (np.maximum(brightness[a], brightness[b]) + np.float32(floor))) \
            | (np.abs(alpha[a] - alpha[b]) > np.float32(threshold))
        edges[a] |= differs
        edges[b] |= differs
    return edges


def grid_side(samples):
    """Edges Only's grid: side x side samples an edge pixel (the smallest square grid of at least ``samples``),
    at the centres of its cells, as pixel_jitter(side ** 2)."""
    return max(int(np.ceil(np.sqrt(max(int(samples), 1)) - 1e-9)), 1)


def edge_tiles(edges, tile):
    """[(x0, y0)]: the lower-left pixels (x right, y UP: the mask's rows from the bottom) of the tile x tile
    squares of the image that hold an edge pixel of ``edges`` ((H, W) bool)."""
    height, width = edges.shape
    rows, columns = -(-height // tile), -(-width // tile)
    padded = np.zeros((rows * tile, columns * tile), bool)
    padded[:height, :width] = edges
    holds = padded.reshape(rows, tile, columns, tile).any(axis=(1, 3))
    return [(int(column) * tile, int(row) * tile) for row, column in zip(*np.nonzero(holds))]


def tile_projection(projection, origin, tile, width, height):
    """The projection matrix of the tile x tile pixels from ``origin`` (x right, y UP) of a width x height
    image: the tile's part of the view made the whole of clip space, so a framebuffer `side` times the tile's
    size has its pixel centres at the centres of each image pixel's side x side grid cells."""
    x0, y0 = origin
    scale = np.array([width / tile, height / tile])
    # the tile's centre in the image's NDC, moved to 0 and the tile's half-size scaled to 1
    centre = np.array([2.0 * (x0 + 0.5 * tile) / width - 1.0, 2.0 * (y0 + 0.5 * tile) / height - 1.0])
    crop = np.eye(4)
    crop[0, 0], crop[1, 1] = scale
    crop[:2, 3] = -centre * scale
    return crop @ np.asarray(projection, np.float64).reshape(4, 4)


def footprint_grid_limit(grid_side):
    """The most specular samples a side of Specular Anti-Aliasing's footprint (CameraExport.footprint_grid_limit)
    in each sample of a grid_side x grid_side grid: 8 a pixel's side in all, between 1 and the shader's 4.
    Measured against Cycles (the truth suite at 128 px, 16 samples at the edges): a 2 x 2 grid in each of 4 x 4
    samples gives the 4 x 4 grid's error (ggx030_point 0.052, ggx010_hdri 0.148) in half the time on
    ggx010_hdri; none (the centre) doubles ggx030_point's (0.112)."""
    return int(min(max(np.ceil(8.0 / max(int(grid_side), 1)), 1), 4))
