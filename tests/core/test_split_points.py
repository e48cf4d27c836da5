"""Where per-vertex bakes are made (visibility.per_vertex.split_points, inset_points): a point a vertex where
every vertex has one normal, a point a vertex and normal where flat faces or sharp edges give it several."""
import numpy as np

from sg_prt_addon.visibility import per_vertex

# a cube's 6 faces as quads over its 8 corners
CUBE_FACES = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
CUBE_VERTICES = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])


def _cube_corners(flat):
    corner_vertex = np.array([v for face in CUBE_FACES for v in face])
    face_normals = np.array([np.sign(CUBE_VERTICES[list(face)].sum(axis=0)) for face in CUBE_FACES])
    if flat:
        normals = np.repeat(face_normals, 4, axis=0)
    else:
        normals = CUBE_VERTICES[corner_vertex] / np.sqrt(3.0)
    return corner_vertex, normals


def test_smooth_mesh_has_a_point_a_vertex():
    corner_vertex, normals = _cube_corners(flat=False)
    corner_point, point_vertex, point_normal = per_vertex.split_points(corner_vertex, normals + 1e-7)
    assert len(point_vertex) == 8 and np.array_equal(point_vertex[corner_point], corner_vertex)
    assert np.allclose(point_normal[corner_point], normals, atol=1e-6)


def test_flat_cube_has_a_point_a_face_corner():
    corner_vertex, normals = _cube_corners(flat=True)
    corner_point, point_vertex, point_normal = per_vertex.split_points(corner_vertex, normals)
    assert len(point_vertex) == 24
    assert np.array_equal(point_vertex[corner_point], corner_vertex)
    assert np.array_equal(point_normal[corner_point], normals)       # each corner reads its own face's normal


def test_corners_sharing_a_face_normal_share_a_point():
    """Two coplanar triangles of a quad meet at two vertices: their corners there agree, so one point each."""
    corner_vertex = np.array([0, 1, 2, 0, 2, 3])
    normals = np.tile([0.0, 0.0, 1.0], (6, 1))
    corner_point, point_vertex, _ = per_vertex.split_points(corner_vertex, normals)
    assert len(point_vertex) == 4 and corner_point[0] == corner_point[3] and corner_point[2] == corner_point[4]


def test_inset_moves_points_into_their_faces():
    """A box's bottom corner sits on the floor's plane; its side face's point moves up, into the face, by
    CORNER_INSET of the way to the face's centre."""
    corner_vertex, normals = _cube_corners(flat=True)
    corner_point, point_vertex, _ = per_vertex.split_points(corner_vertex, normals)
    face_centres = np.repeat([CUBE_VERTICES[list(face)].mean(axis=0) for face in CUBE_FACES], 4, axis=0)
    moved = per_vertex.inset_points(CUBE_VERTICES[point_vertex], corner_point, face_centres)
    offset = moved[corner_point] - CUBE_VERTICES[corner_vertex]
    assert np.allclose(offset, per_vertex.CORNER_INSET * (face_centres - CUBE_VERTICES[corner_vertex]))
    side = CUBE_FACES.index((0, 4, 5, 1))          # the face of y = -1
    points = moved[corner_point[4 * side:4 * side + 4]]
    assert np.all(points[:, 1] == -1.0) and np.all(points[:, 2] > -1.0)    # in its plane, off the floor z = -1


def test_split_normals_are_found():
    smooth_vertex, smooth_normals = _cube_corners(flat=False)
    vertex_normals = CUBE_VERTICES / np.sqrt(3.0)
    assert not per_vertex.has_split_normals(smooth_normals, vertex_normals, smooth_vertex)
    flat_vertex, flat_normals = _cube_corners(flat=True)
    assert per_vertex.has_split_normals(flat_normals, vertex_normals, flat_vertex)
