import numpy as np

from validation.camera import Camera


def orthographic_camera(half_width, half_height, width, height, height_above=5.0):
    """Camera at (0, 0, height_above) looking down -z, world +y up in the image."""
    view = np.eye(4)
    view[2, 3] = -height_above
    near, far = 0.1, 100.0
    projection = np.diag([1.0 / half_width, 1.0 / half_height, -2.0 / (far - near), 1.0])
    projection[2, 3] = -(far + near) / (far - near)
    return Camera(view, projection, width, height)


def test_look_at_projects_known_points_to_expected_pixels():
    camera = Camera.look_at((0, 0, 5.0), (0, 0, 0), (0, 1.0, 0), 90.0, 100, 100)
    pixels, depth = camera.project(np.array([[0, 0, 0.0], [1.0, 2.0, 0.0], [-5.0, -5.0, 0.0]]))
    # tan(45 deg) = 1: x / 5 in NDC; +y (up) is towards row 0.
    np.testing.assert_allclose(pixels, [[50, 50], [60, 30], [0, 100]], atol=1e-9)
    assert np.all(np.abs(depth) < 1)


def test_look_at_aspect_and_orientation():
    camera = Camera.look_at((0, -10.0, 0), (0, 0, 0), (0, 0, 1.0), 60.0, 200, 100)
    # Looking along +y with z up: +x is to the right, +z up (small rows).
    (right, up), _ = camera.project(np.array([[1.0, 0, 0], [0, 0, 1.0]]))
    focal_pixels = 50 / np.tan(np.radians(30))
    np.testing.assert_allclose(right, [100 + focal_pixels / 10, 50], atol=1e-9)
    np.testing.assert_allclose(up, [100, 50 - focal_pixels / 10], atol=1e-9)
    np.testing.assert_allclose(camera.position, [0, -10, 0], atol=1e-12)


def test_primary_rays_go_through_pixel_centres():
    camera = Camera.look_at((1.0, -4.0, 2.0), (0, 0, 0.5), (0, 0, 1.0), 50.0, 7, 5)
    origins, directions = camera.primary_rays()
    assert origins.shape == directions.shape == (5, 7, 3)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1.0, atol=1e-12)
    y, x = np.mgrid[0:5, 0:7]
    for distance in (0.5, 3.0):
        pixels, _ = camera.project(origins + distance * directions)
        np.testing.assert_allclose(pixels, np.stack([x + 0.5, y + 0.5], -1), atol=1e-9)
    # A perspective camera's rays all come from the eye.
    back = origins - directions * np.sum((origins - camera.position) * directions, -1, keepdims=True)
    np.testing.assert_allclose(back, np.broadcast_to(camera.position, back.shape), atol=1e-9)


def test_jitter_moves_rays_inside_their_pixel():
    camera = Camera.look_at((0, 0, 5.0), (0, 0, 0), (0, 1.0, 0), 40.0, 8, 6)
    jitter = np.random.default_rng(0).random((6, 8, 2))
    origins, directions = camera.primary_rays(jitter)
    pixels, _ = camera.project(origins + directions)
    y, x = np.mgrid[0:6, 0:8]
    np.testing.assert_allclose(pixels, np.stack([x, y], -1) + jitter, atol=1e-9)


def test_orthographic_rays_are_parallel_and_hit_the_expected_footprint():
    camera = orthographic_camera(2.0, 1.0, 40, 20)
    origins, directions = camera.primary_rays()
    np.testing.assert_allclose(directions, np.broadcast_to([0, 0, -1.0], directions.shape), atol=1e-12)
    # Pixel (0, 0) is the top-left: x = -2 + 0.05, y = +1 - 0.05.
    np.testing.assert_allclose(origins[0, 0, :2], [-1.95, 0.95], atol=1e-12)
    np.testing.assert_allclose(origins[-1, -1, :2], [1.95, -0.95], atol=1e-12)
