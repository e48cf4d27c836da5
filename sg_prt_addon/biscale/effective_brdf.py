"""The effective BRDF of a bi-scale material as SGs the SG technique renders (iwasaki2012 section 4.1-4.2).

The small-scale BRDF is kd / pi + ks rho_s with rho_s = M(i, o; n) D(n.h), its NDF as SG lobes
D ~ sum_s mu_s G(n; h, eta_s) (reflectance.brdf's ndf_lobes, the same lobes the SG technique renders).  With the
BVNDF's lobes (bvndf.py), the product integral of eq. 1 is, lobe by lobe,

    integral mu_j G(n; xi_j, eta_j) mu_s G(n; h, eta_s) M dn  ~  M(n*) mu_j mu_s <G_j, G_s>(h)

with M taken at the product lobe's axis n* = normalize(eta_j xi_j + eta_s h) (M varies slowly across it), and
<G_j, G_s> in the single-SG form of eq. 14 (spherical.sg.convolution_lobe): an SG in h with axis xi_j,
sharpness eta_j eta_s / (eta_j + eta_s) and amplitude 2 pi / (eta_j + eta_s) (eq. 15).  Every factor that
depends smoothly on (i, o) (mu_j and the amplitude) goes into one table per effective lobe over the BVNDF's
lattice, divided by cos(theta_i); M, which grows as 1 / cos towards grazing angles where a bilinear table
would not follow it, is evaluated where it is needed.  The effective BRDF without the large-scale cosine, as
every technique expects it:

    rho(i, o) = kd / pi D(i, o) + ks sum_l T_l(i, o) M(n*_l; i, o) G(h; xi_l, eta_l, 1),

D(i, o) the integral of gamma~ over n (the diffuse term of eq. 9, exact from the tile's samples).
"""
from dataclasses import dataclass

import numpy as np

from ..reflectance import brdf as brdf_models
from ..reflectance import models
from ..spherical import sg
from ..visibility import hemisphere_map
from . import bvndf

CONVOLUTIONS = ("sg_form", "exact")


@dataclass(frozen=True)
class SmallScaleMaterial:
    """The small-scale BRDF: diffuse albedo and specular colour (RGB), a reflectance.models model and its
    parameters (those the model does not read are ignored), the NDF lobe count of its SG form."""
    diffuse_color: tuple = (0.0, 0.0, 0.0)
    specular_color: tuple = (1.0, 1.0, 1.0)
    model: str = "GGX"
    parameters: tuple = (("roughness", 0.2),)
    ndf_lobe_count: int = 2         # GGX's: its two-lobe fit (the tail matters once the tile spreads it)

    def brdf(self):
        if self.model not in models.BY_NAME:
            raise ValueError(f"unknown small-scale model {self.model!r}")
        if models.BY_NAME[self.model].anisotropic:
            raise ValueError(f"the small-scale BRDF must be isotropic (iwasaki2012 sec. 4.1); "
                             f"{models.BY_NAME[self.model].label} is anisotropic")
        return brdf_models.model_from_name(self.model, **dict(self.parameters))

    def ndf_lobes(self):
        """(sharpness (S,), amplitude (S,)) of the small-scale NDF's SG lobes (small_scale_lobes)."""
        return small_scale_lobes(self.brdf(), self.model, self.ndf_lobe_count)


