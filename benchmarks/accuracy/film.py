"""Accuracy of what a pixel averages: the pixel filter's reconstruction (engine/pixel_filter.py), the material
textures' mip levels (spherical/texture_mips.py) with a minified normal map's spread of normals, and the dithered
coverage of a transparent surface (anti_aliasing.coverage_threshold).

References: the filtered row of an image by dense quadrature (2001 points over the filter's support); the mean
of the texels under a pixel's square footprint; the von Mises-Fisher mean length coth kappa - 1 / kappa; the
surface's alpha.
"""
import numpy as np

from sg_prt_addon.engine import anti_aliasing
from sg_prt_addon.engine.pixel_filter import PixelFilter, filter_supersampled
from sg_prt_addon.spherical import texture_mips
from sg_prt_addon.techniques.sg import sg_shading

PIXELS = 52
HARRIS = PixelFilter("BLACKMAN_HARRIS", 1.5)


def signal(x):
    """A row of an image across x (pixels): a step from 0.2 to 1 at x = 30.37 and Gaussian highlights of sigma
    0.3, 0.5 and 1 pixel, peaks 8, 5, 3: sub-pixel detail where the filter's shape matters."""
    out = np.where(x > 30.37, 1.0, 0.2)
    for centre, sigma, peak in ((10.2, 0.3, 8.0), (20.3, 0.5, 5.0), (40.7, 1.0, 3.0)):
        out = out + peak * np.exp(-0.5 * ((x - centre) / sigma) ** 2)
    return out


def _integral(values, x):
    return np.sum(0.5 * (values[..., 1:] + values[..., :-1]) * np.diff(x), axis=-1)


def exactly_filtered(pixel_filter, pixels=PIXELS):
    """Each pixel's filtered value of signal() by dense quadrature over the filter's support."""
    x = np.linspace(-pixel_filter.radius, pixel_filter.radius, 2001)
    density = pixel_filter.weight(x) / _integral(pixel_filter.weight(x), x)
    centres = np.arange(pixels) + 0.5
    return _integral(signal(centres[:, None] + x[None, :]) * density[None, :], x)


def grid_filtered(pixel_filter, side, pixels=PIXELS):
    """signal() sampled at the centres of side cells a pixel (as Edges Only's tiles), filtered down."""
    samples = (np.arange(pixels * side) + 0.5) / side
    image = np.broadcast_to(signal(samples)[None, :, None], (side, pixels * side, 1))
    return filter_supersampled(image, pixel_filter, side)[0, :, 0]


def frames_filtered(pixel_filter, samples, pixels=PIXELS):
    """signal() drawn by jittered frames at pixel_jitter's strata, each pixel the filter-weighted sum of the frames'
    pixels around it (engine/add_frame.frag.glsl), borders repeated."""
    strata = pixel_filter.jitter_offsets(anti_aliasing.pixel_jitter(samples))
    weights = pixel_filter.frame_weights(strata)
    reach = pixel_filter.reach
    out = np.zeros(pixels)
    for offset, (along_x, along_y) in zip(strata, weights):
        frame = np.pad(signal(np.arange(pixels) + 0.5 + offset[0]), reach, mode="edge")
        out += along_y.sum() * sum(weight * frame[k:k + pixels] for k, weight in enumerate(along_x))
    return out


def relative_rmse(image, reference):
    return float(np.sqrt(np.mean((image - reference) ** 2)) / np.sqrt(np.mean(reference ** 2)))


def filter_errors():
    """Relative RMSE against the exactly filtered Blackman-Harris 1.5 row, away from the borders: Edges Only's
    4 x 4 and 8 x 8 grids, 16 jittered frames, and the 1-pixel box of 16 samples."""
    inner = slice(3, PIXELS - 3)
    exact = exactly_filtered(HARRIS)[inner]
    return {"grid 4": relative_rmse(grid_filtered(HARRIS, 4)[inner], exact),
            "grid 8": relative_rmse(grid_filtered(HARRIS, 8)[inner], exact),
            "frames 16": relative_rmse(frames_filtered(HARRIS, 16)[inner], exact),
            "box 16": relative_rmse(grid_filtered(PixelFilter("BOX", 1.0), 4)[inner], exact)}


def kappa_errors(kappa=np.geomspace(1.0, 1000.0, 200)):
    """|estimated kappa / kappa - 1| of normal_spread's Banerjee estimate at the vMF mean length of each kappa."""
    r = 1 / np.tanh(kappa) - 1 / kappa
    mean = np.stack([np.zeros_like(r), np.zeros_like(r), r], axis=-1)
    return np.abs(1 / sg_shading.normal_spread(mean, np.ones_like(r), 1.0) / kappa - 1)


