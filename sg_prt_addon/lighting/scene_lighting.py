"""The scene's light as the engine hands it to every technique: lights as SGs with their cone data, and
the world as a colour or an environment (its SG mixture for diffuse light, its prefiltered layers for
glossy light, and the map itself), float32 like the GPU's copies (engine/renderer.py scene_block)."""
from dataclasses import dataclass, field

import numpy as np

FLOAT = np.float32


@dataclass
class LightData:
    """Lights as the shader gets them (float32).

    point: position (P, 3), radius (P,), intensity (P, 3) W/sr, spot: direction (P, 3),
    spot_size (P,) full cone angle (negative: a point light), spot_blend (P,); emitter (P, 3): x 1 for a
    patch of an area light (one-sided, its normal the spot direction: lights.emission_factor), y and z
    the tan of its spread's half angle and the spread's normalization (0: none); soft_falloff (P,) bool: Blender's
    Soft Falloff (lights.light_cap_extent: the light a disk facing the point, not a sphere).
    sun: axis (S, 3), sharpness (S,), amplitude (S, 3) (precomputed SGs), radius (S,) the angular radius
    (the shadow maps' penumbra).
    """
    point_position: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    point_radius: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    point_intensity: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    spot_direction: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    spot_size: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    spot_blend: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    point_emitter: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    point_soft_falloff: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))
    sun_axis: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    sun_sharpness: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    sun_amplitude: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    sun_radius: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))

    @property
    def count(self):
        return len(self.point_radius) + len(self.sun_sharpness)

    @property
    def soft_falloff(self):
        """(P,) bool: point_soft_falloff, all False where it was not given for every point light."""
        flags = np.asarray(self.point_soft_falloff, bool).reshape(-1)
        return flags if len(flags) == len(self.point_radius) else np.zeros(len(self.point_radius), bool)


@dataclass
class EnvironmentData:
    """Constant colour, or SG mixture (diffuse) + prefiltered pyramid (specular)."""
    colour: np.ndarray = field(default_factory=lambda: np.zeros(3, FLOAT))
    lobe_axis: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    lobe_sharpness: np.ndarray = field(default_factory=lambda: np.zeros(0, FLOAT))
    lobe_amplitude: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), FLOAT))
    prefiltered: object = None          # env_prefilter.PrefilteredEnvironment or None
    radiance: np.ndarray = None         # the equirect map it was made of (H, W, 3), row 0 at the top

    @property
    def has_texture(self):
        return self.prefiltered is not None