@dataclass(frozen=True)
class EffectiveBRDF:
    """The effective lobes, one per BVNDF lobe j and small-scale lobe s: axes (L, 3) xi_j (tile frame),
    ndf_sharpness (L,) eta_j, small_sharpness (L,) eta_s, tables (L, K, K) mu_j(i, o) 2 pi mu_s / (eta_j + eta_s)
    per unit cos(theta_i) over the BVNDF's lattice (resolution R); diffuse (K, K) D(i, o); small the
    SmallScaleMaterial (its M and colours apply at shading)."""
    axes: np.ndarray
    ndf_sharpness: np.ndarray
    small_sharpness: np.ndarray
    tables: np.ndarray
    diffuse: np.ndarray
    resolution: int
    small: SmallScaleMaterial

    @property
    def lobe_count(self):
        return len(self.ndf_sharpness)

    @property
    def sharpness(self):
        """eta_l of eq. 14-15: eta_j eta_s / (eta_j + eta_s)."""
        return sg.convolution_lobe(self.ndf_sharpness, 1.0, self.small_sharpness, 1.0)[0]

    def m_factors(self, wi, wo):
        """(L, ...) the small-scale M at each lobe's product axis n* for directions (..., 3)."""
        h = sg.normalize(np.asarray(wi, np.float64) + np.asarray(wo, np.float64))
        shape = (-1,) + (1,) * (h.ndim - 1)
        normals = sg.normalize(self.ndf_sharpness.reshape(shape)[..., None] * self.axes.reshape(shape + (3,)) +
                               self.small_sharpness.reshape(shape)[..., None] * h[None])
        return facet_m_factor(self.small.brdf(), normals, wi, wo)

    def specular(self, wi, wo, convolution="sg_form"):
        """ks-less rho_s(i, o) of the effective BRDF at any directions (..., 3) (tile frame); convolution
        "exact" takes eq. 10's inner product in place of eq. 14's lobe (for measuring the latter)."""
        wi, wo = np.asarray(wi, np.float64), np.asarray(wo, np.float64)
        h = sg.normalize(wi + wo)
        shape = (-1,) + (1,) * (h.ndim - 1)
        factors = bvndf.interpolate(self.tables, wi, wo, self.resolution)              # (L, ...)
        if convolution == "exact":
            eta_j, eta_s = self.ndf_sharpness.reshape(shape), self.small_sharpness.reshape(shape)
            lobes = sg.inner_product(self.axes.reshape(shape + (3,)), eta_j, 1.0, h[None], eta_s, 1.0) * \
                (eta_j + eta_s) / (2.0 * np.pi)
        elif convolution == "sg_form":
            lobes = sg.evaluate(h[None], self.axes.reshape(shape + (3,)), self.sharpness.reshape(shape), 1.0)
        else:
            raise ValueError(f"unknown convolution {convolution!r}: {CONVOLUTIONS}")
        value = np.sum(factors * lobes * self.m_factors(wi, wo), axis=0)
        return value * ((wi[..., 2] > 0) & (wo[..., 2] > 0))

    def diffuse_factor(self, wi, wo):
        """D(i, o): the Lambertian term kd / pi is scaled by it (1 on a flat tile)."""
        wi, wo = np.asarray(wi, np.float64), np.asarray(wo, np.float64)
        return bvndf.interpolate(self.diffuse[None], wi, wo, self.resolution)[0] * ((wi[..., 2] > 0) & (wo[..., 2] > 0))

    def evaluate(self, wi, wo, convolution="sg_form"):
        """rho(i, o) RGB (..., 3): the effective BRDF without the large-scale cosine."""
        return (self.diffuse_factor(wi, wo)[..., None] * (np.asarray(self.small.diffuse_color) / np.pi) +
                self.specular(wi, wo, convolution)[..., None] * np.asarray(self.small.specular_color))


def small_scale_lobes(model, name, lobe_count=2):
    """(sharpness (..., S), amplitude (..., S)) of a small-scale model's NDF lobes (a reflectance.brdf model
    called `name`, its parameters scalars or per-pixel arrays), all on the facet normal: GGX's `lobe_count`-lobe
    fit, one lobe for the others; amplitudes scaled so the lobes' projected mass integral D(h) (n.h) dh is 1,
    as the NDF's own: the fits match the peak and lose the tail (GGX roughness 0.35: 23% of the mass), which the
    convolution with the tile's lobes spreads into the whole highlight."""
    _, sharpness, amplitude = model.ndf_lobes(lobe_count) if name == "GGX" else model.ndf_lobes()
    sharpness, amplitude = np.asarray(sharpness, np.float64), np.asarray(amplitude, np.float64)
    mass = np.sum(amplitude * sg.axis_cosine_integral(sharpness), axis=-1, keepdims=True)
    return sharpness, amplitude / np.maximum(mass, 1e-30)


def facet_m_factor(model, normals, wi, wo):
    """M(i, o) of the small-scale model on facets with normals (..., 3): the directions in each facet's frame."""
    frames = hemisphere_map.local_frame(normals)
    local_i = np.einsum("...ij,...j->...i", frames, np.broadcast_to(wi, frames.shape[:-1]))
    local_o = np.einsum("...ij,...j->...i", frames, np.broadcast_to(wo, frames.shape[:-1]))
    return model.m_factor(local_o, local_i)


def compute(model, small):
    """The effective BRDF of a BVNDF (bvndf.compute) and a SmallScaleMaterial (eq. 15's lobes)."""
    small.brdf()                                     # refuses an unknown or anisotropic model now, not at shading
    small_sharpness, small_amplitude = small.ndf_lobes()
    _, scale = sg.convolution_lobe(model.sharpness[:, None], 1.0, small_sharpness[None, :],
                                   small_amplitude[None, :])                     # (J, S): 2 pi mu_s / (eta_j + eta_s)
    tables = model.amplitudes[:, None].astype(np.float64) * scale[..., None, None]
    count, nodes = tables.shape[0] * tables.shape[1], len(model.directions)
    return EffectiveBRDF(
        axes=np.repeat(model.axes, len(small_sharpness), axis=0),
        ndf_sharpness=np.repeat(model.sharpness, len(small_sharpness)),
        small_sharpness=np.tile(small_sharpness, model.lobe_count),
        tables=tables.reshape(count, nodes, nodes).astype(np.float32),
        diffuse=model.integral,
        resolution=model.resolution,
        small=small)
