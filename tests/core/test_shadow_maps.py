"""lighting.shadow_maps without a GPU: the plan's tiles and the lookup (the mirror of shaders/lib/shadow_maps.glsl)
on an atlas drawn here by ray casting, a square blocker over a floor, against the exact visible fraction of the
light.  The GLSL itself is compared with this mirror in tests/gpu/test_engine_mirror.py (test_shadow_maps)."""
import math

import numpy as np
import pytest

from sg_prt_addon.lighting import shadow_maps
from validation import shadow_map_scene as scene


def test_plan_tiles_and_layout():
    """Six tiles a point light, drawn where the casters' box is (not the +z face over it; a spot straight down only
    the faces its cone reaches), one a sun; the atlas within the limits; lights wider than MAX_LIGHT_ANGLE and area
    patches get no map."""
    point = shadow_maps.plan(scene.lights(), scene.BOUNDS, 512)
    assert point.active and point.slot_lights == [0] and [tile for tile, _ in point.tiles] == [0, 1, 2, 3, 5]
    assert point.atlas_shape == (3 * 512, 2 * 512)
    spot = shadow_maps.plan(scene.lights(spot=0.6), scene.BOUNDS, 512)
    assert [tile for tile, _ in spot.tiles] == [5]          # -z alone
    sun = shadow_maps.plan(scene.lights(sun_radius=0.01), scene.BOUNDS, 512)
    assert sun.slot_lights == [0 + 0] and len(sun.tiles) == 1 and sun.sun_slot[0] == 0
    wide = shadow_maps.plan(scene.lights(radius=1.0), scene.BOUNDS, 512)       # 1 m at 4 m: 0.24 rad
    assert not wide.active
    area = scene.lights()
    area.point_emitter[0, 0] = 1.0
    assert not shadow_maps.plan(area, scene.BOUNDS, 512).active
    assert not shadow_maps.plan(scene.lights(), None, 512).active
    huge = shadow_maps.plan(scene.lights(), scene.BOUNDS, 100000)
    assert max(huge.atlas_shape) <= shadow_maps.MAX_SIDE
    assert huge.atlas_shape[0] * huge.atlas_shape[1] <= shadow_maps.MAX_TEXELS


@pytest.mark.parametrize("kind", ["point", "sun"])
def test_hard_edge_lies_where_the_blocker_casts_it(kind):
    """A point light (radius 0) or a sun straight above (angle 0): the floor is dark under the blocker's shadow
    and lit beyond it, the edge within two texels of its exact place (x = 2 under the point light at 4 m, x = 1
    under the sun)."""
    lights = scene.lights() if kind == "point" else scene.lights(sun_radius=0.0)
    shadow_plan = shadow_maps.plan(lights, scene.BOUNDS, 1024)
    atlas = scene.draw_atlas(shadow_plan)
    edge = 2.0 if kind == "point" else 1.0
    texel = 2.0 * scene.LIGHT_HEIGHT / (shadow_plan.size * shadow_plan.inner) if kind == "point" else \
        float(shadow_plan.sun_texel[0])
    xs, position, normal = scene.receivers(edge - 0.5, edge + 0.5)
    visible = shadow_maps.light_visibility(atlas, shadow_plan, lights, position, normal)[:, 0, 0]
    inside, outside = xs < edge - 2 * texel, xs > edge + 2 * texel
    assert np.all(visible[inside] < 1e-6) and np.all(visible[outside] > 1 - 1e-6)
    # the floor far from the blocker: lit, no self-shadowing (the bias and the normal offset)
    _, far, far_normal = scene.receivers(2.6 if kind == "point" else 1.5, 3.5)
    assert np.all(shadow_maps.light_visibility(atlas, shadow_plan, lights, far, far_normal)[:, 0, 0] > 1 - 1e-6)


