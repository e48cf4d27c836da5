"""Accuracy of the spherical-harmonic machinery (sg_prt_addon/harmonics, kautz2002): rotation by the
recurrence and by the zyz method against projecting the rotated function (orders 2-8); projections of an
equirect image, of caps, windows (ringing against blur); the BRDF product tables' quadrature against a
dense one, the parametric models' and a stored lobe fit's (harmonics/fitted_table.py: per order, its view
interpolation, a 64 x 64-texel fit's build time and size); the shading error of the SH method itself (eq. 1, per order 3-6 and per model) against
direct quadrature of the shading integral, under courtyard.exr and under sphere lights of three sizes; and
the transfer bake (visibility/transfer.py): its direction lattice against exact integrals where the
visibility is known, and its PCA compression on a floor under a sphere."""
import math
import time

import numpy as np
from scipy.spatial.transform import Rotation

from benchmarks.accuracy.lighting import load_world
from sg_prt_addon.harmonics import basis, brdf_table, fitted_table, projection, rotation
from sg_prt_addon.lighting import equirect
from sg_prt_addon.measured import microfacet_fit
from sg_prt_addon.reflectance import brdf
from sg_prt_addon.spherical.lattice import hemisphere_points
from sg_prt_addon.visibility import transfer
from sg_prt_addon.visibility.raytrace import RayTracer
from validation import brdf_generators, fitted_sh_reference

SHADING_ORDERS = (3, 4, 5, 6)
TABLE_MODELS = [
    ("GGX r=0.2", "GGX", {"roughness": 0.2}),
    ("GGX r=0.5", "GGX", {"roughness": 0.5}),
    ("Cook-Torrance m=0.3 (Fresnel)", "COOK_TORRANCE", {"roughness": 0.3, "ior": 1.5}),
    ("Blinn-Phong n=50", "BLINN_PHONG", {"exponent": 50.0}),
    ("Ward anisotropic 0.3 x 0.1", "WARD_ANISO", {"alpha_x": 0.3, "alpha_y": 0.1}),
    ("Ashikhmin-Shirley 20 x 200", "ASHIKHMIN_SHIRLEY", {"nu": 20.0, "nv": 200.0}),
]
CAP_SIZES = (0.05, 0.2, 0.5)            # sphere lights' angular radii (rad)


def measure():
    return (_rotation_rows() + _projection_rows() + _table_rows() + _fitted_table_rows() + _shading_rows()
            + _transfer_rows())


def _rotation_rows():
    rows = []
    rotations = list(Rotation.random(6, random_state=2).as_matrix()) + [np.eye(3), rotation.axis_rotation(1, math.pi)]
    for method, apply in (("recurrence (Ivanic-Ruedenberg)", rotation.rotate), ("zyz (the GLSL's)", rotation.rotate_zyz)):
        errors, seconds = [], []
        for order in range(2, 9):
            directions, weights = projection.exact_quadrature(order)
            rng = np.random.default_rng(order)
            worst = 0.0
            for r in rotations:
                c = rng.normal(size=order * order)
                rotated = projection.project_samples(directions, basis.reconstruct(c, directions @ r), weights, order)
                worst = max(worst, float(np.max(np.abs(apply(c, r) - rotated))))
            start = time.perf_counter()
            for r in rotations:
                apply(c, r)
            seconds.append((time.perf_counter() - start) / len(rotations))
            errors.append(worst)
        rows.append(dict(name=f"SH rotation, {method}", reference="projection of the rotated function (exact rule)",
                         metric="max abs coefficient error, unit-normal coefficients, orders 2-8",
                         max_error=max(errors), mean_error=float(np.mean(errors)),
                         note="numpy ms per rotation, order 3 / 5 / 8: "
                              + " / ".join(f"{seconds[o - 2] * 1e3:.2f}" for o in (3, 5, 8))))
    counts = rotation.flop_counts(5)
    rows.append(dict(name="SH rotation cost, order 5 (flops a colour)", reference="-", metric="count",
                     max_error=None, mean_error=None,
                     note=f"block-diagonal matrix {counts['matrix']} ({counts['matrix'] // 2} multiply-adds); zyz "
                          f"{counts['zyz']} (x90 blocks: {counts['x90_nonzero']} non-zeros); recurrence building the "
                          f"matrix then applying it {counts['recurrence']}"))
    return rows


