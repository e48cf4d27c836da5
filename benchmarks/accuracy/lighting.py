"""Accuracy of the lighting representations (wang2009 section 6): SG lights (eq. 32-33), the
SG-prefiltered environment (eq. 34-35) and the SG-mixture diffuse fit (eq. 39).

References: exact quadrature of a uniform spherical cap times SG lobes
(lighting.exact_references.cap_sg_inner_product_reference); closed-form SG inner products for an
SG-mixture environment; brute-force summation over every texel of Blender's
bundled HDRIs; quadrature of the clamped cosine for irradiance.
"""
import time
from pathlib import Path

import numpy as np

from sg_prt_addon.lighting import env_fit, env_prefilter, equirect, light_clusters, lights
from sg_prt_addon.spherical import sg
from validation import exact_references

WORLD_DIR = Path(__file__).resolve().parents[2] / ".venv/lib/python3.11/site-packages/bpy/5.0/datafiles/studiolights/world"
WORLDS = ["courtyard", "forest", "city", "interior", "night", "studio", "sunrise", "sunset"]


def load_world(name):
    """A bundled Blender HDRI as (H, W, 3) float32, row 0 at the top (bpy used only here)."""
    import bpy

    image = bpy.data.images.load(str(WORLD_DIR / f"{name}.exr"), check_existing=True)
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return np.ascontiguousarray(pixels.reshape(height, width, 4)[::-1, :, :3])


def _light_errors(model, caps, lobe_sharpness):
    """Per (cap, lobe sharpness): max over lobe offsets of |SG - exact| / max exact (unit-radiance sphere)."""
    errors = []
    for cap in caps:
        radius = np.sin(cap)
        axis, sharpness, amplitude = lights.sphere_light_sg(np.zeros(3), [0, 0, 1.0], radius, np.pi * radius ** 2, model)
        for lam in lobe_sharpness:
            offsets = np.linspace(0, min(cap + 4 / np.sqrt(lam) + 0.2, np.pi), 40)
            exact = exact_references.cap_sg_inner_product_reference(cap, lam, offsets, nodes=600)
            lobe_axis = np.stack([np.sin(offsets), 0 * offsets, np.cos(offsets)], -1)
            approx = sg.inner_product(axis, sharpness, amplitude, lobe_axis, lam, 1.0)
            errors.append(float(np.max(np.abs(approx - exact)) / exact.max()))
    return np.array(errors)


def _light_rows():
    caps = [0.005, 0.02, 0.05, 0.1, 0.2]
    rows = []
    for label, lobes in [("diffuse lobes (lambda 1-4)", [1.0, 2.133, 4.0]),
                         ("glossy lobes (lambda 10-100)", [10.0, 30.0, 100.0]),
                         ("sharp lobes (lambda 300-1e4)", [300.0, 1e3, 1e4])]:
        ours = _light_errors("energy", caps, lobes)
        paper = _light_errors("paper", caps, lobes)
        rows.append(dict(
            name=f"sphere light SG, energy-normalized (eq. 32), {label}",
            reference="quadrature of uniform cap x SG lobe",
            metric="max over offsets |err| / peak, cap 0.3-11 deg",
            max_error=ours.max(), mean_error=ours.mean(), paper=paper.max(),
            note="paper: eq. 32 amplitude s/d^2 (integral off by ~r^2/d^2)"))
    return rows


def _exact_sg_environment():
    axes = sg.normalize(np.array([[0.3, 0.2, 0.9], [-0.8, 0.1, -0.2], [0.1, -0.9, 0.3], [0.0, 0.0, -1.0]]))
    sharpness = np.array([30.0, 6.0, 60.0, 2.0])
    amplitude = np.array([[4.0, 3.0, 2.0], [1.0, 1.5, 2.0], [6.0, 5.0, 1.0], [0.3, 0.3, 0.3]])
    constant = np.array([0.2, 0.25, 0.3])
    directions = equirect.texel_directions(512, 1024)
    image = sg.evaluate(directions[..., None, :], axes, sharpness) @ amplitude + constant

    def exact(axis, lam):
        inner = sg.inner_product(axis[:, None, :], lam[:, None], 1.0, axes, sharpness, 1.0)
        return (inner @ amplitude) / sg.sphere_integral(lam)[:, None] + constant

    return image, exact


BANDS = [(0.125, 8.0), (8.0, 64.0), (64.0, 512.0), (512.0, 2048.0)]


