"""The pixel filter a final render reconstructs with: Cycles' three (Box, Gaussian, Blackman-Harris) at the
scene's film Filter Size, each separable (the weight of an offset (x, y) is f(x) f(y)).

Cycles' widths (intern/cycles/scene/film.cpp): a Box of width w covers |x| <= w/2; a Gaussian exp(-8 x^2 / w^2)
(sigma w/4) is cut at |x| <= 1.5 w; a Blackman-Harris window spans |x| <= w.  Cycles draws each sample's offset
from the filter; here every sample weighs by the filter the pixels it falls near, each sample shared by a pixel
and its neighbours (nine times the samples a pixel for a 3-pixel filter): the jittered frames' (frame_weights)
and Edges Only's supersampled tiles' (grid_weights).  Offsets in pixels from the pixel's centre."""
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

KINDS = ("BOX", "GAUSSIAN", "BLACKMAN_HARRIS")
DEFAULT_KIND = "BLACKMAN_HARRIS"          # Cycles' default filter, at Blender's default Filter Size of 1.5 px
MAX_RADIUS = 3.0        # pixels: a wider filter is cut here (its apron of neighbouring pixels grows with it)
_QUADRATURE_POINTS = 4097      # over the filter's support, for its variance


@dataclass(frozen=True)
class PixelFilter:
    kind: str = DEFAULT_KIND
    width: float = 1.5          # Filter Size, pixels

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"unknown pixel filter {self.kind!r}: one of {', '.join(KINDS)}")

    @property
    def full_radius(self):
        """Pixels from the centre to where the filter falls to 0 (or is cut, for the Gaussian)."""
        width = max(float(self.width), 0.0)
        return {"BOX": 0.5 * width, "GAUSSIAN": 1.5 * width, "BLACKMAN_HARRIS": width}[self.kind]

    @property
    def radius(self):
        """The radius rendered: full_radius, at most MAX_RADIUS."""
        return min(self.full_radius, MAX_RADIUS)

    @property
    def truncated(self):
        return self.full_radius > MAX_RADIUS

    @property
    def reach(self):
        """Neighbouring pixels a side whose area the filter covers: a pixel k away spans [k - 1/2, k + 1/2]."""
        return max(int(np.ceil(self.radius - 0.5 - 1e-9)), 0)

    def weight(self, x):
        """The filter's 1D profile at offsets x (not normalised), 0 beyond radius."""
        x = np.abs(np.asarray(x, np.float64))
        radius = self.radius
        if self.kind == "BOX":
            profile = np.ones_like(x)
        elif self.kind == "GAUSSIAN":
            profile = np.exp(-8.0 * (x / max(float(self.width), 1e-12)) ** 2)
        else:
            phase = np.pi * (x / max(self.full_radius, 1e-12) + 1.0)
            profile = 0.35875 - 0.48829 * np.cos(phase) + 0.14128 * np.cos(2.0 * phase) - 0.01168 * np.cos(3.0 * phase)
        return np.where(x <= radius, profile, 0.0)

    def jitter_offsets(self, strata):
        """The jittered frames' offsets: anti_aliasing.pixel_jitter's strata of the pixel, squeezed into the
        filter's support when it is narrower than a pixel (so every frame weighs)."""
        return np.asarray(strata, np.float64) * min(1.0, 2.0 * self.radius)

    def frame_weights(self, offsets):
        """(frames, 2, 2 reach + 1): for each frame drawn at an offset of ``offsets`` ((frames, 2) pixels), the
        weight along x (row 0) and along y (row 1) of its pixel k - reach .. k + reach away, whose sample lies at
        k + offset from the pixel's centre; the products summed over frames and neighbours make 1."""
        offsets = np.asarray(offsets, np.float64).reshape(-1, 2)
        neighbours = np.arange(-self.reach, self.reach + 1)
        weights = self.weight(neighbours[None, None, :] + offsets[:, :, None])
        total = float(np.sum(weights[:, 0].sum(axis=1) * weights[:, 1].sum(axis=1)))
        if total <= 0.0:
            raise ValueError(f"{self} weighs none of the offsets {offsets.tolist()}")
        weights[:, 0] /= total
        return weights

    def variance(self):
        """The filter's variance along an axis, pixels squared."""
        return _variance(self)

    def footprint_side(self):
        """The side of the square, in pixels, whose box has the filter's variance (side^2 / 12): what a frame
        shaded once a pixel averages its specular over (anti_aliasing.specular_footprint); 1 for a 1-pixel Box."""
        return float(np.sqrt(12.0 * self.variance()))

    def grid_weights(self, grid_side):
        """(2 reach + 1) grid_side weights along an axis, summing to 1: those of the samples at the centres of
        each pixel's grid_side cells, from reach pixels before the pixel to reach pixels after it (Edges Only's
        supersampled tiles).  A filter narrower than the cells weighs the samples nearest the centre alike."""
        side = max(int(grid_side), 1)
        reach = self.reach
        positions = (np.arange((2 * reach + 1) * side) + 0.5) / side - 0.5 - reach
        weights = self.weight(positions)
        if weights.sum() <= 0.0:
            nearest = np.abs(positions)
            weights = (nearest <= nearest.min() + 1e-9).astype(np.float64)
        return weights / weights.sum()


@lru_cache(maxsize=16)
def _variance(pixel_filter):
    """PixelFilter.variance by the trapezoid rule, once a filter: the viewport asks for it at every redraw."""
    radius = max(pixel_filter.radius, 1e-6)
    x = np.linspace(-radius, radius, _QUADRATURE_POINTS)
    density = pixel_filter.weight(x)
    return float(_trapezoids(x * x * density, x).sum() / _trapezoids(density, x).sum())


def _trapezoids(values, x):
    return 0.5 * (values[1:] + values[:-1]) * np.diff(x)


def filter_supersampled(image, pixel_filter, grid_side):
    """An image grid_side times larger ((H S, W S, ...) with S = grid_side, its samples at the centres of each
    pixel's S x S cells) filtered down to (H, W, ...) with the filter's grid_weights, past the borders the border
    samples repeated: the filtered image Cycles converges to, for tests and benchmarks."""
    side = int(grid_side)
    weights = pixel_filter.grid_weights(side)
    margin = pixel_filter.reach * side
    out = np.asarray(image, np.float64)
    for axis in (0, 1):
        count = out.shape[axis] // side
        pad = [(0, 0)] * out.ndim
        pad[axis] = (margin, margin)
        padded = np.pad(out, pad, mode="edge")
        taken = [np.take(padded, np.arange(count) * side + j, axis=axis) * weight
                 for j, weight in enumerate(weights)]
        out = np.sum(taken, axis=0)
    return out
