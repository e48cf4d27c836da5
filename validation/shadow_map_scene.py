"""A scene for lighting.shadow_maps' lookup without a GPU (tests/core/test_shadow_maps.py, benchmarks/accuracy/
shadow_maps.py): a 2 x 2 square blocker 2 m over an infinite floor, lit from 4 m above; its atlas drawn by ray
casting each tile's texels, receivers along the floor, and the exact visible fraction of a sphere light's disc behind
a straight edge."""
import numpy as np

from sg_prt_addon.lighting.scene_lighting import LightData

BLOCKER_HEIGHT = 2.0        # a 2 x 2 square at z = 2 over the floor z = 0
LIGHT_HEIGHT = 4.0
BOUNDS = np.array([[-4.0, -4.0, 0.0], [4.0, 4.0, BLOCKER_HEIGHT]])


def lights(radius=0.0, sun_radius=None, spot=None):
    data = LightData()
    if sun_radius is None:
        data.point_position = np.array([[0.0, 0.0, LIGHT_HEIGHT]], np.float32)
        data.point_radius = np.array([radius], np.float32)
        data.point_intensity = np.ones((1, 3), np.float32)
        data.spot_direction = np.array([[0.0, 0.0, -1.0]], np.float32)
        data.spot_size = np.array([-1.0 if spot is None else spot], np.float32)
        data.spot_blend = np.zeros(1, np.float32)
        data.point_emitter = np.zeros((1, 3), np.float32)
    else:
        data.sun_axis = np.array([[0.0, 0.0, 1.0]], np.float32)
        data.sun_sharpness = np.array([1000.0], np.float32)
        data.sun_amplitude = np.ones((1, 3), np.float32)
        data.sun_radius = np.array([sun_radius], np.float32)
    return data


def draw_atlas(shadow_plan):
    """The atlas the GPU would draw: each tile's texels cast into the scene (the floor and the blocker), the
    window depth of the nearest hit (1 where none)."""
    width, height = shadow_plan.atlas_shape
    atlas = np.ones((height, width), np.float64)
    size = shadow_plan.size
    centres = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(centres, centres)
    for tile, matrix in shadow_plan.tiles:
        inverse = np.linalg.inv(matrix)

        def unproject(depth, x=x, y=y, inverse=inverse):
            clip = np.stack([x, y, np.full_like(x, depth), np.ones_like(x)], -1) @ inverse.T
            return clip[..., :3] / clip[..., 3:]
        start, end = unproject(-1.0), unproject(1.0)
        direction = end - start
        best = np.full(x.shape, np.inf)
        for plane_z, half in ((0.0, np.inf), (BLOCKER_HEIGHT, 1.0)):
            with np.errstate(divide="ignore", invalid="ignore"):
                t = (plane_z - start[..., 2]) / direction[..., 2]
            hit = start + t[..., None] * direction
            ok = (t >= 0) & (t <= 1) & (np.abs(hit[..., 0]) <= half) & (np.abs(hit[..., 1]) <= half)
            best = np.where(ok & (t < best), t, best)
        point = start + np.where(np.isfinite(best), best, 0.0)[..., None] * direction
        clip = np.concatenate([point, np.ones(x.shape + (1,))], -1) @ matrix.T
        window = np.where(np.isfinite(best), 0.5 * clip[..., 2] / clip[..., 3] + 0.5, 1.0)
        ox, oy = shadow_plan.tile_origin(tile)
        atlas[oy:oy + size, ox:ox + size] = window
    return atlas.astype(np.float32)


def receivers(low, high, count=201):
    xs = np.linspace(low, high, count)
    return xs, np.stack([xs, np.zeros_like(xs), np.zeros_like(xs)], -1), np.tile([0.0, 0.0, 1.0], (count, 1))


def disc_fraction(c, radius):
    """Visible fraction of a disc of `radius` beyond the chord at signed distance c from its centre."""
    c = np.clip(c / radius, -1.0, 1.0)
    return (np.arccos(c) - c * np.sqrt(1.0 - c * c)) / np.pi