def _prefilter_rows():
    rows = []
    rng = np.random.default_rng(0)
    count = 400
    axes = sg.normalize(rng.normal(size=(count, 3)))
    image, exact = _exact_sg_environment()
    pre = env_prefilter.prefilter_environment(image, size=256)
    for low, high in [(1e-3, 0.125)] + BANDS:  # the first band is below the broadest level
        lam = np.exp(rng.uniform(np.log(low), np.log(high), count))
        error = np.max(np.abs(env_prefilter.lookup(pre, axes, lam) - exact(axes, lam)) / exact(axes, lam), axis=1)
        rows.append(dict(
            name=f"prefiltered env lookup, 256^2 x {pre.sharpness.size} layers, lambda {low:g}-{high:g}",
            reference="closed-form SG inner products (SG-mixture environment)",
            metric="relative to local value", max_error=error.max(), mean_error=error.mean(),
            note="2 bilinear fetches + log2-lambda blend, 3 levels/octave"))
    for world in ("courtyard", "sunset"):
        image = load_world(world)
        start, cpu_start = time.perf_counter(), time.process_time()
        pre = env_prefilter.prefilter_environment(image, size=256)
        seconds, cpu_seconds = time.perf_counter() - start, time.process_time() - cpu_start
        for low, high in BANDS + [(2048.0, 1e5)]:
            lam = np.exp(rng.uniform(np.log(low), np.log(high), 150))
            reference = exact_references.brute_force_convolution(image, axes[:150], lam)
            got = env_prefilter.lookup(pre, axes[:150], lam)
            relative = np.max(np.abs(got - reference), axis=1) / np.maximum(np.max(reference, axis=1), 1e-6)
            to_mean = np.max(np.abs(got - reference), axis=1) / image.mean()
            rows.append(dict(
                name=f"prefiltered {world}.exr {image.shape[1]}x{image.shape[0]}, lambda {low:g}-{high:g}",
                reference="brute-force sum over every texel",
                metric="relative to local value (max/mean)", max_error=relative.max(), mean_error=relative.mean(),
                note=f"max error / map mean radiance {to_mean.max():.3g}; prefilter {seconds:.1f} s wall, "
                     f"{cpu_seconds:.1f} s CPU"
                     + ("; beyond the top level (radiance at layer resolution)" if low >= 2048 else "")))
    return rows


def _fit_rows():
    rows = []
    for world in WORLDS:
        image = load_world(world)
        start = time.perf_counter()
        fit = env_fit.fit_environment_sg(image, lobes=8)
        seconds = time.perf_counter() - start
        report = env_fit.evaluate_fit(fit, image)
        rows.append(dict(
            name=f"8-SG diffuse fit (eq. 39), {world}.exr",
            reference="clamped-cosine quadrature of the map, 400 normals",
            metric="irradiance |err| / max_n E (max), RMS / mean E (mean)",
            max_error=report.irradiance_max_error, mean_error=report.irradiance_rms_error,
            paper=report.irradiance_max_error_eq40,
            note=f"radiance RMS error {report.radiance_rms_error:.2f}; fit {seconds:.1f} s; "
                 "paper's column: same lobes through eq. 40's one-lobe clamped cosine"))
    return rows


def _group_rows():
    """Point lights merged into groups (light_clusters): a floor's irradiance against the members' exact sum."""
    rng = np.random.default_rng(0)
    rows = []
    for count, groups in ((300, 64), (1000, 128)):
        position = rng.uniform([-4.0, -4.0, 2.0], [4.0, 4.0, 4.0], (count, 3))
        intensity = rng.uniform(0.1, 10.0, (count, 1))
        clusters = light_clusters.cluster_point_lights(position, np.full(count, 0.05), intensity, groups)
        grid = np.linspace(-4.0, 4.0, 41)
        points = np.stack(np.meshgrid(grid, grid, [0.0], indexing="ij"), axis=-1).reshape(-1, 3)

        def irradiance(lights_at, lights_intensity):
            offset = lights_at[None, :, :] - points[:, None, :]
            distance2 = np.sum(offset ** 2, axis=2)
            return np.einsum("pl,l->p", np.maximum(offset[..., 2], 0.0) / distance2 ** 1.5, lights_intensity[:, 0])
        exact = irradiance(position, intensity)
        relative = np.abs(irradiance(clusters.position, clusters.intensity) - exact) / exact
        rows.append(dict(
            name=f"{count} point lights as {groups} groups (light_clusters), 2-4 m over a floor",
            reference="sum over every light", metric="relative irradiance on the floor below them",
            max_error=relative.max(), mean_error=relative.mean(), paper=None,
            note="lightcuts' representative lights, one level"))
    return rows


def measure():
    return _light_rows() + _prefilter_rows() + _fit_rows() + _group_rows()


if __name__ == "__main__":
    for row in measure():
        print(row)
