"""Accuracy of the SSDF visibility bake (wang2009 eq. 23-31, section 5.2): sg_prt_addon/visibility."""
import numpy as np

from benchmarks.bake_speed import sphere_over_floor
from sg_prt_addon.spherical import hemisphere, sg
from sg_prt_addon.visibility import BakeOptions, binary_visibility, broad_lobes, decode, hemisphere_map, pca, ssdf
from sg_prt_addon.visibility.pipeline import bake_ssdf
from sg_prt_addon.visibility.raytrace import RayTracer


def _row(name, error, reference, metric, paper=None, note=""):
    error = np.asarray(error, np.float64)
    row = dict(name=name, reference=reference, metric=metric, max_error=float(np.max(error)),
               mean_error=float(np.mean(error)), note=note)
    if paper is not None:
        row["paper"] = paper
    return row


def _quad(centre, normal, half_size):
    u = np.cross(normal, [0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    corners = np.array([centre + half_size * (a * u + b * v) for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    return corners, np.array([[0, 1, 2], [0, 2, 3]])


def _plane_ssdf(direction, m):
    """Closed form for occluded = {i.m > 0} or below the horizon (tests/core/test_ssdf_analytic.py)."""
    dot = direction @ m
    elevation = np.arcsin(np.clip(direction[..., 2], -1, 1))
    projection = direction - dot[..., None] * m
    corner = np.cross(m, [0.0, 0.0, 1.0])
    corner /= np.linalg.norm(corner)
    to_corner = np.arccos(np.clip(np.abs(direction @ corner), -1, 1))
    occluded = np.where(projection[..., 2] >= 0, np.arcsin(np.clip(dot, 0, 1)), to_corner)
    return np.where(dot <= 0, np.minimum(np.arcsin(np.clip(-dot, 0, 1)), elevation), -occluded)


def _plane_bake(tilt_degrees, resolution, refinement=5):
    tilt = np.radians(tilt_degrees)
    m = np.array([np.sin(tilt), 0.3 * np.cos(tilt), np.cos(tilt)])
    m /= np.linalg.norm(m)
    vertices, triangles = _quad(m, m, 400.0)
    tracer = RayTracer(vertices, triangles, threads=2)
    values = bake_ssdf(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), tracer,
                       BakeOptions(resolution=resolution, refinement=refinement))[0]
    tracer.close()
    frame = hemisphere_map.local_frame(np.array([[0.0, 0.0, 1.0]]))[0]
    return values.astype(np.float64).reshape(resolution, resolution), m, frame


def _broad_lobe_rows(model, samples, normals, dense, fine_local, rng):
    """The visible fraction of lobes G(i; axis, lambda) max(0, n.i) at baked vertices against dense rays:
    the quadrature of visibility.broad_lobes, eq. 30's reading at the axis (techniques.sg.sg_shading.
    lobe_visibility), and the blend the per-vertex pass of the diffuse lobes uses."""
    from sg_prt_addon.techniques.sg import sg_shading

    resolution = 32
    coefficients = pca.project(model, samples)
    basis, mean = model.basis.reshape(-1, resolution, resolution), model.mean.reshape(resolution, resolution)
    vertices = sg_shading.Visibility(rows=decode.pack_coefficients(coefficients), normal=normals.astype(np.float32),
                                     basis_texture=decode.pack_basis_texture(mean, basis))
    axes = rng.normal(size=(len(samples), 16, 3))
    axes[..., 2] = np.abs(axes[..., 2]) + 0.1
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    world_axes = np.einsum("nex,nxw->new", axes, hemisphere_map.local_frame(normals))
    coverage = sg_shading.vertex_coverage(vertices)
    lit = dense.reshape(len(samples), -1)
    rows = []
    for sharpness in (0.0, 2.0, 5.0, 10.0, 20.0, 40.0):
        lobe = np.exp(sharpness * (np.einsum("nex,px->nep", axes, fine_local) - 1.0)) * fine_local[:, 2]
        exact = np.einsum("nep,np->ne", lobe, lit) / lobe.sum(-1)
        lam = np.full(axes.shape[:2], sharpness)
        quadrature = broad_lobes.quadrature_visible_fraction(coverage, axes, lam)
        eq30 = sg_shading.lobe_visibility(world_axes.astype(np.float32), lam.astype(np.float32),
                                          normals.astype(np.float32), vertices)
        weight = broad_lobes.quadrature_weight(sharpness)
        shipped = weight * quadrature + (1 - weight) * eq30
        note = (f"eq. 30 at the axis: max {np.abs(eq30 - exact).max():.3g}, mean {np.abs(eq30 - exact).mean():.3g}, "
                f"bias {np.mean(eq30 - exact):+.3f}; the quadrature alone: max {np.abs(quadrature - exact).max():.3g}, "
                f"mean {np.abs(quadrature - exact).mean():.3g}; quadrature weight {weight:g}")
        rows.append(_row(f"broad lobe visible fraction, lambda {sharpness:g} ({broad_lobes.QUADRATURE_POINTS}-point "
                         "quadrature handing over to eq. 30)", np.abs(shipped - exact),
                         "dense 160^2 ray-traced visibility", "abs error of the visible fraction",
                         note=f"{len(samples)} vertices of sphere over floor, 16 lobe axes each; " + note))
    return rows


def measure():
    rows = []
    # 1. texel values against closed forms
    for tilt in (10.0, 20.0, 55.0):
        image, m, frame = _plane_bake(tilt, 32)
        directions = hemisphere_map.sample_directions(32).reshape(-1, 3) @ frame
        rows.append(_row(f"SSDF texels, tilted plane {tilt:.0f} deg (32^2 stored, 160^2 fine)",
                         np.abs(image.ravel() - _plane_ssdf(directions, m)), "closed-form angle to the occluded set",
                         "abs error, rad", note="wedge tip at the horizon below the outer fine row dominates the max"))
    for refinement in (3, 7):
        image, m, frame = _plane_bake(20.0, 32, refinement)
        directions = hemisphere_map.sample_directions(32).reshape(-1, 3) @ frame
        rows.append(_row(f"SSDF texels, tilted plane 20 deg (32^2 stored, refinement {refinement})",
                         np.abs(image.ravel() - _plane_ssdf(directions, m)), "closed-form angle to the occluded set",
                         "abs error, rad", note="the default refinement is 5 (row above)"))
    # 2. stored resolution needed by shading: bilinear lookups at random directions
    rng = np.random.default_rng(0)
    local = rng.normal(size=(20000, 3))
    local[:, 2] = np.abs(local[:, 2])
    local /= np.linalg.norm(local, axis=1, keepdims=True)
    for resolution in (16, 32, 64):
        image, m, frame = _plane_bake(55.0, resolution, refinement=5 if resolution <= 32 else 3)
        looked_up = decode.decode_image(image, local)
        exact = _plane_ssdf(local @ frame, m)
        fh_error = np.abs(hemisphere.fh_normalized(looked_up, 100.0) - hemisphere.fh_normalized(exact, 100.0))
        rows.append(_row(f"SSDF bilinear lookup, {resolution}^2 stored (plane 55 deg)", np.abs(looked_up - exact),
                         "closed form at random directions", "abs error of theta_d, rad",
                         note=f"fh_hat at lambda 100: max {fh_error.max():.3g}, mean {fh_error.mean():.3g}"))
    # 3. fast nearest boundary vs brute force
    fine = hemisphere_map.texel_directions(160)
    normals = rng.normal(size=(32, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    visible = (np.einsum("rcx,bx->brc", fine, normals) < 0.3) | (np.einsum("rcx,bx->brc", fine, normals[::-1]) > 0.8)
    index = np.clip(np.floor((hemisphere_map.sample_points(32) + 1) * 80), 0, 159).astype(int)
    query_visible = visible[:, index][:, :, index].reshape(32, -1)
    fast = ssdf.ssdf_from_fine(visible, 32).reshape(32, -1)
    brute = ssdf.signed_distance_brute_force(visible, fine, query_visible,
                                             hemisphere_map.sample_directions(32).reshape(-1, 3))
    rows.append(_row("SSDF nearest boundary (float32 argmax + float64 chord)", np.abs(fast - brute),
                     "float64 arccos against every boundary point", "abs error, rad"))
    # 4. adaptive vs dense visibility, and PCA on the sphere-over-floor scene
    vertices, triangles, normals = sphere_over_floor(2000)
    tracer = RayTracer(vertices, triangles, threads=2)
    pick = rng.choice(len(vertices), 48, replace=False)
    frames = hemisphere_map.local_frame(normals[pick])
    origins = vertices[pick] + tracer.offset * normals[pick]
    adaptive, rays = binary_visibility.adaptive_visibility(tracer, origins, frames, 32, 5)
    dense = binary_visibility.dense_visibility(tracer, origins, frames, 160)
    rows.append(_row("adaptive visibility (32^2 coarse, x5 where the coarse centres around a fine texel disagree)", np.mean(adaptive != dense, axis=(1, 2)),
                     "dense 160^2 rays", "fraction of mismatched texels per vertex", paper="512^2 rays",
                     note=f"{rays / len(pick):.0f} rays/vertex vs 25600; sphere over floor"))
    samples = bake_ssdf(vertices, normals, tracer, BakeOptions())
    tracer.close()
    model = pca.fit(samples, terms=48)
    # end to end at those vertices: mu fh(V_d(p)) from the PCA-decoded SSDF vs the SG integrated over
    # the dense ray-traced visibility (equal-area texels, 2 pi / 160^2 each)
    fine_local = hemisphere_map.texel_directions(160).reshape(-1, 3)
    axes = rng.normal(size=(32, 3))
    axes[:, 2] = np.abs(axes[:, 2]) + 0.2
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for terms in (16, 32, None):
        truncated = model if terms is None else pca.PcaModel(
            model.mean, model.basis[:terms], model.eigenvalues, model.rms_error_by_terms, model.total_variance)
        coefficients = pca.project(truncated, samples[pick])
        resolution = 32
        basis = truncated.basis.reshape(-1, resolution, resolution)
        mean = truncated.mean.reshape(resolution, resolution)
        for sharpness in (10.0, 100.0):
            errors = []
            for index in range(len(pick)):
                theta_d = decode.decode(coefficients[index], basis, mean, axes)
                approx = hemisphere.fh(theta_d, sharpness)
                lit = dense[index].ravel()
                exact = np.array([sg.evaluate(fine_local[lit], a, sharpness).sum() for a in axes]) * 2 * np.pi / 160 ** 2
                errors.append(np.abs(approx - exact) / sg.axis_hemisphere_integral(sharpness))
            rows.append(_row(f"bake end to end: mu fh(V_d(p)), lambda {sharpness:g}, PCA {truncated.terms} terms",
                             np.concatenate(errors), "SG over dense 160^2 ray-traced visibility",
                             "abs error / fh(pi/2)", note=f"{len(pick)} vertices of sphere over floor, 32 lobe axes each"))
    rows += _broad_lobe_rows(model, samples[pick], normals[pick], dense, fine_local, np.random.default_rng(1))
    data = samples.astype(np.float64)
    for terms in (8, 16, 32, 48):
        truncated = pca.PcaModel(model.mean, model.basis[:terms], model.eigenvalues, model.rms_error_by_terms,
                                 model.total_variance)
        error = np.abs(pca.reconstruct(truncated, pca.project(truncated, samples)) - data)
        rows.append(_row(f"SSDF PCA, {terms} terms (sphere over floor, {len(vertices)} vertices)",
                         np.sqrt(np.mean(error ** 2, axis=1)), "uncompressed SSDF", "RMS error per vertex, rad",
                         paper="48 terms" if terms == 48 else None, note=f"max texel error {error.max():.3g}"))
    # 5. shadowed SG integral (eq. 30) vs the SG integrated over the true visible set (spherical cap occluder)
    cap_centre = np.array([0.0, np.sin(0.5), np.cos(0.5)])
    visible = (fine @ cap_centre < np.cos(0.5))[None]
    image = ssdf.ssdf_from_fine(visible, 32)[0]
    count = 300000
    k = np.arange(count) + 0.5
    z = 1 - 2 * k / count
    phi = np.pi * (1 + 5 ** 0.5) * k
    points = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    points = points[(points[:, 2] >= 0) & (points @ cap_centre < np.cos(0.5))]
    axes = rng.normal(size=(60, 3))
    axes[:, 2] = np.abs(axes[:, 2]) + 0.3
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    for sharpness in (10.0, 100.0, 1000.0):
        approx = decode.shadowed_integral(axes, sharpness, 1.0, np.ones((60, 1)), image[None], np.zeros_like(image))
        exact = np.array([sg.evaluate(points, a, sharpness).sum() for a in axes]) * 4 * np.pi / count
        rows.append(_row(f"mu fh(V_d(p)) (eq. 30), lambda {sharpness:g}, cap occluder radius 0.5",
                         np.abs(approx - exact) / sg.axis_hemisphere_integral(sharpness),
                         "SG over the true visible set (Fibonacci sphere 3e5)", "abs error / fh(pi/2)",
                         note="hemisphere reconstruction of a curved boundary (wang2009 Fig. 7)"))
    rows += _light_cap_rows() + _buried_rows()
    return rows


def _light_cap_rows():
    """A light's visible fraction: its cap's share beyond the SSDF's boundary (sg_shading.light_cap_visibility),
    eq. 30's fh of its SG beside it (validation.visibility_cases)."""
    from validation import visibility_cases

    rows = []
    for radius, baked in ((0.05, False), (0.15, False), (0.4, False), (0.15, True)):
        cap, fh = visibility_cases.cap_share_errors(radius, baked)
        source = "baked 32^2 SSDF (x5)" if baked else "exact SSDF"
        rows.append(_row(f"light's visible fraction: its cap (radius {radius:g} rad) beyond the SSDF's boundary, "
                         f"{source}", cap, "cosine-weighted share of the cap beside a half-plane's edge (Monte "
                         "Carlo 2e5, noise ~1e-3)", "abs error of the visible fraction",
                         paper="eq. 30's fh of the light's SG",
                         note=f"41 positions across the edge; eq. 30's fh of the light's SG: max {fh.max():.3g}, "
                              f"mean {fh.mean():.3g}"))
    return rows


def _buried_rows():
    """Points of a floor buried in a sphere, as baked and filled from their neighbours (visibility.buried)."""
    from validation import visibility_cases

    errors = visibility_cases.seam_open_share_errors()
    baked = errors["baked"]
    return [_row("SSDF interpolated across a seam with buried corners, their rows filled from their neighbours",
                 errors["filled"], "rays from each point (16^2 stored, x3)", "abs error of the cosine-weighted "
                 "open share", note=f"{len(baked)} visible points of a floor's triangles leaving the sphere it passes "
                                    f"through; the buried rows as baked: max {baked.max():.3g}, mean "
                                    f"{baked.mean():.3g}")]
