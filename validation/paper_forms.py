"""wang2009's forms as printed that the engine replaces, kept to measure them (docs/ACCURACY.md): the appendix's
sigmoid for fh (eq. 47-48) and the diffuse integral through the one-lobe clamped cosine C* (eq. 39-40)."""
import numpy as np

from sg_prt_addon.spherical import clamped_cosine, hemisphere, sg

# The appendix's constants as printed in our copy
PAPER_SIGMOID_SCALE = 1.05
PAPER_K_COEFFICIENTS = (0.204, -0.892, 2.995, 0.067)  # k = 0.204 l^3 - 0.892 l^2 + 2.995 l + 0.067


def fh_normalized_paper(theta_d, sharpness):
    """wang2009 appendix (eq. 47-48) as printed in our copy, read as
    a / (1 + exp(-k theta_d)) + (1 - a) / 2 with a = 1.05 and k cubic in lambda,
    clamped to [0, 1].  Kept only to measure it: it is off by 0.2-0.5 for lambda <= 100.
    """
    theta = hemisphere.clamp_theta(theta_d)
    lam = np.asarray(sharpness, theta.dtype)
    c3, c2, c1, c0 = PAPER_K_COEFFICIENTS
    k = ((c3 * lam + c2) * lam + c1) * lam + c0
    z = -k * theta
    # Logistic in overflow-free form.
    e = np.exp(-np.abs(z))
    logistic = np.where(z <= 0, 1 / (1 + e), e / (1 + e))
    a = PAPER_SIGMOID_SCALE
    return np.clip(a * logistic + (1 - a) / 2, 0, 1).astype(theta.dtype, copy=False)


def sg_clamped_cosine_integral_paper(axis, sharpness, amplitude, normal):
    """wang2009 eq. 39-40: integral of G(i; p, lambda, mu) C*(i; n), i.e. the SG inner
    product (eq. 5) of the light lobe with the eq. 40 lobe (visibility left out)."""
    normal = np.asarray(normal)
    dtype = sg._float_dtype(axis, sharpness, amplitude, normal)
    lobe_sharpness = np.asarray(clamped_cosine.CLAMPED_COSINE_SHARPNESS, dtype)
    lobe_amplitude = np.asarray(clamped_cosine.CLAMPED_COSINE_AMPLITUDE, dtype)
    return sg.inner_product(sg.normalize(axis), np.asarray(sharpness, dtype), np.asarray(amplitude, dtype),
                            sg.normalize(normal), lobe_sharpness, lobe_amplitude)
