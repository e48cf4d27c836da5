"""A tabulated SVBRDF in the general microfacet form of wang2009 eq. 13-14 (our own format).

Per texel (H, W) of the texture:

    rho(o, i) = diffuse / pi + specular * F(o, i; eta) S(o) S(i) D(h) / (pi (i.n)(o.n))

with F the dielectric Fresnel of eq. 14 at c = |i.h|, S the isotropic shadowing
S(theta) and D the NDF tabulated on a fixed grid of half-vector directions.

File: a NumPy ``.npz`` (no pickles) with

    format            str  "sg-prt-svbrdf-table"
    version           int  1
    diffuse           (H, W, 3)     float32 >= 0   albedo kd (the Lambert term is kd/pi)
    specular          (H, W, 3)     float32 >= 0   colour of the specular term
    eta               (H, W)        float32 > 0    relative index of refraction
    ndf_theta         (T,)          float64        polar angles of the NDF grid, increasing, in [0, pi/2]
    ndf_phi           (P,)          float64        azimuths, uniform 2 pi k / P (P = 1: isotropic)
    ndf               (H, W, T, P)  float32 >= 0   D(theta_t, phi_p)
    shadowing_theta   (S,)          float64        polar angles of S, increasing, in [0, pi/2]
    shadowing         (H, W, S)     float32 >= 0   S(theta), 1 = unshadowed

D is interpolated linearly in theta (0 beyond the last node) and periodically in
phi; S linearly, clamped below its first node, and falling linearly to 0 at pi/2
beyond its last node (if that is short of pi/2), as microfacet shadowing does.  The scale between S and D is fixed by
S = 1 on average below 60 degrees
(what microfacet_fit writes; S may exceed 1 near grazing); readers do not depend on it.
"""
import zipfile
from dataclasses import dataclass

import numpy as np

from ..reflectance.brdf import fresnel_dielectric

FORMAT_NAME = "sg-prt-svbrdf-table"
FORMAT_VERSION = 1
HALF_PI = 0.5 * np.pi
_TEXEL_ARRAYS = ("diffuse", "specular", "eta", "ndf", "shadowing")
_GRID_ARRAYS = ("ndf_theta", "ndf_phi", "shadowing_theta")


class SvbrdfTableError(ValueError):
    """An SVBRDF table file or array set that breaks the format (the message says how)."""


def default_ndf_theta(count=90):
    """NDF nodes denser near the pole (theta = (k/(T-1))^2 pi/2, the MERL theta_h spacing)."""
    return (np.arange(count) / (count - 1)) ** 2 * HALF_PI


def default_shadowing_theta(count=90):
    """One node per degree at bin centres (the paper's 90D shadowing vector)."""
    return (np.arange(count) + 0.5) / count * HALF_PI