def _projection_rows():
    rows = []
    c = np.random.default_rng(4).normal(size=(36, 3))
    for height in (64, 128, 512):
        image = basis.reconstruct(c, equirect.texel_directions(height, 2 * height))
        error = float(np.max(np.abs(projection.project_equirect(image, 6) - c)) / np.max(np.abs(c)))
        rows.append(dict(name=f"equirect projection {2 * height} x {height}, order 6",
                         reference="the coefficients of the band-limited image", metric="max abs error / max coefficient",
                         max_error=error, mean_error=None, note="texel centres x exact texel solid angles"))
    worst = 0.0
    for half_angle in (0.05, 0.4, 1.2, 2.5):
        t, w = np.polynomial.legendre.leggauss(60)
        low = math.cos(half_angle)
        z, wz = low + (1 - low) * 0.5 * (t + 1), (1 - low) * 0.5 * w
        phi = (np.arange(120) + 0.5) * 2 * np.pi / 120
        r = np.sqrt(1 - z * z)
        d = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
        weights = np.broadcast_to(wz[:, None] * 2 * np.pi / 120, (60, 120)).reshape(-1)
        numeric = projection.project_samples(d.reshape(-1, 3), np.ones(len(weights)), weights, 8)
        worst = max(worst, float(np.max(np.abs(projection.cap_coefficients([0, 0, 1], half_angle, 1.0, 8)[:, 0]
                                               - numeric))))
    rows.append(dict(name="uniform cap (sphere light) closed form, order 8", reference="Gauss-Legendre over the cap",
                     metric="max abs coefficient error", max_error=worst, mean_error=None,
                     note="half-angles 0.05, 0.4, 1.2, 2.5 rad"))
    theta = np.linspace(0, np.pi, 4001)
    along = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], -1)
    for order in (5, 8):
        delta = projection.rotate_zonal([basis.normalization(b, 0) for b in range(order)], [0, 0, 1])
        for window in (None,) + projection.WINDOWS:
            values = basis.reconstruct(projection.apply_window(delta, projection.window_factors(window, order)), along)
            half = theta[np.argmax(values < 0.5 * values[0])]
            rows.append(dict(name=f"window {window or 'none'}, order {order}: a point light's expansion",
                             reference="the delta", metric="ringing: most negative value / peak",
                             max_error=float(-values.min() / values[0]), mean_error=None,
                             note=f"half maximum at {half:.3f} rad (the blur)"))
    return rows


def _table_rows():
    rows = []
    dense = hemisphere_points(300000)
    y = basis.evaluate(dense, 6)
    views = np.array([[math.sin(t), 0.0, math.cos(t)] for t in (0.1, 0.5, 0.9, 1.3)])
    for label, name, params in TABLE_MODELS:
        model = brdf.model_from_name(name, **params)
        start = time.perf_counter()
        c = brdf_table.project_product(model, views, 6)
        seconds = (time.perf_counter() - start) / len(views)
        reference = np.stack([(model.specular(np.broadcast_to(v, dense.shape), dense) * dense[:, 2]) @ y
                              * (2 * np.pi / len(dense)) for v in views])
        error = float(np.max(np.abs(c - reference)) / np.max(np.abs(reference)))
        table = brdf_table.table_for(name, order=5, **params)
        rows.append(dict(name=f"BRDF product table quadrature: {label}",
                         reference="300,000-point uniform lattice (about 1e-4 itself)",
                         metric="max abs coefficient error / max coefficient, order 6", max_error=error,
                         mean_error=None, note=f"MIS 1024 + 1024 samples, {seconds * 1e3:.1f} ms a view; order-5 "
                                               f"table {table.coefficients.shape} in {table.seconds:.1f} s"))
    return rows


FITTED_ORDERS = (3, 4, 5, 6)
FITTED_VIEWS = (1, 8, 13, 15)           # nodes of a 16-node table: theta_v 0.15, 0.83, 1.28, 1.52 rad


