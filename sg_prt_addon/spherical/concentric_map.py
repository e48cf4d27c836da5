"""Shirley & Chiu's concentric map (1997) between the square [-1, 1]^2 and the unit disc: no folding, area
preserving up to a constant, nearly square cells.  The SSDF's hemisphere map (visibility/hemisphere_map.py) lifts
its disc to the hemisphere; area lights place their samples with it (lighting/lights.py)."""
import numpy as np

QUARTER_PI = 0.25 * np.pi


def square_to_disc(square):
    """Concentric map (Shirley & Chiu 1997): (..., 2) square points -> (..., 2) disc points."""
    square = np.asarray(square, np.float64)
    a, b = square[..., 0], square[..., 1]
    a_major = np.abs(a) >= np.abs(b)
    radius = np.where(a_major, a, b)  # signed: a negative radius puts the point on the other side
    safe_radius = np.where(radius == 0, 1.0, radius)
    angle = np.where(a_major, QUARTER_PI * b / safe_radius, 2 * QUARTER_PI - QUARTER_PI * a / safe_radius)
    return np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=-1)


def disc_to_square(disc):
    """Inverse of ``square_to_disc``."""
    disc = np.asarray(disc, np.float64)
    x, y = disc[..., 0], disc[..., 1]
    radius = np.hypot(x, y)
    x_major = np.abs(x) >= np.abs(y)
    safe_x = np.where(x == 0, 1.0, x)
    safe_y = np.where(y == 0, 1.0, y)
    # |x| >= |y|: a = sign(x) r, b = a (4 / pi) atan(y / x); otherwise with the roles swapped.
    a = np.where(x_major, np.copysign(radius, x), np.copysign(radius, y) * np.arctan(x / safe_y) / QUARTER_PI)
    b = np.where(x_major, np.copysign(radius, x) * np.arctan(y / safe_x) / QUARTER_PI, np.copysign(radius, y))
    return np.stack([a, b], axis=-1)
