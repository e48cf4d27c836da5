"""Environment prefiltered with SG kernels of many sharpnesses (wang2009 eq. 34-35).

Gamma_L(p, lambda) = integral over the sphere of G(i; p, lambda, 1) L(i) di turns
the inner product of any SG with the environment into one lookup:
<G(p, lambda, mu), L> = mu Gamma_L(p, lambda) (eq. 35).

Stored convention: each texel holds the *normalized* value
Gamma_L(p, lambda) / integral G = the SG-weighted average radiance around p,
so every layer is in radiance units and well conditioned for float32 /
half-float textures, and the limits are simple: lambda -> 0 gives the mean
radiance, lambda -> infinity the radiance itself.  ``lookup_integral``
multiplies back by sg.sphere_integral(lambda) = 2 pi (1 - e^-2 lambda) / lambda.

GPU layout: one 2D texture array, all layers (size x size).  Layer k holds an
octahedral map of the level sharpness ``sharpness[k]`` (log-spaced,
``levels_per_octave`` per factor 2).  Its content is ``content_size[k]``
texels square in the layer's lower-left corner (row 0 = texture t near 0: upload
the array as is, no flip), sized to the lobe width (broad lobes need few
texels), with a 1-texel gutter around the octahedron holding the values of
the octahedral continuation, so hardware bilinear filtering is seamless.
A fetch is, per layer, texcoord = oct(p) * texcoord_scale[k] + texcoord_offset[k]
(oct(p) in [-1, 1]^2), then a linear blend of two adjacent layers in
log2(lambda); outside the level range the blend clamps to the end layer
(sharper than the top level: the top layer approximates the radiance itself,
which is what Gamma / integral G tends to); broader than the first level, the
value moves linearly in lambda to the map's mean radiance (exact at lambda = 0).
``lookup`` mirrors exactly that.
"""
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..spherical import sg, texture_fetch
from . import equirect

DEFAULT_MIN_SHARPNESS = 0.125
DEFAULT_MAX_SHARPNESS = 2048.0
TEXELS_PER_LOBE = 64.0  # content texels per unit sqrt(lambda); octahedral creases make the error O(texel)
SOURCE_TEXELS_PER_LOBE = 3.0  # equirect source rows per pi per lobe std (1/sqrt(lambda))
MIN_SOURCE_ROWS = 64
WEIGHT_CUTOFF = 1e-6  # source rows whose kernel weight is below this everywhere are skipped


@dataclass
class PrefilteredEnvironment:
    """SG-prefiltered environment, ready for upload as a 2D texture array.

    layers: float32 (L, size, size, C), normalized values (see module doc).
    sharpness: float64 (L,), the kernel sharpness of each layer, log-spaced.
    content_size: int (L,), texels used in each layer (gutter included).
    texcoord_scale, texcoord_offset: float32 (L,), oct coords -> texture coords.
    levels_per_octave: layers per doubling of sharpness.
    mean_radiance: the lambda = 0 value; below the broadest level the lookup blends linearly in
    lambda between it and the broadest layer (the normalized convolution is affine in lambda near 0).
    """
    layers: np.ndarray
    sharpness: np.ndarray
    content_size: np.ndarray
    texcoord_scale: np.ndarray
    texcoord_offset: np.ndarray
    levels_per_octave: float
    mean_radiance: np.ndarray  # (C,) float32, the lambda -> 0 limit (solid-angle mean of the map)

    @property
    def size(self):
        return self.layers.shape[1]

    @property
    def log2_min_sharpness(self):
        return float(np.log2(self.sharpness[0]))

    def texture_data(self):
        """Layers as contiguous float32 RGBA (L, size, size, 4), alpha 1, ready for a 2D array texture
        (upload as is: row 0 is t = 0)."""
        layers = self.layers
        if layers.shape[3] < 4:
            alpha = np.ones(layers.shape[:3] + (4 - layers.shape[3],), np.float32)
            layers = np.concatenate([layers, alpha], axis=3)
        return np.ascontiguousarray(layers[..., :4], dtype=np.float32)

    def level_uniforms(self):
        """Per-level vec4 (texcoord_scale, texcoord_offset, sharpness, 0) as float32 (L, 4), std140-ready."""
        zeros = np.zeros_like(self.texcoord_scale)
        return np.ascontiguousarray(np.stack([self.texcoord_scale, self.texcoord_offset,
                                              self.sharpness.astype(np.float32), zeros], axis=1), np.float32)


