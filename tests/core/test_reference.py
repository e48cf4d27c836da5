"""Reference renderer and environment sampling against closed-form answers."""
import numpy as np
import pytest

from benchmarks.reference_speed import make_icosphere
from sg_prt_addon.lighting import equirect
from validation.camera import Camera
from validation.env_sampling import EnvironmentSampler
from validation.reference import DirectionalLight, Material, PointLight, Scene, render_reference


# -- helpers ------------------------------------------------------------------------------------
def orthographic_down(half_size, pixels, height_above=5.0):
    """Camera above the origin looking down -z: pixel footprints are exact squares on z = 0."""
    view = np.eye(4)
    view[2, 3] = -height_above
    near, far = 0.1, 100.0
    projection = np.diag([1.0 / half_size, 1.0 / half_size, -2.0 / (far - near), 1.0])
    projection[2, 3] = -(far + near) / (far - near)
    return Camera(view, projection, pixels, pixels)


def ground_plane(half_size=10.0, z=0.0):
    vertices = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float) * half_size + [0, 0, z]
    return vertices, np.array([[0, 1, 2], [0, 2, 3]]), np.tile([0, 0, 1.0], (4, 1))


def _reflect_frame(axis):
    helper = np.where(np.abs(axis[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]])
    tangent = np.cross(helper, axis)
    tangent /= np.linalg.norm(tangent, axis=-1, keepdims=True)
    return tangent, np.cross(axis, tangent)


class PhongStandIn:
    """Private glossy test model (not reflectance.brdf): rho_s = (n + 2) / (2 pi) cos^n(angle to the mirror
    direction), sampled exactly from its cos^n lobe, in the local frame (normal z+)."""

    def __init__(self, exponent):
        self.exponent = exponent

    def _mirror(self, wo):
        return wo * [-1.0, -1.0, 1.0]

    def specular(self, wo, wi):
        cosine = np.maximum(np.sum(self._mirror(wo) * wi, axis=-1), 0.0)
        return (self.exponent + 2) / (2 * np.pi) * cosine ** self.exponent

    def pdf(self, wo, wi):
        cosine = np.maximum(np.sum(self._mirror(wo) * wi, axis=-1), 0.0)
        return (self.exponent + 1) / (2 * np.pi) * cosine ** self.exponent

    def sample(self, wo, u):
        axis = self._mirror(wo)
        cos_alpha = u[:, 0] ** (1.0 / (self.exponent + 1))
        sin_alpha = np.sqrt(np.maximum(0.0, 1 - cos_alpha ** 2))
        phi = 2 * np.pi * u[:, 1]
        tangent, bitangent = _reflect_frame(axis)
        wi = (tangent * (sin_alpha * np.cos(phi))[:, None] + bitangent * (sin_alpha * np.sin(phi))[:, None]
              + axis * cos_alpha[:, None])
        return wi, self.pdf(wo, wi)


def rms(values):
    return float(np.sqrt(np.mean(np.square(values))))


# -- environment sampling -----------------------------------------------------------------------
def test_environment_sampler_is_consistent_and_unbiased():
    rng = np.random.default_rng(3)
    image = rng.random((12, 24, 3)) ** 6 * 20     # high dynamic range
    sampler = EnvironmentSampler(image)
    directions, pdf = sampler.sample(rng.random((200000, 2)))
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_allclose(pdf, sampler.pdf(directions), rtol=1e-12)
    np.testing.assert_array_equal(sampler.radiance(directions), equirect.lookup_nearest(image, directions))
    # Texel frequencies follow the texel probabilities (luminance x solid angle).
    row, column = sampler.texel_index(directions)
    frequency = np.bincount(row * 24 + column, minlength=12 * 24) / len(directions)
    expected = sampler.texel_probability.ravel()
    assert np.max(np.abs(frequency - expected) / np.sqrt(expected / len(directions))) < 5.5
    # Probabilities / densities recover the texel solid angles: they sum to 4 pi.
    assert abs(np.sum(sampler.texel_probability / sampler.texel_pdf) / (4 * np.pi) - 1) < 1e-12
    # E[L / pdf] = the exact integral of the piecewise-constant map.
    exact = np.sum(image * equirect.texel_solid_angles(12, 24)[..., None], axis=(0, 1))
    np.testing.assert_allclose(np.mean(sampler.radiance(directions) / pdf[:, None], axis=0), exact, rtol=0.01)