def _fitted_table_rows():
    """A 2-lobe fit of a generated 8 x 8 SVBRDF table (sharpness 3 to 15,000): every texel's entries at four view
    nodes against the dense lattice; the shader's interpolation between the 64 view nodes; the build of a
    64 x 64-texel fit."""
    table, _ = brdf_generators.generate_svbrdf_table(size=8, seed=5)
    fit = fitted_sh_reference.fit_arrays(microfacet_fit.fit_lobes(table, 2, shadowing_components=5))
    texels = np.arange(len(fit["sharpness"]))
    thetas = fitted_table.view_thetas(16)
    reference = {view: fitted_sh_reference.dense_product(fit, texels, thetas[view], max(FITTED_ORDERS))
                 for view in FITTED_VIEWS}
    rows = []
    for order in FITTED_ORDERS:
        start = time.perf_counter()
        sh_table = fitted_table.table_for(fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], (8, 8),
                                          order, views=16)
        seconds = time.perf_counter() - start
        count = order * order
        scale = np.max(np.abs(np.stack([r[:, :count] for r in reference.values()])), axis=(0, 2, 3))    # (T,)
        errors = np.max(np.stack([np.max(np.abs(fitted_sh_reference.table_product(fit, sh_table, texels, view)
                                                - reference[view][:, :count]), axis=(1, 2)) / scale
                                  for view in FITTED_VIEWS]), axis=0)                                      # (T,)
        rows.append(dict(name=f"SH table of a lobe fit, order {order}: quadrature",
                         reference="300,000-point uniform lattice of the fitted BRDF x cosine (the SG_FITTED "
                                   "mirror's M x lobes)",
                         metric="max abs coefficient error / the texel's max coefficient (mean: over texels), "
                                "64 texels x 4 views to 87 degrees",
                         max_error=float(errors.max()), mean_error=float(errors.mean()),
                         note=f"half-vector Gauss rule shared by the texels; 64 texels x 16 views in {seconds:.2f} s"))
    nodes = fitted_table.project_texels(fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], 5,
                                        fitted_table.view_thetas())
    middles = (np.arange(fitted_table.DEFAULT_VIEWS - 1) + 1.0) / fitted_table.DEFAULT_VIEWS * (np.pi / 2)
    sh_table = fitted_table.FittedTable(5, (8, 8), nodes)
    looked_up = np.stack([fitted_table.lookup(sh_table, texels, np.full(len(texels), theta)) for theta in middles],
                         2)[..., fitted_table.positive_m_indices(5)]
    direct = fitted_table.project_texels(fit["sharpness"], fit["eta"], fit["shadowing"], fit["theta"], 5, middles)
    error = np.abs(looked_up - direct) / np.max(np.abs(nodes), axis=(1, 2, 3))[:, None, None, None]
    below = middles < np.radians(70)
    rows.append(dict(name="SH table of a lobe fit: linear interpolation between its 64 view nodes",
                     reference="the table's quadrature at the view itself (halfway between nodes)",
                     metric="max abs coefficient error / the texel's max coefficient, order 5 (mean: below 70 degrees)",
                     max_error=float(error.max()), mean_error=float(error[:, :, below].max()),
                     note="S(o) / (pi o.z) left out of the table and applied per pixel: tabulated, its rise at "
                          "grazing views made the error at the last nodes 0.09 that did not fall with more nodes"))
    big, _ = brdf_generators.generate_svbrdf_table(size=64, seed=3)
    big_fit = fitted_sh_reference.fit_arrays(microfacet_fit.fit_lobes(big, 2, shadowing_components=5))
    notes = []
    for order in (5, 8):
        start = time.perf_counter()
        fitted_table.table_for(big_fit["sharpness"], big_fit["eta"], big_fit["shadowing"], big_fit["theta"],
                               (64, 64), order)
        notes.append(f"order {order}: {time.perf_counter() - start:.1f} s, "
                     f"{fitted_table.table_bytes(64 * 64, 2, order) / 2 ** 20:.0f} MB")
    rows.append(dict(name="SH table of a lobe fit, 64 x 64 texels, 2 lobes: build", reference="-", metric="seconds, MB",
                     max_error=None, mean_error=None,
                     note="; ".join(notes) + f" (64 views; the engine builds at most "
                                            f"{fitted_table.MAX_TABLE_BYTES / 2 ** 20:.0f} MB)"))
    return rows


