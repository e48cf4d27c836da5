"""Lights in Blender's units, as the quantities lighting/lights.py takes."""
from dataclasses import dataclass

import numpy as np

from .meshes import matrix_to_numpy
from .messages import warn


@dataclass
class LightExport:
    """One light: kind 'POINT' (point, spot), 'AREA' or 'SUN'."""
    name: str
    kind: str
    position: tuple                # world position (POINT, AREA: the centre)
    direction: tuple               # world direction the light points along (-Z of the object)
    colour_intensity: tuple        # POINT: radiant intensity W/sr per channel; SUN: irradiance per channel;
                                   # AREA: power W per channel
    radius: float = 0.0            # POINT sphere radius
    angle: float = 0.0             # SUN full angular diameter
    spot_size: float = np.pi       # >= pi: no cone
    spot_blend: float = 0.0
    is_spot: bool = False
    shape: str = "SQUARE"          # AREA: lighting.lights.AREA_SHAPES
    edge_u: tuple = (0.0, 0.0, 0.0)  # AREA: world vectors spanning the light (size along local x and y)
    edge_v: tuple = (0.0, 0.0, 0.0)
    spread: float = np.pi          # AREA: full spread angle
    soft_falloff: bool = False     # POINT: Blender's Soft Falloff (a disk facing the point: lights.light_cap_extent)


# --------------------------------------------------------------------------- lights

# Radiant intensity [W/sr] (point, spot, area) and irradiance [W/m^2] (sun) beyond this are clamped to
# it: the shader multiplies them by the light's SG amplitude (up to ~1e17 at a shading point on the
# light) and the BRDF lobe's, and float32 ends at 3.4e38.  1e20 W/sr is a 1.3e21 W lamp.
MAX_LIGHT_INTENSITY = 1e20


def _clamped_intensity(values, name):
    """Per-channel intensity (or irradiance) with NaN set to 0 and magnitudes beyond
    MAX_LIGHT_INTENSITY (Inf included) clamped to it, warned."""
    values = np.asarray(values, np.float64)
    if np.all(np.abs(values) <= MAX_LIGHT_INTENSITY):           # (False with a NaN)
        return values
    warn(f"light '{name}': intensity {tuple(float(v) for v in values)} clamped to "
         f"+-{MAX_LIGHT_INTENSITY:g} (NaN to 0): float32 shading would overflow")
    return np.clip(np.nan_to_num(values, nan=0.0), -MAX_LIGHT_INTENSITY, MAX_LIGHT_INTENSITY)


def finite_setting(value, default, what):
    """float(value), or `default` with a warning when it is NaN/Inf (Blender stores what scripts set)."""
    value = float(value)
    if np.isfinite(value):
        return value
    warn(f"{what} {value} not finite, {default:g} used")
    return default


# narrower area light spreads are beams from the patch centres (lighting.lights.MIN_SPREAD)
AREA_SPREAD_WARNING = np.radians(30.0)


def export_light(object_eval, matrix_world=None):
    """LightExport of an evaluated light object in Blender's units, at matrix_world (an instance's; default
    the object's); None for unsupported types (and for a light whose transform is not finite).  Intensities
    are finite and at most MAX_LIGHT_INTENSITY in magnitude, sizes and angles finite (warned otherwise)."""
    from ...lighting import lights as core_lights

    light = object_eval.data
    matrix = matrix_to_numpy(object_eval.matrix_world if matrix_world is None else matrix_world)
    if not np.all(np.isfinite(matrix)):
        warn(f"light '{object_eval.name}': transform not finite, left out")
        return None
    what = f"light '{object_eval.name}':"
    position = tuple(matrix[:3, 3])
    direction = -matrix[:3, 2]
    direction = tuple(direction / max(np.linalg.norm(direction), 1e-30))
    power = _emitted_power(light)
    normalized = bool(getattr(light, "normalize", True))
    if light.type == "SUN":
        angle = finite_setting(light.angle, 0.0, what + " angle")
        if not normalized and angle > 0.0:
            # Cycles: an unnormalized sun's strength is its radiance, over its disc's projected area
            # pi sin^2(angle / 2) (measured: 1.385x at 1 rad); a sun of angle 0 stays a delta of irradiance S
            power = power * np.pi * np.sin(0.5 * angle) ** 2
        irradiance = _clamped_intensity(power * float(core_lights.blender_sun_irradiance(1.0)), object_eval.name)
        return LightExport(object_eval.name, "SUN", position, direction, tuple(irradiance), angle=angle)
    if light.type in ("POINT", "SPOT"):
        radius = finite_setting(getattr(light, "shadow_soft_size", 0.0), 0.0, what + " radius")
        # Cycles: an unnormalized sphere has the radiance P / pi, whatever its size (radius 0: intensity P / pi)
        unnormalized = 4 * np.pi * radius * radius if radius > 0 else 4.0
        intensity = _clamped_intensity(power * float(core_lights.blender_point_light_intensity(1.0))
                                       * (1.0 if normalized else unnormalized), object_eval.name)
        export = LightExport(object_eval.name, "POINT", position, direction, tuple(intensity), radius=radius,
                             soft_falloff=bool(getattr(light, "use_soft_falloff", False)))
        if light.type == "SPOT":
            export.is_spot = True
            export.spot_size = finite_setting(light.spot_size, np.pi, what + " spot size")
            export.spot_blend = finite_setting(light.spot_blend, 0.0, what + " spot blend")
        return export
    if light.type == "AREA":
        # a one-sided emitter of its shape, cut into patches by the scene state (lights.area_light_patches)
        shape = light.shape
        size_x = finite_setting(light.size, 0.0, what + " size")
        size_y = finite_setting(light.size_y, 0.0, what + " size y") if shape in ("RECTANGLE", "ELLIPSE") else size_x
        edge_u, edge_v = matrix[:3, 0] * size_x, matrix[:3, 1] * size_y
        spread = finite_setting(getattr(light, "spread", np.pi), np.pi, what + " spread")
        if spread < AREA_SPREAD_WARNING:
            warn(f"{what} a spread of {np.degrees(spread):.0f} degrees is rendered as a beam from each of its "
                 f"patches: the edge of its shaft of light is approximate (Cycles: exact)")
        if not normalized:      # Cycles: the radiance P / pi, whatever the area, so the power P A
            power = power * core_lights.area_light_area(shape, np.linalg.norm(edge_u), np.linalg.norm(edge_v))
        return LightExport(object_eval.name, "AREA", position, direction,
                           tuple(_clamped_intensity(power, object_eval.name)), shape=shape,
                           edge_u=tuple(edge_u), edge_v=tuple(edge_v), spread=spread)
    return None


def _emitted_power(light):
    """A light's power (a sun's strength) per colour as Cycles takes it: colour x energy x 2^exposure, the
    colour tinted by the blackbody colour of its temperature where that is on (Blender 4.5+)."""
    colour = np.asarray(light.color, np.float64)
    if getattr(light, "use_temperature", False):
        colour = colour * np.asarray(light.temperature_color, np.float64)[:3]
    exposure = float(getattr(light, "exposure", 0.0))
    return colour * float(light.energy) * 2.0 ** (exposure if np.isfinite(exposure) else 0.0)
