"""Exact microfacet BRDF models, their SG fits of the NDF, and importance sampling.

wang2009 section 4.1: the specular lobe is written rho_s(o, i) = M_o(i) D(h)
(eq. 9), with h = (o + i)/|o + i|; D carries the high frequencies and is
replaced by an SG mixture D*(h), M_o(i) (shadowing, Fresnel, cosines) is smooth.

Local frame: normal z+, tangent x+, bitangent y+.  ``wo`` points to the viewer,
``wi`` to the light.  Directions are arrays (..., 3); model parameters are
scalars or arrays broadcastable against the directions' leading shape, so a
spatially-varying material evaluates many pixels in one call.

Every model has the same protocol:

    ndf(h)                -> D(h) as the model defines it
    m_factor(wo, wi)      -> M_o(i) with specular == m_factor * ndf(h)  (eq. 9)
    specular(wo, wi)      -> rho_s(o, i), 0 below the horizon of either direction
    ndf_lobes(...)        -> (axis (..., K, 3), sharpness (..., K), amplitude (..., K))
    sample(wo, u)         -> (wi (N, 3), pdf (N,)), pdf per solid angle of wi
    pdf(wo, wi)           -> the density sample() draws wi with

Kernels keep the dtype of the directions (float32 stays float32).  Cosines in
denominators are clamped at COSINE_EPSILON (about 89.99999 degrees) so the
exact formulas stay finite at grazing angles.

Isotropic models map their parameter to one SG lobe analytically (like eq. 12).
The mappings of CookTorranceBeckmann, Beckmann, BlinnPhong, WardIsotropic and GGX are
L2-optimal fits (derived by ndf_fit.derive_isotropic_mapping and frozen in ndf_fit as
polynomials in the lobe width); CookTorrance keeps the paper's eq. 12.
"""
from dataclasses import dataclass

import numpy as np

from . import ndf_fit

COSINE_EPSILON = 1e-7
INV_PI = 1.0 / np.pi


# ----------------------------------------------------------------------------- helpers

def _dtype(*arrays):
    """Promoted floating dtype of the inputs (python floats count as float64; no floats: float64)."""
    dtype = None
    for a in arrays:
        kind = np.asarray(a).dtype
        if kind.kind == "f":
            dtype = kind if dtype is None else np.promote_types(dtype, kind)
    return np.dtype(np.float64) if dtype is None else dtype


def _param(value, dtype, floor=None):
    """Parameter as an array of ``dtype``, clamped below at ``floor`` (a typed constant, so
    numpy scalars do not promote to float64)."""
    value = np.asarray(value).astype(dtype, copy=False)
    return value if floor is None else np.maximum(value, np.asarray(floor, dtype))


