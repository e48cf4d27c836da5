"""SSDF (wang2009 eq. 23) of ray-traced analytic configurations against closed-form angular distances.

One vertex at the origin, normal +z; the occluder is real geometry traced by
visibility.raytrace through the bake (adaptive 32 x 32 coarse rays, x5 refinement).
The error budget: boundary midpoints lie within about half a fine texel
diagonal (0.011 rad at 160 x 160) of the true boundary, plus float16 storage
(<= 5e-4 rad); where a visible wedge meets the horizon at a shallow angle, its
tip below the outermost fine texel row (0.7 degrees up) is lost, which moves
the nearest boundary point of the occluded directions near that corner
(measured 0.031 rad at a 10 degree tilt, 0.026 at 20, 0.011 at 55).
"""
import numpy as np
import pytest

from sg_prt_addon.visibility import BakeOptions, decode, hemisphere_map, ssdf
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer

OPTIONS = BakeOptions(resolution=32, refinement=5)
# Boundary sampling at 160 x 160, float16, and the lost wedge tip at the horizon (module docstring).
MAX_ERROR = 0.035
MEAN_ERROR = 0.012


def _bake_one(vertices, triangles, options=OPTIONS):
    tracer = RayTracer(vertices, triangles, threads=1)
    values = bake_ssdf(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), tracer, options)
    tracer.close()
    resolution = options.resolution
    # the default frame of normal +z: local x = the reference axis projected
    frame = hemisphere_map.local_frame(np.array([[0.0, 0.0, 1.0]]))[0]
    local = hemisphere_map.sample_directions(resolution).reshape(-1, 3)
    return values[0].astype(np.float64), local @ frame, values[0].reshape(resolution, resolution), frame


