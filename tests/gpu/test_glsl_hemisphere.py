"""shaders/lib/hemisphere.glsl (float32) against sg_prt_addon/spherical/hemisphere.py (float64)."""
import numpy as np

from sg_prt_addon.spherical import hemisphere

N = 20000
LIB = ["sg.glsl", "hemisphere.glsl"]


def test_erf_approx(glsl, fuzz, record_error):
    y = fuzz.f32(np.concatenate([[0.0, 1e-20, -1e-6, 6.0, -7.0, 1e30],
                                 fuzz.uniform(-8, 8, N), fuzz.log_uniform(1e-8, 1, N)]))
    out = glsl(LIB, "vec4(erf_approx(a.x))", {"a": y}, 1)
    expected = hemisphere.erf_approx(y)
    # |y| < 1e-19 squares into float32 denormals (flushed): absolute error < 1e-19 there
    error = fuzz.relative_error(out, expected, 1e-12)
    assert record_error("hemisphere erf_approx, relative", error.max()) <= 2e-6


def test_fh_normalized_from_sine(glsl, fuzz, record_error):
    sine = fuzz.uniform(-1.2, 1.2, N)
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-4, 1e6, 1e8], fuzz.log_uniform(1e-4, 1e6, N - 4)]))
    out = glsl(LIB, "vec4(fh_normalized_from_sine(a.x, a.y), fh_k(a.y), 0, 0)",
               {"a": np.c_[sine, sharpness]}, 2)
    assert record_error("hemisphere fh_normalized_from_sine, absolute",
                        np.abs(out[:, 0] - hemisphere.fh_normalized_from_sine(sine, sharpness)).max()) <= 3e-6
    assert record_error("hemisphere fh_k, relative", fuzz.relative_error(out[:, 1], hemisphere.fh_k(sharpness), 1e-30).max()) <= 2e-6


def test_fh_and_visibility_product(glsl, fuzz, record_error):
    theta = fuzz.uniform(-2.0, 2.0, N)
    sharpness = fuzz.log_uniform(1e-4, 1e6, N)
    amplitude = fuzz.uniform(0.0, 4.0, N)
    out = glsl(LIB, "vec4(fh_normalized(a.x, a.y), fh(a.x, a.y), visibility_product_amplitude(a.y, a.z, a.x),"
                    " visibility_product_integral_preserving_amplitude(a.y, a.z, a.x))",
               {"a": np.c_[theta, sharpness, amplitude]}, 4)
    normalized = hemisphere.fh_normalized(theta, sharpness)
    # sin(theta) in float32 near +-pi/2 and rounding of x: absolute error on fh_hat in [0, 1]
    assert record_error("hemisphere fh_normalized, absolute", np.abs(out[:, 0] - normalized).max()) <= 3e-6
    # fh = fh_hat * hemisphere integral: relative to the hemisphere integral's scale
    scale = 2 * np.pi * np.minimum(1.0, 1.0 / sharpness)
    assert record_error("hemisphere fh, relative to fh(pi/2)",
                        (np.abs(out[:, 1] - hemisphere.fh(theta, sharpness)) / scale).max()) <= 4e-6
    _, _, expected_amplitude = hemisphere.visibility_product(None, sharpness, amplitude, theta)
    assert record_error("hemisphere visibility_product amplitude (mu <= 4), absolute",
                        np.abs(out[:, 2] - expected_amplitude).max()) <= 4 * 3e-6
    _, _, preserving = hemisphere.visibility_product_integral_preserving(None, sharpness, amplitude, theta)
    assert record_error("hemisphere visibility_product_integral_preserving amplitude (mu <= 4), absolute",
                        np.abs(out[:, 3] - preserving).max()) <= 4 * 3e-6


def test_hemisphere_integral(glsl, fuzz, record_error):
    axis = fuzz.unit_vectors(N)
    normal = fuzz.f32(fuzz.unit_vectors(N) * fuzz.log_uniform(1e-3, 1e3, N)[:, None])  # not unit: normalised inside
    sharpness = fuzz.log_uniform(1e-4, 1e6, N)
    amplitude = fuzz.uniform(0.0, 4.0, N)
    out = glsl(LIB, "vec4(hemisphere_integral(p.xyz, p.w, n.w, n.xyz))",
               {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude]}, 1)
    expected = hemisphere.hemisphere_integral(axis, sharpness, amplitude, normal)
    scale = 2 * np.pi * np.minimum(1.0, 1.0 / sharpness) * np.maximum(amplitude, 1e-30)
    assert record_error("hemisphere hemisphere_integral, relative to mu fh(pi/2)", (np.abs(out - expected) / scale).max()) <= 1e-5


def test_fh_symmetry_and_bounds(glsl, fuzz):
    """Properties of the GLSL itself: fh(t) + fh(-t) = sphere integral (g is odd),
    e^-lambda <= fh_hat <= 1, and fh_hat non-decreasing in theta_d."""
    theta = fuzz.uniform(0.0, np.pi / 2, N)
    sharpness = fuzz.log_uniform(1e-4, 1e6, N)
    call = ("vec4(fh(a.x, a.y) + fh(-a.x, a.y), sg_sphere_integral(a.y, 1.0),"
            " fh_normalized(a.x, a.y), fh_normalized(a.x + 1e-3, a.y) - fh_normalized(a.x, a.y))")
    out = glsl(LIB, call, {"a": np.c_[theta, sharpness]}, 4)
    assert np.all(np.abs(out[:, 0] - out[:, 1]) <= 1e-6 * out[:, 1] + 1e-30)
    assert np.all(out[:, 2] >= np.exp(-sharpness) * (1 - 1e-5)) and np.all(out[:, 2] <= 1)
    assert out[:, 3].min() >= -1e-6
