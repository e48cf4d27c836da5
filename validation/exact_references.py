"""References the maths is measured against that the engine never evaluates: an environment's SG convolution
summed over every texel, a rectangular light's irradiance by the midpoint rule, and a cap's inner product with
an SG by Gauss-Legendre quadrature."""
import numpy as np

from sg_prt_addon.lighting import equirect, lights
from sg_prt_addon.spherical import sg


def brute_force_convolution(equirect_image, axis, sharpness):
    """Reference Gamma_L(p, lambda) / integral G by direct summation over every texel of the map.

    Uses the analytic kernel integral (not the discrete one) as the normaliser.
    (N, 3) axes, (N,) sharpness -> (N, C); for tests and benchmarks.
    """
    image = np.asarray(equirect_image, dtype=np.float64)
    height, width, channels = image.shape
    src = equirect.texel_directions(height, width).reshape(-1, 3)
    omega = np.broadcast_to(equirect.texel_solid_angles(height, width), (height, width)).reshape(-1)
    radiance = image.reshape(-1, channels) * omega[:, None]
    axis = sg.normalize(np.asarray(axis, dtype=np.float64)).reshape(-1, 3)
    sharpness = np.broadcast_to(np.asarray(sharpness, dtype=np.float64), axis.shape[:1])
    out = np.empty((axis.shape[0], channels))
    for start in range(0, axis.shape[0], 64):
        p = axis[start:start + 64]
        lam = sharpness[start:start + 64, None]
        d2 = np.maximum(2.0 - 2.0 * (p @ src.T), 0.0)
        out[start:start + 64] = np.exp(-0.5 * lam * d2) @ radiance
    return out / sg.sphere_integral(sharpness)[:, None]


def area_irradiance_quadrature(position, normal, centre, edge_u, edge_v, light_normal, spread=np.pi, nodes=400):
    """Irradiance (N,) from a rectangular light of unit radiance (times the spread's attenuation) by the
    midpoint rule over its area on nodes x nodes points: the reference where a spread rules out Lambert's
    formula (polygon_irradiance)."""
    s = (np.arange(nodes) + 0.5) / nodes - 0.5
    grid = np.stack(np.meshgrid(s, s), -1).reshape(-1, 2)
    points = np.asarray(centre) + grid[:, :1] * np.asarray(edge_u) + grid[:, 1:] * np.asarray(edge_v)
    tan_half, normalization = lights.spread_parameters(spread)
    light_normal = sg.normalize(np.asarray(light_normal, np.float64))
    result = []
    for x, n in zip(np.atleast_2d(position), np.atleast_2d(normal)):
        to_point = x - points
        distance2 = np.sum(to_point ** 2, axis=-1)
        direction = to_point / np.sqrt(distance2)[:, None]
        emitted = lights.emission_factor(direction @ light_normal, -1.0, 0.0, True, tan_half, normalization)
        result.append(np.sum(emitted * np.maximum(-direction @ n, 0.0) / distance2) / nodes ** 2)
    return np.array(result) * abs(np.linalg.norm(np.cross(edge_u, edge_v)))


def cap_sg_inner_product_reference(cap_half_angle, sharpness, offset_angle, nodes=400):
    """Exact integral over a uniform unit-radiance cap of G(i; p, sharpness, 1).

    The cap has half-angle ``cap_half_angle`` around z, the lobe axis p makes
    ``offset_angle`` with z.  The azimuthal integral is 2 pi I0(.) in closed form;
    the polar one is Gauss-Legendre with ``nodes`` points (the reference for
    the light-model accuracy tests).  Broadcasts over its three arguments.
    """
    from scipy.special import ive

    cap, lam, beta = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in
                                           (cap_half_angle, sharpness, offset_angle)))
    x, w = np.polynomial.legendre.leggauss(nodes)
    theta = 0.5 * cap[..., None] * (x + 1.0)  # polar angle inside the cap
    weight = 0.5 * cap[..., None] * w
    bessel_arg = lam[..., None] * np.sin(theta) * np.sin(beta[..., None])
    # exp(l (cos(theta) cos(beta) - 1)) * I0(arg) = ive(0, arg) * exp(l (cos(theta - beta) - 1))
    log_rest = lam[..., None] * (np.cos(theta - beta[..., None]) - 1.0)
    integrand = 2.0 * np.pi * ive(0, bessel_arg) * np.exp(log_rest) * np.sin(theta)
    return np.sum(integrand * weight, axis=-1)