def quad(centre, normal, half_size):
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    u = np.cross(normal, [0.0, 1.0, 0.0] if abs(normal[1]) < 0.9 else [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    corners = np.array([centre + half_size * (su * u + sv * v) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return corners, np.array([[0, 1, 2], [0, 2, 3]])


def disc(centre, normal, radius, segments=512):
    normal = np.asarray(normal, float) / np.linalg.norm(normal)
    u = np.cross(normal, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    angle = np.linspace(0, 2 * np.pi, segments, endpoint=False)
    rim = centre + radius * (np.cos(angle)[:, None] * u + np.sin(angle)[:, None] * v)
    vertices = np.concatenate([[centre], rim])
    index = np.arange(segments)
    return vertices, np.stack([np.zeros(segments, int), 1 + index, 1 + (index + 1) % segments], 1)


def tilted_plane_ssdf(direction, plane_normal):
    """Closed form: occluded = {i.m > 0} (the plane, m towards it) or below the horizon."""
    m = plane_normal
    dot = direction @ m
    elevation = np.arcsin(np.clip(direction[:, 2], -1, 1))
    visible = dot <= 0
    visible_distance = np.minimum(np.arcsin(np.clip(-dot, 0, 1)), elevation)
    # occluded: nearest visible point is the projection on the great circle if above the horizon,
    # else a corner of the lune (great circle x horizon)
    projection = direction - dot[:, None] * m
    corner = np.cross(m, [0.0, 0.0, 1.0])
    corner /= np.linalg.norm(corner)
    to_corner = np.arccos(np.clip(np.abs(direction @ corner), -1, 1))
    occluded_distance = np.where(projection[:, 2] >= 0, np.arcsin(np.clip(dot, 0, 1)), to_corner)
    return np.where(visible, visible_distance, -occluded_distance)


@pytest.mark.parametrize("tilt_degrees", [10.0, 20.0, 55.0])
def test_tilted_infinite_plane(tilt_degrees):
    tilt = np.radians(tilt_degrees)
    m = np.array([np.sin(tilt), 0.3 * np.cos(tilt), np.cos(tilt)])
    m /= np.linalg.norm(m)
    vertices, triangles = quad(1.0 * m, m, 400.0)
    values, directions, _, _ = _bake_one(vertices, triangles)
    error = np.abs(values - tilted_plane_ssdf(directions, m))
    assert error.max() < MAX_ERROR and error.mean() < MEAN_ERROR, (error.max(), error.mean())


def test_spherical_cap_occluder():
    centre = np.array([np.cos(1.0) * np.cos(0.4), np.cos(1.0) * np.sin(0.4), np.sin(1.0)])
    distance, radius = 2.0, 0.8
    vertices, triangles = disc(distance * centre, -centre, radius)
    values, directions, _, _ = _bake_one(vertices, triangles)
    cap = np.arctan(radius / distance)
    angle = np.arccos(np.clip(directions @ centre, -1, 1))
    elevation = np.arcsin(directions[:, 2])
    expected = np.where(angle >= cap, np.minimum(angle - cap, elevation), angle - cap)
    error = np.abs(values - expected)
    assert error.max() < MAX_ERROR and error.mean() < MEAN_ERROR, (error.max(), error.mean())


def test_open_plane_is_the_elevation_and_reconstructs_the_upper_hemisphere():
    """Nothing above: V_d = elevation (the horizon is the boundary), so V_d(n) ~ pi/2 and a lobe
    at the normal keeps all of its upper-hemisphere integral."""
    floor, triangles = quad(np.zeros(3), [0.0, 0.0, 1.0], 10.0)
    values, directions, image, frame = _bake_one(floor, triangles)
    assert np.abs(values - np.arcsin(directions[:, 2])).max() < 1e-3
    normal_value = decode.decode_image(image, np.array([0.0, 0.0, 1.0]))
    assert abs(normal_value - np.pi / 2) < 0.05     # bilinear between the four samples around the pole
    horizon = np.array([[np.cos(a), np.sin(a), 0.0] for a in np.linspace(0, 6, 50)])
    assert np.abs(decode.decode_image(image, horizon)).max() < 1e-3   # samples on the horizon: exactly 0


def test_fully_occluded_is_minus_pi():
    box, triangles = disc(np.array([0.0, 0.0, 0.5]), [0.0, 0.0, -1.0], 100.0, segments=16)
    values, _, _, _ = _bake_one(box, triangles)
    assert np.all(values == np.float16(ssdf.FULLY_OCCLUDED_VALUE))


def test_fast_nearest_boundary_matches_brute_force():
    """signed_distance (float32 argmax + float64 chord) against float64 arccos over every boundary point."""
    resolution, refinement = 16, 5
    fine = hemisphere_map.texel_directions(resolution * refinement)
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(24, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    visible = (np.einsum("rcx,bx->brc", fine, normals) < 0.3) | (np.einsum("rcx,bx->brc", fine, normals[::-1]) > 0.8)
    visible[0] = True
    visible[1] = False
    index = np.clip(np.floor((hemisphere_map.sample_points(resolution) + 1) * 0.5 * len(fine)), 0, len(fine) - 1)
    index = index.astype(int)
    query_visible = visible[:, index][:, :, index].reshape(len(visible), -1)
    query = hemisphere_map.sample_directions(resolution).reshape(-1, 3)
    fast = ssdf.ssdf_from_fine(visible, resolution).reshape(len(visible), -1)
    exact = ssdf.signed_distance_brute_force(visible, fine, query_visible, query)
    assert np.abs(fast - exact).max() < 5e-6


def test_bilinear_lookup_between_samples():
    """What shading sees: the stored 32 x 32 image looked up bilinearly at random directions,
    against the closed form.  The max sits on the ridge where the plane and the horizon are
    equidistant (bilinear interpolation of a kink): measured max 0.058, mean 0.0065 rad."""
    tilt = np.radians(55.0)
    m = np.array([np.sin(tilt), 0.3 * np.cos(tilt), np.cos(tilt)])
    m /= np.linalg.norm(m)
    vertices, triangles = quad(1.0 * m, m, 400.0)
    _, _, image, frame = _bake_one(vertices, triangles)
    rng = np.random.default_rng(10)
    local = rng.normal(size=(20000, 3))
    local[:, 2] = np.abs(local[:, 2])
    local /= np.linalg.norm(local, axis=1, keepdims=True)
    error = np.abs(decode.decode_image(image, local) - tilted_plane_ssdf(local @ frame, m))
    assert error.max() < 0.07 and error.mean() < 0.008, (error.max(), error.mean())