def _dot(a, b):
    # explicit components: much faster than a reduction over a length-3 axis
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _unit(v):
    """Unit vectors; zero or non-finite vectors become z+ (their BRDF is 0 anyway).
    Scaled by the largest component first, so tiny vectors do not underflow when squared;
    written per component (reductions over a length-3 axis are slow in numpy)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    largest = np.maximum(np.maximum(np.abs(x), np.abs(y)), np.abs(z))
    ok = np.isfinite(largest) & (largest > 0)
    inverse_scale = 1 / np.where(ok, largest, 1)
    x, y, z = x * inverse_scale, y * inverse_scale, z * inverse_scale
    inverse_length = np.where(ok, 1 / np.sqrt(np.where(ok, x * x + y * y + z * z, 1)), 0)
    out = np.empty(v.shape, v.dtype)
    out[..., 0] = x * inverse_length
    out[..., 1] = y * inverse_length
    out[..., 2] = np.where(ok, z * inverse_length, 1)
    return out


def _directions(*vectors):
    dtype = _dtype(*vectors)
    return [_unit(np.asarray(v).astype(dtype, copy=False)) for v in vectors]


def half_vector(wo, wi):
    """h = (o + i)/|o + i| (eq. 9); o = -i gives z+ (then one of them is below the horizon)."""
    wo, wi = _directions(wo, wi)
    return _unit(wo + wi)


def _sin2_cos(h):
    """sin^2(theta) from the tangent components (no 1 - z^2 cancellation) and cos(theta)."""
    return h[..., 0] ** 2 + h[..., 1] ** 2, h[..., 2]


def _theta(h):
    """Polar angle by atan2: accurate near the pole, where arccos(h.z) is not."""
    sin2, cos = _sin2_cos(h)
    return np.arctan2(np.sqrt(sin2), cos)


def reflect(wo, h):
    """i = 2 (o.h) h - o (eq. 17)."""
    return 2.0 * _dot(wo, h)[..., None] * h - wo


def _lift_above_horizon(wo):
    """wo with z clamped to COSINE_EPSILON: samplers need a view above the horizon."""
    lifted = wo.copy()
    lifted[..., 2] = np.maximum(lifted[..., 2], COSINE_EPSILON)
    return _unit(lifted)


def fresnel_dielectric(cos_theta, eta):
    """Unpolarized Fresnel reflectance of a dielectric, wang2009 eq. 14 (Cook-Torrance 1981).

    F = (g - c)^2 / (2 (g + c)^2) * (1 + ((c (g + c) - 1) / (c (g - c) + 1))^2),
    g = sqrt(eta^2 + c^2 - 1), c = |cos_theta|, eta the relative index.
    g - c is formed as (eta^2 - 1)/(g + c) (no cancellation for eta near 1);
    g^2 < 0 is total internal reflection (F = 1); c = 0 gives F = 1.
    """
    c = np.abs(np.asarray(cos_theta))
    dtype = _dtype(c)  # the cosines' dtype; eta follows it
    c = c.astype(dtype, copy=False)
    eta = _param(eta, dtype)
    g2 = eta * eta + c * c - 1
    total = (g2 <= 0) | (c <= 0)  # total internal reflection, or grazing: F = 1
    # evaluate the masked entries at a harmless point so nothing overflows
    c = np.where(total, 1, c)
    eta = np.where(total, 2, eta)
    g = np.sqrt(np.where(total, 4, g2))
    g_plus_c = g + c
    g_minus_c = (eta * eta - 1) / g_plus_c
    ratio = (c * g_plus_c - 1) / (c * g_minus_c + 1)
    f = 0.5 * (g_minus_c / g_plus_c) ** 2 * (1 + ratio * ratio)
    return np.where(total, np.ones_like(f), np.minimum(f, 1)).astype(dtype, copy=False)


def fresnel_schlick(cos_theta, rf0):
    """Schlick's approximation rf0 + (1 - rf0)(1 - cos)^5 (Ashikhmin-Shirley 2000)."""
    c = np.clip(np.abs(np.asarray(cos_theta)), 0, 1)
    return rf0 + (1 - rf0) * (1 - c) ** 5


def shadowing_cook_torrance(wo, wi, h):
    """S_CT = min(1, 2 (n.h)(n.o)/(o.h), 2 (n.h)(n.i)/(o.h)) (Cook-Torrance 1981, V-cavities)."""
    oh = np.maximum(np.abs(_dot(wo, h)), COSINE_EPSILON)
    nh = h[..., 2]
    return np.clip(np.minimum(2 * nh * wo[..., 2] / oh, 2 * nh * wi[..., 2] / oh), 0, 1)


def _cosines(wo, wi):
    """Clamped n.o, n.i and the above-horizon mask."""
    no, ni = wo[..., 2], wi[..., 2]
    visible = (no > 0) & (ni > 0)
    return np.maximum(no, COSINE_EPSILON), np.maximum(ni, COSINE_EPSILON), visible


def _frame_lobes(parameter, sharpness, amplitude):
    """Single lobe around z+ with shapes (..., 1, 3), (..., 1), (..., 1), in the parameter's dtype."""
    dtype = _dtype(parameter)
    sharpness, amplitude = np.broadcast_arrays(np.asarray(sharpness, dtype), np.asarray(amplitude, dtype))
    axis = np.zeros(sharpness.shape + (1, 3), sharpness.dtype)
    axis[..., 2] = 1
    return axis, sharpness[..., None].copy(), amplitude[..., None].copy()


# ----------------------------------------------------------------------------- sampling helpers

def _uniforms(u, dtype):
    u = np.asarray(u).astype(dtype, copy=False)
    # keep away from exactly 0 and 1 so logs and powers stay finite
    eps = np.finfo(dtype).eps
    return np.clip(u[..., 0], eps, 1 - eps), np.clip(u[..., 1], eps, 1 - eps)


def _from_spherical(cos_theta, phi):
    sin_theta = np.sqrt(np.maximum(0, 1 - cos_theta * cos_theta))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