def test_environment_sampler_handles_black_and_constant_maps():
    black = EnvironmentSampler(np.zeros((4, 8, 3)))
    directions, pdf = black.sample(np.random.default_rng(0).random((1000, 2)))
    assert np.all(np.isfinite(pdf)) and np.all(pdf > 0)
    constant = EnvironmentSampler(np.ones((6, 12, 3)))
    np.testing.assert_allclose(constant.pdf(directions), 1 / (4 * np.pi), rtol=1e-9)


# -- (a) Lambertian plane under a constant environment: R = kd L ------------------------------------
def _constant_sky_scene(albedo=0.6, sky=(1.0, 0.5, 2.0)):
    vertices, triangles, normals = ground_plane()
    environment = np.broadcast_to(np.asarray(sky), (8, 16, 3)).copy()
    return Scene(vertices, triangles, normals, [Material((albedo,) * 3)], environment=environment)


@pytest.mark.parametrize("environment_samples", [1, 3, 16])
def test_constant_environment_on_lambertian_plane_is_unbiased_and_calibrated(environment_samples):
    scene = _constant_sky_scene()
    camera = orthographic_down(1.0, 24)
    expected = 0.6 * np.array([1.0, 0.5, 2.0])
    image, error = render_reference(scene, camera, 16, seed=1, environment_samples=environment_samples)
    assert np.all(np.isfinite(image)) and np.all(np.isfinite(error)) and np.all(error > 0)
    deviation = image - expected
    # Standard error calibrated: actual RMS error / RMS reported error near 1 (1728 values).
    ratio = rms(deviation) / rms(error)
    assert 0.85 < ratio < 1.15, ratio
    # Unbiased: the mean over pixels is within 4 standard errors of the mean.
    error_of_mean = np.sqrt(np.sum(error ** 2, axis=(0, 1))) / (24 * 24)
    assert np.all(np.abs(deviation.mean(axis=(0, 1))) < 4 * error_of_mean)


def test_error_falls_as_one_over_sqrt_samples():
    scene = _constant_sky_scene()
    camera = orthographic_down(1.0, 16)
    expected = 0.6 * np.array([1.0, 0.5, 2.0])
    samples = np.array([4, 16, 64, 256])
    errors = [rms(render_reference(scene, camera, int(n), seed=10 + k, environment_samples=1)[0] - expected)
              for k, n in enumerate(samples)]
    slope = np.polyfit(np.log(samples), np.log(errors), 1)[0]
    assert -0.6 < slope < -0.4, (slope, errors)


def test_constant_background_lights_like_a_constant_environment_and_fills_misses():
    vertices, triangles, normals = ground_plane(half_size=0.5)
    scene = Scene(vertices, triangles, normals, [Material((0.5, 0.5, 0.5))], background=(0.2, 0.4, 0.8))
    image, error = render_reference(scene, orthographic_down(1.0, 16), 32, seed=2)
    # Plane covers the central 8x8 pixels; the rest shows the background exactly.
    np.testing.assert_allclose(image[0, 0], [0.2, 0.4, 0.8], rtol=1e-12)
    np.testing.assert_allclose(error[0, 0], 0.0, atol=1e-12)
    centre = image[5:11, 5:11]
    assert np.all(np.abs(centre - [0.1, 0.2, 0.4]) < 5 * error[5:11, 5:11] + 1e-12)


