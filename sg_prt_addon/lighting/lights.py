"""Local and distant lights as single spherical Gaussians (wang2009 section 6, eq. 32-33).

A spherical light of radius r seen from distance d covers a cap of half-angle
theta (sin theta = r / d) with uniform radiance L_e.  Eq. 32 replaces it by one
SG centred on the light direction.  Two choices are offered:

``model="energy"`` (default)
    the paper's sharpness, fa^-1(2 pi sin^2 theta) = ln(10) / sin^2 theta
    (= ln(10) d^2 / r^2), with the amplitude set so that the SG's sphere
    integral equals the true radiance integral of the cap, L_e * Omega_cap:
    diffuse irradiance and broad lobes are then exact for small lights, and a
    mirror lobe sees a peak of 1.15 L_e.  Scanning lambda = c / sin^2 theta
    against exact quadrature, c in [2.2, 2.6] is best (mean error 0.21-0.22),
    c = 4 (matching the cap's mean cosine) doubles the peak and the error.
``model="paper"``
    eq. 32 as printed: sharpness fa^-1(2 pi r^2 / d^2) = ln(10) d^2 / r^2 and
    amplitude s / d^2 (peak radiance = intensity over squared distance).  Its
    integral is 2 pi s r^2 / (ln(10) d^4): not the light's energy unless r/d
    happens to equal sqrt(ln 10 / (2 pi)); kept only for comparison.

benchmarks/accuracy/lighting.py measures both against exact quadrature of the
cap times SG lobes of every sharpness (see docs/ACCURACY.md).

Blender / Cycles units (checked against Cycles' ``Light::area`` and
``device_update_lights``): a point or spot light of power P [W] and radius r
is a sphere of radiance P / (pi * 4 pi r^2), i.e. radiant intensity
P / (4 pi) [W/sr] in every direction, for any radius (radius 0: intensity
P / (4 pi) directly).  A sun of strength S has radiance S / (pi sin^2(a/2)) over
its disc of angular diameter a, i.e. irradiance S [W/m^2] on a surface facing
it (exactly 2 S / (1 + cos(a/2)) since the disc is a cap).  Blender's default
"soft falloff" point light differs from a sphere only closer than a few radii.
"""
import numpy as np

from ..spherical import sg

MAX_SHARPNESS = 1e6  # sg.py kernels are stable up to here; radius 0 lights clamp to it
_LN10 = np.log(10.0)


def blender_point_light_intensity(power):
    """Radiant intensity [W/sr] of a Blender point/spot light of power P [W]: P / (4 pi)."""
    return np.asarray(power) / sg.FOUR_PI


def blender_sun_irradiance(strength):
    """Irradiance [W/m^2] on a surface facing a Blender sun of strength S: S itself."""
    return np.asarray(strength)


def blender_sun_radiance(strength, angle):
    """Radiance of a Blender sun disc of full angular diameter ``angle``: S / (pi sin^2(angle/2))."""
    sin_half = np.sin(0.5 * np.asarray(angle, dtype=float))
    return np.asarray(strength) / (np.pi * np.maximum(sin_half * sin_half, 1e-300))


