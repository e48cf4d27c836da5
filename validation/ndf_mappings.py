"""The frozen one-lobe NDF mappings (reflectance ndf_fit.ISOTROPIC_MAPPINGS) against the models they stand
for: the model of a lobe width, its normalized NDF (what ndf_fit.derive_isotropic_mapping fits) and the
mapping's error next to the optimal single lobe's."""
import numpy as np

from sg_prt_addon.reflectance import brdf, ndf_fit


def isotropic_model_of_width(kind, width):
    """The brdf model whose 1-lobe mapping ``kind`` (a key of ndf_fit.ISOTROPIC_MAPPINGS) is
    parametrized by ``width``, and its peak D(n)."""
    if kind == "BECKMANN":
        return brdf.CookTorranceBeckmann(roughness=width), 1 / (np.pi * width * width)
    if kind == "BLINN_PHONG":
        exponent = 2 / (width * width)
        return brdf.BlinnPhong(exponent=exponent), (exponent + 2) / (2 * np.pi)
    if kind == "WARD_ISO":
        return brdf.WardIsotropic(alpha_x=width), 1 / (np.pi * width * width)
    if kind == "GGX":
        return brdf.GGX(roughness=np.sqrt(width)), 1 / (np.pi * width * width)
    raise ValueError(kind)


def isotropic_ndf_of_width(kind):
    """ndf_of_width(theta, width) -> D(theta) / D(n) for derive_isotropic_mapping."""
    def ndf_of_width(theta, width):
        model, peak = isotropic_model_of_width(kind, width)
        h = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=-1)
        return model.ndf(h) / peak
    return ndf_of_width


def isotropic_mapping_errors(kind, widths):
    """Relative L2 (hemisphere) of the frozen brdf mapping and of the L2-optimal
    single lobe, per width: (mapping_error (W,), optimal_error (W,))."""
    mapping_errors, optimal_errors = [], []
    ndf_of_width = isotropic_ndf_of_width(kind)
    for width in np.asarray(widths, np.float64):
        theta, weights = ndf_fit.polar_quadrature([width])
        target = ndf_of_width(theta, width)
        scaled_sharpness, relative_amplitude = ndf_fit.isotropic_mapping(kind, np.float64(width))
        lobe = relative_amplitude * np.exp(-scaled_sharpness / width ** 2 * 2 * np.sin(0.5 * theta) ** 2)
        mapping_errors.append(ndf_fit.relative_l2(target, lobe, weights))
        optimal_errors.append(ndf_fit.fit_isotropic(target, theta, weights, 1)[2])
    return np.array(mapping_errors), np.array(optimal_errors)
