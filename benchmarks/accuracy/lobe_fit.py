"""Measured-BRDF lobe fitting (wang2009 section 4.2, measured.microfacet_fit) on generated data.

Each material is generated analytically (validation.brdf_generators), written as a noisy MERL
file (2% log-normal noise, 1e-4 corrupt samples) or sampled per texel (SVBRDF), then
factorized into kd, ks, eta, tabulated D and S (eq. 13), S PCA-compressed, D fitted by
1, 2 (z+, Levenberg-Marquardt) or 4 (free axes, TNC) SG lobes.  The error is the relative
RMSE of the cosine-weighted BRDF rho(o, i) (i.n) over hemisphere x hemisphere against the
noise-free analytic BRDF, on a half/difference quadrature independent of the fitting grid.
"""
import os
import tempfile

import numpy as np

from sg_prt_addon.measured import merl, microfacet_fit
from validation import brdf_generators

METRIC = "relative RMSE of rho (i.n), 4D"
METRIC_IO = "relative RMSE of rho (i.n)(o.n), 4D"
REFERENCE = "noise-free analytic BRDF, 64x32x32x2 half/difference quadrature"

MATERIALS = {
    "GGX r=0.3 + Fresnel + Lambert, separable Smith (eq. 13's class)": brdf_generators.AnalyticMaterial(
        diffuse=(0.2, 0.15, 0.1), oren_nayar_sigma=0.0, roughness=0.3, eta=1.5, retro=(0, 0, 0),
        separable_shadowing=True),
    "GGX r=0.3 + Fresnel + Lambert, height-correlated Smith": brdf_generators.AnalyticMaterial(
        diffuse=(0.2, 0.15, 0.1), oren_nayar_sigma=0.0, roughness=0.3, eta=1.5, retro=(0, 0, 0)),
    "GGX r=0.15 + Fresnel + Oren-Nayar 0.3 + retro-reflection": brdf_generators.AnalyticMaterial(
        roughness=0.15, eta=1.4, oren_nayar_sigma=0.3, retro=(0.03, 0.03, 0.03)),
}


def _row(name, errors, note="", metric=METRIC):
    errors = np.atleast_1d(errors)
    return {"name": name, "reference": REFERENCE, "metric": metric, "max_error": float(errors.max()),
            "mean_error": float(errors.mean()), "note": note}


def _merl_rows(label, material, directory):
    path = os.path.join(directory, "material.binary")
    brdf_generators.generate_merl(path, material, seed=7)
    brdf = merl.read_merl(path)
    os.remove(path)
    wo, wi, rho, valid, weights = microfacet_fit.merl_samples(brdf)
    factorization = microfacet_fit.factorize(wo, wi, rho, weights, valid, eta=microfacet_fit.DEFAULT_ETA_CANDIDATES)
    reference = lambda a, b, texels: material.evaluate(a, b)[None]  # noqa: E731
    table = factorization.to_table((1, 1))
    rows = [_row(f"MERL {label}: tabulated D and S (no SG)", microfacet_fit.relative_rmse(reference, table.evaluate),
                 f"MERL bins are 1 degree wide in theta_d: coarse at grazing; factorization residual "
                 f"{factorization.residual[0]:.3g}, eta chosen {factorization.eta[0]:.2f} "
                 f"(true {material.eta})")]
    for lobe_count in (1, 2, 4):
        fit = microfacet_fit.fit_lobes(factorization, lobe_count)
        note = f"relative L2 of D {fit.ndf_error[0]:.3g}" + (", free axes" if lobe_count > 2 else "")
        rows.append(_row(f"MERL {label}: {lobe_count} SG lobes", microfacet_fit.relative_rmse(reference, fit.evaluate),
                         note))
        rows.append(_row(f"MERL {label}: {lobe_count} SG lobes",
                         microfacet_fit.relative_rmse(reference, fit.evaluate, cosines="io"), note, METRIC_IO))
    return rows


def _svbrdf_rows(size=6):
    params = brdf_generators.spatial_parameters(size)
    material = brdf_generators.AnalyticMaterial(diffuse=params["diffuse"], specular=params["specular"],
                                                roughness=params["roughness"], eta=params["eta"],
                                                oren_nayar_sigma=0.0, retro=(0, 0, 0), separable_shadowing=True)
    wo, wi, weights = microfacet_fit.half_difference_samples(64, 32, 32, 1, offset=0.6)
    rho = brdf_generators.sample_svbrdf_measurements(material, wo, wi)
    factorization = microfacet_fit.factorize(wo, wi, rho, weights, eta=microfacet_fit.DEFAULT_ETA_CANDIDATES)

    def reference(a, b, texels):
        part = brdf_generators.AnalyticMaterial(
            diffuse=params["diffuse"][texels], specular=params["specular"][texels],
            roughness=params["roughness"][texels], eta=params["eta"][texels], oren_nayar_sigma=0.0,
            retro=(0, 0, 0), separable_shadowing=True)
        return part.evaluate(a, b)

    reference.texel_count = size * size
    label = f"SVBRDF {size}x{size} GGX roughness 0.1-0.7, separable Smith, per-texel samples"
    rows = []
    for lobe_count in (1, 2, 4):
        fit = microfacet_fit.fit_lobes(factorization, lobe_count)
        note = f"over texels; S by PCA 8 of 90; mean relative L2 of D {fit.ndf_error.mean():.3g}"
        rows.append(_row(f"{label}: {lobe_count} SG lobes", microfacet_fit.relative_rmse(reference, fit.evaluate),
                         note))
        rows.append(_row(f"{label}: {lobe_count} SG lobes",
                         microfacet_fit.relative_rmse(reference, fit.evaluate, cosines="io"), note, METRIC_IO))
    return rows


def measure():
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for label, material in MATERIALS.items():
            rows.extend(_merl_rows(label, material, directory))
    rows.extend(_svbrdf_rows())
    return rows


if __name__ == "__main__":
    for row in measure():
        print(f"{row['name']} [{row['metric']}]: max {row['max_error']:.4f} mean {row['mean_error']:.4f}  "
              f"{row['note']}")
