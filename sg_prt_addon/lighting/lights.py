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
from dataclasses import dataclass

import numpy as np

from ..spherical import concentric_map, sg

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


def cap_radius(sharpness):
    """Half-angle of the cap a light's SG of this sharpness stands for (the inverse of ln(10) / sin^2)."""
    ratio = _LN10 / np.maximum(np.asarray(sharpness, np.float64), 1e-30)
    return np.arcsin(np.sqrt(np.clip(ratio, 0.0, 1.0)))


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


def light_cap_extent(distance2, radius2, soft_falloff=False):
    """max(d^2, r^2) of a sphere light (points inside it see a hemisphere), or d^2 + r^2 with Blender's Soft
    Falloff (on by default for point and spot lights): Cycles then draws the light as a disk of its radius
    facing the shading point, seen within tan a = r / d, so sin^2 a = r^2 / (d^2 + r^2) and, the radiance being
    the sphere's, the intensity falls as I / (d^2 + r^2) near the light.  Floored at 1e-12 max(r^2, 1)."""
    distance2 = np.asarray(distance2, np.float64)
    radius2 = np.asarray(radius2, np.float64)
    extent2 = np.where(soft_falloff, distance2 + radius2, np.maximum(distance2, radius2))
    return np.maximum(extent2, 1e-12 * np.maximum(radius2, 1.0))


def sphere_light_sg(shading_position, light_position, radius, intensity, model="energy", soft_falloff=False):
    """SG radiance field of a spherical light seen from shading points (wang2009 eq. 32).

    shading_position (..., 3), light_position (..., 3), radius (...) >= 0 and
    intensity (...) or (..., C) in W/sr (use ``blender_point_light_intensity``).
    Returns (axis (..., 3), sharpness (...), amplitude (...) or (..., C)).

    Points inside the light (d < r) see a hemisphere of it (the cap is clamped
    at 90 degrees).  soft_falloff (...): Blender's Soft Falloff, the light a disk facing the point
    (light_cap_extent).  Distances are floored at 1e-6 of the light scale so a
    zero distance gives a finite, very bright lobe and never NaN/Inf.
    """
    x = np.asarray(shading_position)
    dtype = np.result_type(x, np.asarray(light_position), np.float32)
    to_light = (np.asarray(light_position, dtype=np.float64) - np.asarray(x, dtype=np.float64))
    distance2 = np.sum(to_light * to_light, axis=-1)
    radius2 = np.square(np.asarray(radius, dtype=np.float64))
    effective2 = light_cap_extent(distance2, radius2, soft_falloff)
    sin2 = radius2 / effective2
    cos_half = np.sqrt(np.maximum(1.0 - sin2, 0.0))
    intensity64 = np.asarray(intensity, dtype=np.float64)
    # cap radiance integral L_e * Omega = I/(pi r^2) * 2 pi sin^2/(1+cos) = 2 I / (extent^2 (1+cos))
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
    falloff = emission_factor(cos_angle, np.asarray(spot_size, np.float64), np.asarray(spot_blend, np.float64),
                              False, 0.0, 0.0)
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


# --------------------------------------------------------------------------- area lights

AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")
# the grid's default patches a side: irradiance within 1.2% relative L2 of Lambert's formula from half the
# light's size away (docs/ACCURACY.md, "area_lights")
AREA_PATCHES_PER_SIDE = 4
# Cycles turns a spread of 0 into a delta beam; below this a beam from each patch centre is all a patch can
# give (blender/export/lights.py warns where the shaft's edge is then approximate)
MIN_SPREAD = 1e-3


@dataclass
class AreaPatches:
    """An area light cut into equal-area patches: position (K, 3), radius (K,) of the sphere of each patch's
    area, intensity (K, C) in W/sr along the light's normal (3,); the spread's (tan of the half angle,
    normalization), normalization 0 for none."""
    position: np.ndarray
    radius: np.ndarray
    intensity: np.ndarray
    normal: np.ndarray
    tan_half_spread: float = 0.0
    spread_normalization: float = 0.0