# -- octahedral mapping ----------------------------------------------------------

def _sign_not_zero(x):
    return np.where(x >= 0, 1.0, -1.0).astype(np.asarray(x).dtype)


def oct_encode(direction):
    """Unit directions (..., 3) -> octahedral coordinates (..., 2) in [-1, 1]^2 (z- folded to the corners)."""
    d = np.asarray(direction)
    d = d / np.maximum(np.sum(np.abs(d), axis=-1, keepdims=True), np.finfo(sg._float_dtype(d)).tiny)
    u, v, z = d[..., 0], d[..., 1], d[..., 2]
    lower = z < 0
    folded_u = (1 - np.abs(v)) * _sign_not_zero(u)
    folded_v = (1 - np.abs(u)) * _sign_not_zero(v)
    return np.stack([np.where(lower, folded_u, u), np.where(lower, folded_v, v)], axis=-1)


def _fold_into_square(u, v):
    """Octahedral continuation: points up to one gutter outside [-1, 1]^2 -> the point they continue."""
    over_u = np.abs(u) > 1
    u, v = np.where(over_u, np.sign(u) * 2 - u, u), np.where(over_u, -v, v)
    over_v = np.abs(v) > 1
    u, v = np.where(over_v, -u, u), np.where(over_v, np.sign(v) * 2 - v, v)
    return u, v


def oct_decode(coords):
    """Octahedral coordinates (..., 2) -> unit directions (..., 3); coords slightly outside the
    square follow the octahedral continuation (used for the gutter)."""
    coords = np.asarray(coords, dtype=np.float64)
    u, v = _fold_into_square(coords[..., 0], coords[..., 1])
    z = 1 - np.abs(u) - np.abs(v)
    lower = z < 0
    x = np.where(lower, (1 - np.abs(v)) * _sign_not_zero(u), u)
    y = np.where(lower, (1 - np.abs(u)) * _sign_not_zero(v), v)
    return sg.normalize(np.stack([x, y, z], axis=-1))


def content_texel_coords(content_size):
    """Octahedral coords (n, n, 2) of every texel centre of a content block with a 1-texel gutter.

    Interior texels 1..n-2 tile [-1, 1]^2; texels 0 and n-1 are the gutter, one texel outside.
    Index [row, col] -> (u from col, v from row).
    """
    interior = content_size - 2
    c = ((np.arange(content_size) - 1) + 0.5) / interior * 2 - 1
    u, v = np.meshgrid(c, c)
    return np.stack([u, v], axis=-1)


# -- levels ----------------------------------------------------------------------------

def max_sharpness_for(size):
    """Sharpest useful level for a layer size: lobe std 1/sqrt(lambda) about the largest octahedral
    texel spacing, 2.45 * 2 / (size - 2) radians (sharper lobes are not resolved by the layer)."""
    return ((size - 2) / (2 * 2.45)) ** 2


def default_levels(min_sharpness=DEFAULT_MIN_SHARPNESS, max_sharpness=DEFAULT_MAX_SHARPNESS, levels_per_octave=3):
    """Log-spaced level sharpnesses, min_sharpness * 2^(k / levels_per_octave), up to max_sharpness."""
    count = int(np.floor(np.log2(max_sharpness / min_sharpness) * levels_per_octave + 1e-9)) + 1
    return min_sharpness * 2.0 ** (np.arange(count) / levels_per_octave)


