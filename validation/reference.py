"""Monte Carlo reference renderer: exact direct lighting with ray-traced visibility.

Computes wang2009 eq. 1 at the first surface seen through each pixel:

    R(o) = integral L(i) V(i) rho(o, i) max(0, n.i) di,  rho = kd / pi + ks rho_s(o, i)

with V by ray casts against every triangle of the scene (visibility.raytrace).  No
indirect light.  Every sample of a pixel takes a new uniformly jittered
position inside the pixel (anti-aliasing) and traces its own camera ray, so a
pixel's value is the average of R over its footprint.

Estimators, per pixel sample (one camera ray):
  - environment (an equirect map, or a constant background colour):
    multiple importance sampling, power heuristic, of ``environment_samples``
    (default 16, stratified 4x4) environment samples (validation.env_sampling) and as
    many BRDF samples (cosine lobe or the specular model, picked by weight);
  - point lights (sphere of radius r, or with Soft Falloff a disk of radius r facing the point; r = 0 a true
    point; optional spot cone)
    and directional lights (cone of angular radius a, a = 0 a delta): one light
    sample, uniform over the solid angle the light subtends; lights of finite
    size seen by points with a specular model add one BRDF sample, power
    heuristic (sharp lobes rarely meet a light sample);
  - area lights (one-sided rectangles and ellipses, Cycles' spread): one sample
    uniform over the area and, for points with a specular model, one BRDF
    sample that may hit the light, power heuristic.

Conventions:
  - Pixels whose camera ray misses the scene show the environment radiance
    along the ray (the constant background colour, or 0 without either).
  - Surfaces are two-sided: the geometric normal is turned towards the viewer
    and the shading normal to the same side.  Where the interpolated shading
    normal faces away from the viewer, the view direction is lifted just above
    its horizon before the BRDF is evaluated.
  - BRDF models work in the local frame (normal z+, tangent x+) with the
    protocol specular(wo, wi) -> (N,), sample(wo, u) -> (wi, pdf), pdf(wo, wi)
    (reflectance.brdf); specular(wo, wi) is rho_s without the cosine.
  - The standard error of a pixel is sqrt(sample variance / samples): the
    samples of a pixel are independent, so it is calibrated.
"""
from collections import deque
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence

import numpy as np

from sg_prt_addon.lighting import lights
from sg_prt_addon.spherical import concentric_map
from sg_prt_addon.visibility.raytrace import RayTracer, offset_origins
from validation.env_sampling import LUMINANCE_WEIGHTS, EnvironmentSampler

INV_PI = 1.0 / np.pi
# Lowest cosine of the view direction over the shading horizon (see module notes).
_MIN_VIEW_COSINE = 1e-3


@dataclass
class Material:
    diffuse_color: Any = (0.8, 0.8, 0.8)     # kd (3,), albedo of the Lambertian term kd / pi
    specular_color: Any = (0.0, 0.0, 0.0)    # ks (3,), scales the specular model
    specular_model: Any = None               # object with specular (N,) or (N, 3) RGB / sample / pdf, or None
    # Spatial variation: callable uv (N, 2) -> dict with any of diffuse_color (N, 3),
    # specular_color (N, 3) and specular_model (a model whose parameters are (N,) arrays),
    # replacing the constant fields above at those points.  None: a homogeneous material.
    textures: Optional[Callable] = None


@dataclass
class PointLight:
    """Point / sphere light, optionally a spot.  Blender: intensity = power / (4 pi)
    (lighting.lights.blender_point_light_intensity), radius = shadow_soft_size."""
    position: Any                             # (3,) world
    intensity: Any                            # (3,) W/sr
    radius: float = 0.0                       # > 0: a uniformly emitting sphere of the same intensity
    spot_direction: Any = None                # (3,) world axis of a spot cone; None: no cone
    spot_size: float = np.pi                  # full cone angle (Blender spot_size)
    spot_blend: float = 0.0                   # Blender spot_blend: smoothstep over this fraction of 1 - cos(size/2)
    soft_falloff: bool = False                # Blender's Soft Falloff: a disk of the radius facing the point, not a sphere

    def spot_falloff(self, to_light):
        """Intensity factor (N,) for unit directions (N, 3) from shading points to the light centre:
        smoothstep((cos a - cos(size/2)) / ((1 - cos(size/2)) blend)), a the angle off the spot axis
        (Cycles' round spot at unit scale, like lighting.lights.spot_light_sg)."""
        if self.spot_direction is None:
            return np.ones(len(to_light))
        axis = np.asarray(self.spot_direction, float)
        axis = axis / max(np.linalg.norm(axis), 1e-300)
        cos_half = np.cos(0.5 * self.spot_size)
        width = max((1.0 - cos_half) * self.spot_blend, 1e-12)
        t = np.clip((-(to_light @ axis) - cos_half) / width, 0.0, 1.0)
        return t * t * (3.0 - 2.0 * t)


@dataclass
class DirectionalLight:
    """Distant light (Blender sun: irradiance = strength, angular_radius = angle / 2)."""
    direction: Any                            # (3,) world, from the surface TOWARDS the light
    irradiance: Any                           # (3,) W/m^2 on a surface facing the light
    angular_radius: float = 0.0               # radians; > 0: a uniform cap of directions, radiance E / (pi sin^2)


