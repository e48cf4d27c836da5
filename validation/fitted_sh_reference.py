"""The reference the SH tables of a lobe fit (harmonics/fitted_table.py) are checked against: the fitted BRDF x
cosine, exactly as the SG_FITTED mirror evaluates it (techniques.sg.fitted_texels.fitted_m_factor times the RGB
lobes), projected into SH on a dense uniform lattice; and the tables' own entries put together the way the
shader does (colours and the view's S(o) / (pi o.z) applied).  Shared by tests/core/test_sh_fitted_table.py and
benchmarks/accuracy/harmonics.py."""
import numpy as np

from sg_prt_addon.harmonics import basis, fitted_table
from sg_prt_addon.measured import microfacet_fit
from sg_prt_addon.reflectance import brdf
from sg_prt_addon.spherical.lattice import hemisphere_points
from sg_prt_addon.techniques.sg import fitted_texels

DENSE_POINTS = 300000      # against 4,000,000: within 1e-6 of the largest coefficient on the generated fits


def fit_arrays(lobe_fit):
    """The per-texel arrays of a measured.microfacet_fit.LobeFit the tables and this reference take."""
    shadowing = microfacet_fit.decompress_shadowing(lobe_fit.shadowing_mean, lobe_fit.shadowing_basis,
                                                    lobe_fit.shadowing_coefficients)
    return dict(sharpness=lobe_fit.sharpness, eta=lobe_fit.eta, shadowing=shadowing, theta=lobe_fit.shadowing_theta,
                colour=lobe_fit.amplitude)


def dense_product(fit, texels, theta_v, order, points=DENSE_POINTS):
    """(T, N^2, 3): the SH projection of sum_k a_k G_k(h) M_o(i) (i.n) at view angle theta_v for the texels
    (indices) of fit_arrays, by a uniform Fibonacci lattice of the hemisphere."""
    lattice = hemisphere_points(points)
    wo = np.array([np.sin(theta_v), 0.0, np.cos(theta_v)])
    params = {"eta": fit["eta"][texels], "shadowing": fit["shadowing"][texels], "shadowing_theta": fit["theta"]}
    out = 0.0
    for start in range(0, points, 100000):
        wi = lattice[start:start + 100000]
        h = brdf.half_vector(np.broadcast_to(wo, wi.shape), wi)
        m = fitted_texels.fitted_m_factor(params, np.broadcast_to(wo, (len(wi), len(texels), 3)),
                                          np.broadcast_to(wi[:, None], (len(wi), len(texels), 3)))      # (S, T)
        lobes = np.exp(fit["sharpness"][texels][None] * (h[:, None, None, 2] - 1))                      # (S, T, K)
        f = np.einsum("stk,tkc->stc", lobes, fit["colour"][texels]) * (m * wi[:, None, 2])[..., None]
        out = out + np.einsum("stc,si->tic", f, basis.evaluate(wi, order)) * (2 * np.pi / points)
    return out


def table_product(fit, table, texels, view):
    """(T, N^2, 3): a FittedTable's entries at view node `view` as the shader combines them: each lobe times its
    colour and the view's S(o) / (pi o.z)."""
    theta_v = fitted_table.view_thetas(table.views)[view]
    direction = np.broadcast_to([np.sin(theta_v), 0.0, np.cos(theta_v)], (len(texels), 1, 3))
    shadowing = fitted_texels.fitted_shadowing({"shadowing": fit["shadowing"][texels], "shadowing_theta": fit["theta"]},
                                               direction)
    full = np.zeros(table.coefficients.shape[:3] + (table.order ** 2,))
    full[..., fitted_table.positive_m_indices(table.order)] = table.coefficients
    lobes = full[texels, :, view] * (shadowing / (np.pi * np.cos(theta_v)))[:, :, None]                  # (T, K, N^2)
    return np.einsum("tki,tkc->tic", lobes, fit["colour"][texels])
