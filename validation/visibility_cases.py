"""Two visibility cases with exact answers, measured by tests (tests/core/test_light_cap_visibility.py,
tests/core/test_buried.py) and by docs/ACCURACY.md's ssdf rows (benchmarks/accuracy/ssdf.py).

- A light's cap crossing the edge of a half-plane: the share of the cap (cosine-weighted) the SSDF's
  reading leaves visible (techniques.sg.sg_shading.light_cap_visibility), and eq. 30's fh of the light's SG,
  against the exact share.
- A glossy lobe crossing the same edge under an environment brighter on the edge's open side: the radiance the
  lobe's visible part receives, read at the lobe's axis and at its visible part (techniques.sg.sg_shading.
  visible_part_axes: turned to the side lobe_visibility_side finds in the baked SSDF, narrowed), against
  quadrature over the sphere.
- A floor through a sphere: floor vertices inside the sphere are buried (visibility.buried); at visible
  points of the triangles they share, the open share of the SSDF interpolated from the corners against rays
  cast from the point, with the buried rows as baked and filled from their neighbours.
"""
import numpy as np

from benchmarks.bake_speed import grid, icosphere
from sg_prt_addon.lighting import lights
from sg_prt_addon.spherical import hemisphere
from sg_prt_addon.visibility import BakeOptions, buried, decode, hemisphere_map
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer

CAP_TILT = 0.7          # the lights' sweep, turned 40 degrees off the normal: the cosine varies across the cap
SPHERE_RADIUS = 0.35    # the sphere the floor passes through


def _cap_directions(axis, radius, count=200_000, seed=0):
    """Uniform directions (count, 3) in the cap of half-angle radius about axis."""
    rng = np.random.default_rng(seed)
    cosine = 1 - rng.random(count) * (1 - np.cos(radius))
    sine = np.sqrt(1 - cosine ** 2)
    phi = 2 * np.pi * rng.random(count)
    t = np.cross(axis, [0.0, 1.0, 0.0])
    t /= np.linalg.norm(t)
    return np.stack([sine * np.cos(phi), sine * np.sin(phi), cosine], -1) @ np.stack([t, np.cross(axis, t), axis])


def cap_sweep(radius, steps=41):
    """Light axes (K, 3) whose caps of half-angle ``radius`` cross the great circle x = 0 (the edge of the
    half-plane {z = 1, x < 0} seen from the origin, normal +z), and the exact cosine-weighted share of each cap
    on its visible side x > 0 (Monte Carlo, 2e5 directions: noise about 1e-3)."""
    tilt = np.array([[1, 0, 0], [0, np.cos(CAP_TILT), -np.sin(CAP_TILT)], [0, np.sin(CAP_TILT), np.cos(CAP_TILT)]])
    alpha = np.linspace(-2 * radius, 2 * radius, steps)
    axes = np.stack([np.sin(alpha), np.zeros_like(alpha), np.cos(alpha)], -1) @ tilt.T
    exact = []
    for axis in axes:
        d = _cap_directions(axis, radius)
        w = np.maximum(d[:, 2], 0)
        exact.append((w * (d[:, 0] > 0)).sum() / w.sum())
    return axes, np.array(exact)


def baked_half_plane_ssdf(axes, resolution=32, refinement=5):
    """The SSDF (K,) at local directions ``axes`` of the origin (normal +z) under the half-plane, baked from rays
    and read as the shader reads it."""
    quad = np.array([[-20.0, -20.0, 1.0], [0.0, -20.0, 1.0], [0.0, 20.0, 1.0], [-20.0, 20.0, 1.0]])
    tracer = RayTracer(quad, np.array([[0, 1, 2], [0, 2, 3]]), threads=1)
    try:
        image = bake_ssdf(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), tracer,
                          BakeOptions(resolution, refinement))[0]
    finally:
        tracer.close()
    frame = hemisphere_map.local_frame(np.array([[0.0, 0.0, 1.0]]))[0]
    return decode.decode_image(image.reshape(resolution, resolution).astype(np.float64), axes @ frame.T)


