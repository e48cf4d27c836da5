"""SG-mixture fit of an environment map for diffuse lighting (wang2009 section 6, eq. 39).

The diffuse term R_d = (C*(i; n) (x) L*(i)) . V(i) needs the lighting as a few
SG lobes L*(i) = sum_k G(i; p_k, lambda_k, mu_k) with RGB amplitudes mu_k.  As in
Tsai & Shih 2006 the lobes are placed greedily on the brightest regions, then
refined jointly by nonlinear least squares (scipy ``least_squares``) on a
downsampled, solid-angle weighted map.  The objective mixes

- the radiance L2 error (the paper's criterion), and
- the error of the diffuse irradiance E(n) = int L(i) max(0, n.i) di over all
  normals, which is what diffuse shading actually sees,

weighted by ``irradiance_weight``.  ``FitReport`` gives both errors, the
irradiance one computed exactly (quadrature of the fitted mixture against the
clamped cosine, compared with the same quadrature of the map).
"""
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from ..spherical import sg
from . import equirect
from .env_prefilter import _equirect_pyramid

MIN_SHARPNESS = 0.05



def max_sharpness_for(fit_height):
    """Sharpest lobe the fit grid resolves (std 1/sqrt(lambda) >= one row, pi / height): sharper lobes
    would be point-sampled by the quadrature, and diffuse lighting cannot tell them apart anyway."""
    return (fit_height / np.pi) ** 2


@dataclass
class EnvironmentSGFit:
    """axis (K, 3), sharpness (K,), amplitude (K, C): the mixture L*(i) = sum_k G(i; p_k, lambda_k, mu_k)."""
    axis: np.ndarray
    sharpness: np.ndarray
    amplitude: np.ndarray

    def evaluate(self, direction):
        """L*(direction) (..., 3) -> (..., C)."""
        direction = np.asarray(direction)[..., None, :]
        weights = sg.evaluate(direction, self.axis, self.sharpness)  # (..., K)
        return weights @ self.amplitude


@dataclass
class FitReport:
    radiance_rms_error: float  # solid-angle RMS of L* - L, relative to the RMS of L
    irradiance_max_error: float  # max over normals of |E* - E| / max_n E
    irradiance_rms_error: float  # RMS over normals of |E* - E| / mean_n E
    irradiance_max_error_eq40: float  # same, E* through the paper's one-lobe clamped cosine (eq. 40)


def fibonacci_sphere(count):
    """Nearly uniform unit vectors (count, 3)."""
    k = np.arange(count) + 0.5
    z = 1 - 2 * k / count
    phi = k * np.pi * (3 - np.sqrt(5))
    r = np.sqrt(np.maximum(1 - z * z, 0))
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=-1)


