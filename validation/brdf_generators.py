"""Synthetic 'measured' BRDFs for tests and benchmarks (no measured database is reachable).

``AnalyticMaterial`` is deliberately not a sum of SGs and not exactly the microfacet
form of wang2009 eq. 13: an Oren-Nayar base (qualitative model), a GGX lobe with
dielectric Fresnel and height-correlated Smith shadowing (reflectance.brdf.GGX), and a
retro-reflective cosine-power lobe around the view direction.  Parameters are scalars
or arrays with a leading texel axis (B,) for spatially-varying materials.

``generate_merl`` tabulates a material at the MERL bin centres with measurement-like
noise (multiplicative log-normal, plus a few negative / NaN / Inf samples) and writes
it; ``generate_svbrdf_table`` makes a small SVBRDF table (measured.svbrdf_table) whose
NDF is a GGX / Beckmann blend (not a GGX) with noise and spatially varying roughness,
colours and eta.
"""
from dataclasses import dataclass

import numpy as np

from sg_prt_addon.measured import merl
from sg_prt_addon.measured.svbrdf_table import SvbrdfTable, default_ndf_theta, default_shadowing_theta
from sg_prt_addon.reflectance import brdf

HALF_PI = 0.5 * np.pi


def _texel_param(value):
    """Scalar or (B,) parameter broadcastable against (B, N) pair values."""
    value = np.asarray(value, np.float64)
    return value[..., None] if value.ndim >= 1 else value


def _colour(value):
    """Colour (3,) or (B, 3) broadcastable against (B, N, 3)."""
    value = np.asarray(value, np.float64)
    return value[:, None, :] if value.ndim == 2 else value


@dataclass(frozen=True)
class AnalyticMaterial:
    diffuse: object = (0.3, 0.2, 0.1)      # Oren-Nayar albedo
    oren_nayar_sigma: object = 0.3         # facet slope deviation (radians)
    specular: object = (1.0, 1.0, 1.0)     # colour of the GGX lobe
    roughness: object = 0.3                # GGX with Blender's alpha = roughness^2
    eta: object = 1.5                      # relative index for the Fresnel factor
    retro: object = (0.02, 0.02, 0.02)     # retro-reflective albedo-like weight
    retro_exponent: object = 20.0          # (o.i)^e lobe width
    separable_shadowing: bool = False      # G1(o) G1(i) instead of the height-correlated Smith G

    def specular_scalar(self, wo, wi):
        """F(i.h) * GGX rho_s (B, N) or (N,): the glossy part without colour."""
        wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
        roughness = _texel_param(self.roughness)
        ggx = brdf.GGX(roughness=roughness)
        h = brdf.half_vector(wo, wi)
        fresnel = brdf.fresnel_dielectric(np.sum(wi * h, axis=-1), _texel_param(self.eta))
        if not self.separable_shadowing:
            return fresnel * ggx.specular(wo, wi)
        # the uncorrelated Smith form is exactly eq. 13's S(o) S(i): the fit's model class
        alpha = np.maximum(roughness * roughness, 1e-9)
        masking = 1 / ((1 + ggx.smith_lambda(wo, alpha)) * (1 + ggx.smith_lambda(wi, alpha)))
        cosines = 4 * np.maximum(wo[..., 2], 1e-7) * np.maximum(wi[..., 2], 1e-7)
        above = (wo[..., 2] > 0) & (wi[..., 2] > 0)
        return np.where(above, fresnel * masking * ggx.ndf(h) / cosines, 0.0)

    def evaluate(self, wo, wi):
        """rho(o, i) (..., N, 3); directions (N, 3) or (B, N, 3); 0 below either horizon."""
        wo, wi = np.asarray(wo, np.float64), np.asarray(wi, np.float64)
        cos_o, cos_i = wo[..., 2], wi[..., 2]
        above = (cos_o > 0) & (cos_i > 0)
        sigma2 = _texel_param(self.oren_nayar_sigma) ** 2
        a = 1 - 0.5 * sigma2 / (sigma2 + 0.33)
        b = 0.45 * sigma2 / (sigma2 + 0.09)
        # max(0, cos(phi_i - phi_o)) sin(alpha) tan(beta) = max(0, o_t.i_t) / max(cos_o, cos_i)
        tangential = np.maximum(wo[..., 0] * wi[..., 0] + wo[..., 1] * wi[..., 1], 0)
        oren_nayar = (a + b * tangential / np.maximum(np.maximum(cos_o, cos_i), 1e-7)) / np.pi
        cos_oi = np.clip(np.sum(wo * wi, axis=-1), 0, 1)
        retro_lobe = cos_oi ** _texel_param(self.retro_exponent) / np.pi
        value = (_colour(self.diffuse) * oren_nayar[..., None]
                 + _colour(self.specular) * self.specular_scalar(wo, wi)[..., None]
                 + _colour(self.retro) * retro_lobe[..., None])
        return np.where(above[..., None], value, 0.0)

    __call__ = evaluate


