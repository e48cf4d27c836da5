"""Area lights (lighting.lights.area_light_patches): the patch grid against Lambert's exact polygon formula, the
formula against quadrature, Cycles' spread keeping the power, and the grid's bookkeeping."""
import numpy as np
import pytest

from sg_prt_addon.lighting import lights
from validation import exact_references

CENTRE = np.zeros(3)
EDGE_U, EDGE_V = np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
DOWN = np.array([0.0, 0.0, -1.0])


def _square(centre=CENTRE, edge_u=EDGE_U, edge_v=EDGE_V, normal=DOWN):
    """The square's corners, turning anticlockwise about its normal (polygon_irradiance's emitting side)."""
    corners = np.array([centre - edge_u / 2 - edge_v / 2, centre + edge_u / 2 - edge_v / 2,
                        centre + edge_u / 2 + edge_v / 2, centre - edge_u / 2 + edge_v / 2])
    turn = np.cross(corners[1] - corners[0], corners[2] - corners[0])
    return corners if np.dot(turn, normal) > 0 else corners[::-1]


def _receivers(distance, count=300, seed=1):
    """Points under the unit square at `distance`, normals turned up to 70 degrees off its direction."""
    rng = np.random.default_rng(seed)
    position = np.c_[rng.uniform(-1.0, 1.0, count), rng.uniform(-1.0, 1.0, count), np.full(count, -distance)]
    normal = rng.normal(size=(count, 3))
    normal[:, 2] = np.abs(normal[:, 2]) + 0.4
    return position, normal / np.linalg.norm(normal, axis=-1, keepdims=True)


def _patch_irradiance(position, normal, patches):
    return lights.patches_irradiance(position, normal, patches)[:, 0]


def _quadrature_irradiance(position, normal, spread=np.pi):
    return exact_references.area_irradiance_quadrature(position, normal, CENTRE, EDGE_U, EDGE_V, DOWN, spread)


def _relative_l2(value, reference):
    return float(np.sqrt(np.mean((value - reference) ** 2) / np.mean(reference ** 2)))


def test_polygon_formula_matches_quadrature():
    """The reference itself: Lambert's formula against the midpoint rule, including receivers whose horizon
    cuts the light (clipped) and points behind the one-sided emitter (zero)."""
    position, normal = _receivers(1.0, count=40)
    normal[:10] = [[1.0, 0.0, 0.3]] / np.linalg.norm([1.0, 0.0, 0.3])        # the horizon cuts the square
    exact = lights.polygon_irradiance(position, normal, _square())
    assert _relative_l2(exact, _quadrature_irradiance(position, normal)) < 1e-5        # measured 7.9e-7
    behind = lights.polygon_irradiance(position * [1, 1, -1], -normal, _square())
    assert np.all(behind == 0)


@pytest.mark.parametrize("distance, per_side, bound", [
    (0.25, 4, 0.05),      # measured 0.041 (a quarter of the light's size away)
    (0.5, 4, 0.016),      # 0.012
    (1.0, 4, 0.008),      # 0.0061
    (2.0, 4, 0.0035),     # 0.0027
    (0.5, 2, 0.075),      # 0.059
    (0.5, 6, 0.007),      # 0.0054
])
def test_patch_grid_against_polygon_formula(distance, per_side, bound):
    """The default grid (4 a side) lights receivers from half the light's size away within 1.6% relative L2."""
    position, normal = _receivers(distance)
    patches = lights.area_light_patches(CENTRE, EDGE_U, EDGE_V, DOWN, "SQUARE", np.array([np.pi]), per_side)
    exact = lights.polygon_irradiance(position, normal, _square())           # radiance P / (pi A) = 1
    error = _relative_l2(_patch_irradiance(position, normal, patches), exact)
    assert error <= bound


def test_patch_grid_converges():
    position, normal = _receivers(0.5)
    exact = lights.polygon_irradiance(position, normal, _square())
    errors = [_relative_l2(_patch_irradiance(position, normal, lights.area_light_patches(
        CENTRE, EDGE_U, EDGE_V, DOWN, "SQUARE", np.array([np.pi]), n)), exact) for n in (1, 2, 4, 8)]
    assert all(later < 0.6 * earlier for earlier, later in zip(errors, errors[1:])), errors


