"""Accuracy of the homomorphic factorization (measured/homomorphic.py, mccool2001): the factored BRDF
against its source at every pair of a 128 x 128 hemisphere lattice (not the fit's 256 x 256), cosine
weighted, per model, form, resolution and map (parabolic, the paper's and the technique's, and
hemi-octahedral for the three-factor form with r); and, on one measured BRDF (a MERL file of the generated
material), the Fit Lobes operator's SG lobe fit (wang2009) beside the Factor BRDF operator's factors, both
scored against the analytic material the file was made from."""
import os
import tempfile

import numpy as np

from sg_prt_addon.measured import homomorphic, merl, microfacet_fit
from sg_prt_addon.reflectance import brdf
from validation import brdf_generators
from validation.brdf_generators import AnalyticMaterial

RESOLUTIONS = (16, 32, 64, 128)
SOURCES = {
    "GGX r=0.3": lambda wo, wi: brdf.GGX(roughness=0.3).specular(wo, wi),
    "GGX r=0.6": lambda wo, wi: brdf.GGX(roughness=0.6).specular(wo, wi),
    "Cook-Torrance m=0.2 (Fresnel)": lambda wo, wi: brdf.CookTorrance(roughness=0.2).specular(wo, wi),
    "Blinn-Phong n=50": lambda wo, wi: brdf.BlinnPhong(exponent=50.0).specular(wo, wi),
    "Ward anisotropic 0.3 x 0.1": lambda wo, wi: brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.1).specular(wo, wi),
    "Ashikhmin-Shirley 50 x 500 (Fresnel)": lambda wo, wi: brdf.AshikhminShirley(nu=50, nv=500).specular(wo, wi),
    "generated measured BRDF (Oren-Nayar + GGX + Fresnel + retro-reflection, RGB)": AnalyticMaterial(),
}


def measure():
    rows = []
    for name, source in SOURCES.items():
        wo, wi, values = homomorphic.sample_brdf(source, 256, 256)
        cases = [(form, "parabolic") for form in ("pq", "pqp", "pqpr")] + [("pqpr", "octahedral")]
        for form, mapping in cases:
            errors = {}
            for resolution in RESOLUTIONS:
                factorization = homomorphic.factorize(wo, wi, values, form=form, resolution=resolution,
                                                      mapping=mapping)
                errors[resolution] = (homomorphic.relative_rms(factorization, source), factorization.seconds)
            best = min(errors, key=lambda r: errors[r][0])
            rows.append(dict(
                name=f"{name}: {homomorphic.FORM_LABELS[form]}" + (", octahedral maps" if mapping != "parabolic" else ""),
                reference="the source BRDF, 128 x 128 hemisphere pairs",
                metric="relative RMS of f (n.i), resolution 64 (max: the worst of 16 / 32 / 64 / 128)",
                max_error=max(error for error, _ in errors.values()), mean_error=errors[64][0],
                paper="pqp" if (form, mapping) == ("pqp", "parabolic") else None,
                note=", ".join(f"{r}: {e:.3f} ({s:.1f} s)" for r, (e, s) in errors.items()) + f"; best {best}"))
    return rows + _measured_rows()


def _relative_rms(function, truth, count=128):
    wo, wi, values = homomorphic.sample_brdf(truth, count, count)
    approximation = np.asarray(function(wo, wi)).reshape(values.shape)
    weight = wi[:, 2:3]
    return float(np.sqrt(np.sum(((approximation - values) * weight) ** 2) / np.sum((values * weight) ** 2)))


def _measured_rows():
    """A MERL file (no noise, no corrupt bins) of the generated material: lobes against factors."""
    truth = AnalyticMaterial()
    with tempfile.TemporaryDirectory() as directory:
        path = os.path.join(directory, "generated.binary")
        brdf_generators.generate_merl(path, relative_noise=0.0, corrupt_fraction=0.0)
        source = merl.read_merl(path)
    rows = []
    for lobe_count in (1, 2, 3):
        fit = microfacet_fit.fit_merl(source, lobe_count)
        rows.append(dict(name=f"measured BRDF (MERL of the generated material): SG lobe fit, {lobe_count} lobe(s)",
                         reference="the analytic material, 128 x 128 hemisphere pairs",
                         metric="relative RMS of f (n.i)", max_error=_relative_rms(lambda o, i: fit.evaluate(o, i)[0],
                                                                                   truth),
                         mean_error=None, note="Fit Lobes (microfacet_fit.fit_merl, eq. 13-14 + SG lobes)"))
    wo, wi, values = homomorphic.sample_merl(source)
    for resolution in (32, 64):
        factorization = homomorphic.factorize(wo, wi, values, form="pqpr", resolution=resolution)
        rows.append(dict(name=f"measured BRDF (MERL of the generated material): factors p q p r, {resolution}^2",
                         reference="the analytic material, 128 x 128 hemisphere pairs",
                         metric="relative RMS of f (n.i)", max_error=_relative_rms(factorization.evaluate, truth),
                         mean_error=None, note=f"Factor BRDF ({factorization.seconds:.1f} s)"))
    return rows