def add_measurement_noise(rho, rng, relative_noise=0.02, corrupt_fraction=0.0):
    """rho with multiplicative log-normal noise, and ``corrupt_fraction`` of the samples set
    to -1, NaN or +Inf in equal parts (what measured files contain)."""
    noisy = rho * np.exp(relative_noise * rng.standard_normal(rho.shape))
    if corrupt_fraction > 0:
        flat = noisy.reshape(-1)
        picked = rng.choice(flat.size, int(round(corrupt_fraction * flat.size)), replace=False)
        flat[picked] = np.array([-1.0, np.nan, np.inf])[np.arange(len(picked)) % 3]
    return noisy


def generate_merl(path, material=None, seed=0, relative_noise=0.02, corrupt_fraction=1e-4):
    """Tabulate ``material`` (default AnalyticMaterial()) at the MERL bin centres, add noise,
    write a MERL file at ``path``; returns the noise-free table rho (90, 90, 180, 3).
    Bins with a direction below the horizon hold -1, like measured files.  About 2 s."""
    material = AnalyticMaterial() if material is None else material
    clean = merl.tabulate(material.evaluate)
    rng = np.random.default_rng(seed)
    noisy = np.where(clean < 0, clean, add_measurement_noise(clean, rng, relative_noise, corrupt_fraction))
    merl.write_merl(path, noisy)
    return clean


def _beckmann(theta, m):
    tan2 = np.tan(np.minimum(theta, HALF_PI - 1e-6)) ** 2
    return np.exp(-tan2 / (m * m)) / (np.pi * m * m * np.cos(theta) ** 4)


def _ggx(theta, alpha):
    scaled = (np.sin(theta) / alpha) ** 2 + np.cos(theta) ** 2
    return 1 / (np.pi * alpha * alpha * scaled * scaled)


def spatial_parameters(size=16, seed=0):
    """Per-texel parameters of a size x size material, flattened to (size*size,): roughness
    0.15..0.6 along x, colours along y, eta 1.3..1.7 in a checker, smooth random jitter."""
    rng = np.random.default_rng(seed)
    v, u = np.meshgrid(np.linspace(0, 1, size), np.linspace(0, 1, size), indexing="ij")
    jitter = 0.03 * rng.standard_normal((size, size))
    checker = ((np.arange(size)[:, None] // 4 + np.arange(size)[None, :] // 4) % 2).astype(float)
    return {
        "roughness": (0.15 + 0.45 * u + jitter).clip(0.1, 0.7).ravel(),
        "diffuse": np.stack([0.1 + 0.4 * v, 0.3 - 0.2 * v, 0.2 + 0.0 * v], axis=-1).reshape(-1, 3),
        "specular": np.stack([0.8 + 0.2 * v, 0.8 + 0.0 * v, 1.0 - 0.2 * v], axis=-1).reshape(-1, 3),
        "eta": (1.3 + 0.4 * checker).ravel(),
        "beckmann_weight": (0.3 * (1 - v)).ravel(),  # how far the NDF departs from GGX
    }


def generate_svbrdf_table(size=16, seed=0, relative_noise=0.02, ndf_theta=None, shadowing_theta=None):
    """(SvbrdfTable (size, size), parameters dict) with isotropic tabulated NDFs: a blend of
    GGX(alpha) and Beckmann(1.3 alpha) per texel (weights in parameters), each normalized
    (integral of D cos = 1), S = Smith G1 of the GGX, both with log-normal noise."""
    params = spatial_parameters(size, seed)
    rng = np.random.default_rng(seed + 1)
    ndf_theta = default_ndf_theta() if ndf_theta is None else np.asarray(ndf_theta, np.float64)
    shadowing_theta = default_shadowing_theta() if shadowing_theta is None else np.asarray(shadowing_theta)
    alpha = params["roughness"][:, None] ** 2
    weight = params["beckmann_weight"][:, None]
    ndf = (1 - weight) * _ggx(ndf_theta, alpha) + weight * _beckmann(ndf_theta, 1.3 * alpha)
    ndf *= np.exp(relative_noise * rng.standard_normal(ndf.shape))
    tan2 = np.tan(np.minimum(shadowing_theta, HALF_PI - 1e-6)) ** 2
    smith_lambda = 0.5 * (np.sqrt(1 + alpha * alpha * tan2) - 1)
    shadowing = np.clip(1 / (1 + smith_lambda) * np.exp(relative_noise * rng.standard_normal(smith_lambda.shape)),
                        0, 1)
    texel = (size, size)
    table = SvbrdfTable(
        diffuse=params["diffuse"].reshape(texel + (3,)).astype(np.float32),
        specular=params["specular"].reshape(texel + (3,)).astype(np.float32),
        eta=params["eta"].reshape(texel).astype(np.float32),
        ndf_theta=ndf_theta, ndf_phi=np.zeros(1),
        ndf=ndf.reshape(texel + (len(ndf_theta), 1)).astype(np.float32),
        shadowing_theta=shadowing_theta,
        shadowing=shadowing.reshape(texel + (len(shadowing_theta),)).astype(np.float32))
    return table.validate(), params


def sample_svbrdf_measurements(material, wo, wi, seed=0, relative_noise=0.02):
    """Noisy per-texel samples (B, N, 3) of a spatially-varying AnalyticMaterial (parameters
    with a leading (B,) axis) at shared direction pairs (N, 3): a 'measured' SVBRDF."""
    rho = material.evaluate(wo, wi)
    return add_measurement_noise(rho, np.random.default_rng(seed), relative_noise)
