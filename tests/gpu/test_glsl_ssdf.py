"""shaders/lib/ssdf.glsl (float32, llvmpipe) against sg_prt_addon/visibility (float64)."""
import numpy as np

from sg_prt_addon.spherical import hemisphere
from sg_prt_addon.visibility import decode, hemisphere_map

N = 20000
LIB = ["sg.glsl", "hemisphere.glsl", "hemisphere_map.glsl", "#define SSDF_MAX_LAYERS 3\n", "ssdf.glsl"]


def _directions(fuzz, count):
    d = fuzz.unit_vectors(count)
    d[:6] = [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, -1, 0], [0.6, 0.8, 0], [-0.6, 0, -0.8]]
    return fuzz.f32(d)


def test_horizon_lookup(glsl, fuzz, record_error):
    d = _directions(fuzz, N)
    out = glsl(LIB, "vec4(ssdf_horizon_lookup(a.xyz), 0)", {"a": d}, 3)
    square, below = hemisphere_map.horizon_lookup(d)
    # float32 atan near the square's diagonals and the poles: measured 4.2e-6
    assert record_error("ssdf horizon_lookup square, absolute", np.abs(out[:, :2] - square).max()) <= 1e-5
    assert record_error("ssdf horizon_lookup angle below, absolute", np.abs(out[:, 2] - below).max()) <= 1e-5


def test_local_frame(glsl, fuzz, record_error):
    n = _directions(fuzz, N)
    n[6] = hemisphere_map.FRAME_REFERENCE_AXIS
    w = _directions(fuzz, N)[::-1].copy()
    out = glsl(LIB, "vec4(ssdf_to_local(w.xyz, n.xyz), 0)", {"w": w, "n": n}, 3)
    expected = np.einsum("nij,nj->ni", hemisphere_map.local_frame(n), w)
    # the tangent is a projection of length >= 0.01 (fallback threshold): float32 rounding x 100 at worst
    assert record_error("ssdf to_local, absolute", np.abs(out - expected).max()) <= 3e-5


def test_decode_and_shadowed_integral(glsl, fuzz, record_error):
    resolution, terms = 16, 9                               # 10 images: 3 layers, the last one padded
    basis = fuzz.f32(fuzz.rng.normal(size=(terms, resolution, resolution)) * 0.3)
    mean = fuzz.f32(fuzz.rng.uniform(-1.5, 1.5, (resolution, resolution)))
    coefficients = fuzz.f32(fuzz.rng.normal(size=(N, terms)))
    packed = decode.pack_coefficients(coefficients)         # (N, 12)
    d = _directions(fuzz, N)
    sharpness = fuzz.log_uniform(0.1, 1e4, N)
    call = """
    vec4 c[SSDF_MAX_LAYERS];
    c[0] = c0; c[1] = c1; c[2] = c2;
    float value = ssdf_decode(ssdf_basis, c, 3, d.xyz);
    float leading;
    float same = ssdf_decode_leading(ssdf_basis, c, 3, 1, d.xyz, leading);
    result = vec4(value, ssdf_shadowed_integral(d.xyz, d.w, 1.0, ssdf_basis, c, 3),
                  ssdf_visibility_amplitude(d.w, 1.0, value) + 1000.0 * abs(same - value), leading);
    """
    out = glsl(LIB, call, {"d": np.c_[d, sharpness], "c0": packed[:, 0:4], "c1": packed[:, 4:8], "c2": packed[:, 8:12]},
               4, textures={"ssdf_basis": decode.pack_basis_texture(mean, basis)})
    expected = decode.decode(coefficients, basis, mean, d)
    # bilinear weights on llvmpipe: the sum of |w| |image| bounds float32 rounding
    scale = 1.0 + np.abs(coefficients).sum(axis=1) * 0.3
    assert record_error("ssdf decode, relative to sum |w_j| |B_j|",
                        (np.abs(out[:, 0] - expected) / scale).max()) <= 1e-4
    # the leading layer alone (the mean and 3 terms), and the full value again on the way
    leading = decode.decode(coefficients[:, :3], basis[:3], mean, d)
    assert record_error("ssdf decode_leading, relative to sum |w_j| |B_j|",
                        (np.abs(out[:, 3] - leading) / scale).max()) <= 1e-4
    integral = decode.shadowed_integral(d, sharpness, 1.0, coefficients, basis, mean)
    # compare at GLSL's own decoded value: fh's float32 error alone, relative to fh(pi/2)
    at_glsl_value = hemisphere.fh(out[:, 0].astype(np.float64), sharpness)
    upper = 2 * np.pi * np.minimum(1.0, 1.0 / sharpness)
    assert record_error("ssdf shadowed_integral (at GLSL's theta_d), relative to fh(pi/2)",
                        (np.abs(out[:, 1] - at_glsl_value) / upper).max()) <= 1e-5
    assert np.abs(out[:, 1] - integral).max() / upper.max() < 0.05
    _, _, amplitude = hemisphere.visibility_product_integral_preserving(None, sharpness, 1.0, out[:, 0].astype(np.float64))
    assert record_error("ssdf visibility_amplitude, absolute", np.abs(out[:, 2] - amplitude).max()) <= 5e-6


