"""Point sets on the sphere that the fits, tables and bakes integrate over."""
import numpy as np


def hemisphere_points(count):
    """(count, 3) directions on a Fibonacci lattice of the upper hemisphere (z > 0), uniform in solid angle:
    each stands for 2 pi / count steradians."""
    k = np.arange(count) + 0.5
    z = 1.0 - k / count
    phi = k * np.pi * (3.0 - np.sqrt(5.0))
    r = np.sqrt(np.maximum(1.0 - z * z, 0.0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)