@dataclass
class AreaLight:
    """One-sided Lambertian emitter of a Blender area light's shape (Cycles' area light): radiance
    power / (pi A) along directions at angle a from its normal, times the spread's soft-box attenuation
    (lighting.lights.emission_factor), sampled exactly over its area."""
    centre: Any                               # (3,) world
    edge_u: Any                               # (3,) world vector spanning the light (size along local x)
    edge_v: Any                               # (3,) likewise along local y
    normal: Any                               # (3,) the direction it emits along (-Z of the object)
    power: Any                                # (3,) W
    shape: str = "SQUARE"                     # lighting.lights.AREA_SHAPES
    spread: float = np.pi                     # full spread angle

    @property
    def elliptic(self):
        return self.shape in ("DISK", "ELLIPSE")

    @property
    def area(self):
        return lights.area_light_area(self.shape, np.linalg.norm(self.edge_u), np.linalg.norm(self.edge_v))

    def sample(self, uniforms):
        """(N, 3) points uniform over the light's area."""
        square = 2.0 * uniforms - 1.0
        if self.elliptic:
            square = concentric_map.square_to_disc(square)
        return (np.asarray(self.centre, float) + 0.5 * square[:, :1] * np.asarray(self.edge_u, float)
                + 0.5 * square[:, 1:] * np.asarray(self.edge_v, float))

    def hit(self, origins, directions):
        """Distance (N,) along rays to the light's front face, inf where they miss it."""
        normal = _normalize(np.asarray(self.normal, float)[None], np.array([0.0, 0.0, 1.0]))[0]
        facing = directions @ normal
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((np.asarray(self.centre, float) - origins) @ normal) / facing
        offset = origins + np.where(np.isfinite(t), t, 0.0)[:, None] * directions - np.asarray(self.centre, float)
        u = 2.0 * (offset @ self.edge_u) / max(float(np.dot(self.edge_u, self.edge_u)), 1e-300)
        v = 2.0 * (offset @ self.edge_v) / max(float(np.dot(self.edge_v, self.edge_v)), 1e-300)
        inside = (u * u + v * v <= 1.0) if self.elliptic else ((np.abs(u) <= 1.0) & (np.abs(v) <= 1.0))
        return np.where((facing < 0) & (t > 0) & inside, t, np.inf)

    def radiance(self, directions_to_light):
        """(N, 3) radiance leaving the light toward points that see it along directions_to_light (N, 3)."""
        normal = _normalize(np.asarray(self.normal, float)[None], np.array([0.0, 0.0, 1.0]))[0]
        tan_half, normalization = lights.spread_parameters(self.spread)
        cos_angle = -(directions_to_light @ normal)
        with np.errstate(divide="ignore", invalid="ignore"):
            factor = lights.emission_factor(cos_angle, -1.0, 0.0, True, tan_half, normalization)
            factor = np.where(cos_angle > 0, factor / cos_angle, 0.0)     # the cosine is the area's, not L's
        return factor[:, None] * (np.asarray(self.power, float) / (np.pi * max(self.area, 1e-300)))[None]


@dataclass
class Scene:
    vertices: Any                             # (V, 3)
    triangles: Any                            # (T, 3) int, counter-clockwise seen from the front
    normals: Any                              # (V, 3) shading normals, interpolated
    materials: Sequence[Material] = field(default_factory=lambda: [Material()])
    material_index: Any = None                # (T,) int into materials; None: all 0
    uvs: Any = None                           # (V, 2), read by materials with textures
    tangents: Any = None                      # (V, 3) for anisotropic models; None: built from the normal
    lights: Sequence[Any] = ()                # PointLight / DirectionalLight / AreaLight
    environment: Any = None                   # equirect (H, W, 3) radiance, Blender world mapping
    background: Any = None                    # (3,) constant radiance, used when environment is None


def render_reference(scene, camera, samples_per_pixel, seed=0, progress: Optional[Callable] = None,
                     batch_rays=1 << 16, tracer=None, threads=2, environment_samples=16, pixel_centres=False):
    """Render ``scene`` through ``camera`` (validation.camera.Camera).

    Returns (image, standard_error), both (H, W, 3) float64.  ``progress`` is
    called after every batch as progress(samples_done, samples_total) with
    counts of pixel samples; if it returns True rendering stops there and the
    images average the samples taken so far (standard_error is inf where a
    pixel has fewer than two).  ``tracer`` lets callers reuse a RayTracer of
    the same mesh.  Batches of about ``batch_rays`` shading rows (pixel
    samples x environment samples; this bounds memory) run on
    ``threads`` threads (numpy and Embree release the GIL); every batch has
    its own random stream, so the result depends on ``seed`` only.

    A pixel sample is one camera ray, one sample of each light, and
    ``environment_samples`` stratified pairs of environment and BRDF samples
    (the environment dominates the noise; sharing the camera ray and the
    surface set-up makes extra pairs cheap, and a 4x4 stratification of 16
    pairs measured 3x less time to 1% noise than 4 pairs on the benchmark
    scene).  samples_per_pixel counts camera rays: use at least 4 for a
    usable standard error.
    """
    own_tracer = tracer is None
    if own_tracer:
        tracer = RayTracer(scene.vertices, scene.triangles, threads=threads)
    try:
        return _render(scene, camera, samples_per_pixel, seed, progress, batch_rays, threads,
                       _Renderer(scene, tracer, environment_samples), pixel_centres)
    finally:
        if own_tracer:
            tracer.close()


