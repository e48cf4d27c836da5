"""lighting.equirect.rotated (a world Mapping node's turn of the environment) against the turned function."""
import numpy as np
import pytest

from sg_prt_addon.lighting import equirect

AXIS_A, AXIS_B = np.array([0.3, -0.5, 0.8]), np.array([0.7, 0.1, 0.2])


def _smooth(directions):
    return (1 + directions @ AXIS_A + (directions @ AXIS_B) ** 2)[..., None] * np.ones(3)


def _turn(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


@pytest.mark.parametrize("matrix, bound", [
    (_turn((0, 0, 1), 0.7), 3e-4),                       # measured 1.6e-4: along u only
    (_turn((1, 0, 0), 0.7) @ _turn((0, 0, 1), 0.7), 3e-3),  # measured 2.2e-3: bilinear in u and v
    (np.diag([1.0, -1.0, 1.0]), 1e-6),                   # a mirror in y: texel centres land on texel centres
    (np.diag([2.0, 2.0, 1.0]), 1e-3),                    # measured 2.4e-4: x and y scaled, not z, move the
                                                         # elevations (read along u only: 0.19)
])
def test_turned_map_reads_the_turned_function(matrix, bound):
    directions = equirect.texel_directions(64, 128)
    image = _smooth(directions).astype(np.float32)
    turned = equirect.rotated(image, matrix)
    mapped = directions @ matrix.T
    exact = _smooth(mapped / np.linalg.norm(mapped, axis=-1, keepdims=True))      # the map reads normalize(M d)
    assert np.abs(turned - exact).max() / np.abs(exact).max() < bound


def test_a_turn_by_whole_texels_about_z_is_a_shift():
    image = np.random.default_rng(1).uniform(size=(16, 32, 3)).astype(np.float32)
    turned = equirect.rotated(image, _turn((0, 0, 1), 2 * np.pi * 3 / 32))
    np.testing.assert_allclose(turned, np.roll(image, 3, axis=1), atol=1e-5)
