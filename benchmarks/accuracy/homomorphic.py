"""Accuracy of the homomorphic factorization (measured/homomorphic.py, mccool2001): the factored BRDF
against its source at every pair of a 128 x 128 hemisphere lattice (not the fit's 256 x 256), cosine
weighted, per model, form and resolution; and the SG lobe fit of the same measured BRDF beside it."""
from sg_prt_addon.measured import homomorphic
from sg_prt_addon.reflectance import brdf
from validation.brdf_generators import AnalyticMaterial

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
        for form in ("pq", "pqp", "pqpr"):
            errors = {}
            for resolution in (16, 32, 64):
                factorization = homomorphic.factorize(wo, wi, values, form=form, resolution=resolution)
                errors[resolution] = (homomorphic.relative_rms(factorization, source), factorization.seconds)
            best = min(errors, key=lambda r: errors[r][0])
            rows.append(dict(
                name=f"{name}: {homomorphic.FORM_LABELS[form]}",
                reference="the source BRDF, 128 x 128 hemisphere pairs",
                metric="relative RMS of f (n.i), resolution 32 (max: the worst of 16 / 32 / 64)",
                max_error=max(error for error, _ in errors.values()), mean_error=errors[32][0],
                paper="pqp" if form == "pqp" else None,
                note=", ".join(f"{r}: {e:.3f} ({s:.1f} s)" for r, (e, s) in errors.items()) + f"; best {best}"))
    return rows