def test_sphere_occluding_a_constant_environment_matches_its_form_factor():
    """A sphere (radius R, centre c) fully above a plane point p hides the cosine-weighted fraction
    R^2 c_z / |c - p|^3 of the sky: R = kd L (1 - R^2 c_z / d^3).  Tests environment visibility."""
    sphere_vertices, sphere_triangles, sphere_normals = make_icosphere(4, 1.0, (0.0, 0.0, 1.3))
    plane_vertices, plane_triangles, plane_normals = ground_plane()
    scene = Scene(np.concatenate([sphere_vertices, plane_vertices]),
                  np.concatenate([sphere_triangles, plane_triangles + len(sphere_vertices)]),
                  np.concatenate([sphere_normals, plane_normals]), [Material((0.5, 0.5, 0.5))],
                  background=(1.0, 1.0, 1.0))
    pixels = 24
    image, error = render_reference(scene, orthographic_down(1.5, pixels, height_above=0.25), 16, seed=12)
    y, x = np.mgrid[0:pixels, 0:pixels]
    centre = np.stack([-1.5 + (x + 0.5) * 3 / pixels, 1.5 - (y + 0.5) * 3 / pixels, np.zeros((pixels, pixels))], -1)
    distance = np.linalg.norm(np.array([0, 0, 1.3]) - centre, axis=-1)
    expected = 0.5 * (1 - 1.3 / distance ** 3)
    assert expected.min() < 0.3 and expected.max() > 0.4        # the shadowing really varies
    z = (image[..., 0] - expected) / error[..., 0]
    assert rms(z) < 1.3 and abs(np.mean(z)) < 0.3, (rms(z), np.mean(z))
    assert np.mean(error[..., 0] / expected) < 0.03                 # the z-test has power: errors of ~3%


# -- (b) directional light on a Lambertian sphere: kd / pi E max(0, n.l) ------------------------------
def test_directional_light_on_lambertian_sphere_matches_closed_form():
    vertices, triangles, normals = make_icosphere(4)
    light = np.array([0.8, 0.3, 0.5]) / np.linalg.norm([0.8, 0.3, 0.5])
    irradiance = np.array([3.0, 2.0, 1.0])
    albedo = np.array([0.8, 0.6, 0.4])
    scene = Scene(vertices, triangles, normals, [Material(albedo)],
                  lights=[DirectionalLight(light, irradiance)])
    camera = Camera.look_at((0, 0, 4.0), (0, 0, 0), (0, 1.0, 0), 40.0, 48, 48)
    image, error = render_reference(scene, camera, 32, seed=3)
    # Exact normal of the true sphere under each pixel centre.
    origins, directions = camera.primary_rays()
    b = np.sum(origins * directions, -1)
    discriminant = b ** 2 - (np.sum(origins ** 2, -1) - 1)
    hit = discriminant > 0
    t = -b - np.sqrt(np.where(hit, discriminant, 0))
    normal = origins + t[..., None] * directions
    facing = np.sum(normal * -directions, -1)
    cosine = normal @ light
    expected = albedo / np.pi * irradiance * np.maximum(cosine, 0)[..., None]
    interior = hit & (facing > 0.3)
    lit = interior & (cosine > 0.15)
    dark = interior & (cosine < -0.15)
    assert lit.sum() > 200 and dark.sum() > 50
    relative = np.abs(image[lit] - expected[lit]) / expected[lit]
    assert np.all(relative < 0.01 + 4 * error[lit] / expected[lit]), relative.max()
    assert rms(relative) < 0.01
    np.testing.assert_array_equal(image[dark], 0.0)
    np.testing.assert_array_equal(image[discriminant < -0.2], 0.0)   # misses (a pixel away), no environment


