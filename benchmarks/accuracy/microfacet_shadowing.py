"""Accuracy of the models' Smith shadowing where a closed form is replaced: Beckmann's Lambda by Walter et al.
2007's rational form (reflectance.brdf.Beckmann, Cycles' own).

Reference: the exact Lambda(a) = (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi)), a = 1 / (alpha tan theta).
"""
import math

import numpy as np

from sg_prt_addon.reflectance import brdf


def beckmann_lambda_errors(a=np.linspace(0.01, 6.0, 6000), alpha=0.3):
    """|Lambda - exact| / (1 + exact) at each a: what G1 = 1 / (1 + Lambda) takes of the error."""
    exact = np.array([(math.erf(v) - 1) / 2 + math.exp(-v * v) / (2 * v * math.sqrt(math.pi)) for v in a])
    theta = np.arctan(1 / (alpha * a))
    w = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=-1)
    return np.abs(brdf.Beckmann.smith_lambda(w, alpha) - exact) / (1 + exact)


def measure():
    errors = beckmann_lambda_errors()
    return [dict(name="Beckmann's Smith Lambda, Walter et al.'s rational form",
                 reference="the exact (erf(a) - 1) / 2 + exp(-a^2) / (2 a sqrt(pi))",
                 metric="|Lambda - exact| / (1 + exact) over a = 1 / (alpha tan theta) in 0.01..6 (max / mean)",
                 max_error=float(errors.max()), mean_error=float(errors.mean()),
                 note="largest near a = 1.3; the form is cut to 0 at a = 1.6, as Cycles'")]