def test_decode_degenerate_directions_are_finite(glsl, fuzz):
    resolution = 8
    basis = fuzz.f32(fuzz.rng.normal(size=(3, resolution, resolution)))
    mean = fuzz.f32(fuzz.rng.normal(size=(resolution, resolution)))
    d = fuzz.stress_vectors(N)
    coefficients = fuzz.f32(fuzz.rng.normal(size=(N, 3)))
    packed = decode.pack_coefficients(coefficients)
    call = """
    vec4 c[SSDF_MAX_LAYERS];
    c[0] = c0; c[1] = vec4(0.0); c[2] = vec4(0.0);
    result = vec4(ssdf_decode(ssdf_basis, c, 1, d.xyz));
    """
    out = glsl(LIB, call, {"d": d, "c0": packed[:, 0:4]}, 1,
               textures={"ssdf_basis": decode.pack_basis_texture(mean, basis)})
    assert np.all(np.isfinite(out))
    expected = decode.decode(coefficients, basis, mean, d)
    assert np.abs(out - expected).max() < 1e-3 * (1 + np.abs(coefficients).sum(axis=1) * 3).max()


def _quadrature_library():
    from sg_prt_addon.techniques.sg import sg_lobes

    defines = "".join(f"#define {name} {value}\n" for name, value in sg_lobes.quadrature_defines().items())
    return ["sg.glsl", "hemisphere.glsl", defines, "ssdf_quadrature.glsl"]


def test_quadrature_points_coverage_and_weight(glsl, fuzz, record_error):
    """lib/ssdf_quadrature.glsl against visibility.broad_lobes, with the constants the engine defines."""
    from sg_prt_addon.visibility import broad_lobes

    library = _quadrature_library()
    index = np.arange(broad_lobes.QUADRATURE_POINTS, dtype=np.float32)
    out = glsl(library, "vec4(ssdf_quadrature_point(int(a.x)), 0)", {"a": np.stack([index] * 4, 1)}, 3)
    # float32 cos / sin of up to 31 golden angles (74 rad): measured 2.3e-6
    assert record_error("ssdf quadrature points, absolute",
                        np.abs(out - broad_lobes.quadrature_points()).max()) <= 1e-5
    distance = fuzz.f32(np.concatenate([fuzz.rng.uniform(-0.5, 0.5, N - 4), [-1.0, 1.0, 0.0, 0.25]]))
    sharpness = fuzz.f32(fuzz.rng.uniform(0.0, 40.0, N))
    inputs = {"a": np.stack([distance, sharpness, distance, sharpness], 1)}
    out = glsl(library, "vec4(ssdf_cell_coverage(a.x, 0.25), ssdf_quadrature_weight(a.y), ssdf_cell_radius(), 0)",
               inputs, 3)
    assert record_error("ssdf cell radius, relative",
                        np.abs(out[:, 2] / broad_lobes.cell_radius() - 1).max()) <= 1e-6
    # hemisphere.glsl's disc_coverage (thin segments by a series, asin by atan): measured 1e-6 (with GLSL's asin
    # it was 1.2e-4)
    assert record_error("ssdf cell coverage, absolute",
                        np.abs(out[:, 0] - broad_lobes.cell_coverage(distance, 0.25)).max()) <= 1e-5
    assert record_error("ssdf quadrature weight, absolute",
                        np.abs(out[:, 1] - broad_lobes.quadrature_weight(sharpness)).max()) <= 1e-6