# -- (c) a small occluder casts exactly the expected point-light shadow ---------------------------------
def test_point_light_shadow_falls_on_exactly_the_expected_pixels():
    vertices, triangles, normals = ground_plane(half_size=2.0)
    occluder = np.array([[-0.3, -0.2, 1.0], [0.35, -0.25, 1.0], [0.0, 0.4, 1.0]])
    scene = Scene(np.concatenate([vertices, occluder]), np.concatenate([triangles, [[4, 5, 6]]]),
                  np.concatenate([normals, np.tile([0, 0, 1.0], (3, 1))]), [Material((0.5, 0.5, 0.5))],
                  lights=[PointLight((0.05, 0.0, 2.0), (4.0, 4.0, 4.0))])
    pixels = 40
    camera = orthographic_down(1.0, pixels, height_above=0.9)   # below the occluder, above the plane
    image, error = render_reference(scene, camera, 8, seed=4)
    # Shadow on z = 0: the occluder scaled by 2 from the light (light at height 2, occluder at 1).
    light = np.array([0.05, 0.0])
    shadow = light + 2.0 * (occluder[:, :2] - light)

    def inside(points):
        sign = []
        for k in range(3):
            a, b = shadow[k], shadow[(k + 1) % 3]
            sign.append((b[0] - a[0]) * (points[..., 1] - a[1]) - (b[1] - a[1]) * (points[..., 0] - a[0]))
        sign = np.stack(sign)
        return np.all(sign > 0, axis=0) | np.all(sign < 0, axis=0)

    # Pixel (x, y) covers world [x0, x0 + s] x [y0 - s, y0] on the plane.
    size = 2.0 / pixels
    y, x = np.mgrid[0:pixels, 0:pixels]
    corners = [np.stack([-1 + (x + dx) * size, 1 - (y + dy) * size], -1) for dx in (0, 1) for dy in (0, 1)]
    corner_inside = np.stack([inside(c) for c in corners])
    fully_shadowed = corner_inside.all(axis=0)        # the shadow is convex
    touched = corner_inside.any(axis=0)
    # Margin: pixels whose centre is farther than a pixel diagonal from the shadow are fully lit.
    centre = np.stack([-1 + (x + 0.5) * size, 1 - (y + 0.5) * size], -1)
    near = np.zeros_like(touched)
    for dx in np.linspace(-1.5, 1.5, 7):
        for dy in np.linspace(-1.5, 1.5, 7):
            near |= inside(centre + size * np.array([dx, dy]))
    assert fully_shadowed.sum() > 40
    np.testing.assert_array_equal(image[fully_shadowed], 0.0)
    zero = np.all(image == 0, axis=-1)
    assert np.all(zero <= (touched | near))              # no shadow away from where it should be
    lit = ~near
    position = np.concatenate([centre, np.zeros(centre.shape[:-1] + (1,))], -1)
    to_light = np.array([0.05, 0.0, 2.0]) - position
    distance = np.linalg.norm(to_light, axis=-1)
    expected = 0.5 / np.pi * 4.0 * (to_light[..., 2] / distance) / distance ** 2
    # Lit pixels: kd / pi I cos / d^2 at the centre, up to the jitter noise of 8 samples
    # (the value varies ~1% across a pixel); on average exact.
    relative = image[lit][:, 0] / expected[lit] - 1
    assert np.max(np.abs(relative)) < 0.03 and abs(np.mean(relative)) < 1e-3, (np.abs(relative).max(), relative.mean())


# -- area lights: a uniform sphere / cone fully above the horizon gives the point-light answer -------------
@pytest.mark.parametrize("light", [PointLight((0.4, -0.2, 1.5), (2.0, 3.0, 4.0), radius=0.5),
                                   DirectionalLight((0.4, -0.2, 1.0), (1.0, 2.0, 3.0), angular_radius=0.3)])