def test_penumbra_of_a_sphere_light_against_the_exact_fraction():
    """A sphere light of radius 0.05 at 4 m behind a straight edge halfway down: the exact visible fraction is the
    light's disc beyond the edge's image (c = 2 - x); PCSS's filter over the penumbra (radius r (z_r - z_b) / z_b
    = 0.05, 6 texels at 1024) gives a ramp.  Measured: max error 0.093, mean over the penumbra 0.041 (docs/
    ACCURACY.md, shadow_maps).  A light of radius 0.2 needs 25 texels, past the guard band: the softness is 1
    there, and a baked object takes the SSDF's visibility instead."""
    radius = 0.05
    lights = scene.lights(radius=radius)
    shadow_plan = shadow_maps.plan(lights, scene.BOUNDS, 1024)
    atlas = scene.draw_atlas(shadow_plan)
    xs, position, normal = scene.receivers(2.0 - 1.5 * radius, 2.0 + 1.5 * radius)
    result = shadow_maps.light_visibility(atlas, shadow_plan, lights, position, normal)[:, 0]
    exact = scene.disc_fraction(2.0 - xs, radius)
    error = np.abs(result[:, 0] - exact)
    penumbra = np.abs(xs - 2.0) < radius
    print(f"max error {error.max():.3f}, mean over the penumbra {error[penumbra].mean():.3f}")
    assert error.max() < 0.12
    assert error[penumbra].mean() < 0.06
    assert np.all(result[:, 1] == 0.0)
    wide = scene.lights(radius=0.2)
    wide_plan = shadow_maps.plan(wide, scene.BOUNDS, 1024)
    xs, position, normal = scene.receivers(1.95, 2.05, 5)
    softness = shadow_maps.light_visibility(scene.draw_atlas(wide_plan), wide_plan, wide, position, normal)[:, 0, 1]
    assert np.all(softness[1:-1] == 1.0)


def test_degenerate_input_stays_finite():
    """NaN positions or normals, a light inside the bounds, zero normals: finite fractions in [0, 1]."""
    lights = scene.lights(radius=0.1)
    lights.point_position[0] = (0.0, 0.0, 1.0)         # inside the casters' box
    shadow_plan = shadow_maps.plan(lights, scene.BOUNDS, 256)
    assert shadow_plan.active and shadow_plan.point_near_far[0, 0] > 0
    atlas = scene.draw_atlas(shadow_plan)
    position = np.array([[0.5, 0.5, 0.0], [np.nan, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]])
    normal = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [np.nan, 0.0, 1.0]])
    with np.errstate(invalid="ignore"):
        result = shadow_maps.light_visibility(atlas, shadow_plan, lights, position, normal)
    assert np.all(np.isfinite(result[:, 0, 0])) and np.all((result >= 0) & (result <= 1))
    assert math.isfinite(float(shadow_plan.point_near_far[0, 1]))


def test_sun_tile_narrowed_to_the_view():
    """A camera 10 m over the floor at x = 2 looking down with a 20-degree field sees x in [0.24, 3.76] of the 8 m
    box: the sun's tile covers that (a texel 2.3x finer), and the shadow's edge at x = 1 stays in place."""
    fov = np.radians(20.0)
    f, near, far = 1.0 / np.tan(fov / 2), 0.1, 100.0
    projection = np.array([[f, 0, 0, 0], [0, f, 0, 0], [0, 0, -(far + near) / (far - near), -2 * far * near /
                                                          (far - near)], [0, 0, -1, 0]])
    view = np.eye(4)
    view[:3, 3] = (-2.0, 0.0, -10.0)
    corners = shadow_maps.view_corners(projection @ view, scene.BOUNDS)
    lights = scene.lights(sun_radius=0.0)
    whole = shadow_maps.plan(lights, scene.BOUNDS, 1024)
    narrowed = shadow_maps.plan(lights, scene.BOUNDS, 1024, corners)
    assert whole.sun_texel[0] / narrowed.sun_texel[0] > 2.0
    atlas = scene.draw_atlas(narrowed)
    texel = float(narrowed.sun_texel[0])
    xs, position, normal = scene.receivers(0.5, 1.5)
    visible = shadow_maps.light_visibility(atlas, narrowed, lights, position, normal)[:, 0, 0]
    assert np.all(visible[xs < 1.0 - 2 * texel] < 1e-6) and np.all(visible[xs > 1.0 + 2 * texel] > 1 - 1e-6)
    looking_up = np.diag([1.0, -1.0, -1.0, 1.0]) @ view         # the box behind the camera: no narrowing
    assert shadow_maps.view_corners(projection @ looking_up, scene.BOUNDS) is None
