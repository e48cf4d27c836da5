"""SG fits of microfacet NDFs (wang2009 section 4.1-4.2): reflectance.brdf ndf_lobes and reflectance.ndf_fit.

Two metrics: the relative L2 of D over the hemisphere (quadrature) and the relative
RMSE of the cosine-weighted specular BRDF M_o(i) D(h) (n.i) over hemisphere x
hemisphere (Monte Carlo, 100k pairs, importance + uniform mixture).
"""
import numpy as np

from sg_prt_addon.reflectance import brdf, ndf_fit
from validation import ndf_mappings

L2 = "relative L2 of D over the hemisphere"
RMSE = "relative RMSE of M D (n.i), 4D"
QUADRATURE = "exact D, Gauss-Legendre x uniform-phi quadrature"
MONTE_CARLO = "exact BRDF, 100k-pair Monte Carlo"


def _row(name, reference, metric, errors, note="", paper=None):
    errors = np.atleast_1d(np.asarray(errors, np.float64))
    row = {"name": name, "reference": reference, "metric": metric,
           "max_error": float(errors.max()), "mean_error": float(errors.mean()), "note": note}
    if paper is not None:
        row["paper"] = paper
    return row


def _curvature_mapping_errors(kind, widths):
    """The naive mapping: same peak and same second derivative at the pole (lambda w^2 = 2 - 4 w^2
    for Beckmann, 2 for Blinn-Phong and Ward, 4 for GGX)."""
    ndf_of_width = ndf_mappings.isotropic_ndf_of_width(kind)
    errors = []
    for width in widths:
        theta, weights = ndf_fit.polar_quadrature([width])
        scaled = {"BECKMANN": max(2 - 4 * width * width, 0.0), "GGX": 4.0}.get(kind, 2.0)
        lobe = np.exp(-scaled / width ** 2 * 2 * np.sin(0.5 * theta) ** 2)
        errors.append(ndf_fit.relative_l2(ndf_of_width(theta, width), lobe, weights))
    return np.array(errors)


def _isotropic_rows():
    rows = []
    roughness = [0.045, 0.1, 0.2, 0.3, 0.5]
    models = [brdf.CookTorrance(roughness=m) for m in roughness]
    rows.append(_row("Cook-Torrance 1 lobe, eq. 12 (lambda = 2/m^2)", QUADRATURE, L2,
                     [ndf_fit.ndf_l2_error(m, m.ndf_lobes()) for m in models], "m in 0.045..0.5"))
    rows.append(_row("Cook-Torrance 1 lobe, eq. 12", MONTE_CARLO, RMSE,
                     [ndf_fit.brdf_relative_rmse(m, m.ndf_lobes(), 100_000) for m in models], "m in 0.045..0.5"))
    for kind, label in (("BECKMANN", "Beckmann (CT, normalized) m"), ("BLINN_PHONG", "Blinn-Phong sqrt(2/n)"),
                        ("WARD_ISO", "Ward iso alpha"), ("GGX", "GGX alpha = roughness^2")):
        high = ndf_fit.ISOTROPIC_MAPPINGS[kind]["width_range"][1]
        widths = np.linspace(0.01, high, 25)
        mapping, optimal = ndf_mappings.isotropic_mapping_errors(kind, widths)
        curvature = _curvature_mapping_errors(kind, widths)
        rows.append(_row(f"{kind} 1 lobe, frozen L2 mapping", QUADRATURE, L2, mapping,
                         f"{label} in 0.01..{high}; excess over the optimal lobe <= {np.max(mapping - optimal):.2g}; "
                         f"curvature match at the pole instead: max {np.max(curvature):.3g}, "
                         f"mean {np.mean(curvature):.3g}"))
    ggx = [brdf.GGX(roughness=r) for r in (0.05, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9)]
    rows.append(_row("GGX 2 lobes, table in log alpha", QUADRATURE, L2,
                     [ndf_fit.ndf_l2_error(m, m.ndf_lobes(2)) for m in ggx], "roughness 0.05..0.9"))
    rows.append(_row("GGX 1 lobe, frozen L2 mapping", MONTE_CARLO, RMSE,
                     [ndf_fit.brdf_relative_rmse(m, m.ndf_lobes(1), 100_000) for m in ggx], "roughness 0.05..0.9"))
    rows.append(_row("GGX 2 lobes", MONTE_CARLO, RMSE,
                     [ndf_fit.brdf_relative_rmse(m, m.ndf_lobes(2), 100_000) for m in ggx], "roughness 0.05..0.9"))
    return rows