def test_sphere_and_cone_lights_keep_point_light_irradiance(light):
    vertices, triangles, normals = ground_plane()
    scene = Scene(vertices, triangles, normals, [Material((0.7, 0.7, 0.7))], lights=[light])
    camera = orthographic_down(0.5, 12)
    image, error = render_reference(scene, camera, 64, seed=5)
    y, x = np.mgrid[0:12, 0:12]
    position = np.stack([-0.5 + (x + 0.5) / 12, 0.5 - (y + 0.5) / 12, np.zeros((12, 12))], -1)
    if isinstance(light, PointLight):
        to_light = np.asarray(light.position) - position
        distance = np.linalg.norm(to_light, axis=-1)
        irradiance = np.asarray(light.intensity) * (to_light[..., 2] / distance ** 3)[..., None]
    else:
        direction = np.asarray(light.direction) / np.linalg.norm(light.direction)
        irradiance = np.broadcast_to(np.asarray(light.irradiance) * direction[2], (12, 12, 3))
    expected = 0.7 / np.pi * irradiance
    assert rms(error / expected) > 1e-3                  # really sampled, not a delta
    z = (image - expected) / error
    assert rms(z) < 1.3 and abs(np.mean(z)) < 0.3, (rms(z), np.mean(z))


# -- MIS with glossy lobes under a non-constant environment vs quadrature ------------------------------
def _oblique_plane_mean_vs_quadrature(model, pixels, samples, seed, tangents=None):
    """Mean of an orthographic oblique view of a plane (the same wo at every pixel), its standard
    error, and the midpoint quadrature of the same integral."""
    rng = np.random.default_rng(6)
    environment = rng.random((8, 16, 3)) ** 3 * 4
    vertices, triangles, normals = ground_plane()
    material = Material((0.3, 0.2, 0.1), (0.6, 0.6, 0.6), model)
    scene = Scene(vertices, triangles, normals, [material], environment=environment,
                  tangents=None if tangents is None else np.tile(tangents, (4, 1)))
    wo = np.array([0.0, -np.sin(0.7), np.cos(0.7)])
    view = Camera.look_at(4 * wo, (0, 0, 0), (0, 0, 1.0), 10.0, pixels, pixels).view_matrix
    projection = np.diag([1.0, 1.0, -0.02, 1.0])
    projection[2, 3] = -1.0
    image, error = render_reference(scene, Camera(view, projection, pixels, pixels), samples, seed=seed)
    # The plane's frame is the world frame (tangent x, normal z) for the built frame at n = z and
    # for tangents = x.  Midpoint quadrature on cells aligned with the texel edges (uniform in
    # sin(elevation) and azimuth inside each texel of the upper half), so the integrand is smooth
    # in every cell: relative error below 1e-4 (measured against 25x finer cells).
    height, width, cells = environment.shape[0], environment.shape[1], 40
    top = np.pi / 2 - np.arange(height // 2) * np.pi / height
    z_top, z_bottom = np.sin(top), np.sin(top - np.pi / height)
    z = (z_bottom[:, None] + (np.arange(cells) + 0.5)[None, :] / cells * (z_top - z_bottom)[:, None]).ravel()
    dz = np.repeat((z_top - z_bottom) / cells, cells)
    u = (np.arange(width * cells) + 0.5) / (width * cells)
    u_grid, z_grid = np.meshgrid(u, z)
    wi = equirect.uv_to_direction(u_grid, 0.5 + np.arcsin(z_grid) / np.pi).reshape(-1, 3)
    solid_angle = (np.broadcast_to(dz[:, None], z_grid.shape) * (2 * np.pi / (width * cells))).ravel()
    brdf = np.asarray(material.diffuse_color) / np.pi + 0.6 * model.specular(np.broadcast_to(wo, wi.shape), wi)[:, None]
    expected = np.sum(equirect.lookup_nearest(environment, wi) * brdf * (wi[:, 2] * solid_angle)[:, None], axis=0)
    mean = image.mean(axis=(0, 1))
    error_of_mean = np.sqrt(np.sum(error ** 2, axis=(0, 1))) / pixels ** 2
    return mean, error_of_mean, expected


def test_glossy_plane_under_environment_matches_quadrature():
    mean, error_of_mean, expected = _oblique_plane_mean_vs_quadrature(PhongStandIn(30.0), 24, 16, seed=7)
    assert np.all(error_of_mean < 0.008 * expected)
    assert np.all(np.abs(mean - expected) < 4 * error_of_mean + 5e-4 * expected), (mean, expected, error_of_mean)


def _core_brdf_models():
    brdf = pytest.importorskip("sg_prt_addon.reflectance.brdf")
    return [("ggx", lambda: brdf.GGX(roughness=0.5)), ("cook_torrance", lambda: brdf.CookTorrance(roughness=0.3)),
            ("ward_anisotropic", lambda: brdf.WardAnisotropic(alpha_x=0.35, alpha_y=0.15))]


@pytest.mark.parametrize("name", ["ggx", "cook_torrance", "ward_anisotropic"])
def test_core_brdf_models_under_environment_match_quadrature(name):
    model = dict(_core_brdf_models())[name]()
    mean, error_of_mean, expected = _oblique_plane_mean_vs_quadrature(model, 16, 12, seed=8,
                                                                      tangents=(1.0, 0.0, 0.0))
    assert np.all(error_of_mean < 0.015 * expected)
    assert np.all(np.abs(mean - expected) < 4 * error_of_mean + 5e-4 * expected), (mean, expected, error_of_mean)


def test_spot_light_cone_edge_falls_on_the_expected_pixels():
    vertices, triangles, normals = ground_plane()
    radius_on_plane = 0.5
    light = PointLight((0.0, 0.0, 2.0), (3.0, 3.0, 3.0), spot_direction=(0, 0, -1.0),
                       spot_size=2 * np.arctan(radius_on_plane / 2.0))
    scene = Scene(vertices, triangles, normals, [Material((0.5, 0.5, 0.5))], lights=[light])
    pixels = 32
    image, _ = render_reference(scene, orthographic_down(1.0, pixels), 4, seed=11)
    size = 2.0 / pixels
    y, x = np.mgrid[0:pixels, 0:pixels]
    corner_radius = np.stack([np.hypot(-1 + (x + dx) * size, 1 - (y + dy) * size) for dx in (0, 1) for dy in (0, 1)])
    inside, outside = corner_radius.max(axis=0) < radius_on_plane, corner_radius.min(axis=0) > radius_on_plane
    assert inside.sum() > 100 and outside.sum() > 500
    np.testing.assert_array_equal(image[outside], 0.0)
    assert np.all(image[inside] > 0)
    # Inside the cone: the plain point light, kd / pi I cos / d^2 (within the jitter across a pixel).
    centre = np.stack([-1 + (x + 0.5) * size, 1 - (y + 0.5) * size], -1)
    distance2 = np.sum(centre ** 2, -1) + 4.0
    expected = 0.5 / np.pi * 3.0 * 2.0 / distance2 ** 1.5
    np.testing.assert_allclose(image[inside][:, 0], expected[inside], rtol=0.01)


# -- bookkeeping ---------------------------------------------------------------------------------------
def test_seed_determinism_progress_and_early_stop():
    scene = _constant_sky_scene()
    camera = orthographic_down(1.0, 8)
    first, _ = render_reference(scene, camera, 4, seed=9, batch_rays=32, environment_samples=1)
    again, _ = render_reference(scene, camera, 4, seed=9, batch_rays=32, environment_samples=1)
    other, _ = render_reference(scene, camera, 4, seed=10, batch_rays=32, environment_samples=1)
    assert np.any(first != other)
    np.testing.assert_array_equal(first, again)
    calls = []
    image, error = render_reference(scene, camera, 4, seed=9, batch_rays=32, environment_samples=1,
                                    progress=lambda done, total: calls.append((done, total)) or len(calls) == 3)
    assert calls == [(32, 256), (64, 256), (96, 256)]
    assert np.all(np.isfinite(image))
    assert np.isinf(error).any()                       # pixels with one sample have no error estimate


def test_degenerate_geometry_stays_finite():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]], float)   # first triangle has zero area
    triangles = np.array([[0, 1, 2], [0, 1, 3]])
    normals = np.zeros((4, 3))                                                # no usable shading normals
    scene = Scene(vertices, triangles, normals, [Material((0.5, 0.5, 0.5), (0.5, 0.5, 0.5), PhongStandIn(1e4))],
                  lights=[PointLight((0.2, 0.2, 0.0), (1, 1, 1.0)), DirectionalLight((0, 0, 1.0), (1, 1, 1.0))],
                  environment=np.zeros((4, 8, 3)))
    image, error = render_reference(scene, Camera.look_at((0.3, 0.3, 2.0), (0.3, 0.3, 0), (0, 1.0, 0), 60, 8, 8), 2)
    assert np.all(np.isfinite(image)) and np.all(np.isfinite(error))


