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

    rho(i, o) = kd / pi D(i, o) + sum_l c_l T_l(i, o) M(n*_l; i, o) G(h; xi_l, eta_l, 1),

D(i, o) the integral of gamma~ over n (the diffuse term of eq. 9, exact from the tile's samples), c_l the RGB
colour of lobe l's small-scale lobe (ks for a parametric model, the lobe's fitted amplitude for a lobe fit).

A small-scale BRDF is either a parametric model (SmallScaleMaterial) or one texel of a stored lobe fit to
measured data (FittedSmallScale: wang2009 eq. 13 with SG lobes about the facet normal, iwasaki2012 fig. 8's
measured small-scale BRDFs); both give their NDF lobes, the lobes' colours, M on facets and their exact value
on facets (for the ground truth).
"""
from dataclasses import dataclass

import numpy as np

from ..measured.svbrdf_table import interpolate_shadowing
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

    def lobe_colours(self):
        """(S, 3): every lobe takes the specular colour."""
        return np.tile(np.asarray(self.specular_color, np.float64), (len(self.ndf_lobes()[0]), 1))

    def m_factor(self, normals, wi, wo):
        return facet_m_factor(self.brdf(), normals, wi, wo)

    def evaluate_on_facets(self, normals, wi, wo):
        """(N, 3) the exact small-scale BRDF kd / pi + ks rho_s on facets with normals (N, 3), directions (3,) or
        (N, 3) in the tile frame (0 where either lies below the facet)."""
        local_i, local_o = facet_directions(normals, wi, wo)
        specular = self.brdf().specular(local_o, local_i)
        lit = (local_i[:, 2] > 0) & (local_o[:, 2] > 0)
        return np.where(lit[:, None], np.asarray(self.diffuse_color) / np.pi +
                        specular[:, None] * np.asarray(self.specular_color), 0.0)

    @property
    def typical_roughness(self):
        """A GGX roughness of about this BRDF's width (a sampling proposal's)."""
        return float(dict(self.parameters).get("roughness", 0.3))


AXIS_TOLERANCE = 1e-3      # sin of the largest tilt of a fitted lobe's axis from the facet normal taken as isotropic


def axis_tilt(axes):
    """(sin of the largest tilt of lobe axes (..., 3) from the normal z, that tilt in degrees)."""
    axes = np.asarray(axes, np.float64)
    tilt = float(np.max(np.linalg.norm(axes[..., :2], axis=-1) / np.maximum(np.linalg.norm(axes, axis=-1), 1e-30)))
    return tilt, float(np.degrees(np.arcsin(min(tilt, 1.0))))


@dataclass(frozen=True)
class FittedSmallScale:
    """One texel of a lobe fit (measured.microfacet_fit.LobeFit, or the stored fit's layers) as the small-scale
    BRDF: rho = kd / pi + sum_s c_s G(h; n, eta_s) F_eta(|i.h|) S(o) S(i) / (pi (i.n)(o.n)), the lobes about the
    facet normal n (an isotropic fit), c_s their RGB amplitudes (ks included), S tabulated on shadowing_theta."""
    diffuse_color: tuple
    eta: float
    sharpness: tuple                # (S,)
    colours: tuple                  # (S, 3)
    shadowing_theta: tuple          # (T,)
    shadowing: tuple                # (T,)

    @classmethod
    def from_arrays(cls, diffuse, eta, axis, sharpness, colours, shadowing_theta, shadowing):
        """From one texel's arrays: axis (S, 3), sharpness (S,), colours (S, 3); ValueError for lobes whose axes
        leave the normal (a free-axes fit is anisotropic or off-specular; iwasaki2012 takes isotropic BRDFs)."""
        tilt, degrees = axis_tilt(axis)
        if tilt > AXIS_TOLERANCE:
            raise ValueError(f"the small-scale lobe fit has lobes off the normal (up to {degrees:.1f} degrees): a "
                             "bi-scale material needs an isotropic fit (Fit Lobes with Axes: Auto, 1-2 lobes)")
        as_tuple = lambda values: tuple(np.asarray(values, np.float64).tolist())       # noqa: E731 (hashable)
        return cls(as_tuple(diffuse), float(eta), as_tuple(sharpness), tuple(map(tuple, np.asarray(colours, float))),
                   as_tuple(shadowing_theta), as_tuple(shadowing))

    @classmethod
    def from_lobe_fit(cls, fit, texel=0):
        return cls.from_arrays(fit.diffuse[texel], fit.eta[texel], fit.axis[texel], fit.sharpness[texel],
                               fit.amplitude[texel], fit.shadowing_theta, fit.shadowing[texel])

    def ndf_lobes(self):
        """The fit's lobes as they are (amplitude 1, the colour apart): the fit is the BRDF, tail and all."""
        sharpness = np.asarray(self.sharpness, np.float64)
        return sharpness, np.ones_like(sharpness)

    def lobe_colours(self):
        return np.asarray(self.colours, np.float64)

    def shadowing_of(self, directions):
        """S at local directions (..., 3)."""
        d = np.asarray(directions, np.float64)
        theta = np.arctan2(np.hypot(d[..., 0], d[..., 1]), np.maximum(d[..., 2], 0.0))
        values = interpolate_shadowing(np.asarray(self.shadowing)[None], np.asarray(self.shadowing_theta),
                                       theta.reshape(1, -1))
        return values.reshape(theta.shape)

    def local_m_factor(self, local_o, local_i):
        """M_o(i) in the facet's frame (directions (..., 3))."""
        local_o, local_i = sg.normalize(local_o), sg.normalize(local_i)
        h = sg.normalize(local_o + local_i)
        fresnel = brdf_models.fresnel_dielectric(np.abs(np.sum(local_i * h, axis=-1)), self.eta)
        above = (local_o[..., 2] > 0) & (local_i[..., 2] > 0)
        cosines = np.pi * np.maximum(local_o[..., 2], brdf_models.COSINE_EPSILON) * \
            np.maximum(local_i[..., 2], brdf_models.COSINE_EPSILON)
        return np.where(above, fresnel * self.shadowing_of(local_o) * self.shadowing_of(local_i) / cosines, 0.0)

    def m_factor(self, normals, wi, wo):
        local_i, local_o = facet_directions(normals, wi, wo)
        return self.local_m_factor(local_o, local_i)

    def evaluate_on_facets(self, normals, wi, wo):
        local_i, local_o = facet_directions(normals, wi, wo)
        h = sg.normalize(local_o + local_i)
        lobes = np.exp(np.asarray(self.sharpness)[None, :] * np.minimum(h[:, 2:3] - 1.0, 0.0))        # (N, S)
        specular = (lobes @ self.lobe_colours()) * self.local_m_factor(local_o, local_i)[:, None]
        lit = (local_i[:, 2] > 0) & (local_o[:, 2] > 0)
        return np.where(lit[:, None], np.asarray(self.diffuse_color) / np.pi + specular, 0.0)

    @property
    def typical_roughness(self):
        """The GGX roughness whose NDF peak's width matches the sharpest lobe's: alpha^2 ~ 2 / eta."""
        return float((2.0 / max(max(self.sharpness), 1e-6)) ** 0.25)


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

    @property
    def lobe_colours(self):
        """(L, 3) c_l: each effective lobe's small-scale lobe colour."""
        return np.tile(self.small.lobe_colours(), (self.lobe_count // len(self.small.lobe_colours()), 1))

    def m_factors(self, wi, wo):
        """(L, ...) the small-scale M at each lobe's product axis n* for directions (..., 3)."""
        h = sg.normalize(np.asarray(wi, np.float64) + np.asarray(wo, np.float64))
        shape = (-1,) + (1,) * (h.ndim - 1)
        normals = sg.normalize(self.ndf_sharpness.reshape(shape)[..., None] * self.axes.reshape(shape + (3,)) +
                               self.small_sharpness.reshape(shape)[..., None] * h[None])
        return self.small.m_factor(normals, wi, wo)

    def specular(self, wi, wo, convolution="sg_form"):
        """Colourless rho_s(i, o) of the effective BRDF (every c_l = 1) at any directions (..., 3) (tile frame);
        convolution "exact" takes eq. 10's inner product in place of eq. 14's lobe (for measuring the latter)."""
        return np.sum(self.lobe_values(wi, wo, convolution), axis=0)

    def lobe_values(self, wi, wo, convolution="sg_form"):
        """(L, ...) each effective lobe's colourless term T_l M G_l at directions (..., 3)."""
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
        return factors * lobes * self.m_factors(wi, wo) * ((wi[..., 2] > 0) & (wo[..., 2] > 0))

    def diffuse_factor(self, wi, wo):
        """D(i, o): the Lambertian term kd / pi is scaled by it (1 on a flat tile)."""
        wi, wo = np.asarray(wi, np.float64), np.asarray(wo, np.float64)
        return bvndf.interpolate(self.diffuse[None], wi, wo, self.resolution)[0] * ((wi[..., 2] > 0) & (wo[..., 2] > 0))

    def evaluate(self, wi, wo, convolution="sg_form"):
        """rho(i, o) RGB (..., 3): the effective BRDF without the large-scale cosine."""
        return (self.diffuse_factor(wi, wo)[..., None] * (np.asarray(self.small.diffuse_color) / np.pi) +
                np.einsum("l...,lc->...c", self.lobe_values(wi, wo, convolution), self.lobe_colours))


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


def facet_directions(normals, wi, wo):
    """(local i, local o): directions (3,) or (..., 3) in the frames of facets with normals (..., 3)."""
    frames = hemisphere_map.local_frame(normals)
    local_i = np.einsum("...ij,...j->...i", frames, np.broadcast_to(wi, frames.shape[:-1]))
    local_o = np.einsum("...ij,...j->...i", frames, np.broadcast_to(wo, frames.shape[:-1]))
    return local_i, local_o


def facet_m_factor(model, normals, wi, wo):
    """M(i, o) of a reflectance.brdf model on facets with normals (..., 3)."""
    local_i, local_o = facet_directions(normals, wi, wo)
    return model.m_factor(local_o, local_i)


def compute(model, small):
    """The effective BRDF of a BVNDF (bvndf.compute) and a small-scale BRDF (SmallScaleMaterial or
    FittedSmallScale): eq. 15's lobes.  An unknown or anisotropic model is refused here, not at shading."""
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
