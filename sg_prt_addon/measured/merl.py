"""Reader, writer and evaluator of the MERL binary BRDF format (Matusik et al. 2003).

File layout (little endian): three int32 dimensions, which must be (90, 90, 180)
(theta_h, theta_d, phi_d bins; product 1,458,000), then 3 x 1,458,000 float64,
planar: all red, then green, then blue.  Sample index
    phi_d_bin + 180 * theta_d_bin + 180 * 90 * theta_h_bin,
theta_h_bin = floor(sqrt(theta_h / (pi/2)) * 90) (denser near the specular peak),
theta_d_bin = floor(theta_d / (pi/2) * 90), phi_d_bin = floor(phi_d / pi * 180) with
phi_d folded into [0, pi) by reciprocity (phi_d and phi_d + pi are i and o swapped).
Stored values times (1/1500, 1.15/1500, 1.66/1500) are the RGB BRDF in 1/sr.

In memory a BRDF is ``rho`` (90, 90, 180, 3) float64 in physical units, indexed
[theta_h, theta_d, phi_d, channel].  Measured files hold negative (-1 marks
configurations the gantry could not measure), NaN and Inf samples.  The reader
counts them and, by choice, replaces them with 0 and clears their ``valid`` flag:
interpolating from neighbours would invent data exactly where there was none, while
the mask lets fits ignore them (microfacet_fit weights them by 0).
"""
import os
import tempfile
from dataclasses import dataclass, field

import numpy as np

THETA_H_BINS = 90
THETA_D_BINS = 90
PHI_D_BINS = 180
DIMENSIONS = (THETA_H_BINS, THETA_D_BINS, PHI_D_BINS)
SAMPLE_COUNT = THETA_H_BINS * THETA_D_BINS * PHI_D_BINS  # 1,458,000
HEADER_BYTES = 12
FILE_BYTES = HEADER_BYTES + 3 * SAMPLE_COUNT * 8  # 34,992,012
CHANNEL_SCALES = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])
HALF_PI = 0.5 * np.pi


class MerlFormatError(ValueError):
    """A file that is not a readable MERL BRDF (the message names what is wrong)."""


@dataclass
class MerlBrdf:
    """A MERL BRDF: ``rho`` (90, 90, 180, 3) float64 in 1/sr, invalid samples set to 0;
    ``valid`` (90, 90, 180) bool, False where any channel was negative, NaN or Inf;
    ``counts``: how many channel samples were negative, NaN, Inf."""
    rho: np.ndarray
    valid: np.ndarray
    counts: dict = field(default_factory=lambda: {"negative": 0, "nan": 0, "inf": 0})

    def evaluate(self, wo, wi):
        """rho(wo, wi) (..., 3) by nearest-bin lookup (as the MERL reference code); 0 when
        either direction is below the horizon or the bin is invalid."""
        theta_h_bin, theta_d_bin, phi_d_bin, above = bin_indices(wo, wi)
        value = self.rho[theta_h_bin, theta_d_bin, phi_d_bin]
        ok = above & self.valid[theta_h_bin, theta_d_bin, phi_d_bin]
        return np.where(ok[..., None], value, 0.0)

    __call__ = evaluate


def clean_samples(rho):
    """(cleaned rho, valid mask (...,) over the last axis, counts): negative, NaN and Inf
    channel samples are counted and replaced by 0; a bin is valid if all channels are."""
    rho = np.asarray(rho, np.float64)
    nan = np.isnan(rho)
    inf = np.isinf(rho)
    negative = rho < 0  # NaN compares False; -Inf counts as Inf and negative: report it once, as Inf
    negative &= ~inf
    bad = nan | inf | negative
    counts = {"negative": int(negative.sum()), "nan": int(nan.sum()), "inf": int(inf.sum())}
    return np.where(bad, 0.0, rho), ~bad.any(axis=-1), counts