class TangentProbe:
    """Private test model whose value depends on the tangent: rho_s = max(0, wi.x)."""

    def specular(self, wo, wi):
        return np.maximum(wi[:, 0], 0.0)

    def pdf(self, wo, wi):
        return np.maximum(wi[:, 2], 0.0) / np.pi

    def sample(self, wo, u):
        r, phi = np.sqrt(u[:, 0]), 2 * np.pi * u[:, 1]
        wi = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u[:, 0])], -1)
        return wi, self.pdf(wo, wi)


@pytest.mark.parametrize("tangent, expected_x", [((1.0, 0, 0), 0.6), ((0, 1.0, 0), 0.0), ((-1.0, 0, 0), 0.0),
                                                 (None, None)])
def test_tangents_orient_the_local_frame(tangent, expected_x):
    vertices, triangles, normals = ground_plane()
    light = np.array([0.6, 0.0, 0.8])
    material = Material((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), TangentProbe())
    tangents = None if tangent is None else np.tile(tangent, (4, 1))
    scene = Scene(vertices, triangles, normals, [material], tangents=tangents,
                  lights=[DirectionalLight(light, (2.0, 2.0, 2.0))])
    image, _ = render_reference(scene, orthographic_down(1.0, 4), 2, seed=0)
    if tangent is None:
        # Built frame: some tangent perpendicular to z; the value is 2 * 0.8 * max(0, t.l) <= 2 * 0.8 * 0.6.
        assert np.all(image >= 0) and np.all(image <= 2 * 0.8 * 0.6 + 1e-12)
        assert np.ptp(image) < 1e-12
    else:
        np.testing.assert_allclose(image, 2.0 * 0.8 * expected_x, atol=1e-12)