def half_plane_visibility(count, resolution=32, refinement=5):
    """techniques.sg.sg_shading.Visibility of ``count`` pixels at the origin (normal +z) under the half-plane, its
    baked SSDF as the mean image of a basis without terms."""
    from sg_prt_addon.techniques.sg import sg_shading

    quad = np.array([[-20.0, -20.0, 1.0], [0.0, -20.0, 1.0], [0.0, 20.0, 1.0], [-20.0, 20.0, 1.0]])
    tracer = RayTracer(quad, np.array([[0, 1, 2], [0, 2, 3]]), threads=1)
    try:
        image = bake_ssdf(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), tracer,
                          BakeOptions(resolution, refinement))[0]
    finally:
        tracer.close()
    basis = decode.pack_basis_texture(image.reshape(resolution, resolution), np.zeros((0, resolution, resolution)))
    return sg_shading.Visibility(rows=np.tile(decode.pack_coefficients(np.zeros((1, 0))), (count, 1)),
                                 normal=np.tile(np.float32([0.0, 0.0, 1.0]), (count, 1)), basis_texture=basis)


def _edge_environment(directions):
    """Radiance brighter on the edge's open side (+x) and towards the zenith: exp(2 x + z)."""
    return np.exp(2.0 * directions[..., 0] + directions[..., 2])


def _lobe_mean(directions, weights, axis, sharpness):
    """Mean of _edge_environment over G(axis, sharpness) times weights (quadrature over ``directions``)."""
    lobe = np.exp(sharpness[:, None] * (axis @ directions.T - 1.0)) * weights
    return (lobe * _edge_environment(directions)).sum(-1) / lobe.sum(-1)


def lobe_edge_radiance(sharpness, steps=41):
    """{"exact", "axis", "visible part", "visible", "side angle"} (K,) over a sweep of lobes of ``sharpness``
    across the half-plane's edge (cap_sweep's, in lobe widths): the mean radiance of the lobe's visible part,
    G V max(0, z) (quadrature over 4e5 directions), read at the lobe's axis, and at its visible part (the baked
    SSDF's side, offset and narrowing: visible_part_axes); the exact visible fraction; the angle between the side
    lobe_visibility_side finds and the edge's open side across the axis."""
    from sg_prt_addon.lighting.env_fit import fibonacci_sphere
    from sg_prt_addon.techniques.sg import sg_shading

    tilt = np.array([[1, 0, 0], [0, np.cos(CAP_TILT), -np.sin(CAP_TILT)], [0, np.sin(CAP_TILT), np.cos(CAP_TILT)]])
    alpha = np.linspace(-2.0, 2.0, steps) / np.sqrt(sharpness)
    axes = np.stack([np.sin(alpha), np.zeros_like(alpha), np.cos(alpha)], -1) @ tilt.T
    directions = fibonacci_sphere(400_000)
    cosine = np.maximum(directions[:, 2], 0.0)
    lam = np.full(steps, float(sharpness))
    lobe = np.exp(lam[:, None] * (axes @ directions.T - 1.0)) * cosine
    visible = (lobe * (directions[:, 0] > 0)).sum(-1) / lobe.sum(-1)
    pixels = half_plane_visibility(steps)
    normal = np.tile(np.float32([0.0, 0.0, 1.0]), (steps, 1))
    shaded, side = sg_shading.lobe_visibility_side(axes[:, None].astype(np.float32), lam[:, None].astype(np.float32),
                                                  normal, pixels)
    part_axis, part_sharpness = sg_shading.visible_part_axes(axes[:, None].astype(np.float32),
                                                             lam[:, None].astype(np.float32), shaded, side, [0], 1)
    part_axis = part_axis[:, 0] / np.linalg.norm(part_axis[:, 0], axis=-1, keepdims=True)
    across = np.array([1.0, 0.0, 0.0]) - axes * axes[:, :1]          # the edge's open side, across each axis
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    return {"exact": _lobe_mean(directions, cosine * (directions[:, 0] > 0), axes, lam),
            "axis": _lobe_mean(directions, cosine, axes, lam),
            "visible part": _lobe_mean(directions, cosine, part_axis.astype(np.float64),
                                       part_sharpness[:, 0].astype(np.float64)),
            "visible": visible,
            "side angle": np.arccos(np.clip(np.sum(side[:, 0] * across, -1), -1.0, 1.0))}