def area_light_area(shape, size_u, size_v):
    """Area of a light of Blender's shape with edge lengths (world) size_u, size_v (a disk's diameter)."""
    return size_u * size_v * (np.pi / 4 if shape in ("DISK", "ELLIPSE") else 1.0)


def spread_parameters(spread):
    """(tan of the half angle, normalization) of Cycles' soft-box attenuation for an area light of full
    spread angle ``spread``: max((tan h - tan a) N, 0) at angle a from the normal, N = 1 / (tan h - h)
    (3 / h^3 below h = 0.05, its series), which keeps the light's power; (0, 0) for a spread of pi (none)."""
    half = 0.5 * float(np.clip(spread, MIN_SPREAD, np.pi))
    if half >= 0.5 * np.pi - 1e-6:
        return 0.0, 0.0
    tan_half = float(np.tan(half))
    return tan_half, float(1.0 / (tan_half - half) if half > 0.05 else 3.0 / half ** 3)


def area_grid(size_u, size_v, per_side):
    """Patch counts (n_u, n_v) along the two edges: about per_side^2 patches, each near square."""
    aspect = np.sqrt(max(size_u, 1e-12) / max(size_v, 1e-12))
    n_u = int(np.clip(round(per_side * aspect), 1, per_side * per_side))
    n_v = int(np.clip(round(per_side / aspect), 1, per_side * per_side))
    return n_u, n_v


def area_light_patches(centre, edge_u, edge_v, normal, shape, power, per_side, spread=np.pi):
    """AreaPatches of a Blender area light: centre (3,), edge_u / edge_v (3,) the world vectors spanning
    the light (its size along local x and y, object scale included), normal (3,) the direction it emits
    along (-Z), shape in AREA_SHAPES, power (C,) W per colour, per_side the grid's patches per side.

    A rectangle is cut into an n_u x n_v grid; a disk or ellipse into the same grid through the concentric
    map, which keeps areas equal.  Each patch carries the intensity P / (pi K) along the normal (the
    radiance P / (pi A) times its area A / K), so a light of zero size is a Lambertian point emitter."""
    centre, edge_u, edge_v = (np.asarray(v, np.float64) for v in (centre, edge_u, edge_v))
    size_u, size_v = float(np.linalg.norm(edge_u)), float(np.linalg.norm(edge_v))
    n_u, n_v = area_grid(size_u, size_v, int(per_side))
    u = (np.arange(n_u) + 0.5) / n_u * 2.0 - 1.0
    v = (np.arange(n_v) + 0.5) / n_v * 2.0 - 1.0
    square = np.stack(np.meshgrid(u, v, indexing="xy"), -1).reshape(-1, 2)
    if shape in ("DISK", "ELLIPSE"):
        square = concentric_map.square_to_disc(square)
    count = len(square)
    position = centre + 0.5 * square[:, :1] * edge_u + 0.5 * square[:, 1:] * edge_v
    patch_area = area_light_area(shape, size_u, size_v) / count
    radius = np.full(count, np.sqrt(patch_area / np.pi))
    intensity = np.broadcast_to(np.asarray(power, np.float64) / (np.pi * count), (count,) + np.shape(power))
    tan_half, normalization = spread_parameters(spread)
    return AreaPatches(position, radius, np.array(intensity), sg.normalize(np.asarray(normal, np.float64)),
                       tan_half, normalization)