def content_size_for(sharpness, size, texels_per_lobe=TEXELS_PER_LOBE):
    """Texels (gutter included) that a level of this sharpness needs, capped at the layer size."""
    wanted = np.ceil(texels_per_lobe * np.sqrt(np.asarray(sharpness, dtype=float))) + 2
    return np.clip(wanted, 16, size).astype(int)


# -- source pyramid ------------------------------------------------------------------

def _halve_equirect(image):
    """2x2 solid-angle-weighted average of an equirect map (even height and width)."""
    height, width = image.shape[:2]
    weights = equirect.texel_solid_angles(height, width)[:, :, None]  # (H, 1, 1)
    weighted = (image * weights).reshape(height // 2, 2, width // 2, 2, -1).sum(axis=(1, 3))
    total = weights.reshape(height // 2, 2, 1, 1).sum(axis=1) * 2
    return weighted / total


def _equirect_pyramid(image, min_height=16):
    """Maps of halving resolution, finest first; odd sizes are first resampled to even ones."""
    image = np.asarray(image, dtype=np.float32)
    height, width = image.shape[:2]
    if height % 2 or width % 2 or width != 2 * height:
        new_height = max(2 * (height // 2), 2)
        rows = np.minimum((np.arange(new_height) + 0.5) * height / new_height, height - 1).astype(int)
        cols = np.minimum((np.arange(2 * new_height) + 0.5) * width / (2 * new_height), width - 1).astype(int)
        image = image[rows][:, cols]
    pyramid = [image]
    while pyramid[-1].shape[0] >= 2 * min_height and pyramid[-1].shape[0] % 2 == 0:
        pyramid.append(_halve_equirect(pyramid[-1]).astype(np.float32))
    return pyramid


def _source_for(pyramid, sharpness):
    """The coarsest pyramid level with at least SOURCE_TEXELS_PER_LOBE rows per lobe std
    (and MIN_SOURCE_ROWS: a box-averaged texel moves sub-texel features to its centre)."""
    wanted_rows = max(SOURCE_TEXELS_PER_LOBE * np.pi * np.sqrt(sharpness), MIN_SOURCE_ROWS)
    for image in reversed(pyramid):
        if image.shape[0] >= wanted_rows:
            return image
    return pyramid[0]


def _compensated_sharpness(sharpness, source_height, finest_height):
    """Sharpness to use on a box-downsampled source so the result matches the full-resolution map.

    A box of width h adds about h^2/12 to the kernel's variance 1/lambda, so the
    kernel is sharpened by exactly that much (when that leaves it positive).
    """
    spacing2 = (np.pi / source_height) ** 2 - (np.pi / finest_height) ** 2
    variance = 1.0 / sharpness - spacing2 / 12.0
    return 1.0 / variance if variance > 0.5 / sharpness else sharpness


# -- convolution -----------------------------------------------------------------------

def convolve_equirect(source, sharpness, row_block=64):
    """Normalized SG convolution of an equirect map, on its own grid: (H, W, C).

    Exact factorization of the kernel on a latitude-longitude grid (elevations
    t_p, t_q, azimuth difference dphi):
        exp(lambda (p.q - 1)) = exp(-2 lambda sin^2((t_p - t_q)/2))
                              * exp(-2 lambda cos t_p cos t_q sin^2(dphi/2)),
    so for each pair of rows the sum over columns is a circular convolution
    (done by FFT), and only rows with |t_p - t_q| within the kernel radius
    (weight >= WEIGHT_CUTOFF) contribute.  The result is divided by the
    discrete kernel sum (the same sums over a constant map), so a constant
    map is reproduced exactly.
    """
    from scipy import fft

    height, width, channels = source.shape
    elevation = np.pi / 2 - (np.arange(height) + 0.5) * np.pi / height
    row_omega = equirect.texel_solid_angles(height, width)[:, 0]
    half_sin2_dphi = np.sin(np.pi * np.arange(width) / width) ** 2  # sin^2(dphi / 2)
    radius = 2 * np.arcsin(min(1.0, 0.5 * np.sqrt(2 * np.log(1 / WEIGHT_CUTOFF) / sharpness)))
    half_rows = min(int(np.ceil(radius * height / np.pi)) + 1, height)
    # float32 spectra: the kernel sums are normalized, so rounding stays ~1e-6 relative
    # the column kernel's spectrum ~ exp(-k^2 / (2 lambda cos t_p cos t_q)): frequencies past
    # sqrt(2 ln(1/cutoff) lambda) are below WEIGHT_CUTOFF and are dropped
    frequencies = min(width // 2 + 1, int(np.ceil(np.sqrt(2 * np.log(1 / WEIGHT_CUTOFF) * sharpness))) + 2)
    spectrum = fft.rfft(source.astype(np.float32), axis=1)[:, :frequencies]  # (H, K, C)
    out = np.empty((height, width, channels), np.float64)
    offsets = np.arange(-half_rows, half_rows + 1)
    for start in range(0, height, row_block):
        rows_out = np.arange(start, min(start + row_block, height))
        rows_in = rows_out[:, None] + offsets[None, :]
        valid = (rows_in >= 0) & (rows_in < height)
        rows_in = np.clip(rows_in, 0, height - 1)
        t_out, t_in = elevation[rows_out][:, None], elevation[rows_in]
        row_weight = np.exp(-2 * sharpness * np.sin(0.5 * (t_out - t_in)) ** 2) * row_omega[rows_in] * valid
        cos_product = np.maximum(np.cos(t_out) * np.cos(t_in), 0.0)
        column_kernel = np.exp(np.float32(-2 * sharpness) * cos_product[..., None].astype(np.float32)
                               * half_sin2_dphi.astype(np.float32))  # (n, 2R+1, W)
        kernel_spectrum = fft.rfft(column_kernel, axis=2)[:, :, :frequencies].real  # symmetric: real
        weighted = row_weight[..., None].astype(np.float32) * kernel_spectrum  # (n, 2R+1, W/2+1)
        total = np.einsum("nqk,nqkc->nkc", weighted, spectrum[rows_in])
        norm = weighted[:, :, 0].astype(np.float64).sum(axis=1)  # DC term = sum of the kernel over columns
        out[rows_out] = fft.irfft(total, n=width, axis=1) / np.maximum(norm, 1e-300)[:, None, None]
    return out


def _catmull_rom(t):
    """Catmull-Rom weights (..., 4) for fractional positions t in [0, 1)."""
    t2, t3 = t * t, t * t * t
    return np.stack([-0.5 * t3 + t2 - 0.5 * t, 1.5 * t3 - 2.5 * t2 + 1, -1.5 * t3 + 2 * t2 + 0.5 * t,
                     0.5 * t3 - 0.5 * t2], axis=-1)


def bicubic_taps(height, width, directions):
    """Flat texel indices and weights (..., 16) of Catmull-Rom interpolation on an equirect grid.

    Rows past a pole continue on the opposite meridian (row reflected, column
    shifted by half the width); columns wrap.
    """
    u, v = equirect.direction_to_uv(np.asarray(directions, dtype=np.float64))
    x = u * width - 0.5
    y = (1 - v) * height - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    wx, wy = _catmull_rom(x - x0), _catmull_rom(y - y0)
    rows = y0.astype(np.int64)[..., None] + np.arange(-1, 3)
    cols = x0.astype(np.int64)[..., None] + np.arange(-1, 3)
    above, below = rows < 0, rows >= height
    shift = np.where(above | below, width // 2, 0)
    rows = np.where(above, -rows - 1, np.where(below, 2 * height - 1 - rows, rows))
    flat = rows[..., :, None] * width + (cols[..., None, :] + shift[..., :, None]) % width
    weights = wy[..., :, None] * wx[..., None, :]
    shape = flat.shape[:-2] + (16,)
    return flat.reshape(shape), weights.reshape(shape)


def sample_equirect_bicubic(image, directions, taps=None):
    """Catmull-Rom interpolation of an equirect map at directions (..., 3) -> (..., C).

    Negative overshoot is clamped at 0 (radiance).  ``taps`` may pass
    precomputed ``bicubic_taps`` for the same grid and directions.
    """
    height, width, channels = image.shape
    flat, weights = taps if taps is not None else bicubic_taps(height, width, directions)
    values = np.einsum("...t,...tc->...c", weights, image.reshape(-1, channels)[flat])
    return np.maximum(values, 0.0)


def prefilter_environment(equirect_image, levels=None, size=256, levels_per_octave=3, workers=2):
    """Prefilter an equirect map (H, W, C) (Blender world mapping, row 0 at the top).

    levels: the level sharpnesses (log-spaced with ``levels_per_octave`` per
    octave; default ``default_levels`` up to ``max_sharpness_for(size)``);
    ``workers`` threads filter levels in parallel.  Returns a PrefilteredEnvironment.
    courtyard.exr (1024 x 512) at size 256, 44 layers: about 4 s of CPU.
    """
    image = np.asarray(equirect_image, dtype=np.float32)
    image = np.nan_to_num(image, nan=0.0, posinf=0.0, neginf=0.0)
    if levels is None:
        levels = default_levels(max_sharpness=max_sharpness_for(size), levels_per_octave=levels_per_octave)
    levels = np.asarray(levels, dtype=np.float64)
    ratios = np.diff(np.log2(levels)) * levels_per_octave
    if levels.size > 1 and not np.allclose(ratios, 1.0, atol=1e-6):
        raise ValueError("levels must be min * 2^(k / levels_per_octave)")
    channels = image.shape[2]
    pyramid = _equirect_pyramid(image)
    content = content_size_for(levels, size)
    layers = np.zeros((levels.size, size, size, channels), np.float32)
    taps_cache = {}  # many levels share a content size and a source grid
    for k, sharpness in enumerate(levels):
        source = _source_for(pyramid, sharpness)
        key = (int(content[k]), source.shape[0], source.shape[1])
        if key not in taps_cache:
            taps_cache[key] = bicubic_taps(source.shape[0], source.shape[1], oct_decode(content_texel_coords(key[0])))

    def filter_level(k):
        n = int(content[k])
        source = _source_for(pyramid, levels[k])
        kernel = _compensated_sharpness(levels[k], source.shape[0], pyramid[0].shape[0])
        values = sample_equirect_bicubic(convolve_equirect(source, kernel), None,
                                         taps_cache[(n, source.shape[0], source.shape[1])])
        layers[k, :n, :n] = values.reshape(n, n, channels)

    # levels are independent and numpy/scipy release the GIL in exp, FFT and einsum: threads scale
    order = list(np.argsort(-levels))  # sharpest (slowest) first for better balance
    if workers > 1:
        with ThreadPoolExecutor(max_workers=workers) as pool:
            list(pool.map(filter_level, order))
    else:
        for k in order:
            filter_level(k)
    interior = content - 2
    scale = (interior / (2.0 * size)).astype(np.float32)
    offset = ((1 + interior / 2.0) / size).astype(np.float32)
    finest = pyramid[0]
    row_omega = equirect.texel_solid_angles(finest.shape[0], finest.shape[1])[:, 0]
    mean = (np.einsum("h,hwc->c", row_omega, finest.astype(np.float64)) / (row_omega.sum() * finest.shape[1]))
    return PrefilteredEnvironment(layers, levels, content, scale, offset, float(levels_per_octave),
                                  mean.astype(np.float32))


# -- lookup (numpy mirror of the GLSL) -------------------------------------------------

def blend_parameter(prefiltered, sharpness):
    """Continuous layer index: (log2(lambda) - log2(lambda_0)) * levels_per_octave, clamped to the levels."""
    sharpness = np.asarray(sharpness, dtype=np.float32)
    last = prefiltered.sharpness.size - 1
    tiny = np.finfo(np.float32).tiny
    position = (np.log2(np.maximum(sharpness, tiny)) - np.float32(prefiltered.log2_min_sharpness)) \
        * np.float32(prefiltered.levels_per_octave)
    return np.clip(np.nan_to_num(position, nan=0.0), 0, last)


def lookup(prefiltered, axis, sharpness):
    """SG-weighted average radiance around ``axis`` (..., 3) for kernel ``sharpness`` (...): (..., C).

    Exactly what the shader does: octahedral coords, per-layer scale/offset,
    two bilinear fetches with clamp-to-edge, linear blend in log2 sharpness.
    Computed in float32 like the GPU (so float32 out whatever the input dtype).
    In GLSL, with u_level[k] = level_uniforms()[k]::

        vec2 oct = oct_encode(normalize(axis));
        float t = clamp((log2(max(lambda, 1e-38)) - log2_min) * levels_per_octave, 0.0, last);
        float k0 = min(floor(t), max(last - 1.0, 0.0));
        float k1 = min(k0 + 1.0, last);
        vec3 a = texture(layers, vec3(oct * u_level[int(k0)].x + u_level[int(k0)].y, k0)).rgb;
        vec3 b = texture(layers, vec3(oct * u_level[int(k1)].x + u_level[int(k1)].y, k1)).rgb;
        return mix(mean_radiance, mix(a, b, t - k0), clamp(lambda / lambda_min, 0.0, 1.0));
    """
    axis = np.asarray(axis, dtype=np.float32)
    coords = oct_encode(sg.normalize(axis)).astype(np.float32)
    position = np.broadcast_to(blend_parameter(prefiltered, sharpness), coords.shape[:-1])
    last = prefiltered.sharpness.size - 1
    lower = np.minimum(np.floor(position).astype(np.int64), max(last - 1, 0))
    upper = np.minimum(lower + 1, last)
    fraction = (position - lower).astype(np.float32)[..., None]
    values = []
    for index in (lower, upper):
        s = coords[..., 0] * prefiltered.texcoord_scale[index] + prefiltered.texcoord_offset[index]
        t = coords[..., 1] * prefiltered.texcoord_scale[index] + prefiltered.texcoord_offset[index]
        values.append(texture_fetch.bilinear(prefiltered.layers, np.stack([s, t], axis=-1), layer=index))
    result = values[0] + (values[1] - values[0]) * fraction
    # below the broadest level: affine in lambda towards the mean radiance at lambda = 0
    below = np.clip(np.nan_to_num(np.asarray(sharpness, dtype=np.float32), nan=0.0)
                    / np.float32(prefiltered.sharpness[0]), 0, 1)
    below = np.broadcast_to(below, coords.shape[:-1])[..., None]
    mean = np.asarray(prefiltered.mean_radiance, dtype=np.float32)
    return mean + (result - mean) * below


def lookup_integral(prefiltered, axis, sharpness, amplitude=1.0):
    """<G(axis, sharpness, amplitude), L> = amplitude * Gamma_L (eq. 35): lookup times the SG integral.

    amplitude: scalar, per lobe (...) or per lobe and colour (..., C).  Returns (..., C).
    """
    values = lookup(prefiltered, axis, sharpness)
    kernel_integral = sg.sphere_integral(np.asarray(sharpness, dtype=np.float32))
    amplitude = np.asarray(amplitude, dtype=np.float32)
    scale = np.broadcast_to(kernel_integral, values.shape[:-1])[..., None]
    if amplitude.ndim == 0 or amplitude.ndim < values.ndim:
        amplitude = amplitude[..., None]
    return values * scale * amplitude