def _cap_sharpness_and_integral(sin2, energy_scale, model, paper_amplitude):
    """Shared by sphere and directional lights: sin2 = sin^2 theta of the cap (0 = a point)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        if model not in ("energy", "paper"):
            raise ValueError(f"unknown light model {model!r}")
        sharpness = _LN10 / sin2  # fa^-1(2 pi sin^2 theta), eq. 3 with epsilon = 0.1
    sharpness = np.minimum(np.where(sin2 > 0, sharpness, MAX_SHARPNESS), MAX_SHARPNESS)
    if model == "energy":
        # amplitude such that sphere_integral(sharpness, amplitude) == energy_scale
        amplitude = energy_scale / sg.sphere_integral(sharpness)
    else:
        amplitude = paper_amplitude
    return sharpness, amplitude


def sphere_light_sg(shading_position, light_position, radius, intensity, model="energy"):
    """SG radiance field of a spherical light seen from shading points (wang2009 eq. 32).

    shading_position (..., 3), light_position (..., 3), radius (...) >= 0 and
    intensity (...) or (..., C) in W/sr (use ``blender_point_light_intensity``).
    Returns (axis (..., 3), sharpness (...), amplitude (...) or (..., C)).

    Points inside the light (d < r) see a hemisphere of it (the cap is clamped
    at 90 degrees).  Distances are floored at 1e-6 of the light scale so a
    zero distance gives a finite, very bright lobe and never NaN/Inf.
    """
    x = np.asarray(shading_position)
    dtype = np.result_type(x, np.asarray(light_position), np.float32)
    to_light = (np.asarray(light_position, dtype=np.float64) - np.asarray(x, dtype=np.float64))
    distance2 = np.sum(to_light * to_light, axis=-1)
    radius2 = np.square(np.asarray(radius, dtype=np.float64))
    floor2 = 1e-12 * np.maximum(radius2, 1.0)
    effective2 = np.maximum(np.maximum(distance2, radius2), floor2)
    sin2 = radius2 / effective2
    cos_half = np.sqrt(np.maximum(1.0 - sin2, 0.0))
    intensity64 = np.asarray(intensity, dtype=np.float64)
    # cap radiance integral L_e * Omega = I/(pi r^2) * 2 pi sin^2/(1+cos) = 2 I / (max(d, r)^2 (1+cos))
    energy = 2.0 / (effective2 * (1.0 + cos_half))
    axis = sg.normalize(to_light)
    sharpness, amplitude = _cap_sharpness_and_integral(sin2, energy, model, 1.0 / effective2)
    amplitude = _broadcast_colour(amplitude, intensity64)
    return axis.astype(dtype), sharpness.astype(dtype), _finite(amplitude, dtype)


def point_light_sg(shading_position, light_position, intensity, radius=0.0, model="energy"):
    """A point light is a sphere light of radius ``radius`` (0: the sharpest lobe, MAX_SHARPNESS)."""
    return sphere_light_sg(shading_position, light_position, radius, intensity, model)


def spot_light_sg(shading_position, light_position, spot_direction, spot_size, spot_blend,
                  intensity, radius=0.0, model="energy"):
    """Spot light as a point light whose intensity is scaled by the cone falloff.

    Falloff smoothstep((cos a - cos(size/2)) / ((1 - cos(size/2)) * blend)) with a
    the angle between ``spot_direction`` and the ray from the light to the
    point: Cycles' round spot with unit object scale, up to its small
    projective remapping of the angle (not matched here).
    """
    axis, sharpness, amplitude = sphere_light_sg(shading_position, light_position, radius, intensity, model)
    cos_angle = np.sum(-axis.astype(np.float64) * sg.normalize(np.asarray(spot_direction, dtype=np.float64)), axis=-1)
    cos_half = np.cos(0.5 * np.asarray(spot_size, dtype=np.float64))
    width = np.maximum((1.0 - cos_half) * np.asarray(spot_blend, dtype=np.float64), 1e-12)
    t = np.clip((cos_angle - cos_half) / width, 0.0, 1.0)
    falloff = t * t * (3.0 - 2.0 * t)
    falloff = falloff.reshape(falloff.shape + (1,) * (np.ndim(amplitude) - np.ndim(falloff)))
    return axis, sharpness, (amplitude * falloff).astype(amplitude.dtype)


def directional_light_sg(direction, angular_radius, irradiance, model="energy"):
    """SG of a distant disc light (wang2009 eq. 33), e.g. Blender's sun.

    direction (..., 3) towards the light, angular_radius (...) = half the
    disc's angular diameter (Blender: sun.angle / 2), irradiance (...) or
    (..., C) = Blender's sun strength S (``blender_sun_irradiance``).  The
    energy model carries 2 S / (1 + cos(angular_radius)), the disc's radiance
    times its solid angle as in Cycles; the paper model uses amplitude S and
    sharpness ln(10) / sin^2(angular_radius).
    """
    direction = np.asarray(direction)
    dtype = np.result_type(direction, np.float32)
    half = np.clip(np.asarray(angular_radius, dtype=np.float64), 0.0, 0.5 * np.pi)
    sin2 = np.sin(half) ** 2
    cos_half = np.cos(half)
    energy = 2.0 / (1.0 + cos_half)
    sharpness, amplitude = _cap_sharpness_and_integral(sin2, energy, model, np.ones_like(sin2))
    amplitude = _broadcast_colour(amplitude, np.asarray(irradiance, dtype=np.float64))
    axis = sg.normalize(direction)
    return axis.astype(dtype), sharpness.astype(dtype), _finite(amplitude, dtype)


def _broadcast_colour(per_lobe, intensity):
    """Multiply a per-lobe factor (...) by an intensity (...) or colour (..., C)."""
    per_lobe = np.asarray(per_lobe)
    if intensity.ndim == 0:
        return per_lobe * intensity
    try:
        scalar_shape = np.broadcast_shapes(per_lobe.shape, intensity.shape)
    except ValueError:
        scalar_shape = None
    # a trailing colour axis when shapes say so: more dims than the lobes, or not broadcastable as scalars
    if intensity.ndim > per_lobe.ndim or scalar_shape is None or scalar_shape != per_lobe.shape:
        return per_lobe[..., None] * intensity
    return per_lobe * intensity


def _finite(values, dtype):
    # huge intensities over zero distances saturate instead of overflowing the target dtype
    limit = np.finfo(dtype).max * 1e-6
    return np.clip(np.nan_to_num(values, nan=0.0, posinf=limit, neginf=-limit), -limit, limit).astype(dtype)


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
