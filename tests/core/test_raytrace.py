import numpy as np
import pytest

from sg_prt_addon.visibility.raytrace import RayTracer, offset_origins

TRIANGLE = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _sphere(subdivisions=3):
    from benchmarks.reference_speed import make_icosphere
    return make_icosphere(subdivisions)


def test_intersect_reports_distance_triangle_and_barycentrics():
    tracer = RayTracer(TRIANGLE, [[0, 1, 2]])
    origins = np.array([[0.2, 0.3, 2.0], [0.6, 0.6, 1.0], [0.1, 0.1, -1.0], [0.25, 0.5, 1.0]])
    directions = np.array([[0, 0, -1.0], [0, 0, -1.0], [0, 0, -1.0], [0, 0, -2.0]])   # last: non-unit
    hits = tracer.intersect(origins, directions)
    assert hits.hit.tolist() == [True, False, False, True]
    np.testing.assert_allclose(hits.distance[[0, 3]], [2.0, 0.5], atol=1e-6)
    assert np.isinf(hits.distance[[1, 2]]).all()
    assert hits.triangle.tolist() == [0, -1, -1, 0]
    np.testing.assert_allclose(hits.u[[0, 3]], [0.2, 0.25], atol=1e-6)
    np.testing.assert_allclose(hits.v[[0, 3]], [0.3, 0.5], atol=1e-6)
    np.testing.assert_allclose(tracer.hit_points(hits)[0], [0.2, 0.3, 0.0], atol=1e-6)


def test_intersect_picks_nearest_of_two_triangles():
    vertices = np.concatenate([TRIANGLE, TRIANGLE + [0, 0, 1.0]])
    tracer = RayTracer(vertices, [[0, 1, 2], [3, 4, 5]])
    hits = tracer.intersect([[0.2, 0.2, 3.0], [0.2, 0.2, -3.0]], [[0, 0, -1.0], [0, 0, 1.0]])
    assert hits.triangle.tolist() == [1, 0]
    np.testing.assert_allclose(hits.distance, [2.0, 3.0], atol=1e-6)


@pytest.mark.parametrize("bad_value", [np.nan, np.inf, 1e30])
def test_a_bad_vertex_drops_its_triangles_alone(bad_value):
    """A NaN, Inf or huge vertex: its triangles are never hit, the others keep their indices and the scene's size
    (the rays' origin offset) is the good vertices'."""
    good = RayTracer(np.concatenate([TRIANGLE, TRIANGLE + [0, 0, 1.0]]), [[0, 1, 2], [3, 4, 5]])
    vertices = np.concatenate([TRIANGLE, TRIANGLE + [0, 0, 1.0], [[bad_value, 0.0, 0.0]]])
    tracer = RayTracer(vertices, [[6, 1, 2], [0, 1, 2], [3, 4, 5], [3, 6, 5]])
    assert tracer.scene_size == good.scene_size and np.isfinite(tracer.offset)
    hits = tracer.intersect([[0.2, 0.2, 3.0], [0.2, 0.2, -3.0], [0.05, 0.05, 0.5]], [[0, 0, -1.0], [0, 0, 1.0],
                                                                                         [-1.0, 0.0, 0.0]])
    assert hits.triangle.tolist() == [2, 1, -1]
    np.testing.assert_allclose(hits.distance[:2], [2.0, 3.0], atol=1e-6)


def test_occluded_respects_max_distance():
    tracer = RayTracer(TRIANGLE, [[0, 1, 2]])
    origins = np.array([[0.2, 0.2, 1.0]] * 3 + [[2.0, 2.0, 1.0]])
    directions = np.array([[0, 0, -1.0]] * 4)
    occluded = tracer.occluded(origins, directions, max_distance=np.array([2.0, 0.99, np.inf, 2.0]))
    assert occluded.tolist() == [True, False, True, False]
    assert tracer.occluded(origins, directions).tolist() == [True, True, True, False]
    assert not tracer.occluded(origins[:1], -directions[:1]).any()


def test_threads_and_chunks_match_single_thread():
    vertices, triangles, _ = _sphere(2)
    rng = np.random.default_rng(0)
    origins = rng.uniform(-2, 2, (5000, 3))
    directions = rng.normal(size=(5000, 3))
    single = RayTracer(vertices, triangles, threads=1)
    chunked = RayTracer(vertices, triangles, threads=2, chunk_rays=333)
    a, b = single.intersect(origins, directions), chunked.intersect(origins, directions)
    assert 0.05 < a.hit.mean() < 0.9
    np.testing.assert_array_equal(a.triangle, b.triangle)
    np.testing.assert_array_equal(a.distance, b.distance)
    np.testing.assert_array_equal(single.occluded(origins, directions), chunked.occluded(origins, directions))
    np.testing.assert_array_equal(a.hit, single.occluded(origins, directions))
    assert chunked.rays_traced == 10000


def test_offset_origins_avoid_self_intersection_on_a_convex_mesh():
    vertices, triangles, _ = _sphere(3)
    tracer = RayTracer(vertices, triangles)
    rng = np.random.default_rng(1)
    triangle = rng.integers(0, len(triangles), 20000)
    weights = rng.dirichlet(np.ones(3), 20000)
    points = np.einsum("nk,nkc->nc", weights, vertices[triangles[triangle]])
    normals = tracer.geometric_normals(triangle)
    # Outward rays from a convex mesh must escape; grazing ones are the hardest.
    directions = rng.normal(size=(20000, 3))
    directions -= normals * np.sum(directions * normals, -1, keepdims=True)
    directions += normals * rng.uniform(1e-3, 1.0, (20000, 1))
    offset = offset_origins(points, normals, tracer.offset)
    assert not tracer.occluded(offset, directions).any()
    # The same rays from below the surface all hit it (the offset is on the right side).
    below = offset_origins(points, -normals, tracer.offset)
    assert tracer.occluded(below, directions).mean() > 0.99


def test_offset_origins_flips_normals_to_the_ray_side():
    points = np.zeros((2, 3))
    normals = np.array([[0, 0, 1.0], [0, 0, 1.0]])
    out = offset_origins(points, normals, 0.1, directions=np.array([[0, 1.0, 1.0], [0, 1.0, -1.0]]))
    np.testing.assert_allclose(out[:, 2], [0.1, -0.1])


def test_empty_mesh_and_empty_batches():
    tracer = RayTracer(np.zeros((0, 3)), np.zeros((0, 3), int))
    assert not tracer.occluded([[0, 0, 0.0]], [[0, 0, 1.0]]).any()
    assert not tracer.intersect([[0, 0, 0.0]], [[0, 0, 1.0]]).hit.any()
    full = RayTracer(TRIANGLE, [[0, 1, 2]])
    assert full.occluded(np.zeros((0, 3)), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(ValueError):
        RayTracer(TRIANGLE, [[0, 1, 3]])