def _mis_integral(model, view, radiance_of, samples=16384):
    """integral of L(s) f(s, v) cos(s) ds by the tables' MIS quadrature at many samples: (C,)."""
    lattice = brdf_table._lattice(samples)
    lobe, _ = model.sample(np.broadcast_to(view, (samples, 3)), lattice)
    directions = np.concatenate([lobe, brdf_table._cosine_directions(lattice)])
    wo = np.broadcast_to(view, directions.shape)
    cosine = np.maximum(directions[:, 2], 0.0)
    density = samples * model.pdf(wo, directions) + samples * cosine / np.pi
    f = np.nan_to_num(model.specular(wo, directions))
    weight = np.where((cosine > 0) & (density > 0), f * cosine / np.maximum(density, 1e-300), 0.0)
    return weight @ radiance_of(directions)


def _views(count=8):
    theta = (np.arange(count) + 0.5) / count * 1.45
    return np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], -1)


def _shading_rows():
    rows = []
    environment = load_world("courtyard")[::2, ::2].astype(np.float64)          # 512 x 256
    frames = Rotation.random(6, random_state=9).as_matrix()                     # local -> world
    world = {order: projection.project_equirect(environment, order) for order in SHADING_ORDERS}
    caps = [(size, axis) for size in CAP_SIZES for axis in
            Rotation.random(6, random_state=int(size * 100)).apply([0, 0, 1]) * [1, 1, 0] + [0, 0, 0.6]]
    for label, name, params in TABLE_MODELS:
        model = brdf.model_from_name(name, **params)
        views = _views()
        truth_env = np.array([[_mis_integral(model, v, lambda d, f=frame: equirect.lookup_nearest(
            environment, d @ f.T)) for v in views] for frame in frames])                  # (F, V, 3)
        cap_truth = {}
        for size, axis in caps:
            axis = axis / np.linalg.norm(axis)
            radiance = 1.0 / (2 * np.pi * (1 - math.cos(size)))                        # unit irradiance at normal incidence
            cap_truth[size, tuple(axis)] = np.array([_mis_integral(
                model, v, lambda d, a=axis: (d @ a >= math.cos(size))[:, None] * radiance, samples=65536)[0]
                for v in views])
        errors_env, errors_cap = [], {size: [] for size in CAP_SIZES}
        for order in SHADING_ORDERS:
            table = brdf_table.table_for(name, order=order, **params)
            parameter = params.get(table.parameter) if table.parameter else None
            c = brdf_table.lookup(table, views, parameter).astype(np.float64)        # (V, N^2)
            approx = np.array([c @ rotation.rotate(world[order], frame.T) for frame in frames])
            errors_env.append(float(np.sqrt(np.sum((approx - truth_env) ** 2) / np.sum(truth_env ** 2))))
            for size in CAP_SIZES:
                num = den = 0.0
                for (cap_size, axis), truth in cap_truth.items():
                    if cap_size != size:
                        continue
                    radiance = 1.0 / (2 * np.pi * (1 - math.cos(size)))
                    light = projection.cap_coefficients(axis, size, radiance, order)[:, 0]
                    num += np.sum((c @ light - truth) ** 2)
                    den += np.sum(truth ** 2)
                errors_cap[size].append(float(math.sqrt(num / den)))
        orders = " / ".join(str(o) for o in SHADING_ORDERS)
        rows.append(dict(name=f"SH shading (eq. 1), courtyard.exr: {label}",
                         reference="MIS quadrature of the shading integral (16,384 + 16,384 samples)",
                         metric="relative RMS over 8 views x 6 frames, order 5 (max: the worst order)",
                         max_error=max(errors_env), mean_error=errors_env[SHADING_ORDERS.index(5)],
                         note=f"orders {orders}: " + " / ".join(f"{e:.3f}" for e in errors_env)))
        for size in CAP_SIZES:
            errors = errors_cap[size]
            rows.append(dict(name=f"SH shading (eq. 1), sphere light of radius {size} rad: {label}",
                             reference="MIS quadrature over the cap (65,536 + 65,536 samples)",
                             metric="relative RMS over 8 views x 6 light directions, order 5 (max: the worst order)",
                             max_error=max(errors), mean_error=errors[SHADING_ORDERS.index(5)],
                             note=f"orders {orders}: " + " / ".join(f"{e:.3f}" for e in errors)))
    return rows