class _Microfacet:
    """Shared protocol; subclasses define ndf(h), _m_factor(wo, wi, h) on unit vectors,
    ndf_lobes, and either half_vector_pdf + sample_half_vector or their own sample/pdf."""

    def ndf_widths(self):
        """Angular widths of the NDF (quadrature breaks of the fits and their error measures)."""
        return [self.roughness]

    def specular(self, wo, wi):
        """rho_s(o, i) = M_o(i) D(h) (eq. 9); 0 below the horizon of either direction."""
        wo, wi = _directions(wo, wi)
        h = _unit(wo + wi)
        return self._m_factor(wo, wi, h) * self.ndf(h)

    def m_factor(self, wo, wi):
        """M_o(i) of eq. 9: everything but the NDF (shadowing, Fresnel, cosines)."""
        wo, wi = _directions(wo, wi)
        return self._m_factor(wo, wi, _unit(wo + wi))

    __call__ = specular

    # Plain NDF sampling: h from p_h, i = reflect(o, h), pdf = p_h / (4 |o.h|).
    # If o.h < 0 the reflected i has (o + i) along -h, so pdf() adds p_h(-h).
    def sample(self, wo, u):
        """Importance-sample wi by the NDF: (wi (N, 3), pdf (N,)); wi may be below the horizon."""
        (wo,) = _directions(wo)
        u1, u2 = _uniforms(u, wo.dtype)
        wo = _lift_above_horizon(np.broadcast_to(wo, u1.shape + (3,)))
        h = self.sample_half_vector(u1, u2)
        wi = reflect(wo, h)
        return wi, self.pdf(wo, wi)

    def pdf(self, wo, wi):
        """Density (per solid angle of wi) of sample()."""
        wo, wi = _directions(wo, wi)
        wo = _lift_above_horizon(wo)
        h = _unit(wo + wi)
        oh = np.maximum(np.abs(_dot(wo, h)), COSINE_EPSILON)
        return (self.half_vector_pdf(h) + self.half_vector_pdf(-h)) / (4 * oh)


def _beckmann_sample(u1, u2, alpha_x, alpha_y):
    """h with density D_Beckmann(h) (n.h), anisotropic: tan^2 = -log(u1)/(cos^2/ax^2 + sin^2/ay^2)."""
    phi = np.arctan2(alpha_y * np.sin(2 * np.pi * u2), alpha_x * np.cos(2 * np.pi * u2))
    cos_phi, sin_phi = np.cos(phi), np.sin(phi)
    tan2 = -np.log(u1) / ((cos_phi / alpha_x) ** 2 + (sin_phi / alpha_y) ** 2)
    cos_theta = 1 / np.sqrt(1 + tan2)
    sin_theta = np.sqrt(tan2) * cos_theta
    return np.stack([sin_theta * cos_phi, sin_theta * sin_phi, cos_theta], axis=-1)


def _beckmann_ndf(h, alpha_x, alpha_y):
    """Normalized anisotropic Beckmann D with integral of D (n.h) = 1, computed in log space."""
    hz = h[..., 2]
    z = np.maximum(hz, COSINE_EPSILON)
    exponent = -((h[..., 0] / alpha_x) ** 2 + (h[..., 1] / alpha_y) ** 2) / (z * z)
    value = np.exp(exponent - 4 * np.log(z)) / (np.pi * alpha_x * alpha_y)
    return np.where(hz > 0, value, 0)


# ----------------------------------------------------------------------------- models

@dataclass(frozen=True, eq=False)
class CookTorrance(_Microfacet):
    """Cook-Torrance as in wang2009 eq. 10-11: D(h) = exp(-(theta_h/m)^2) (unnormalized),
    M_o(i) = F_CT S_CT / (pi (n.i)(n.o)), F by eq. 14 at c = |i.h|.  SG: eq. 12.

    roughness is m, ior the relative index eta.  Sampling draws h from the Beckmann
    distribution of the same m (close to exp(-(theta/m)^2) near the pole).
    """
    roughness: object = 0.2
    ior: object = 1.5

    def _m(self, dtype):
        return _param(self.roughness, dtype, 1e-6)

    def ndf(self, h):
        h = np.asarray(h)
        theta = _theta(h)
        return np.where(h[..., 2] > 0, np.exp(-(theta / self._m(h.dtype)) ** 2), 0)

    def _m_factor(self, wo, wi, h):
        no, ni, visible = _cosines(wo, wi)
        fresnel = fresnel_dielectric(_dot(wi, h), _param(self.ior, wo.dtype))
        value = fresnel * shadowing_cook_torrance(wo, wi, h) / (np.pi * ni * no)
        return np.where(visible, value, 0)

    def ndf_lobes(self):
        """wang2009 eq. 12: G(h; n, 2/m^2, 1)."""
        m = self._m(_dtype(self.roughness))
        return _frame_lobes(m, 2 / (m * m), np.ones_like(m))

    def half_vector_pdf(self, h):
        m = self._m(h.dtype)
        return _beckmann_ndf(h, m, m) * np.maximum(h[..., 2], 0)

    def sample_half_vector(self, u1, u2):
        m = self._m(u1.dtype)
        return _beckmann_sample(u1, u2, m, m)