@dataclass
class SvbrdfTable:
    diffuse: np.ndarray
    specular: np.ndarray
    eta: np.ndarray
    ndf_theta: np.ndarray
    ndf_phi: np.ndarray
    ndf: np.ndarray
    shadowing_theta: np.ndarray
    shadowing: np.ndarray

    @property
    def shape(self):
        return self.diffuse.shape[:2]

    @property
    def texel_count(self):
        return int(np.prod(self.shape))

    @property
    def isotropic(self):
        return len(self.ndf_phi) == 1

    def validate(self):
        """Raise SvbrdfTableError unless shapes, dtypes and values follow the format."""
        for name in _TEXEL_ARRAYS + _GRID_ARRAYS:
            value = getattr(self, name)
            if not isinstance(value, np.ndarray) or value.dtype.kind != "f":
                raise SvbrdfTableError(f"{name}: expected a floating-point array, found "
                                       f"{getattr(value, 'dtype', type(value).__name__)}")
            if not np.all(np.isfinite(value)):
                raise SvbrdfTableError(f"{name}: {int(np.sum(~np.isfinite(value)))} NaN or Inf values")
        if self.diffuse.ndim != 3 or self.diffuse.shape[2] != 3:
            raise SvbrdfTableError(f"diffuse: expected shape (H, W, 3), found {self.diffuse.shape}")
        height, width = self.shape
        for name in _GRID_ARRAYS:
            grid = getattr(self, name)
            if grid.ndim != 1 or len(grid) < 1:
                raise SvbrdfTableError(f"{name}: expected a non-empty 1D grid, found shape {grid.shape}")
        for name in ("ndf_theta", "shadowing_theta"):
            grid = getattr(self, name)
            if len(grid) < 2 or np.any(np.diff(grid) <= 0) or grid[0] < 0 or grid[-1] > HALF_PI + 1e-9:
                raise SvbrdfTableError(f"{name}: expected at least 2 increasing angles in [0, pi/2]")
        phi_count = len(self.ndf_phi)
        if not np.allclose(self.ndf_phi, 2 * np.pi * np.arange(phi_count) / phi_count, atol=1e-6):
            raise SvbrdfTableError(f"ndf_phi: expected the uniform grid 2 pi k / {phi_count}")
        expected = {"specular": (height, width, 3), "eta": (height, width),
                    "ndf": (height, width, len(self.ndf_theta), phi_count),
                    "shadowing": (height, width, len(self.shadowing_theta))}
        for name, shape in expected.items():
            if getattr(self, name).shape != shape:
                raise SvbrdfTableError(f"{name}: expected shape {shape}, found {getattr(self, name).shape}")
        for name in ("diffuse", "specular", "ndf", "shadowing"):
            if np.any(getattr(self, name) < 0):
                raise SvbrdfTableError(f"{name}: negative values")
        if np.any(self.eta <= 0):
            raise SvbrdfTableError("eta: values must be positive")
        return self

    # ------------------------------------------------------------------ evaluation (flattened texels)

    def flat(self, name):
        """A per-texel array with the (H, W) axes merged: (H*W, ...)."""
        value = getattr(self, name)
        return value.reshape((self.texel_count,) + value.shape[2:])

    def ndf_values(self, h, texels=None):
        """D(h) (B, N) of texels (B,) (default: all) at half vectors h (N, 3) or (B, N, 3)."""
        texels = np.arange(self.texel_count) if texels is None else np.asarray(texels)
        return interpolate_ndf(self.flat("ndf")[texels], self.ndf_theta, self.ndf_phi, h)

    def shadowing_values(self, theta, texels=None):
        """S(theta) (B, N) of texels (B,) at polar angles theta (N,) or (B, N)."""
        texels = np.arange(self.texel_count) if texels is None else np.asarray(texels)
        return interpolate_shadowing(self.flat("shadowing")[texels], self.shadowing_theta, theta)

    def evaluate(self, wo, wi, texels=None):
        """rho(o, i) (B, N, 3) of texels (B,) for direction pairs (N, 3) or (B, N, 3); 0 when
        either direction is below the horizon."""
        texels = np.arange(self.texel_count) if texels is None else np.asarray(texels)
        return evaluate_microfacet(wo, wi, self.flat("diffuse")[texels], self.flat("specular")[texels],
                                   self.flat("eta")[texels], self.ndf_values(_half(wo, wi), texels),
                                   self.shadowing_values(_theta(wo), texels),
                                   self.shadowing_values(_theta(wi), texels))


def interpolate_ndf(ndf, ndf_theta, ndf_phi, h):
    """D(h) (B, N) from tables ndf (B, T, P) on the grid (ndf_theta (T,), ndf_phi (P,)) at half
    vectors h (N, 3) or (B, N, 3): linear in theta (0 beyond the last node and below the
    horizon), periodic linear in phi."""
    h = np.asarray(h, np.float64)
    table = np.asarray(ndf, np.float64)
    theta = np.arctan2(np.hypot(h[..., 0], h[..., 1]), h[..., 2])
    grid = np.asarray(ndf_theta, np.float64)
    position = np.interp(theta, grid, np.arange(len(grid)), right=np.inf)
    outside = ~np.isfinite(position)
    position = np.where(outside, 0, position)
    low = np.minimum(np.floor(position).astype(int), len(grid) - 2)
    t = position - low
    rows = np.arange(len(table))[:, None]
    phi_count = table.shape[2]
    if phi_count == 1:
        value = (1 - t) * table[rows, low, 0] + t * table[rows, low + 1, 0]
    else:
        phi = np.mod(np.arctan2(h[..., 1], h[..., 0]), 2 * np.pi) * (phi_count / (2 * np.pi))
        p0 = np.floor(phi).astype(int) % phi_count
        p1 = (p0 + 1) % phi_count
        s = phi - np.floor(phi)
        value = ((1 - t) * ((1 - s) * table[rows, low, p0] + s * table[rows, low, p1])
                 + t * ((1 - s) * table[rows, low + 1, p0] + s * table[rows, low + 1, p1]))
    return np.where(outside | (h[..., 2] <= 0), 0.0, value)