def mean_relative_error(image, standard_error, statistic=np.mean):
    """Noise figure of a render: ``statistic`` (mean by default) of standard_error / value over the
    pixels that carry noise (background pixels are exact) and are not black (< 1e-3 of the mean)."""
    noisy = (standard_error.max(axis=-1) > 0) & (image.mean(axis=-1) > 1e-3 * image.mean())
    if not noisy.any():
        return 0.0
    return float(statistic(standard_error[noisy] / np.maximum(image[noisy], 1e-300)))


def render_to_noise(scene, camera, relative_error=0.01, pilot_samples=8, max_samples=4096, seed=0,
                    tracer=None, **options):
    """Render until mean_relative_error is about ``relative_error``: a pilot of ``pilot_samples``
    samples per pixel predicts the count (error ~ 1/sqrt(samples)), then the remaining samples are
    rendered with another seed and merged.  Returns (image, standard_error, samples_per_pixel).
    The merge assumes both runs finish: a progress callback must not stop them."""
    own_tracer = tracer is None
    if own_tracer:
        tracer = RayTracer(scene.vertices, scene.triangles, threads=options.get("threads", 2))
    try:
        pilot_samples = max(2, int(pilot_samples))
        image, error = render_reference(scene, camera, pilot_samples, seed=seed, tracer=tracer, **options)
        pilot_error = mean_relative_error(image, error)
        wanted = int(np.clip(np.ceil(pilot_samples * (pilot_error / relative_error) ** 2), pilot_samples, max_samples))
        if wanted <= pilot_samples:
            return image, error, pilot_samples
        rest = wanted - pilot_samples
        image2, error2 = render_reference(scene, camera, rest, seed=(seed, 1), tracer=tracer, **options)
        # Merge two uniform-count runs (means and sums of squared deviations, Chan et al.).
        n1, n2 = float(pilot_samples), float(rest)
        squares1 = np.where(np.isfinite(error), error ** 2 * n1 * (n1 - 1), 0.0)
        squares2 = np.where(np.isfinite(error2), error2 ** 2 * n2 * (n2 - 1), 0.0)
        merged = (n1 * image + n2 * image2) / (n1 + n2)
        squares = squares1 + squares2 + (image2 - image) ** 2 * (n1 * n2 / (n1 + n2))
        merged_error = np.sqrt(squares / (n1 + n2 - 1) / (n1 + n2))
        return merged, merged_error, wanted
    finally:
        if own_tracer:
            tracer.close()