def test_render_to_noise_reaches_the_target_and_stays_calibrated():
    from validation.reference import mean_relative_error, render_to_noise
    scene = _constant_sky_scene()
    camera = orthographic_down(1.0, 16)
    image, error, samples = render_to_noise(scene, camera, relative_error=0.01, pilot_samples=4,
                                            environment_samples=4, seed=13)
    assert samples > 8
    assert 0.008 < mean_relative_error(image, error) < 0.012
    ratio = rms(image - 0.6 * np.array([1.0, 0.5, 2.0])) / rms(error)
    assert 0.85 < ratio < 1.15, ratio


@pytest.mark.parametrize("exponent", [20.0, 2000.0])
def test_glossy_highlight_of_a_small_cone_light_matches_quadrature(exponent):
    """Light sample + BRDF sample (MIS) of a sun-like cone seen in a glossy lobe: unbiased."""
    vertices, triangles, normals = ground_plane()
    model = PhongStandIn(exponent)
    alpha = 0.05
    wo = np.array([0.0, -np.sin(0.7), np.cos(0.7)])
    to_light = np.array([0.02, np.sin(0.7), np.cos(0.7)])          # just off the mirror direction
    to_light /= np.linalg.norm(to_light)
    light = DirectionalLight(to_light, (2.0, 2.0, 2.0), angular_radius=alpha)
    scene = Scene(vertices, triangles, normals, [Material((0.1, 0.1, 0.1), (0.5, 0.5, 0.5), model)], lights=[light])
    view = Camera.look_at(4 * wo, (0, 0, 0), (0, 0, 1.0), 10.0, 16, 16).view_matrix
    projection = np.diag([1.0, 1.0, -0.02, 1.0])
    projection[2, 3] = -1.0
    image, error = render_reference(scene, Camera(view, projection, 16, 16), 16, seed=14)
    # Quadrature over the cone (polar grid around its axis, uniform in cos and azimuth).
    cos_grid, phi_grid = np.meshgrid(1 - (np.arange(400) + 0.5) / 400 * (1 - np.cos(alpha)),
                                     (np.arange(400) + 0.5) / 400 * 2 * np.pi, indexing="ij")
    sin_grid = np.sqrt(1 - cos_grid ** 2)
    tangent = np.cross(to_light, [1.0, 0, 0])
    tangent /= np.linalg.norm(tangent)
    bitangent = np.cross(to_light, tangent)
    wi = (tangent * (sin_grid * np.cos(phi_grid))[..., None] + bitangent * (sin_grid * np.sin(phi_grid))[..., None]
          + to_light * cos_grid[..., None]).reshape(-1, 3)
    solid_angle = 2 * np.pi * (1 - np.cos(alpha)) / len(wi)
    radiance = 2.0 / (np.pi * np.sin(alpha) ** 2)
    brdf = 0.1 / np.pi + 0.5 * model.specular(np.broadcast_to(wo, wi.shape), wi)
    expected = np.sum(brdf * wi[:, 2]) * radiance * solid_angle
    mean = image[..., 0].mean()
    error_of_mean = np.sqrt(np.sum(error[..., 0] ** 2)) / 256
    assert error_of_mean < 0.01 * expected
    assert abs(mean - expected) < 4 * error_of_mean + 1e-3 * expected, (mean, expected, error_of_mean)