def _downsampled(image, height):
    pyramid = _equirect_pyramid(np.asarray(image, dtype=np.float32), min_height=max(height // 2, 1))
    for level in pyramid:
        if level.shape[0] <= height:
            return level.astype(np.float64)
    return pyramid[-1].astype(np.float64)


def cosine_irradiance_matrix(normals, height, width):
    """(N, H*W) matrix: irradiance at each normal = matrix @ radiance.reshape(-1, C) (texel quadrature)."""
    directions = equirect.texel_directions(height, width).reshape(-1, 3)
    omega = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    return np.maximum(normals @ directions.T, 0.0) * omega


def _unpack(params, lobes, channels):
    per_lobe = params.reshape(lobes, 4 + channels)
    axis = sg.normalize(per_lobe[:, :3])
    sharpness = np.exp(per_lobe[:, 3])
    amplitude = per_lobe[:, 4:]
    return axis, sharpness, amplitude


def _greedy_init(radiance, directions, omega, lobes):
    """Place lobes one at a time on the brightest remaining texel, sharpness from a small search."""
    residual = radiance.copy()
    candidates = np.array([1.0, 3.0, 10.0, 30.0, 100.0])
    candidates = candidates[candidates <= max_sharpness_for(np.sqrt(directions.shape[0] / 2))]
    available = np.ones(directions.shape[0], bool)
    params = []
    for _ in range(lobes):
        # identical lobes would stay identical under the optimizer (symmetric gradients): each new
        # lobe starts away from the previous ones
        luminance = np.where(available, residual.mean(axis=1), -np.inf)
        axis = directions[np.argmax(luminance)]
        best = None
        for sharpness in candidates:
            g = sg.evaluate(directions, axis, sharpness)
            # non-negative least-squares amplitude for this shape, per channel
            amplitude = np.maximum((omega * g) @ residual / max(float((omega * g) @ g), 1e-30), 0.0)
            cost = float(omega @ np.sum((residual - g[:, None] * amplitude) ** 2, axis=1))
            if best is None or cost < best[0]:
                best = (cost, sharpness, amplitude, g)
        _, sharpness, amplitude, g = best
        residual = residual - g[:, None] * amplitude
        available &= directions @ axis < np.cos(max(0.3, 1.0 / np.sqrt(sharpness)))
        if not np.any(available):
            available[:] = True
        params.append(np.concatenate([axis, [np.log(sharpness)], amplitude]))
    return np.concatenate(params)


def fit_environment_sg(equirect_image, lobes=8, fit_height=32, irradiance_weight=100.0, normal_count=128,
                       max_nfev=50):
    """Fit ``lobes`` (< 10) SGs with RGB amplitudes to an equirect map (H, W, C) for diffuse lighting.

    The map is downsampled to ``fit_height`` rows (solid-angle weighted), lobes
    are initialised greedily on the brightest regions and refined by
    least squares on radiance residuals (weighted by sqrt(solid angle)) plus
    ``irradiance_weight`` times irradiance residuals at ``normal_count``
    normals (scaled so both terms are comparable).  Returns an EnvironmentSGFit.
    """
    if lobes < 1:
        raise ValueError("at least one lobe")
    image = np.nan_to_num(np.asarray(equirect_image, dtype=np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    small = _downsampled(image, fit_height)
    height, width, channels = small.shape
    directions = equirect.texel_directions(height, width).reshape(-1, 3)
    omega = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    radiance = small.reshape(-1, channels)
    normals = fibonacci_sphere(normal_count)
    cosine = cosine_irradiance_matrix(normals, height, width)
    target_irradiance = cosine @ radiance
    sqrt_omega = np.sqrt(omega)[:, None]
    # put both terms on the same scale: radiance residual norm ~ sqrt(4 pi) L, irradiance ~ pi L per normal
    irradiance_scale = irradiance_weight * np.sqrt(sg.FOUR_PI / normal_count) / np.pi

    def model_and_jacobian(params, with_jacobian):
        per_lobe = params.reshape(lobes, 4 + channels)
        raw_axis = per_lobe[:, :3]
        length = np.maximum(np.linalg.norm(raw_axis, axis=1), 1e-12)
        axis = raw_axis / length[:, None]
        sharpness = np.exp(per_lobe[:, 3])
        amplitude = per_lobe[:, 4:]
        cos_term = directions @ axis.T - 1.0  # (J, K), d.p - 1
        lobe = np.exp(sharpness * np.minimum(cos_term, 0.0))  # G_k(d_j)
        model = lobe @ amplitude  # (J, C)
        if not with_jacobian:
            return model, None
        # d model_jc / d params_k: amplitude -> G, log sharpness -> G lambda (d.p - 1) a,
        # raw axis v -> G lambda (I - p p^T) d / |v| a
        jac = np.zeros((directions.shape[0], channels, lobes, 4 + channels))
        tangent = (directions[:, None, :] - (directions @ axis.T)[..., None] * axis[None]) / length[None, :, None]
        grad_axis = (lobe * sharpness)[..., None] * tangent  # (J, K, 3)
        grad_log_sharpness = lobe * sharpness * cos_term  # (J, K)
        jac[:, :, :, :3] = grad_axis[:, None, :, :] * amplitude.T[None, :, :, None]
        jac[:, :, :, 3] = grad_log_sharpness[:, None, :] * amplitude.T[None]
        for c in range(channels):
            jac[:, c, :, 4 + c] = lobe
        return model, jac.reshape(directions.shape[0], channels, -1)

    def residuals(params):
        model, _ = model_and_jacobian(params, False)
        radiance_part = (sqrt_omega * (model - radiance)).ravel()
        irradiance_part = (irradiance_scale * (cosine @ model - target_irradiance)).ravel()
        return np.concatenate([radiance_part, irradiance_part])

    def jacobian(params):
        _, jac = model_and_jacobian(params, True)
        radiance_rows = (sqrt_omega[:, :, None] * jac).reshape(-1, jac.shape[2])
        irradiance_rows = irradiance_scale * np.einsum("nj,jcp->ncp", cosine, jac).reshape(-1, jac.shape[2])
        return np.concatenate([radiance_rows, irradiance_rows])

    start = _greedy_init(radiance, directions, omega, lobes)
    lower = np.tile(np.r_[[-2.0] * 3, np.log(MIN_SHARPNESS), [0.0] * channels], lobes)
    upper = np.tile(np.r_[[2.0] * 3, np.log(max_sharpness_for(height)), [np.inf] * channels], lobes)
    start = np.clip(start, lower, np.where(np.isfinite(upper), upper, start + 1))
    solution = least_squares(residuals, start, jac=jacobian, bounds=(lower, upper), max_nfev=max_nfev, tr_solver="lsmr",
                             x_scale="jac")
    axis, sharpness, amplitude = _unpack(solution.x, lobes, channels)
    return EnvironmentSGFit(axis, sharpness, amplitude)


def _clamped_cosine_eq40_irradiance(fit, normals):
    """E*(n) with the paper's single-lobe clamped cosine C*(i; n) = G(i; n, 2.133, 1.170) (eq. 40)."""
    inner = sg.inner_product(normals[:, None, :], 2.133, 1.170, fit.axis[None], fit.sharpness[None], 1.0)
    return inner @ fit.amplitude


def evaluate_fit(fit, equirect_image, reference_height=128, normal_count=400):
    """Errors of a fit against the map: radiance (solid-angle RMS) and diffuse irradiance over normals.

    Both irradiances use the same quadrature on a ``reference_height`` x 2
    ``reference_height`` grid: the map's (downsampled, solid-angle weighted; the
    cosine kernel is smooth so this is accurate) and the mixture's (evaluated
    at the texel centres; fitted lobes are at most max_sharpness_for(fit height), resolved there).
    """
    image = np.nan_to_num(np.asarray(equirect_image, dtype=np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    small = _downsampled(image, reference_height)
    height, width, channels = small.shape
    directions = equirect.texel_directions(height, width).reshape(-1, 3)
    omega = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    radiance = small.reshape(-1, channels)
    model = fit.evaluate(directions)
    radiance_error = np.sqrt(omega @ np.sum((model - radiance) ** 2, axis=1) / max(omega @ np.sum(radiance ** 2, axis=1), 1e-300))
    normals = fibonacci_sphere(normal_count)
    cosine = cosine_irradiance_matrix(normals, height, width)
    exact = cosine @ radiance
    fitted = cosine @ model
    eq40 = _clamped_cosine_eq40_irradiance(fit, normals)
    peak = max(float(np.max(exact)), 1e-300)
    mean = max(float(np.mean(exact)), 1e-300)
    return FitReport(
        radiance_rms_error=float(radiance_error),
        irradiance_max_error=float(np.max(np.abs(fitted - exact)) / peak),
        irradiance_rms_error=float(np.sqrt(np.mean((fitted - exact) ** 2)) / mean),
        irradiance_max_error_eq40=float(np.max(np.abs(eq40 - exact)) / peak),
    )