def _render(scene, camera, samples_per_pixel, seed, progress, batch_rays, threads, renderer, pixel_centres=False):
    environment_samples = renderer.environment_samples
    height, width = camera.height, camera.width
    pixel_count = height * width
    samples_per_pixel = int(samples_per_pixel)
    # Each batch takes `repeats` samples of a run of `pixels_per_batch` pixels.
    samples_per_batch = max(1, batch_rays // (environment_samples if renderer.environment is not None else 1))
    pixels_per_batch = min(pixel_count, samples_per_batch)
    repeats = max(1, min(samples_per_pixel, samples_per_batch // pixels_per_batch))
    batches = [(first_sample, min(repeats, samples_per_pixel - first_sample), first_pixel,
                min(first_pixel + pixels_per_batch, pixel_count))
               for first_sample in range(0, samples_per_pixel, repeats)
               for first_pixel in range(0, pixel_count, pixels_per_batch)]
    streams = np.random.SeedSequence(seed).spawn(len(batches))

    def run_batch(index):
        _, batch_repeats, first_pixel, end_pixel = batches[index]
        rng = np.random.default_rng(streams[index])
        pixels = np.arange(first_pixel, end_pixel)
        pixel_ids = np.tile(pixels, batch_repeats)
        pixel_xy = np.stack([pixel_ids % width, pixel_ids // width], axis=-1).astype(np.float64)
        pixel_xy += 0.5 if pixel_centres else rng.random(pixel_xy.shape)
        origins, directions = camera.rays_through(pixel_xy)
        values = renderer.radiance(origins, directions, rng).reshape(batch_repeats, len(pixels), 3)
        return pixels, values

    count = np.zeros(pixel_count)
    mean = np.zeros((pixel_count, 3))
    squares = np.zeros((pixel_count, 3))   # sum of squared deviations from the mean
    total = samples_per_pixel * pixel_count
    done = 0
    with ThreadPoolExecutor(max(1, int(threads))) as pool:
        pending = deque()
        next_batch = 0
        while next_batch < len(batches) or pending:
            # Keep a small window of batches in flight, merged in order (deterministic).
            while next_batch < len(batches) and len(pending) < 2 * max(1, int(threads)):
                pending.append(pool.submit(run_batch, next_batch))
                next_batch += 1
            pixels, values = pending.popleft().result()
            # Chan et al.'s merge of the batch's mean and M2 into the running ones.
            batch_repeats = values.shape[0]
            batch_mean = values.mean(axis=0)
            batch_squares = ((values - batch_mean) ** 2).sum(axis=0)
            n_old = count[pixels][:, None]
            n_new = n_old + batch_repeats
            delta = batch_mean - mean[pixels]
            mean[pixels] += delta * (batch_repeats / n_new)
            squares[pixels] += batch_squares + delta ** 2 * (n_old * batch_repeats / n_new)
            count[pixels] = n_new[:, 0]
            done += values.shape[0] * values.shape[1]
            if progress is not None and progress(done, total):
                for future in pending:
                    future.cancel()
                break
    n = count[:, None]
    variance = squares / np.maximum(n - 1, 1)
    standard_error = np.where(n > 1, np.sqrt(variance / np.maximum(n, 1)), np.inf)
    return mean.reshape(height, width, 3), standard_error.reshape(height, width, 3)


def _orthonormal_tangents(normals):
    """A tangent perpendicular to each unit normal, continuous except on one
    meridian (Duff et al. 2017 branchless construction)."""
    sign = np.where(normals[:, 2] >= 0, 1.0, -1.0)
    a = -1.0 / (sign + normals[:, 2])
    b = normals[:, 0] * normals[:, 1] * a
    return np.stack([1.0 + sign * normals[:, 0] ** 2 * a, sign * b, -sign * normals[:, 0]], axis=-1)


def _normalize(v, fallback):
    length = np.sqrt(np.einsum("...i,...i->...", v, v))[..., None]
    ok = length > 1e-12
    return np.where(ok, v / np.where(ok, length, 1.0), fallback)


def _cone_directions(axis, cos_max, uniforms):
    """Uniform directions in the cone of half-angle acos(cos_max) around unit axes (N, 3)."""
    cos_theta = 1.0 - uniforms[:, 0] * (1.0 - cos_max)
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta ** 2))
    phi = 2.0 * np.pi * uniforms[:, 1]
    tangent = _orthonormal_tangents(axis)
    bitangent = np.cross(axis, tangent)
    return (tangent * (sin_theta * np.cos(phi))[:, None] + bitangent * (sin_theta * np.sin(phi))[:, None]
            + axis * cos_theta[:, None])


def _one_minus_cos_from_sin(sin_value):
    """1 - sqrt(1 - s^2) without cancellation for small s."""
    s2 = np.minimum(sin_value ** 2, 1.0)
    return s2 / (1.0 + np.sqrt(1.0 - s2))


class _Renderer:
    def __init__(self, scene, tracer, environment_samples=1):
        self.tracer = tracer
        self.environment_samples = max(1, int(environment_samples))
        self.triangles = np.asarray(scene.triangles, dtype=np.int64).reshape(-1, 3)
        self.normals = np.asarray(scene.normals, dtype=np.float64).reshape(-1, 3)
        self.corner_positions = np.asarray(scene.vertices, dtype=np.float64).reshape(-1, 3)[self.triangles]
        self.face_normals = _normalize(np.cross(self.corner_positions[:, 1] - self.corner_positions[:, 0],
                                                self.corner_positions[:, 2] - self.corner_positions[:, 0]),
                                       np.array([0.0, 0.0, 1.0]))
        self.tangents = None if scene.tangents is None else np.asarray(scene.tangents, np.float64).reshape(-1, 3)
        self.material_index = (np.zeros(len(self.triangles), np.int64) if scene.material_index is None
                               else np.asarray(scene.material_index, np.int64).reshape(-1))
        materials = list(scene.materials) or [Material()]
        self.material_index = np.clip(self.material_index, 0, len(materials) - 1)
        self.diffuse = np.array([np.broadcast_to(np.asarray(m.diffuse_color, float), 3) for m in materials])
        self.specular = np.array([np.broadcast_to(np.asarray(m.specular_color, float), 3)
                                  if m.specular_model is not None else np.zeros(3) for m in materials])
        self.models = [m.specular_model for m in materials]
        self.texture_lookups = [m.textures for m in materials]
        self.uvs = None if scene.uvs is None else np.asarray(scene.uvs, np.float64).reshape(-1, 2)
        # Probability of sampling the specular lobe: its share of the colour weight,
        # kept in [0.1, 0.9] when both lobes exist so neither is starved.
        diffuse_weight = self.diffuse @ LUMINANCE_WEIGHTS
        specular_weight = self.specular @ LUMINANCE_WEIGHTS
        share = specular_weight / np.maximum(diffuse_weight + specular_weight, 1e-300)
        both = (diffuse_weight > 0) & (specular_weight > 0)
        self.specular_probability = np.where(both, np.clip(share, 0.1, 0.9), np.where(specular_weight > 0, 1.0, 0.0))
        self.lights = list(scene.lights)
        environment = scene.environment
        if environment is None and scene.background is not None:
            # A constant background lights the scene like a constant environment.
            environment = np.broadcast_to(np.asarray(scene.background, float).reshape(1, 1, -1)[..., :3], (4, 8, 3))
        self.environment = None if environment is None else EnvironmentSampler(environment)

    # -- per-point BRDF in the local frame ------------------------------------------------------
    def _groups(self, material, uv):
        """A _ModelGroup for every material with a specular model present in the batch."""
        groups = []
        for m, model in enumerate(self.models):
            lookup = self.texture_lookups[m]
            idx = np.flatnonzero(material == m) if (model is not None or lookup is not None) else ()
            if not len(idx):
                continue
            if lookup is not None and "specular_model" in lookup(uv[idx[:1]]):
                groups.append(_ModelGroup(idx, None, lookup, uv[idx]))
            elif model is not None:
                groups.append(_ModelGroup(idx, model))
        return groups

    def _brdf_cosine(self, points, wi_local):
        """(kd/pi + ks rho_s) max(0, n.i): (N, 3); zero below the shading horizon."""
        cosine = np.maximum(wi_local[:, 2], 0.0)
        if not points.groups:
            return points.diffuse_over_pi * cosine[:, None]
        specular = np.zeros((len(wi_local), 3))
        for group in points.groups:
            idx = group.idx
            is_above = cosine[idx] > 0
            above = idx[is_above]
            if len(above):
                # a model's specular is a scalar (N,) or, for one that holds its own colours, RGB (N, 3)
                value = np.asarray(group.model_for(is_above).specular(points.wo_local[above], wi_local[above]))
                value = value[:, None] if value.ndim == 1 else value
                specular[above] = np.nan_to_num(value, nan=0.0, posinf=0.0, neginf=0.0)
        return (points.diffuse_over_pi + points.specular_color * specular) * cosine[:, None]

    def _brdf_pdf(self, points, wi_local):
        q = points.specular_probability
        pdf = (1.0 - q) * np.maximum(wi_local[:, 2], 0.0) * INV_PI
        for group in points.groups:
            idx = group.idx
            pdf[idx] += q[idx] * np.nan_to_num(group.model_for().pdf(points.wo_local[idx], wi_local[idx]),
                                               nan=0.0, posinf=0.0, neginf=0.0)
        return pdf

    def _brdf_sample(self, points, uniforms):
        """Mixture sample: cosine hemisphere or the specular model, chosen per point."""
        radius = np.sqrt(uniforms[:, 1])
        phi = 2.0 * np.pi * uniforms[:, 2]
        wi_local = np.stack([radius * np.cos(phi), radius * np.sin(phi),
                             np.sqrt(np.maximum(0.0, 1.0 - uniforms[:, 1]))], axis=-1)
        choose_specular = uniforms[:, 0] < points.specular_probability
        for group in points.groups:
            is_chosen = choose_specular[group.idx]
            chosen = group.idx[is_chosen]
            if len(chosen):
                # The choice used uniforms[:, 0]; the lobe gets the other two.
                sampled, _ = group.model_for(is_chosen).sample(points.wo_local[chosen], uniforms[chosen, 1:3])
                # A model that fails to sample (non-finite) gives a direction below the horizon: no light.
                wi_local[chosen] = np.where(np.isfinite(sampled).all(axis=-1, keepdims=True), sampled, [0.0, 0.0, -1.0])
        return wi_local, self._brdf_pdf(points, wi_local)

    # -- estimator ---------------------------------------------------------------------------------
    def radiance(self, origins, directions, rng):
        """Estimate of the radiance along each camera ray: (N, 3)."""
        result = np.zeros((len(origins), 3))
        hits = self.tracer.intersect(origins, directions)
        missed = ~hits.hit
        if self.environment is not None and missed.any():
            result[missed] = self.environment.radiance(directions[missed])
        hit_rows = np.flatnonzero(hits.hit)
        if len(hit_rows) == 0:
            return result
        points = self._surface_points(hits, hit_rows, directions[hit_rows])
        shaded = np.zeros((len(hit_rows), 3))
        for light in self.lights:
            shaded += self._light_contribution(points, light, rng)
        if self.environment is not None:
            shaded += self._environment_contribution(points, rng)
        result[hit_rows] = shaded
        return result

    def _surface_points(self, hits, rows, view_directions):
        points = _Points()
        triangle = hits.triangle[rows]
        weights = np.stack([1.0 - hits.u[rows] - hits.v[rows], hits.u[rows], hits.v[rows]], axis=-1)
        # Positions from barycentrics on the float64 mesh: closer to the surface than o + t d.
        points.position = np.einsum("nk,nkc->nc", weights, self.corner_positions[triangle])
        geometric = self.face_normals[triangle]
        wo = -view_directions
        # Two-sided surfaces: face the geometric normal to the viewer, the shading normal with it.
        geometric *= np.where(np.sum(geometric * wo, axis=-1) < 0, -1.0, 1.0)[:, None]
        corners = self.triangles[triangle]
        shading = _normalize(np.einsum("nk,nkc->nc", weights, self.normals[corners]), geometric)
        shading *= np.where(np.sum(shading * geometric, axis=-1) < 0, -1.0, 1.0)[:, None]
        if self.tangents is not None:
            tangent = np.einsum("nk,nkc->nc", weights, self.tangents[corners])
            tangent -= shading * np.sum(tangent * shading, axis=-1, keepdims=True)
            tangent = _normalize(tangent, _orthonormal_tangents(shading))
        else:
            tangent = _orthonormal_tangents(shading)
        points.normal = shading
        points.geometric_normal = geometric
        points.frame = np.stack([tangent, np.cross(shading, tangent), shading], axis=1)   # rows: x, y, z
        wo_local = np.einsum("nij,nj->ni", points.frame, wo)
        wo_local[:, 2] = np.maximum(wo_local[:, 2], _MIN_VIEW_COSINE)
        points.wo_local = _normalize(wo_local, np.array([0.0, 0.0, 1.0]))
        points.material = self.material_index[triangle]
        points.uv = (np.zeros((len(rows), 2)) if self.uvs is None
                     else np.einsum("nk,nkc->nc", weights, self.uvs[corners]))
        points.groups = self._groups(points.material, points.uv)
        points.diffuse_over_pi = self.diffuse[points.material] * INV_PI
        points.specular_color = self.specular[points.material]
        for m, lookup in enumerate(self.texture_lookups):
            idx = np.flatnonzero(points.material == m) if lookup is not None else ()
            if len(idx):
                values = lookup(points.uv[idx])
                if "diffuse_color" in values:
                    points.diffuse_over_pi[idx] = np.asarray(values["diffuse_color"], float) * INV_PI
                if "specular_color" in values:
                    points.specular_color[idx] = values["specular_color"]
        points.specular_probability = self.specular_probability[points.material]
        points.origin_offset = self.tracer.offset
        return points

    def _visible(self, points, wi_world, max_distance, active):
        """Visibility (N,) of each direction, tracing only where ``active``."""
        active_count = np.count_nonzero(active)
        if active_count == 0:
            return np.zeros(len(wi_world), bool)
        if active_count > 0.6 * len(active):
            # Mostly active: tracing the few idle rays is cheaper than gathering the rest.
            origins = offset_origins(points.position, points.geometric_normal, points.origin_offset, wi_world)
            distance = None if max_distance is None else np.maximum(max_distance - points.origin_offset, 0.0)
            return active & ~self.tracer.occluded(origins, wi_world, distance)
        visible = np.zeros(len(wi_world), bool)
        rows = np.flatnonzero(active)
        origins = offset_origins(points.position[rows], points.geometric_normal[rows],
                                 points.origin_offset, wi_world[rows])
        distance = None if max_distance is None else np.maximum(max_distance[rows] - points.origin_offset, 0.0)
        visible[rows] = ~self.tracer.occluded(origins, wi_world[rows], distance)
        return visible

    def _light_contribution(self, points, light, rng):
        """One light sample; for lights of finite size seen by glossy points also one BRDF
        sample, combined by the power heuristic (a sharp lobe barely sees a light sample)."""
        count = len(points.position)
        uniforms = rng.random((count, 2))
        cone = None   # (axis, 1 - cos of the half-angle, radiance, sphere centre distance or None)
        if isinstance(light, AreaLight):
            return self._area_light_contribution(points, light, uniforms, rng)
        if isinstance(light, PointLight):
            to_centre = np.asarray(light.position, float)[None, :] - points.position
            distance = np.linalg.norm(to_centre, axis=-1)
            axis = _normalize(to_centre, np.array([0.0, 0.0, 1.0]))
            intensity = np.asarray(light.intensity, float)[None, :] * light.spot_falloff(axis)[:, None]
            radius = float(light.radius)
            if radius > 0 and light.soft_falloff:
                # Cycles' Soft Falloff: a disk of radius r at the centre, facing the point, radiance I / (pi r^2)
                # along every ray that hits it (its normal is the ray's): a cone of tan a = r / d
                sin_max = radius / np.sqrt(distance ** 2 + radius ** 2)
                radiance = intensity / (np.pi * radius ** 2)
                cone = (axis, _one_minus_cos_from_sin(sin_max), radiance, distance, None)
            elif radius > 0:
                # A uniform sphere of this intensity has radiance I / (pi r^2); points inside it get nothing.
                outside = distance > radius
                sin_max = np.where(outside, radius / np.maximum(distance, 1e-300), 1.0)
                one_minus_cos = _one_minus_cos_from_sin(sin_max)
                radiance = intensity * np.where(outside, 1.0 / (np.pi * radius ** 2), 0.0)[:, None]
                cone = (axis, one_minus_cos, radiance, distance, radius)
            else:
                wi = axis
                weight = intensity / np.maximum(distance, 1e-300)[:, None] ** 2
                max_distance = distance
        elif isinstance(light, DirectionalLight):
            axis = _normalize(np.asarray(light.direction, float)[None, :], np.array([0.0, 0.0, 1.0]))
            axis = np.broadcast_to(axis, (count, 3))
            alpha = min(float(light.angular_radius), np.pi / 2)
            irradiance = np.asarray(light.irradiance, float)
            if alpha > 0:
                # Radiance E / (pi sin^2 a): the irradiance of the cap on a surface facing it is E.
                one_minus_cos = np.full(count, float(_one_minus_cos_from_sin(np.sin(alpha))))
                radiance = np.broadcast_to(irradiance / (np.pi * np.sin(alpha) ** 2), (count, 3))
                cone = (axis, one_minus_cos, radiance, None, None)
            else:
                wi = np.array(axis)
                weight = np.broadcast_to(irradiance, (count, 3))
                max_distance = None
        else:
            raise TypeError(f"unknown light type {type(light).__name__}")
        if cone is None:
            value = self._brdf_cosine(points, np.einsum("nij,nj->ni", points.frame, wi)) * weight
            return value * self._visible(points, wi, max_distance, np.any(value > 0, axis=-1))[:, None]

        axis, one_minus_cos, radiance, distance, radius = cone
        solid_angle = 2.0 * np.pi * one_minus_cos
        light_pdf = 1.0 / np.maximum(solid_angle, 1e-300)
        use_mis = bool(points.groups)
        # Light sample, uniform over the cone.
        wi = _cone_directions(axis, 1.0 - one_minus_cos, uniforms)
        wi_local = np.einsum("nij,nj->ni", points.frame, wi)
        value = self._brdf_cosine(points, wi_local) * radiance * solid_angle[:, None]
        if use_mis:
            value *= _power_weight(light_pdf, self._brdf_pdf(points, wi_local))[:, None]
        max_distance = _light_entry(distance, radius, np.sum(wi * axis, axis=-1))
        total = value * self._visible(points, wi, max_distance, np.any(value > 0, axis=-1))[:, None]
        if not use_mis:
            return total
        # BRDF sample: counts where it falls inside the light's cone.
        wi_local, brdf_pdf = self._brdf_sample(points, rng.random((count, 3)))
        wi = _normalize(np.einsum("nji,nj->ni", points.frame, wi_local), points.frame[:, 2])
        cos_to_axis = np.sum(wi * axis, axis=-1)
        inside = (cos_to_axis >= 1.0 - one_minus_cos) & (brdf_pdf > 0)
        weight = np.where(inside, _power_weight(brdf_pdf, light_pdf) / np.where(brdf_pdf > 0, brdf_pdf, 1.0), 0.0)
        value = self._brdf_cosine(points, wi_local) * radiance * weight[:, None]
        max_distance = _light_entry(distance, radius, cos_to_axis)
        return total + value * self._visible(points, wi, max_distance, np.any(value > 0, axis=-1))[:, None]

    def _area_light_contribution(self, points, light, uniforms, rng):
        """One sample over the light's area and, for glossy points, one BRDF sample that may hit it,
        combined by the power heuristic (pdfs in solid angle: distance^2 / (A cos) for the area's)."""
        count = len(points.position)
        normal = _normalize(np.asarray(light.normal, float)[None], np.array([0.0, 0.0, 1.0]))[0]
        area = max(light.area, 1e-300)

        def solid_angle_pdf(wi, distance):
            cos_light = np.maximum(-(wi @ normal), 0.0)
            return np.where(cos_light > 0, distance ** 2 / (area * np.maximum(cos_light, 1e-300)), 0.0)

        to_light = light.sample(uniforms) - points.position
        distance = np.linalg.norm(to_light, axis=-1)
        wi = _normalize(to_light, normal)
        light_pdf = solid_angle_pdf(wi, distance)
        wi_local = np.einsum("nij,nj->ni", points.frame, wi)
        value = self._brdf_cosine(points, wi_local) * light.radiance(wi)
        value *= np.where(light_pdf > 0, 1.0 / np.where(light_pdf > 0, light_pdf, 1.0), 0.0)[:, None]
        use_mis = bool(points.groups)
        if use_mis:
            value *= _power_weight(light_pdf, self._brdf_pdf(points, wi_local))[:, None]
        total = value * self._visible(points, wi, distance, np.any(value > 0, axis=-1))[:, None]
        if not use_mis:
            return total
        wi_local, brdf_pdf = self._brdf_sample(points, rng.random((count, 3)))
        wi = _normalize(np.einsum("nji,nj->ni", points.frame, wi_local), points.frame[:, 2])
        distance = light.hit(points.position, wi)
        hit = np.isfinite(distance) & (brdf_pdf > 0)
        distance = np.where(hit, distance, 1.0)
        light_pdf = np.where(hit, solid_angle_pdf(wi, distance), 0.0)
        weight = np.where(hit, _power_weight(brdf_pdf, light_pdf) / np.where(brdf_pdf > 0, brdf_pdf, 1.0), 0.0)
        value = self._brdf_cosine(points, wi_local) * light.radiance(wi) * weight[:, None]
        return total + value * self._visible(points, wi, distance, np.any(value > 0, axis=-1))[:, None]

    def _environment_contribution(self, points, rng):
        """MIS of `environment_samples` environment samples and as many BRDF samples, stratified
        over the pixel sample's own uniforms (so pixel samples stay independent), averaged."""
        per_point = self.environment_samples
        if per_point > 1:
            points = points.repeat(per_point, self)
        count = len(points.position)
        to_world = np.swapaxes(points.frame, 1, 2)
        # Environment sample.
        wi_env, pdf_env, radiance_env = self.environment.sample_with_radiance(
            _stratified_uniforms(rng, count, per_point, 2))
        wi_env_local = np.einsum("nij,nj->ni", points.frame, wi_env)
        value_env = self._brdf_cosine(points, wi_env_local) * radiance_env
        pdf_brdf_at_env = self._brdf_pdf(points, wi_env_local)
        # BRDF sample: the lobe choice gets its own uniform, the direction a stratified pair.
        brdf_uniforms = np.concatenate([rng.random((count, 1)), _stratified_uniforms(rng, count, per_point, 2)], 1)
        wi_brdf_local, pdf_brdf = self._brdf_sample(points, brdf_uniforms)
        wi_brdf = _normalize(np.einsum("nij,nj->ni", to_world, wi_brdf_local), points.frame[:, 2])
        radiance_brdf, pdf_env_at_brdf = self.environment.lookup(wi_brdf)
        value_brdf = self._brdf_cosine(points, wi_brdf_local) * radiance_brdf
        # Power heuristic, written as 1 / (1 + ratio^2) so huge pdfs do not overflow.
        weight_env = _power_weight(pdf_env, pdf_brdf_at_env)
        weight_brdf = _power_weight(pdf_brdf, pdf_env_at_brdf)
        estimate_env = value_env * (weight_env / np.maximum(pdf_env, 1e-300))[:, None]
        estimate_brdf = value_brdf * (weight_brdf / np.where(pdf_brdf > 0, pdf_brdf, 1.0))[:, None]
        visible_env = self._visible(points, wi_env, None, np.any(estimate_env > 0, axis=-1))
        visible_brdf = self._visible(points, wi_brdf, None, np.any(estimate_brdf > 0, axis=-1))
        total = estimate_env * visible_env[:, None] + estimate_brdf * visible_brdf[:, None]
        return total.reshape(-1, per_point, 3).mean(axis=1)


def _stratified_uniforms(rng, count, per_point, dimensions):
    """(count, dimensions) uniforms; each run of ``per_point`` rows is stratified: a square
    number of rows gets a jittered grid over the first two dimensions, other counts strata
    along the first dimension only."""
    uniforms = rng.random((count, dimensions))
    if per_point <= 1:
        return uniforms
    stratum = np.arange(count) % per_point
    side = int(round(per_point ** 0.5))
    if side * side == per_point and dimensions >= 2:
        uniforms[:, 0] = (stratum // side + uniforms[:, 0]) / side
        uniforms[:, 1] = (stratum % side + uniforms[:, 1]) / side
    else:
        uniforms[:, 0] = (stratum + uniforms[:, 0]) / per_point
    return uniforms


def _light_entry(distance, radius, cos_to_centre):
    """Distance along rays to where they reach a light: None for a distant light (distance None), the plane of a
    disk facing the point at the centre's distance (radius None: Soft Falloff's), else the sphere's surface."""
    if distance is None:
        return None
    if radius is None:
        return distance / np.maximum(cos_to_centre, 1e-12)
    return _sphere_entry(distance, radius, cos_to_centre)


def _sphere_entry(distance, radius, cos_to_centre):
    """Distance along a ray to where it enters a sphere of ``radius`` at ``distance`` whose
    centre is at angle acos(cos_to_centre) off the ray (the ray is aimed inside its cone)."""
    chord = np.maximum(radius ** 2 - distance ** 2 * (1.0 - cos_to_centre ** 2), 0.0)
    return np.maximum(distance * cos_to_centre - np.sqrt(chord), 0.0)


def _power_weight(pdf_own, pdf_other):
    ratio = pdf_other / np.where(pdf_own > 0, pdf_own, 1.0)
    return np.where(pdf_own > 0, 1.0 / (1.0 + np.minimum(ratio, 1e150) ** 2), 0.0)


class _ModelGroup:
    """The batch points ``idx`` of one material and their specular model: one model for a
    homogeneous material, or one with per-point parameters from its texture lookup."""

    def __init__(self, idx, model, lookup=None, uv=None):
        self.idx, self.model, self.lookup, self.uv = idx, model, lookup, uv

    def model_for(self, mask=None):
        """The model for the points idx[mask] (all of idx without a mask)."""
        if self.lookup is None:
            return self.model
        return self.lookup(self.uv if mask is None else self.uv[mask])["specular_model"]


class _Points:
    """Shading points of one batch (plain attribute bag)."""

    # What the environment estimator reads; the specular ones only when a specular model is present.
    _SAMPLING_FIELDS = ("position", "geometric_normal", "frame", "diffuse_over_pi", "specular_probability")
    _SPECULAR_FIELDS = ("material", "uv", "wo_local", "specular_color")

    def repeat(self, times, renderer):
        """Every point ``times`` times in a row (point i -> rows i * times ... i * times + times - 1),
        with only the fields the environment estimator uses."""
        out = _Points()
        names = self._SAMPLING_FIELDS + (self._SPECULAR_FIELDS if self.groups else ())
        for name in names:
            setattr(out, name, np.repeat(getattr(self, name), times, axis=0))
        out.origin_offset = self.origin_offset
        out.groups = renderer._groups(out.material, out.uv) if self.groups else []
        return out