# -- spatially-varying materials --------------------------------------------------------------------
def test_textured_material_varies_albedo_and_glossiness_over_uv():
    """Left half of the plane (u < 0.5) albedo 0.2, right half 0.8, under a constant sky:
    R = albedo L per half; a textured specular model is evaluated with per-point parameters."""
    from sg_prt_addon.reflectance.brdf import GGX

    vertices, triangles, normals = ground_plane(half_size=1.0)
    uvs = (vertices[:, :2] + 1.0) / 2.0
    calls = []

    def albedo_halves(uv):
        calls.append(len(uv))
        albedo = np.where(uv[:, :1] < 0.5, 0.2, 0.8) * np.ones((1, 3))
        return {"diffuse_color": albedo, "specular_color": np.zeros((len(uv), 3)),
                "specular_model": GGX(roughness=np.where(uv[:, 0] < 0.5, 0.2, 0.9))}

    material = Material((1.0, 1.0, 1.0), (0.0, 0.0, 0.0), GGX(roughness=0.5), textures=albedo_halves)
    scene = Scene(vertices, triangles, normals, [material], uvs=uvs,
                  environment=np.ones((8, 16, 3)))
    image, error = render_reference(scene, orthographic_down(1.0, 16), 8, seed=3)
    assert calls, "the texture lookup was never called"
    left, right = image[:, :7], image[:, 9:]          # skip the two columns straddling u = 0.5
    assert np.all(np.abs(left - 0.2) < 5 * error[:, :7] + 1e-9)
    assert np.all(np.abs(right - 0.8) < 5 * error[:, 9:] + 1e-9)