def _gauss_rule(z_low, z_high, phi_low, phi_high, count=48):
    t, w = np.polynomial.legendre.leggauss(count)
    z, wz = z_low + (z_high - z_low) * 0.5 * (t + 1), (z_high - z_low) * 0.5 * w
    phi, wphi = phi_low + (phi_high - phi_low) * 0.5 * (t + 1), (phi_high - phi_low) * 0.5 * w
    r = np.sqrt(1 - z * z)
    d = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
    return d.reshape(-1, 3), (wz[:, None] * wphi[None, :]).reshape(-1)


def _transfer_rows():
    rows = []
    roof = (np.array([[0.0, -1e3, 1.0], [1e3, -1e3, 1.0], [1e3, 1e3, 1.0], [0.0, 1e3, 1.0]]),
            np.array([[0, 1, 2], [0, 2, 3]]))
    cases = {"nothing around (the hemisphere)": (None, (0.0, 1.0, 0.0, 2 * math.pi)),
             "a roof over half the sky": (roof, (0.0, 1.0, math.pi / 2, 3 * math.pi / 2))}
    for label, (occluders, bounds) in cases.items():
        directions, weights = _gauss_rule(*bounds)
        y = basis.evaluate(directions, 5)
        exact_d, exact_g = (weights * directions[:, 2]) @ y, (y * weights[:, None]).T @ y
        notes, worst = [], 0.0
        for count in (256, 1024, 4096):
            tracer = RayTracer(*(occluders or (np.zeros((0, 3)), np.zeros((0, 3), int))))
            try:
                samples = transfer.transfer_vectors(np.zeros((1, 3)), [[0.0, 0.0, 1.0]], tracer, 5,
                                                    count)
            finally:
                tracer.close()
            diffuse, glossy = transfer.unpack(samples.astype(np.float64), 5)
            error = max(np.max(np.abs(diffuse[0] - exact_d)) / np.max(np.abs(exact_d)),
                        np.max(np.abs(glossy[0] - exact_g)) / np.max(np.abs(exact_g)))
            worst = max(worst, error) if count == 1024 else worst
            notes.append(f"{count}: {error:.2e}")
        rows.append(dict(name=f"transfer lattice, order 5: {label}", reference="Gauss-Legendre over the visible part",
                         metric="max abs error / max entry of t and T, 1024 directions (the default)",
                         max_error=worst, mean_error=None, note="directions " + ", ".join(notes)))
    grid = np.stack(np.meshgrid(np.linspace(-2, 2, 32), np.linspace(-2, 2, 32)), -1).reshape(-1, 2)
    vertices = np.c_[grid, np.zeros(len(grid))]
    from scipy.spatial import ConvexHull
    sphere = projection.sphere_quadrature(12, 24)[0] * 0.7 + [0.0, 0.0, 1.0]
    tracer = RayTracer(sphere, ConvexHull(sphere).simplices)
    try:
        samples = transfer.transfer_vectors(vertices, np.tile([0.0, 0.0, 1.0], (len(grid), 1)), tracer, 5,
                                            1024)
    finally:
        tracer.close()
    model, errors = transfer.compress(samples, error_target=0.02)
    rows.append(dict(name="transfer PCA, order 5: a floor of 1024 vertices under a sphere",
                     reference="the uncompressed transfer vectors (D = 350)",
                     metric="relative RMS of the vectors, at the default target 0.02 (max: 4 terms)",
                     max_error=float(errors[4]), mean_error=float(errors[model.terms]),
                     note=f"{model.terms} terms reach 0.02; " + ", ".join(f"{k} terms {errors[k]:.3f}"
                                                                         for k in (1, 2, 4, 8, 16))))
    return rows