def _anisotropic_rows():
    rows = []
    cases = (("Ashikhmin-Shirley nu=75 nv=1200 (Fig. 2)", brdf.AshikhminShirley(nu=75.0, nv=1200.0)),
             ("Ward aniso ax=0.3 ay=0.05", brdf.WardAnisotropic(alpha_x=0.3, alpha_y=0.05)))
    for label, model in cases:
        directions, weights = ndf_fit.hemisphere_quadrature(model.ndf_widths(), 16, 160)
        exact = model.ndf(directions)
        for lobe_count in range(1, ndf_fit.MAX_LOBES + 1):
            lobes = model.ndf_lobes(lobe_count)
            table_l2 = ndf_fit.ndf_l2_error(model, lobes)
            table_rmse = ndf_fit.brdf_relative_rmse(model, lobes, 100_000)
            axis, sharpness, amplitude, direct_l2 = ndf_fit.fit_anisotropic(exact, directions, weights, lobe_count,
                                                                            initial=lobes, max_iterations=150)
            direct_rmse = ndf_fit.brdf_relative_rmse(model, (axis, sharpness, amplitude), 100_000)
            note = (f"table; free-axis L-BFGS-B refit from it: L2 {direct_l2:.3g}, RMSE {direct_rmse:.3g}")
            rows.append(_row(f"{label}, {lobe_count} lobes", QUADRATURE, L2, table_l2, note))
            rows.append(_row(f"{label}, {lobe_count} lobes", MONTE_CARLO, RMSE, table_rmse, "table"))
    return rows


def _ggx_anisotropic_rows():
    """Anisotropic GGX (the Principled BSDF's anisotropy): its lobes fitted together to GGX's two isotropic lobes
    stretched (ndf_fit.ggx_anisotropic_lobes), beside the same fitted to the plain L2 of D; what the lobes miss of
    its tails the SG technique's light and environment tails return."""
    rows = []
    for alpha_x, alpha_y in ((0.35, 0.06), (0.5, 0.2), (0.16, 0.16)):
        model = brdf.GGXAnisotropic(alpha_x=alpha_x, alpha_y=alpha_y)
        for lobe_count in (2, 4, 8):
            lobes = model.ndf_lobes(lobe_count)
            plane_l2 = ndf_fit.ggx_anisotropic_lobes(np.float64(alpha_x), np.float64(alpha_y), lobe_count,
                                                     ndf_fit.PLANE_L2)
            rows.append(_row(f"GGX aniso ax={alpha_x} ay={alpha_y}, {lobe_count} lobes", QUADRATURE, L2,
                             ndf_fit.ndf_l2_error(model, lobes),
                             "all lobes fitted together to what an environment shows (GGX's own table); "
                             f"fitted to this L2: {ndf_fit.ndf_l2_error(model, plane_l2):.3g}"))
            rows.append(_row(f"GGX aniso ax={alpha_x} ay={alpha_y}, {lobe_count} lobes", MONTE_CARLO, RMSE,
                             ndf_fit.brdf_relative_rmse(model, lobes, 100_000), "GGX's own table"))
    return rows


def _broad_lobe_rows():
    rows = []
    cases = (("Ward aniso 0.5/0.5", brdf.WardAnisotropic(alpha_x=0.5, alpha_y=0.5)),
             ("Ward aniso 0.8/0.4", brdf.WardAnisotropic(alpha_x=0.8, alpha_y=0.4)),
             ("Ward aniso 0.6/0.15", brdf.WardAnisotropic(alpha_x=0.6, alpha_y=0.15)),
             ("Ashikhmin-Shirley 3/30", brdf.AshikhminShirley(nu=3.0, nv=30.0)))
    for label, model in cases:
        for lobe_count in (4, 8):
            plain = ndf_fit.ndf_l2_error(model, model.ndf_lobes(lobe_count))
            corrected = ndf_fit.ndf_l2_error(model, model.ndf_lobes(lobe_count, broad_lobe_correction=True))
            refined = ndf_fit.ndf_l2_error(model, model.ndf_lobes(lobe_count, broad_lobe_correction=True,
                                                                  refine=True))
            rows.append(_row(f"{label}, {lobe_count} lobes, broad_lobe_correction", QUADRATURE, L2, corrected,
                             f"table without the correction: {plain:.3g}; refine=True (sphere fit, uniform "
                             f"parameters): {refined:.3g}"))
    return rows


def measure():
    return _isotropic_rows() + _anisotropic_rows() + _ggx_anisotropic_rows() + _broad_lobe_rows()


if __name__ == "__main__":
    for row in measure():
        print(row)