def shadowing_with_horizon(shadowing, shadowing_theta):
    """(table (B, S'), grid (S',)) with a node S(pi/2) = 0 appended when the grid stops short of
    the horizon: microfacet shadowing vanishes there like cos(theta), which keeps
    S(o) S(i) / ((o.n)(i.n)) finite at grazing angles."""
    table = np.asarray(shadowing, np.float64)
    grid = np.asarray(shadowing_theta, np.float64)
    if grid[-1] < HALF_PI - 1e-9:
        table = np.concatenate([table, np.zeros((len(table), 1))], axis=1)
        grid = np.append(grid, HALF_PI)
    return table, grid


def interpolate_shadowing(shadowing, shadowing_theta, theta):
    """S(theta) (B, N) from tables shadowing (B, S) on shadowing_theta (S,): linear, clamped below the
    first node, to 0 at pi/2 beyond the last (see shadowing_with_horizon)."""
    table, grid = shadowing_with_horizon(shadowing, shadowing_theta)
    position = np.interp(theta, grid, np.arange(len(grid)))
    low = np.minimum(np.floor(position).astype(int), len(grid) - 2)
    t = position - low
    rows = np.arange(len(table))[:, None]
    return (1 - t) * table[rows, low] + t * table[rows, low + 1]


def _half(wo, wi):
    h = np.asarray(wo, np.float64) + np.asarray(wi, np.float64)
    return h / np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)


def _theta(w):
    w = np.asarray(w, np.float64)
    return np.arctan2(np.hypot(w[..., 0], w[..., 1]), np.maximum(w[..., 2], 0))


def evaluate_microfacet(wo, wi, diffuse, specular, eta, ndf, shadowing_o, shadowing_i):
    """Eq. 13 with a Lambert term: (B, N, 3) from per-texel diffuse, specular (B, 3), eta (B,),
    and per-pair D(h), S(o), S(i) (B, N); directions (N, 3) or (B, N, 3)."""
    wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
    h = _half(wo, wi)
    cos_o, cos_i = wo[..., 2], wi[..., 2]
    above = (cos_o > 0) & (cos_i > 0)
    cos_ih = np.abs(np.sum(wi * h, axis=-1))
    fresnel = fresnel_dielectric(np.broadcast_to(cos_ih, ndf.shape), np.asarray(eta, np.float64)[:, None])
    geometry = np.pi * np.maximum(cos_o, 1e-7) * np.maximum(cos_i, 1e-7)
    specular_scalar = fresnel * shadowing_o * shadowing_i * ndf / geometry
    value = (np.asarray(diffuse, np.float64)[:, None, :] / np.pi
             + np.asarray(specular, np.float64)[:, None, :] * specular_scalar[..., None])
    return np.where(np.broadcast_to(above, ndf.shape)[..., None], value, 0.0)


def write_svbrdf_table(path, table):
    """Validate, then write ``table`` as an uncompressed .npz (nothing is written if invalid)."""
    table.validate()
    arrays = {name: np.asarray(getattr(table, name), np.float32) for name in _TEXEL_ARRAYS}
    arrays.update({name: np.asarray(getattr(table, name), np.float64) for name in _GRID_ARRAYS})
    with open(path, "wb") as stream:
        np.savez(stream, format=np.array(FORMAT_NAME), version=np.array(FORMAT_VERSION), **arrays)


def read_svbrdf_table(path):
    """Read and validate a table; SvbrdfTableError names any missing, misshapen or bad array."""
    try:
        with np.load(path, allow_pickle=False) as data:
            contents = {name: data[name] for name in data.files}
    except (OSError, ValueError, EOFError, KeyError, zipfile.BadZipFile) as error:
        raise SvbrdfTableError(f"cannot read SVBRDF table {path!r}: {error}") from error
    if str(contents.get("format", "")) != FORMAT_NAME:
        raise SvbrdfTableError(f"{path!r}: not an SVBRDF table (format field {contents.get('format')!r})")
    version = int(contents.get("version", -1))
    if version != FORMAT_VERSION:
        raise SvbrdfTableError(f"{path!r}: unsupported version {version}, expected {FORMAT_VERSION}")
    missing = [name for name in _TEXEL_ARRAYS + _GRID_ARRAYS if name not in contents]
    if missing:
        raise SvbrdfTableError(f"{path!r}: missing arrays {missing}")
    return SvbrdfTable(**{name: contents[name] for name in _TEXEL_ARRAYS + _GRID_ARRAYS}).validate()