def read_merl(path):
    """Read a MERL .binary file into a MerlBrdf; raises MerlFormatError naming the problem
    (unreadable path, short header, wrong dimensions, truncated or oversized data)."""
    try:
        with open(path, "rb") as stream:
            data = stream.read(FILE_BYTES + 1)
    except OSError as error:
        raise MerlFormatError(f"cannot read MERL file {os.fspath(path)!r}: {error.strerror or error}") from error
    if len(data) < HEADER_BYTES:
        raise MerlFormatError(f"{os.fspath(path)!r}: truncated header: expected {HEADER_BYTES} bytes, "
                              f"found {len(data)}")
    dims = tuple(int(d) for d in np.frombuffer(data[:HEADER_BYTES], "<i4"))
    if dims != DIMENSIONS:
        raise MerlFormatError(f"{os.fspath(path)!r}: wrong dimensions: expected {DIMENSIONS}, found {dims}")
    if len(data) != FILE_BYTES:
        problem = "truncated data" if len(data) < FILE_BYTES else "wrong size (trailing bytes)"
        found = f"{len(data)}" if len(data) <= FILE_BYTES else f"more than {FILE_BYTES}"
        raise MerlFormatError(f"{os.fspath(path)!r}: {problem}: expected {FILE_BYTES} bytes "
                              f"(12-byte header + 3 x {SAMPLE_COUNT} float64), found {found}")
    planar = np.frombuffer(data, "<f8", offset=HEADER_BYTES).reshape(3, *DIMENSIONS)
    rho = np.moveaxis(planar, 0, -1) * CHANNEL_SCALES
    rho, valid, counts = clean_samples(rho)
    return MerlBrdf(rho=rho, valid=valid, counts=counts)


def write_merl(path, rho):
    """Write ``rho`` (90, 90, 180, 3) in 1/sr (non-finite and negative values are written
    as given, like measured files) as a MERL file.  The shape is checked before anything
    is written, and the file appears atomically (temporary file + rename)."""
    rho = np.asarray(rho, np.float64)
    if rho.shape != DIMENSIONS + (3,):
        raise MerlFormatError(f"write_merl: expected an array of shape {DIMENSIONS + (3,)}, found {rho.shape}")
    planar = np.ascontiguousarray(np.moveaxis(rho / CHANNEL_SCALES, -1, 0), "<f8")
    directory = os.path.dirname(os.path.abspath(path))
    handle, temporary = tempfile.mkstemp(dir=directory, suffix=".partial")
    try:
        with os.fdopen(handle, "wb") as stream:
            stream.write(np.asarray(DIMENSIONS, "<i4").tobytes())
            stream.write(planar.tobytes())
        os.replace(temporary, path)
    except BaseException:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise


# ----------------------------------------------------------------------------- angles

def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _unit(v):
    length = np.sqrt(_dot(v, v))[..., None]
    return np.where(length > 1e-300, v / np.where(length > 1e-300, length, 1), np.array([0.0, 0.0, 1.0]))


def half_difference_angles(wo, wi):
    """(theta_h, phi_h, theta_d, phi_d) of Rusinkiewicz's half/difference parametrization:
    the difference vector is wi rotated by -phi_h about the normal, then by -theta_h about
    the bitangent (so the half vector becomes z+).  phi_d in (-pi, pi]."""
    wo, wi = _unit(np.asarray(wo, np.float64)), _unit(np.asarray(wi, np.float64))
    h = _unit(wo + wi)
    theta_h = np.arctan2(np.hypot(h[..., 0], h[..., 1]), h[..., 2])
    phi_h = np.arctan2(h[..., 1], h[..., 0])
    cos_p, sin_p = np.cos(phi_h), np.sin(phi_h)
    x = cos_p * wi[..., 0] + sin_p * wi[..., 1]
    y = -sin_p * wi[..., 0] + cos_p * wi[..., 1]
    z = wi[..., 2]
    cos_t, sin_t = np.cos(theta_h), np.sin(theta_h)
    dx, dz = cos_t * x - sin_t * z, sin_t * x + cos_t * z
    theta_d = np.arctan2(np.hypot(dx, y), dz)
    phi_d = np.arctan2(y, dx)
    return theta_h, phi_h, theta_d, phi_d