@dataclass(frozen=True, eq=False)
class CookTorranceBeckmann(CookTorrance):
    """Cook-Torrance with the normalized Beckmann NDF
    D = exp(-tan^2(theta_h)/m^2) / (pi m^2 cos^4 theta_h)  (integral of D (n.h) = 1),
    M_o(i) = F S_CT / (4 (n.i)(n.o)) (the microfacet-consistent 4, not eq. 10's pi).
    """

    def ndf(self, h):
        h = np.asarray(h)
        m = self._m(h.dtype)
        return _beckmann_ndf(h, m, m)

    def _m_factor(self, wo, wi, h):
        return CookTorrance._m_factor(self, wo, wi, h) * (np.pi / 4)

    def ndf_lobes(self):
        m = self._m(_dtype(self.roughness))
        scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping("BECKMANN", m)
        return _frame_lobes(m, scaled_sharpness / (m * m), relative_amplitude / (np.pi * m * m))


@dataclass(frozen=True, eq=False)
class BlinnPhong(_Microfacet):
    """Blinn 1977: D = (n + 2)/(2 pi) (n.h)^n (integral of D (n.h) = 1) with the
    Torrance-Sparrow V-cavity shadowing and no Fresnel (F = 1, the colour is ks):
    M_o(i) = S_CT / (4 (n.i)(n.o)).
    """

    def ndf_widths(self):
        return [np.sqrt(2 / np.maximum(self.exponent, 1e-6))]
    exponent: object = 100.0

    def _n(self, dtype):
        return _param(self.exponent, dtype, 0)

    def ndf(self, h):
        h = np.asarray(h)
        n = self._n(h.dtype)
        hz = h[..., 2]
        value = (n + 2) / (2 * np.pi) * np.exp(n * np.log(np.maximum(hz, np.finfo(h.dtype).tiny)))
        return np.where(hz > 0, value, 0)

    def _m_factor(self, wo, wi, h):
        no, ni, visible = _cosines(wo, wi)
        return np.where(visible, shadowing_cook_torrance(wo, wi, h) / (4 * ni * no), 0)

    def ndf_lobes(self):
        n = self._n(_dtype(self.exponent))
        width = np.sqrt(2 / np.maximum(n, np.asarray(1e-6, n.dtype)))
        scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping("BLINN_PHONG", width)
        sharpness = scaled_sharpness / np.square(np.clip(width, *ndf_fit.ISOTROPIC_MAPPINGS["BLINN_PHONG"]["width_range"]))
        return _frame_lobes(n, sharpness, relative_amplitude * (n + 2) / (2 * np.pi))

    def half_vector_pdf(self, h):
        return self.ndf(h) * np.maximum(h[..., 2], 0)

    def sample_half_vector(self, u1, u2):
        n = self._n(u1.dtype)
        return _from_spherical(np.exp(np.log(u1) / (n + 2)), 2 * np.pi * u2)