def emission_factor(cos_angle, spot_size, spot_blend, area, tan_half_spread, spread_normalization):
    """The factor on a point-like light's intensity toward a shading point, cos_angle = the cosine between
    the light's direction (spot axis, area normal) and the ray from the light to the point: an area patch's
    one-sided cosine times its spread attenuation (area true), a spot's cone smoothstep (spot_size >= 0),
    else 1.  Broadcasts; keeps float32 inputs float32 (the shaders' lights.glsl light_emission_factor)."""
    dtype = np.result_type(np.asarray(cos_angle), np.float32)
    one = dtype.type(1)
    cos_angle = np.clip(cos_angle, -one, one)
    cos_half = np.cos(dtype.type(0.5) * np.maximum(spot_size, 0).astype(dtype))
    width = np.maximum((one - cos_half) * spot_blend, dtype.type(1e-12))
    t = np.clip((cos_angle - cos_half) / width, 0, 1)
    spot = np.where(np.asarray(spot_size) >= 0, t * t * (3 - 2 * t), one)
    facing = np.maximum(cos_angle, 0)
    with np.errstate(divide="ignore", invalid="ignore"):     # facing 0: tan inf, times a normalization of 0
        tan_angle = np.sqrt(np.maximum(one - facing * facing, 0)) / facing
        attenuation = np.maximum((tan_half_spread - tan_angle) * spread_normalization, 0)
    attenuation = np.where(np.asarray(spread_normalization) > 0, attenuation, one)
    return np.where(area, facing * attenuation, spot).astype(dtype)


def patches_irradiance(position, normal, patches):
    """Irradiance (N, C) at points (N, 3) with normals (N, 3) from AreaPatches as the engine shades them: each
    patch a sphere light's SG times its emission factor, against the clamped cosine (the accurate closed form
    of spherical.clamped_cosine).  What the area lights' accuracy rows measure."""
    from ..spherical import clamped_cosine

    position, normal = np.atleast_2d(position), np.atleast_2d(normal)
    axis, sharpness, amplitude = sphere_light_sg(position[:, None], patches.position[None], patches.radius[None], 1.0)
    factor = emission_factor(np.sum(-axis * patches.normal, axis=-1), -1.0, 0.0, True, patches.tan_half_spread,
                             patches.spread_normalization)
    integral = clamped_cosine.sg_clamped_cosine_integral(axis, sharpness, amplitude * factor, normal[:, None])
    return integral @ patches.intensity


def polygon_irradiance(position, normal, vertices, radiance=1.0):
    """Exact irradiance at points (N, 3) with normals (N, 3) from a planar polygon (M, 3) of uniform
    radiance, emitting to the side its vertices turn anticlockwise about (Lambert's formula on the
    polygon clipped to each point's upper hemisphere; 0 behind the emitter).  The reference of the area
    lights' patch grid."""
    position, normal = np.atleast_2d(position).astype(np.float64), np.atleast_2d(normal).astype(np.float64)
    vertices = np.asarray(vertices, np.float64)
    emitter_normal = sg.normalize(np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0]))
    result = np.zeros(len(position))
    for k, (x, n) in enumerate(zip(position, normal)):
        if np.dot(x - vertices[0], emitter_normal) <= 0:
            continue
        polygon = _clip_to_half_space(vertices - x, n)
        if len(polygon) < 3:
            continue
        r = polygon / np.linalg.norm(polygon, axis=-1, keepdims=True)
        r_next = np.roll(r, -1, axis=0)
        cross = np.cross(r, r_next)
        length = np.linalg.norm(cross, axis=-1)
        angle = np.arctan2(length, np.sum(r * r_next, axis=-1))
        total = np.sum(angle * (cross @ n) / np.maximum(length, 1e-300))
        result[k] = 0.5 * abs(total)
    return result * radiance


def _clip_to_half_space(polygon, normal):
    """Sutherland-Hodgman: the part of a polygon (M, 3) where dot(p, normal) >= 0."""
    out = []
    side = polygon @ normal
    for i in range(len(polygon)):
        j = (i + 1) % len(polygon)
        if side[i] >= 0:
            out.append(polygon[i])
        if (side[i] >= 0) != (side[j] >= 0):
            t = side[i] / (side[i] - side[j])
            out.append(polygon[i] + t * (polygon[j] - polygon[i]))
    return np.array(out).reshape(-1, 3)


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