def cap_share_errors(radius, baked=False):
    """(|error| of the cap's share (K,), |error| of eq. 30's fh of the light's SG (K,)) over cap_sweep: with
    the exact SSDF (the angle to the great circle x = 0), or the baked one."""
    axes, exact = cap_sweep(radius)
    theta_d = baked_half_plane_ssdf(axes) if baked else np.arcsin(axes[:, 0])
    theta_h = np.arcsin(axes[:, 2])
    sharpness = np.log(10.0) / np.sin(radius) ** 2                      # lighting.lights' cap sharpness
    cap_radius = lights.cap_radius(sharpness)
    cap = hemisphere.disc_coverage(theta_d, cap_radius) / hemisphere.disc_coverage(theta_h, cap_radius)
    fh = hemisphere.fh_normalized(theta_d, sharpness) / hemisphere.fh_normalized(theta_h, sharpness)
    return np.abs(cap - exact), np.abs(fh - exact)


def floor_through_sphere():
    """A floor of 21 x 21 vertices (spacing 0.1) through a sphere of radius SPHERE_RADIUS centred on it:
    (floor vertices, floor triangles, all vertices, all triangles)."""
    floor_v, floor_t = grid(21, 1.0)
    sphere_v, sphere_t = icosphere(4)
    return (floor_v, floor_t, np.concatenate([floor_v, sphere_v * SPHERE_RADIUS]),
            np.concatenate([floor_t, sphere_t + len(floor_v)]))


def _open_share(ssdf_rows, directions):
    """Cosine-weighted share of a hemisphere's stored samples with a positive SSDF."""
    z = directions[..., 2].ravel()
    return ((np.asarray(ssdf_rows) > 0) * z).sum(axis=-1) / z.sum()


def seam_open_share_errors(resolution=16, samples_per_triangle=8, seed=3):
    """{"baked": errors, "filled": errors}: |open share error| (S,) at points of the floor's triangles with
    buried and unburied corners, outside the sphere, the SSDF interpolated from the corners as baked and with the
    buried rows filled (visibility.buried), against rays cast from the points."""
    floor_v, floor_t, vertices, triangles = floor_through_sphere()
    normals = np.tile([0.0, 0.0, 1.0], (len(floor_v), 1))
    options = BakeOptions(resolution=resolution, refinement=3)
    tracer = RayTracer(vertices, triangles, threads=1)
    try:
        baked = bake_ssdf(floor_v, normals, tracer, options).astype(np.float32)
        is_buried = buried.backface_share(tracer, floor_v + tracer.offset * normals,
                                          hemisphere_map.local_frame(normals)) >= buried.BURIED_SHARE
        filled = baked.copy()
        buried.fill_buried(filled, is_buried, buried.adjacency(floor_t, len(floor_v)))
        seam = floor_t[np.any(is_buried[floor_t], axis=1) & ~np.all(is_buried[floor_t], axis=1)]
        weights = np.random.default_rng(seed).dirichlet(np.ones(3), size=(len(seam), samples_per_triangle))
        points = np.einsum("tsk,tkc->tsc", weights, floor_v[seam])
        keep = np.linalg.norm(points, axis=-1) > SPHERE_RADIUS + 0.01
        corners = np.repeat(seam[:, None], samples_per_triangle, axis=1)[keep]
        points, weights = points[keep], weights[keep]
        directions = hemisphere_map.sample_directions(resolution)
        truth = _open_share(bake_ssdf(points, np.tile([0.0, 0.0, 1.0], (len(points), 1)), tracer, options),
                            directions)
    finally:
        tracer.close()
    return {name: np.abs(_open_share(np.einsum("sk,skn->sn", weights, rows[corners]), directions) - truth)
            for name, rows in (("baked", baked), ("filled", filled))}