def bin_indices(wo, wi):
    """(theta_h_bin, theta_d_bin, phi_d_bin, above_horizon) of direction pairs."""
    wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
    theta_h, _, theta_d, phi_d = half_difference_angles(wo, wi)
    phi_d = np.where(phi_d < 0, phi_d + np.pi, phi_d)  # reciprocity: (i, o) swapped
    theta_h_bin = np.clip((np.sqrt(np.maximum(theta_h, 0) / HALF_PI) * THETA_H_BINS).astype(int), 0, THETA_H_BINS - 1)
    theta_d_bin = np.clip((theta_d / HALF_PI * THETA_D_BINS).astype(int), 0, THETA_D_BINS - 1)
    phi_d_bin = np.clip((phi_d / np.pi * PHI_D_BINS).astype(int), 0, PHI_D_BINS - 1)
    above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
    return theta_h_bin, theta_d_bin, phi_d_bin, above


def bin_centre_angles(theta_h_step=1, theta_d_step=1, phi_d_step=1):
    """Angles (theta_h, theta_d, phi_d) at the centres of every step-th bin, each
    (Th, Td, Pd) broadcast, and the bin indices (three index arrays of that shape)."""
    ih = np.arange(0, THETA_H_BINS, theta_h_step)
    jd = np.arange(0, THETA_D_BINS, theta_d_step)
    kp = np.arange(0, PHI_D_BINS, phi_d_step)
    ih, jd, kp = np.meshgrid(ih, jd, kp, indexing="ij")
    theta_h = ((ih + 0.5) / THETA_H_BINS) ** 2 * HALF_PI
    theta_d = (jd + 0.5) / THETA_D_BINS * HALF_PI
    phi_d = (kp + 0.5) / PHI_D_BINS * np.pi
    return (theta_h, theta_d, phi_d), (ih, jd, kp)


def directions_from_half_difference(theta_h, theta_d, phi_d, phi_h=0.0):
    """(wo, wi) (..., 3) of half/difference angles: the inverse of half_difference_angles.
    In the half-vector frame wi = d and wo = d reflected about z+."""
    theta_h, theta_d, phi_d, phi_h = np.broadcast_arrays(*(np.asarray(a, np.float64)
                                                           for a in (theta_h, theta_d, phi_d, phi_h)))
    sin_d = np.sin(theta_d)
    dx, dy, dz = sin_d * np.cos(phi_d), sin_d * np.sin(phi_d), np.cos(theta_d)
    cos_t, sin_t = np.cos(theta_h), np.sin(theta_h)
    cos_p, sin_p = np.cos(phi_h), np.sin(phi_h)

    def to_world(x, y, z):
        # rotate by +theta_h about the bitangent, then +phi_h about the normal
        rx, rz = cos_t * x + sin_t * z, -sin_t * x + cos_t * z
        return np.stack([cos_p * rx - sin_p * y, sin_p * rx + cos_p * y, rz], axis=-1)

    return to_world(-dx, -dy, dz), to_world(dx, dy, dz)


def tabulate(brdf_function, chunk=262_144):
    """rho (90, 90, 180, C) of ``brdf_function(wo, wi) -> (N, C)`` at every bin centre
    (evaluated in chunks to bound memory).  Bins whose centre has a direction below the
    horizon are set to -1, as in measured files."""
    (theta_h, theta_d, phi_d), _ = bin_centre_angles()
    wo, wi = directions_from_half_difference(theta_h.ravel(), theta_d.ravel(), phi_d.ravel())
    first = np.asarray(brdf_function(wo[:1], wi[:1]))
    out = np.empty((SAMPLE_COUNT,) + first.shape[1:])
    for start in range(0, SAMPLE_COUNT, chunk):
        part = slice(start, start + chunk)
        out[part] = brdf_function(wo[part], wi[part])
    below = (wo[:, 2] <= 0) | (wi[:, 2] <= 0)
    out[below] = -1.0
    return out.reshape(DIMENSIONS + first.shape[1:])
