"""Scores of a rendered image against a reference image (e.g. the Monte Carlo reference).

All images are (H, W, 3) linear radiance; ``mask`` (H, W) selects the pixels
scored (e.g. the surface pixels; None: all).
"""
import numpy as np


def relative_rmse(image, reference, mask=None):
    """sqrt(mean squared error) / mean reference value: one number, insensitive to dark pixels."""
    image, reference = _select(image, reference, mask)
    scale = max(float(np.mean(reference)), 1e-30)
    return float(np.sqrt(np.mean((image - reference) ** 2)) / scale)


def relative_mean_bias(image, reference, mask=None):
    """(mean image - mean reference) / mean reference: the overall energy error."""
    image, reference = _select(image, reference, mask)
    return float((np.mean(image) - np.mean(reference)) / max(float(np.mean(reference)), 1e-30))


def rmse_noise_floor(standard_error, reference, mask=None):
    """The relative RMSE a perfect image would score against a reference with this noise."""
    error, reference = _select(standard_error, reference, mask)
    return float(np.sqrt(np.mean(error ** 2)) / max(float(np.mean(reference)), 1e-30))


def _select(image, reference, mask):
    image = np.asarray(image, np.float64)[..., :3]
    reference = np.asarray(reference, np.float64)[..., :3]
    if image.shape != reference.shape:
        raise ValueError(f"image {image.shape} and reference {reference.shape} differ in shape")
    if mask is not None:
        image, reference = image[mask], reference[mask]
    finite = np.isfinite(image).all(axis=-1) & np.isfinite(reference).all(axis=-1)
    if not finite.all():
        raise ValueError(f"{np.count_nonzero(~finite)} pixels are not finite")
    return image, reference