@dataclass(frozen=True, eq=False)
class WardAnisotropic(_Microfacet):
    """Ward 1992 (anisotropic):
    rho_s = exp(-tan^2(theta_h)(cos^2 phi/ax^2 + sin^2 phi/ay^2)) / (4 pi ax ay sqrt((n.i)(n.o))),
    split as D = exp(-(hx^2/ax^2 + hy^2/ay^2)/hz^2) / (pi ax ay), M_o(i) = 1/(4 sqrt((n.i)(n.o))),
    so M does not depend on h at all.  SG lobes: K free-axis lobes from the
    precomputed anisotropy table of ndf_fit (see ndf_fit.anisotropic_lobes).
    """

    def ndf_widths(self):
        return [self.alpha_x, self.alpha_y]
    alpha_x: object = 0.2
    alpha_y: object = 0.05

    def _alphas(self, dtype):
        return (_param(self.alpha_x, dtype, 1e-6), _param(self.alpha_y, dtype, 1e-6))

    def ndf(self, h):
        h = np.asarray(h)
        ax, ay = self._alphas(h.dtype)
        # Ward's D is Beckmann's times cos^4(theta_h)
        z = np.maximum(h[..., 2], COSINE_EPSILON)
        exponent = -((h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2) / (z * z)
        return np.where(h[..., 2] > 0, np.exp(exponent) / (np.pi * ax * ay), 0)

    def _m_factor(self, wo, wi, h):
        no, ni, visible = _cosines(wo, wi)
        return np.where(visible, 0.25 / np.sqrt(ni * no), 0)

    def ndf_lobes(self, lobe_count=4, broad_lobe_correction=False, refine=False):
        """K SG lobes from the normalized anisotropy table (ndf_fit.anisotropic_lobes).

        broad_lobe_correction applies the Ward isotropic L2 mapping at the geometric-mean
        width (much better for alpha >~ 0.3; off by default because the GLSL mirror,
        shaders/techniques/sg/anisotropic_lobes.glsl, does not apply it yet).  refine (scalar
        parameters only) fits the exact D on the sphere from there
        (ndf_fit.refined_anisotropic_lobes, cached)."""
        if refine:
            return ndf_fit.refined_anisotropic_lobes(self, lobe_count, "WARD_ISO" if broad_lobe_correction else None)
        ax, ay = self._alphas(_dtype(self.alpha_x, self.alpha_y))
        return ndf_fit.anisotropic_lobes(ax, ay, 1 / (np.pi * ax * ay), lobe_count,
                                         "WARD_ISO" if broad_lobe_correction else None)

    def half_vector_pdf(self, h):
        ax, ay = self._alphas(h.dtype)
        return _beckmann_ndf(h, ax, ay) * np.maximum(h[..., 2], 0)

    def sample_half_vector(self, u1, u2):
        ax, ay = self._alphas(u1.dtype)
        return _beckmann_sample(u1, u2, ax, ay)


@dataclass(frozen=True, eq=False)
class WardIsotropic(WardAnisotropic):
    """Isotropic Ward (alpha_x = alpha_y = alpha): one SG lobe by the frozen L2 mapping."""

    def ndf_widths(self):
        return [self.alpha_x]
    alpha_x: object = 0.2
    alpha_y: object = None

    def _alphas(self, dtype):
        alpha = _param(self.alpha_x, dtype, 1e-6)
        return alpha, alpha

    def ndf_lobes(self):
        alpha, _ = self._alphas(_dtype(self.alpha_x))
        scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping("WARD_ISO", alpha)
        return _frame_lobes(alpha, scaled_sharpness / (alpha * alpha),
                            relative_amplitude / (np.pi * alpha * alpha))


@dataclass(frozen=True, eq=False)
class AshikhminShirley(_Microfacet):
    """Ashikhmin-Shirley 2000 specular term:
    rho_s = sqrt((nu+1)(nv+1))/(8 pi) (n.h)^e / ((h.k) max(n.i, n.o)) F(h.k),
    e = (nu hx^2 + nv hy^2)/(1 - hz^2), F = Schlick with rf0.
    Split D = sqrt((nu+1)(nv+1))/(2 pi) (n.h)^e (integral of D dw_h = 1),
    M_o(i) = F(h.k) / (4 (h.k) max(n.i, n.o)).  Sampling is A-S's own (p_h = D exactly).
    """

    def ndf_widths(self):
        return [np.sqrt(2 / np.maximum(self.nu, 1e-6)), np.sqrt(2 / np.maximum(self.nv, 1e-6))]
    nu: object = 75.0
    nv: object = 1200.0
    rf0: object = 0.05

    def _exponents(self, dtype):
        return _param(self.nu, dtype, 0), _param(self.nv, dtype, 0)

    def ndf(self, h):
        h = np.asarray(h)
        nu, nv = self._exponents(h.dtype)
        sin2, hz = _sin2_cos(h)
        weighted = nu * h[..., 0] ** 2 + nv * h[..., 1] ** 2
        exponent = np.where(sin2 > 0, weighted / np.where(sin2 > 0, sin2, 1), nu)
        log_hz = np.log(np.maximum(hz, np.finfo(h.dtype).tiny))
        value = np.sqrt((nu + 1) * (nv + 1)) / (2 * np.pi) * np.exp(exponent * log_hz)
        return np.where(hz > 0, value, 0)

    def _m_factor(self, wo, wi, h):
        no, ni, visible = _cosines(wo, wi)
        kh = np.maximum(np.abs(_dot(wi, h)), COSINE_EPSILON)
        fresnel = fresnel_schlick(kh, _param(self.rf0, wo.dtype))
        return np.where(visible, fresnel / (4 * kh * np.maximum(ni, no)), 0)

    def ndf_lobes(self, lobe_count=4, broad_lobe_correction=False, refine=False):
        """K SG lobes from the normalized anisotropy table; widths sqrt(2/nu), sqrt(2/nv)
        (the small-angle Gaussian of (n.h)^e).  broad_lobe_correction: the Blinn-Phong
        L2 mapping (same (n.h)^n shape) at the geometric-mean width; refine: see
        WardAnisotropic."""
        if refine:
            return ndf_fit.refined_anisotropic_lobes(self, lobe_count, "BLINN_PHONG" if broad_lobe_correction else None)
        nu, nv = self._exponents(_dtype(self.nu, self.nv))
        floor = np.asarray(1e-6, nu.dtype)
        width_x = np.sqrt(2 / np.maximum(nu, floor))
        width_y = np.sqrt(2 / np.maximum(nv, floor))
        return ndf_fit.anisotropic_lobes(width_x, width_y, np.sqrt((nu + 1) * (nv + 1)) / (2 * np.pi), lobe_count,
                                         "BLINN_PHONG" if broad_lobe_correction else None)

    def half_vector_pdf(self, h):
        return self.ndf(h)

    def sample_half_vector(self, u1, u2):
        nu, nv = self._exponents(u1.dtype)
        # phi = atan(sqrt((nu+1)/(nv+1)) tan(pi u/2)) per quadrant, written with atan2
        ratio = np.sqrt((nu + 1) / (nv + 1))
        angle = 2 * np.pi * u2
        phi = np.arctan2(ratio * np.sin(angle), np.cos(angle))
        cos_phi, sin_phi = np.cos(phi), np.sin(phi)
        exponent = nu * cos_phi ** 2 + nv * sin_phi ** 2
        return _from_spherical(np.exp(np.log(u1) / (exponent + 1)), phi)


@dataclass(frozen=True, eq=False)
class GGX(_Microfacet):
    """GGX / Trowbridge-Reitz with Blender's Glossy/Principled conventions:
    alpha = roughness^2, D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2),
    height-correlated Smith G = 1/(1 + Lambda(i) + Lambda(o)), no Fresnel:
    M_o(i) = G / (4 (n.i)(n.o)).  Sampling: visible normals (Heitz 2018).
    """

    def ndf_widths(self):
        return [self.roughness ** 2]
    roughness: object = 0.3

    def _alpha(self, dtype):
        # alpha >= 1e-9 keeps 1/(pi alpha^2) and (sin^2/alpha^2)^2 finite in float32
        return np.maximum(np.square(_param(self.roughness, dtype)), np.asarray(1e-9, dtype))

    def ndf(self, h):
        h = np.asarray(h)
        alpha = self._alpha(h.dtype)
        sin2, hz = _sin2_cos(h)
        # alpha^2 / (pi (sin^2 + alpha^2 cos^2)^2) without forming alpha^4
        scaled = sin2 / (alpha * alpha) + hz * hz
        return np.where(hz > 0, 1 / (np.pi * alpha * alpha * scaled * scaled), 0)

    @staticmethod
    def smith_lambda(w, alpha):
        """Lambda(w) = (sqrt(1 + alpha^2 tan^2) - 1)/2, in cancellation-free form."""
        z = np.maximum(w[..., 2], COSINE_EPSILON)
        a = alpha * alpha * (w[..., 0] ** 2 + w[..., 1] ** 2) / (z * z)
        return a / (2 * (1 + np.sqrt(1 + a)))

    def _m_factor(self, wo, wi, h):
        alpha = self._alpha(wo.dtype)
        no, ni, visible = _cosines(wo, wi)
        shadowing = 1 / (1 + self.smith_lambda(wo, alpha) + self.smith_lambda(wi, alpha))
        return np.where(visible, shadowing / (4 * ni * no), 0)

    def ndf_lobes(self, lobe_count=1):
        """One lobe by the frozen L2 mapping, or two lobes from ndf_fit.ggx_two_lobe_table."""
        alpha = self._alpha(_dtype(self.roughness))
        peak = 1 / (np.pi * alpha * alpha)
        if lobe_count == 1:
            scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping("GGX", alpha)
            return _frame_lobes(alpha, scaled_sharpness / (alpha * alpha), relative_amplitude * peak)
        if lobe_count != 2:
            raise ValueError("GGX has 1- and 2-lobe fits")
        return ndf_fit.ggx_two_lobes(alpha)

    def sample(self, wo, u):
        """Visible-normal sampling: h ~ G1(o) max(0, o.h) D(h) / (n.o), i = reflect(o, h)."""
        (wo,) = _directions(wo)
        u1, u2 = _uniforms(u, wo.dtype)
        wo = _lift_above_horizon(np.broadcast_to(wo, u1.shape + (3,)))
        alpha = self._alpha(wo.dtype)
        # stretch the view into the configuration where the microsurface is a hemisphere
        stretched = _unit(np.stack([alpha * wo[..., 0], alpha * wo[..., 1], wo[..., 2]], axis=-1))
        tangent_len2 = stretched[..., 0] ** 2 + stretched[..., 1] ** 2
        has_tangent = tangent_len2 > 1e-20
        inv_len = 1 / np.sqrt(np.where(has_tangent, tangent_len2, 1))
        t1 = np.stack([np.where(has_tangent, -stretched[..., 1] * inv_len, 1),
                       np.where(has_tangent, stretched[..., 0] * inv_len, 0),
                       np.zeros_like(inv_len)], axis=-1)
        t2 = np.cross(stretched, t1)
        # uniform disk point, squeezed onto the visible half of the projected hemisphere
        radius = np.sqrt(u1)
        phi = 2 * np.pi * u2
        p1, p2 = radius * np.cos(phi), radius * np.sin(phi)
        blend = 0.5 * (1 + stretched[..., 2])
        p2 = (1 - blend) * np.sqrt(np.maximum(0, 1 - p1 * p1)) + blend * p2
        p3 = np.sqrt(np.maximum(0, 1 - p1 * p1 - p2 * p2))
        normal = p1[..., None] * t1 + p2[..., None] * t2 + p3[..., None] * stretched
        h = _unit(np.stack([alpha * normal[..., 0], alpha * normal[..., 1], np.maximum(normal[..., 2], 0)], axis=-1))
        wi = reflect(wo, h)
        return wi, self.pdf(wo, wi)

    def pdf(self, wo, wi):
        """G1(o) D(h) / (4 n.o) for visible h (h.z > 0, o.h > 0), else 0."""
        wo, wi = _directions(wo, wi)
        wo = _lift_above_horizon(wo)
        alpha = self._alpha(wo.dtype)
        h = _unit(wo + wi)
        visible_masking = 1 / (1 + self.smith_lambda(wo, alpha))
        value = visible_masking * self.ndf(h) / (4 * wo[..., 2])
        return np.where((_dot(wo, h) > 0) & (h[..., 2] > 0), value, 0)


@dataclass(frozen=True, eq=False)
class Beckmann(_Microfacet):
    """Beckmann with Blender's Glossy BSDF conventions: alpha = roughness^2, the normalized Beckmann D,
    height-correlated Smith G = 1/(1 + Lambda(i) + Lambda(o)) with Lambda by Walter et al. 2007's rational
    approximation (as Cycles), no Fresnel: M_o(i) = G / (4 (n.i)(n.o)).  One SG lobe by the frozen L2 mapping.
    """

    def ndf_widths(self):
        return [self.roughness ** 2]
    roughness: object = 0.3

    def _alpha(self, dtype):
        return np.maximum(np.square(_param(self.roughness, dtype)), np.asarray(1e-6, dtype))

    def ndf(self, h):
        h = np.asarray(h)
        alpha = self._alpha(h.dtype)
        return _beckmann_ndf(h, alpha, alpha)

    @staticmethod
    def smith_lambda(w, alpha):
        """Walter et al. 2007: a = 1 / (alpha tan theta); (1 - 1.259 a + 0.396 a^2) / (3.535 a + 2.181 a^2)
        below a = 1.6, else 0: the exact (erf(a) - 1)/2 + exp(-a^2) / (2 a sqrt(pi)) to within 0.4% of 1 + Lambda."""
        z = np.maximum(w[..., 2], COSINE_EPSILON)
        tangent = np.sqrt(w[..., 0] ** 2 + w[..., 1] ** 2) / z
        a = 1 / np.maximum(alpha * tangent, np.asarray(1e-30, tangent.dtype))
        # not below 0: the form dips 2e-5 under near a = 1.6
        return np.where(a < 1.6, np.maximum((1 - 1.259 * a + 0.396 * a * a) / (3.535 * a + 2.181 * a * a), 0), 0)

    def _m_factor(self, wo, wi, h):
        alpha = self._alpha(wo.dtype)
        no, ni, visible = _cosines(wo, wi)
        shadowing = 1 / (1 + self.smith_lambda(wo, alpha) + self.smith_lambda(wi, alpha))
        return np.where(visible, shadowing / (4 * ni * no), 0)

    def ndf_lobes(self):
        alpha = self._alpha(_dtype(self.roughness))
        scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping("BECKMANN", alpha)
        return _frame_lobes(alpha, scaled_sharpness / (alpha * alpha), relative_amplitude / (np.pi * alpha * alpha))

    def half_vector_pdf(self, h):
        return self.ndf(h) * np.maximum(h[..., 2], 0)

    def sample_half_vector(self, u1, u2):
        alpha = self._alpha(u1.dtype)
        return _beckmann_sample(u1, u2, alpha, alpha)


@dataclass(frozen=True, eq=False)
class GGXAnisotropic(_Microfacet):
    """Anisotropic GGX as Blender's Principled and Glossy BSDFs with Anisotropic > 0 (alpha_x along the
    tangent, alpha_y along the bitangent; reflectance.principled.anisotropic_alphas):
    D = 1 / (pi ax ay ((hx/ax)^2 + (hy/ay)^2 + hz^2)^2), height-correlated Smith with
    Lambda(w) = (sqrt(1 + (ax^2 wx^2 + ay^2 wy^2) / wz^2) - 1) / 2, no Fresnel (reflectance.layering adds it).
    SG lobes: all fitted together to GGX's two isotropic lobes stretched to the alphas, from its own table over
    ratio and alpha (ndf_fit.ggx_anisotropic_lobes); what they miss of GGX's tails the SG technique returns
    through its light and environment tails."""
    alpha_x: object = 0.2
    alpha_y: object = 0.05

    def ndf_widths(self):
        return [self.alpha_x, self.alpha_y]

    def _alphas(self, dtype):
        return (_param(self.alpha_x, dtype, 1e-6), _param(self.alpha_y, dtype, 1e-6))

    def ndf(self, h):
        h = np.asarray(h)
        ax, ay = self._alphas(h.dtype)
        scaled = (h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2 + h[..., 2] ** 2
        return np.where(h[..., 2] > 0, 1 / (np.pi * ax * ay * scaled * scaled), 0)

    @staticmethod
    def smith_lambda(w, alpha_x, alpha_y):
        z = np.maximum(w[..., 2], COSINE_EPSILON)
        a = ((alpha_x * w[..., 0]) ** 2 + (alpha_y * w[..., 1]) ** 2) / (z * z)
        return a / (2 * (1 + np.sqrt(1 + a)))

    def _m_factor(self, wo, wi, h):
        ax, ay = self._alphas(wo.dtype)
        no, ni, visible = _cosines(wo, wi)
        shadowing = 1 / (1 + self.smith_lambda(wo, ax, ay) + self.smith_lambda(wi, ax, ay))
        return np.where(visible, shadowing / (4 * ni * no), 0)

    def ndf_lobes(self, lobe_count=4):
        ax, ay = self._alphas(_dtype(self.alpha_x, self.alpha_y))
        return ndf_fit.ggx_anisotropic_lobes(ax, ay, lobe_count)

    def half_vector_pdf(self, h):
        return self.ndf(h) * np.maximum(h[..., 2], 0)

    def sample_half_vector(self, u1, u2):
        """h with density D(h) (n.h): unit-alpha GGX slopes (tan^2 = u1 / (1 - u1)) stretched by the alphas."""
        ax, ay = self._alphas(u1.dtype)
        radius = np.sqrt(u1 / np.maximum(1 - u1, 1e-12))
        phi = 2 * np.pi * u2
        return _unit(np.stack(np.broadcast_arrays(-ax * radius * np.cos(phi), -ay * radius * np.sin(phi),
                                                  np.ones_like(radius)), axis=-1))


@dataclass(frozen=True, eq=False)
class Lambert(_Microfacet):
    """Lambertian kd/pi in the same protocol: ndf = 1 (an SG of sharpness 0), M = kd/pi."""
    kd: object = 1.0

    def ndf(self, h):
        h = np.asarray(h)
        return np.ones_like(h[..., 2])

    def _m_factor(self, wo, wi, h):
        _, _, visible = _cosines(wo, wi)
        return np.where(visible, _param(self.kd, wo.dtype) * INV_PI, 0)

    def ndf_lobes(self):
        kd = np.asarray(self.kd, dtype=_dtype(self.kd))
        return _frame_lobes(kd, np.zeros_like(kd), np.ones_like(kd))

    def sample(self, wo, u):
        """Cosine-weighted hemisphere."""
        (wo,) = _directions(wo)
        u1, u2 = _uniforms(u, wo.dtype)
        wi = _from_spherical(np.sqrt(1 - u1), 2 * np.pi * u2)
        return wi, self.pdf(wo, wi)

    def pdf(self, wo, wi):
        (wi,) = _directions(wi)
        return np.maximum(wi[..., 2], 0) * INV_PI


_MODELS = {
    "COOK_TORRANCE": (CookTorrance, {"roughness": "roughness", "ior": "ior"}),
    "COOK_TORRANCE_BECKMANN": (CookTorranceBeckmann, {"roughness": "roughness", "ior": "ior"}),
    "BLINN_PHONG": (BlinnPhong, {"exponent": "exponent"}),
    "WARD_ISO": (WardIsotropic, {"alpha_x": "alpha_x"}),
    "WARD_ANISO": (WardAnisotropic, {"alpha_x": "alpha_x", "alpha_y": "alpha_y"}),
    "ASHIKHMIN_SHIRLEY": (AshikhminShirley, {"nu": "nu", "nv": "nv", "rf0": "rf0"}),
    "GGX": (GGX, {"roughness": "roughness"}),
    "BECKMANN": (Beckmann, {"roughness": "roughness"}),
    "GGX_ANISO": (GGXAnisotropic, {"alpha_x": "alpha_x", "alpha_y": "alpha_y"}),
    "LAMBERT": (Lambert, {"kd": "kd"}),
}


def model_from_name(name, **params):
    """Model for the Blender material enum ``name``; parameters the model does not use
    (the UI stores every model's properties) are ignored."""
    try:
        cls, accepted = _MODELS[name.upper()]
    except KeyError:
        raise ValueError(f"unknown BRDF model {name!r}; expected one of {sorted(_MODELS)}") from None
    return cls(**{accepted[k]: v for k, v in params.items() if k in accepted})
