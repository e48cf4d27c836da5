"""Importance sampling of an equirect environment in Blender's world mapping.

The map is treated as piecewise constant: every direction sees the radiance of
the texel containing it (equirect.direction_to_uv, floor to a texel, the same
lookup as equirect.lookup_nearest).  Texels are picked with probability
proportional to luminance x solid angle (a marginal over rows, a conditional
over columns), then a direction uniformly in solid angle inside the texel, so
the pdf in solid angle is P(texel) / solid_angle(texel) exactly and the
estimator L / pdf is unbiased for the piecewise-constant map.
"""
import numpy as np

from sg_prt_addon.lighting import equirect

# Rec. 709 luminance weights (Blender's default scene-linear space).
LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])
# A floor, uniform in solid angle, of this fraction of the mean texel weight: every
# direction keeps a non-zero pdf, so dim texels are still sampled and MIS never
# divides by a zero environment pdf.
_FLOOR_FRACTION = 1e-3


class EnvironmentSampler:
    """Sampler over an equirect radiance map (H, W, C), row 0 at the top."""

    def __init__(self, image):
        image = np.asarray(image, dtype=np.float64)
        if image.ndim == 2:
            image = image[..., None]
        self.image = np.nan_to_num(np.maximum(image, 0.0), nan=0.0, posinf=0.0)
        self.height, self.width = self.image.shape[:2]
        self.texel_solid_angle = equirect.texel_solid_angles(self.height, self.width)[:, 0]    # (H,)
        if self.image.shape[2] >= 3:
            luminance = self.image[..., :3] @ LUMINANCE_WEIGHTS
        else:
            luminance = self.image.mean(axis=2)
        # Zero-luminance texels that still carry some colour keep the channel mean.
        brightness = np.maximum(luminance, self.image.mean(axis=2) * 0.1)
        weight = brightness * self.texel_solid_angle[:, None]
        mean_weight = weight.mean()
        if not mean_weight > 0:
            weight = np.ones_like(weight) * self.texel_solid_angle[:, None]
            mean_weight = weight.mean()
        weight = weight + _FLOOR_FRACTION * mean_weight * self.texel_solid_angle[:, None] / self.texel_solid_angle.mean()
        self.texel_probability = weight / weight.sum()                          # (H, W)
        row_probability = self.texel_probability.sum(axis=1)
        self._row_cdf = np.cumsum(row_probability)
        self._row_cdf /= self._row_cdf[-1]
        self._column_cdf = np.cumsum(self.texel_probability, axis=1)
        self._column_cdf /= self._column_cdf[:, -1:]
        self._flat_column_cdf = (self._column_cdf + np.arange(self.height)[:, None]).ravel()
        # Density in solid angle of each texel.
        self.texel_pdf = self.texel_probability / self.texel_solid_angle[:, None]

    def texel_index(self, directions):
        """(row, column) of the texel containing each direction (..., 3)."""
        u, v = equirect.direction_to_uv(directions)
        column = np.clip(np.floor(u * self.width).astype(np.int64), 0, self.width - 1)
        row = np.clip(np.floor((1.0 - v) * self.height).astype(np.int64), 0, self.height - 1)
        return row, column

    def sample(self, uniforms):
        """uniforms (N, 2) in [0, 1) -> unit directions (N, 3), pdf (N,) in solid angle."""
        directions, row, column = self._sample_texels(uniforms)
        return directions, self.texel_pdf[row, column]

    def sample_with_radiance(self, uniforms):
        """As sample, plus the radiance (N, C) of the sampled texel (no second lookup)."""
        directions, row, column = self._sample_texels(uniforms)
        return directions, self.texel_pdf[row, column], self.image[row, column]

    def _sample_texels(self, uniforms):
        uniforms = np.asarray(uniforms, dtype=np.float64).reshape(-1, 2)
        row = np.minimum(np.searchsorted(self._row_cdf, uniforms[:, 0], side="right"), self.height - 1)
        # Per-row binary search in one flat sorted array: row r's cdf is shifted into [r, r + 1].
        position = np.searchsorted(self._flat_column_cdf, row + uniforms[:, 1], side="right")
        column = np.clip(position - row * self.width, 0, self.width - 1)
        # The position of each uniform inside its chosen bin is again uniform:
        # reuse it for the point inside the texel, uniform in u and in
        # sin(elevation), i.e. uniform in solid angle.
        inner_row = _fraction_in_bin(uniforms[:, 0], self._row_cdf, row, row == 0, 0.0)
        inner_column = _fraction_in_bin(row + uniforms[:, 1], self._flat_column_cdf, row * self.width + column,
                                        column == 0, row.astype(np.float64))
        u = (column + inner_column) / self.width
        top = np.pi / 2 - row * np.pi / self.height
        bottom = top - np.pi / self.height
        sin_elevation = np.sin(top) - inner_row * (np.sin(top) - np.sin(bottom))
        elevation = np.arcsin(np.clip(sin_elevation, -1.0, 1.0))
        directions = equirect.uv_to_direction(u, 0.5 + elevation / np.pi)
        # (Rounding can put a direction exactly on the edge of a neighbouring
        # texel, where pdf() would see that texel: a set of measure zero.)
        return directions, row, column

    def pdf(self, directions):
        """Solid-angle density (...) with which sample() produces each direction (..., 3)."""
        row, column = self.texel_index(directions)
        return self.texel_pdf[row, column]

    def lookup(self, directions):
        """(radiance (..., C), pdf (...)) of each direction from one texel lookup."""
        row, column = self.texel_index(directions)
        return self.image[row, column], self.texel_pdf[row, column]

    def radiance(self, directions):
        """Radiance (..., C) of the texel containing each direction."""
        row, column = self.texel_index(directions)
        return self.image[row, column]


def _fraction_in_bin(value, cdf, index, first_bin, lowest):
    """Where value falls inside bin ``index`` of the 1D ``cdf``, in [0, 1).  A bin's lower
    edge is the previous cdf entry, or ``lowest`` where ``first_bin``."""
    upper = cdf[index]
    lower = np.where(first_bin, lowest, cdf[np.maximum(index - 1, 0)])
    width = upper - lower
    return np.clip((value - lower) / np.where(width > 0, width, 1.0), 0.0, 1.0 - 1e-12)
