"""Numpy mirror of shaders/lib/ssdf.glsl: SSDF lookup from PCA data and its product with an SG.

GPU layout (``pack_basis_texture``, ``pack_coefficients``): the mean and the
basis images share one RGBA32F sampler2DArray, four images a layer in the
order [mean, B_0, B_1, ...], zero-padded; each vertex's coefficients are
[1, w_0, w_1, ...] padded to the same 4 x layers floats.  The decoded SSDF is
then sum over layers of dot(texture(basis, (s, t, layer)), coefficients[layer]):
one bilinear fetch per four terms, and bilinear filtering commutes with the
linear PCA sum, so this equals the bilinear sample of the reconstructed image.

``spherical.texture_fetch`` reproduces the GPU linear sampler with clamp-to-edge: texel
centres at (k + 0.5) / R, weights from the fractional part.  Stored samples sit
at the texel centres (``hemisphere_map.sample_texcoord``), so the lookup
interpolates all the way to the horizon.
"""
import numpy as np

from ..spherical import hemisphere, sg, texture_fetch
from . import hemisphere_map


def texcoord_of(local_direction, resolution):
    """Texture coordinates (..., 2) in an R x R SSDF texture and angle below the horizon (...) of local
    directions (normalized here; zero or non-finite -> +z, as in the shader)."""
    square, below = hemisphere_map.horizon_lookup(sg.normalize(np.asarray(local_direction, np.float64)))
    return hemisphere_map.sample_texcoord(square, resolution), below


def decode(coefficients, basis, mean, local_direction):
    """SSDF values (...) at local directions (..., 3) from coefficients (..., N) (broadcast: one vertex's
    (N,) decodes many directions),
    basis (N, R, R) and mean (R, R): bilinear in the map, minus the angle below the horizon."""
    local_direction = np.asarray(local_direction, np.float64)
    texcoord, below = texcoord_of(local_direction, np.shape(mean)[-1])
    flat_coord = texcoord.reshape(-1, 2)
    count = flat_coord.shape[0]
    mean_value = texture_fetch.bilinear_channels_first(np.asarray(mean, np.float64), flat_coord)
    basis_values = texture_fetch.bilinear_channels_first(np.asarray(basis, np.float64), flat_coord)        # (N, Q)
    coefficients = np.asarray(coefficients, np.float64)
    weights = np.broadcast_to(coefficients, below.shape + coefficients.shape[-1:]).reshape(count, -1)
    value = mean_value + np.einsum("qn,nq->q", weights, basis_values)
    return value.reshape(below.shape) - below


def decode_image(image, local_direction):
    """SSDF (...) at local directions from one uncompressed (R, R) image (same lookup as ``decode``)."""
    texcoord, below = texcoord_of(local_direction, np.shape(image)[-1])
    return texture_fetch.bilinear_channels_first(np.asarray(image, np.float64), texcoord) - below


def visibility_product(axis_local, sharpness, amplitude, theta_d):
    """Lobe (x) visibility, wang2009 eq. 31 in the integral-preserving form of spherical.hemisphere
    (apply to the final product lobe).  theta_d = the decoded SSDF at the lobe axis."""
    return hemisphere.visibility_product_integral_preserving(axis_local, sharpness, amplitude, theta_d)


def shadowed_integral(axis_local, sharpness, amplitude, coefficients, basis, mean):
    """Integral over the sphere of G(i; p, lambda, mu) V(i) ~ mu fh(V_d(p), lambda) (eq. 30)."""
    theta_d = decode(coefficients, basis, mean, axis_local)
    return np.asarray(amplitude) * hemisphere.fh(theta_d, sharpness)


def pack_basis_texture(mean, basis):
    """(L, R, R, 4) float32 sampler2DArray data: images [mean, B_0, ..., B_{N-1}] four to a layer."""
    images = np.concatenate([np.asarray(mean)[None], np.asarray(basis)], axis=0)
    layers = -(-images.shape[0] // 4)
    padded = np.zeros((layers * 4,) + images.shape[1:], np.float32)
    padded[:images.shape[0]] = images
    return np.ascontiguousarray(padded.reshape(layers, 4, *images.shape[1:]).transpose(0, 2, 3, 1))


def pack_coefficients(coefficients):
    """(V, 4 L) float32 per-vertex rows [1, w_0, ..., w_{N-1}, 0...] matching ``pack_basis_texture``."""
    coefficients = np.asarray(coefficients, np.float32)
    count, terms = coefficients.shape
    layers = -(-(terms + 1) // 4)
    out = np.zeros((count, layers * 4), np.float32)
    out[:, 0] = 1.0
    out[:, 1:terms + 1] = coefficients
    return out