@pytest.mark.parametrize("spread_degrees, bound", [
    (90.0, 0.02),         # measured 0.014
    (60.0, 0.035),        # 0.025
    (30.0, 0.12),         # 0.089: narrower, each patch's beam shows (blender/export/lights.py warns below 30 degrees)
])
def test_spread_patches_against_quadrature(spread_degrees, bound):
    """A narrowed spread: the patches take the attenuation at their centres, a light's size away."""
    position, normal = _receivers(1.0, count=60)
    patches = lights.area_light_patches(CENTRE, EDGE_U, EDGE_V, DOWN, "SQUARE", np.array([np.pi]), 4,
                                        spread=np.radians(spread_degrees))
    reference = _quadrature_irradiance(position, normal, spread=np.radians(spread_degrees))
    assert _relative_l2(_patch_irradiance(position, normal, patches), reference) <= bound


@pytest.mark.parametrize("spread_degrees", [1.0, 5.0, 30.0, 90.0, 150.0, 180.0])
def test_spread_keeps_the_power(spread_degrees):
    """Cycles' soft-box normalization: the attenuated cosine integrates to pi over the hemisphere at every
    spread, as the Lambertian light does."""
    half = 0.5 * np.radians(spread_degrees)
    theta = np.linspace(0.0, min(half, 0.5 * np.pi), 200001)
    tan_half, normalization = lights.spread_parameters(np.radians(spread_degrees))
    factor = lights.emission_factor(np.cos(theta), -1.0, 0.0, True, tan_half, normalization)
    power = 2 * np.pi * np.trapezoid(factor * np.sin(theta), theta) if hasattr(np, "trapezoid") else \
        2 * np.pi * np.trapz(factor * np.sin(theta), theta)
    assert power == pytest.approx(np.pi, rel=2e-3)


@pytest.mark.parametrize("shape, size_v", [("SQUARE", 2.0), ("RECTANGLE", 0.5), ("DISK", 2.0), ("ELLIPSE", 0.7)])
def test_patches_share_the_power_and_area(shape, size_v):
    edge_u, edge_v = np.array([2.0, 0.0, 0.0]), np.array([0.0, size_v if shape in ("RECTANGLE", "ELLIPSE") else 2.0,
                                                             0.0])
    power = np.array([10.0, 20.0, 30.0])
    patches = lights.area_light_patches(CENTRE, edge_u, edge_v, DOWN, shape, power, 4)
    assert np.allclose(patches.intensity.sum(axis=0), power / np.pi)          # intensity P / pi along the normal
    assert np.allclose(patches.position.mean(axis=0), CENTRE, atol=1e-12)
    area = lights.area_light_area(shape, 2.0, np.linalg.norm(edge_v))
    assert np.pi * np.sum(patches.radius ** 2) == pytest.approx(area)
    local = patches.position[:, :2] / [1.0, np.linalg.norm(edge_v) / 2]
    inside = np.sum(local ** 2, axis=-1) <= 1 if shape in ("DISK", "ELLIPSE") else np.all(np.abs(local) <= 1, -1)
    assert np.all(inside)
    assert 8 <= len(patches.radius) <= 16                                   # about 4 x 4, each near square


def test_zero_size_light_is_a_lambertian_point():
    patches = lights.area_light_patches(CENTRE, np.zeros(3), np.zeros(3), DOWN, "SQUARE", np.array([4.0]), 4)
    assert np.all(np.isfinite(patches.intensity)) and np.all(patches.radius == 0)
    assert patches.intensity.sum() == pytest.approx(4.0 / np.pi)


def test_emission_factor_is_one_sided_and_keeps_spots():
    cos_angle = np.array([-0.5, 0.0, 0.5, 1.0])
    assert np.allclose(lights.emission_factor(cos_angle, -1.0, 0.0, True, 0.0, 0.0), [0, 0, 0.5, 1])
    assert np.allclose(lights.emission_factor(cos_angle, -1.0, 0.0, False, 0.0, 0.0), 1)
    spot = lights.emission_factor(cos_angle, 1.0, 0.2, False, 0.0, 0.0)
    assert spot[0] == 0 and spot[-1] == 1
    assert lights.emission_factor(np.float32([0.3]), -1.0, 0.0, True, 0.0, 0.0).dtype == np.float32