def mip_errors(footprint, count=4000, seed=11):
    """(trilinear, bilinear in the image) absolute errors (count,) at a footprint of that many texels, against the
    mean of the footprint x footprint texels under each pixel of a white-noise image (the hardest case for a box
    pyramid), pixel centres at every phase."""
    rng = np.random.default_rng(seed)
    image = rng.random((256, 256, 4)).astype(np.float32)
    centres = rng.uniform(footprint, 256 - footprint, (count, 2))
    uv = (centres / 256).astype(np.float32)
    filtered = texture_mips.sample(image, uv, np.full(len(uv), footprint / 256))[:, 0]
    point = texture_mips.sample(image, uv)[:, 0]
    exact = np.empty(len(uv))
    for index, (x, y) in enumerate(centres - footprint / 2):
        columns = np.arange(int(np.floor(x)), int(np.ceil(x + footprint)))
        rows = np.arange(int(np.floor(y)), int(np.ceil(y + footprint)))
        along_x = np.clip(np.minimum(columns + 1, x + footprint) - np.maximum(columns, x), 0, None)
        along_y = np.clip(np.minimum(rows + 1, y + footprint) - np.maximum(rows, y), 0, None)
        exact[index] = along_y @ image[rows[:, None], columns[None, :], 0] @ along_x / footprint ** 2
    return np.abs(filtered - exact), np.abs(point - exact)


def coverage_errors(offsets, trials=3000, seed=3):
    """A pixel's coverage after the pixel filter (Blackman-Harris 1.5 px, one frame an offset) minus its alpha, for
    uniform alphas at random pixels: each frame's sample of each neighbour keeps the surface where the alpha
    exceeds its threshold (anti_aliasing.coverage_threshold at that frame's offset)."""
    weights = HARRIS.frame_weights(HARRIS.jitter_offsets(anti_aliasing.pixel_jitter(len(offsets))))
    reach = HARRIS.reach
    rng = np.random.default_rng(seed)
    alpha = rng.uniform(size=trials)
    x, y = rng.integers(0, 4096, (2, trials))
    covered = np.zeros(trials)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            thresholds = anti_aliasing.coverage_threshold((x + dx)[:, None], (y + dy)[:, None],
                                                          np.asarray(offsets)[None, :])
            frame_weights = weights[:, 0, dx + reach] * weights[:, 1, dy + reach]
            covered += ((alpha[:, None] > thresholds) * frame_weights[None, :]).sum(axis=1)
    return covered - alpha


def measure():
    errors = filter_errors()
    rows = [dict(name="Blackman-Harris 1.5 px, Edges Only's 4 x 4 grid a pixel weighted",
                 reference="the filtered row by dense quadrature", metric="relative RMSE over a row of sub-pixel "
                 "highlights and a step", max_error=errors["grid 4"], mean_error=None,
                 note=f"8 x 8: {errors['grid 8']:.3g}; the 1-pixel box of 16 samples: {errors['box 16']:.3g}"),
            dict(name="Blackman-Harris 1.5 px, 16 jittered frames each weighting the pixels around",
                 reference="the filtered row by dense quadrature", metric="relative RMSE over a row of sub-pixel "
                 "highlights and a step", max_error=errors["frames 16"], mean_error=None,
                 note="Render Samples 16 of every pixel")]
    for footprint in (2, 4, 8):
        trilinear, bilinear = mip_errors(footprint)
        rows.append(dict(name=f"mip levels, trilinear at a footprint of {footprint} texels",
                         reference=f"the mean of the {footprint} x {footprint} texels under the pixel",
                         metric="absolute error on a white-noise image in [0, 1] (max / mean)",
                         max_error=float(trilinear.max()), mean_error=float(trilinear.mean()),
                         note=f"bilinear in the image (no levels): mean {bilinear.mean():.3g}"))
    coverage = np.abs(coverage_errors(anti_aliasing.coverage_offsets(16)))
    plain = np.abs(coverage_errors(np.arange(16) / 16.0))
    rows.append(dict(name="dithered coverage, 16 jittered frames, thresholds offset by k x the golden ratio",
                     reference="the surface's alpha", metric="absolute error of the filtered coverage over uniform "
                     "alphas (max / RMS)", max_error=float(coverage.max()),
                     mean_error=float(np.sqrt(np.mean(coverage ** 2))),
                     note=f"offsets k / 16: RMS {np.sqrt(np.mean(plain ** 2)):.3g}; Cycles' 16 random samples: "
                          f"RMS {np.sqrt(1.0 / 96.0):.3g}"))
    kappa = kappa_errors()
    rows.append(dict(name="a minified normal map's spread: kappa from the mean normal's length",
                     reference="the von Mises-Fisher mean length coth kappa - 1 / kappa",
                     metric="relative error of kappa over 1..1000 (max / mean)",
                     max_error=float(kappa.max()), mean_error=float(kappa.mean()),
                     note="Banerjee et al. 2005's (3 r - r^3) / (1 - r^2)"))
    return rows
