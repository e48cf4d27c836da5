"""sg_prt_addon.visibility.hemisphere_map: the square <-> hemisphere map and local frames."""
import numpy as np

from sg_prt_addon.visibility import hemisphere_map as hm


def _square_points(count, seed=0):
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, (count, 2))
    # region boundaries |a| = |b|, axes, corners, centre
    special = [[0, 0], [1, 1], [-1, 1], [1, -1], [-1, -1], [1, 0], [0, -1], [0.3, 0.3], [-0.7, 0.7], [1e-12, -1e-12]]
    return np.concatenate([special, points])


def test_round_trip_is_exact():
    square = _square_points(50000)
    direction = hm.square_to_hemisphere(square)
    assert np.abs(np.linalg.norm(direction, axis=1) - 1).max() < 1e-14
    assert direction[:, 2].min() >= 0
    assert np.abs(hm.hemisphere_to_square(direction) - square).max() < 1e-13
    rng = np.random.default_rng(1)
    d = rng.normal(size=(50000, 3))
    d[:, 2] = np.abs(d[:, 2])
    d[:3] = [[0, 0, 1], [1, 0, 0], [0, -1, 1e-300]]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    assert np.abs(hm.square_to_hemisphere(hm.hemisphere_to_square(d)) - d).max() < 1e-13


def test_edges_map_to_horizon_and_centre_to_normal():
    t = np.linspace(-1, 1, 101)
    edge = np.concatenate([np.c_[t, np.ones_like(t)], np.c_[np.ones_like(t), t], np.c_[t, -np.ones_like(t)]])
    assert np.abs(hm.square_to_hemisphere(edge)[:, 2]).max() < 1e-15
    assert np.allclose(hm.square_to_hemisphere([0.0, 0.0]), [0, 0, 1])
    # a along local x, b along local y
    assert np.allclose(hm.square_to_hemisphere([1.0, 0.0]), [1, 0, 0])
    assert np.allclose(hm.square_to_hemisphere([0.0, 1.0]), [0, 1, 0])


def test_equal_area():
    """Uniform square points give uniform hemisphere directions: z is uniform on [0, 1]
    (Archimedes), also within each square region."""
    square = np.random.default_rng(2).uniform(-1, 1, (400000, 2))
    z = hm.square_to_hemisphere(square)[:, 2]
    histogram, _ = np.histogram(z, bins=20, range=(0, 1))
    assert np.abs(histogram / len(z) * 20 - 1).max() < 0.03
    # per-texel solid angle at 16 x 16: areas from the counts, all within sampling noise of 2 pi / 256
    counts, _, _ = np.histogram2d(square[:, 0], square[:, 1], bins=16, range=[[-1, 1], [-1, 1]])
    assert np.abs(counts / counts.mean() - 1).max() < 0.1


def test_continuity_across_region_diagonals():
    s = np.linspace(-1, 1, 2001)
    for direction in ([1, 1], [1, -1]):
        diagonal = s[:, None] * np.array(direction, float)
        for shift in (1e-9, -1e-9):
            a = hm.square_to_hemisphere(diagonal + [shift, 0])
            b = hm.square_to_hemisphere(diagonal)
            assert np.abs(a - b).max() < 1e-8


def test_horizon_lookup_below_the_horizon():
    rng = np.random.default_rng(3)
    d = rng.normal(size=(1000, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    square, below = hm.horizon_lookup(d)
    up = d[:, 2] >= 0
    assert np.all(below[up] == 0) and np.allclose(square[up], hm.hemisphere_to_square(d[up]))
    looked_up = hm.square_to_hemisphere(square[~up])
    assert np.abs(looked_up[:, 2]).max() < 1e-12                                  # on the horizon
    azimuth = np.arctan2(d[~up, 1], d[~up, 0])
    assert np.abs(np.angle(np.exp(1j * (np.arctan2(looked_up[:, 1], looked_up[:, 0]) - azimuth)))).max() < 1e-12
    assert np.allclose(below[~up], np.arcsin(-d[~up, 2]))
    square, below = hm.horizon_lookup(np.array([[0.0, 0.0, -1.0]]))
    assert np.allclose(below, np.pi / 2) and np.allclose(hm.square_to_hemisphere(square)[:, 2], 0)


def test_local_frame_orthonormal_and_smooth():
    rng = np.random.default_rng(4)
    n = rng.normal(size=(5000, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    n[:4] = [[0, 0, 1], [0, 0, -1], hm.FRAME_REFERENCE_AXIS, -hm.FRAME_REFERENCE_AXIS]
    frame = hm.local_frame(n)
    assert np.abs(frame @ np.swapaxes(frame, 1, 2) - np.eye(3)).max() < 1e-12
    assert np.allclose(np.linalg.det(frame), 1)
    assert np.allclose(frame[:, 2], n)
    # a normal turned by 1e-3 rad turns the frame by O(1e-3) away from the reference axis
    far = np.abs(n @ hm.FRAME_REFERENCE_AXIS) < 0.9
    nudged = n + 1e-3 * rng.normal(size=n.shape)
    change = np.abs(hm.local_frame(nudged) - frame).max(axis=(1, 2))
    assert change[far].max() < 0.02


def test_local_frame_degenerate_inputs():
    frame = hm.local_frame(np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [0.0, 0.0, 2.0]]),
                           np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]))
    assert np.all(np.isfinite(frame))
    assert np.allclose(frame[:, 2], [0, 0, 1])
    assert np.allclose(frame[0, 0], [1, 0, 0])
    assert np.allclose(frame[2], hm.local_frame(np.array([[0.0, 0.0, 1.0]]))[0])   # parallel tangent
