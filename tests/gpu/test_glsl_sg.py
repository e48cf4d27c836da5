"""shaders/lib/sg.glsl (float32, llvmpipe) against sg_prt_addon/spherical/sg.py (float64).

Inputs are exactly float32 values, so the differences measured are the GLSL
kernel's own arithmetic error.
"""
import numpy as np

from sg_prt_addon.spherical import sg

N = 20000
LIB = ["sg.glsl"]


def test_one_minus_exp_over_x(glsl, fuzz, record_error):
    x = np.concatenate([[0.0, 1e-30, 1e-8, 0.2499999, 0.25, 0.2500001],
                        fuzz.log_uniform(1e-8, 2e6, N)])
    x = fuzz.f32(x)
    out = glsl(LIB, "vec4(one_minus_exp_over_x(a.x))", {"a": x}, 1)
    error = fuzz.relative_error(out, sg.one_minus_exp_over_x(x), 1e-30)
    assert record_error("sg one_minus_exp_over_x, relative", error.max()) <= 1e-6, x[np.argmax(error)]


def test_safe_normalize(glsl, fuzz, record_error):
    v = fuzz.f32(fuzz.rng.normal(size=(N, 3)) * fuzz.log_uniform(1e-30, 1e30, N)[:, None])
    v[:4] = [[0, 0, 0], [1e-36, 0, 0], [0, -3, 0], [3e38, -3e38, 0]]
    out = glsl(LIB, "vec4(safe_normalize(a.xyz), 0)", {"a": v}, 3)
    expected = sg.normalize(v)
    assert record_error("sg safe_normalize, absolute", np.abs(out - expected).max()) <= 1e-6
    assert np.allclose(out[:4], [[0, 0, 1], [1, 0, 0], [0, -1, 0], [0.5 ** 0.5, -0.5 ** 0.5, 0]])


def test_evaluate(glsl, fuzz, record_error):
    axis = fuzz.unit_vectors(N)
    direction = fuzz.near(axis, 0.5)
    sharpness = fuzz.log_uniform(1e-4, 1e4, N)
    amplitude = fuzz.uniform(0.0, 10.0, N)
    out = glsl(LIB, "vec4(sg_evaluate(d.xyz, p.xyz, p.w, d.w))",
               {"d": np.c_[direction, amplitude], "p": np.c_[axis, sharpness]}, 1)
    expected = sg.evaluate(direction, axis, sharpness, amplitude)
    # exp(-E): float32 rounding of the exponent E gives ~E * 1e-7 relative error.
    exponent = 0.5 * sharpness * np.sum((direction - axis) ** 2, axis=1)
    well_conditioned = exponent < 60
    error = fuzz.relative_error(out, expected, 1e-30)
    assert record_error("sg evaluate (exponent < 60), relative", error[well_conditioned].max()) <= 2e-5
    assert np.all(np.abs(out - expected)[~well_conditioned] <= 1e-20)


def _product_inputs(fuzz):
    axis1 = fuzz.unit_vectors(N)
    # half near-parallel, half near-opposite: both ends of the stable form
    axis2 = np.where(np.arange(N)[:, None] % 2 == 0, fuzz.near(axis1, 0.3), fuzz.near(-axis1, 0.3))
    sharpness1 = fuzz.log_uniform(1e-4, 1e6, N)
    sharpness2 = fuzz.log_uniform(1e-4, 1e6, N)
    amplitude1 = fuzz.uniform(0.0, 3.0, N)
    amplitude2 = fuzz.uniform(0.0, 3.0, N)
    return axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2


def test_product(glsl, fuzz, record_error):
    axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2 = _product_inputs(fuzz)
    call = """
    vec3 axis; float sharpness, amplitude;
    sg_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y, axis, sharpness, amplitude);
    result = vec4(axis, 0.0);
    if (m.z > 0.5) result = vec4(sharpness, amplitude, 0.0, 0.0);
    """
    inputs = {"p1": np.c_[axis1, sharpness1], "p2": np.c_[axis2, sharpness2],
              "m": np.c_[amplitude1, amplitude2, np.zeros(N)]}
    out_axis = glsl(LIB, call, inputs, 3)
    inputs["m"][:, 2] = 1.0
    out_scalars = glsl(LIB, call, inputs, 2)
    axis, sharpness, amplitude = sg.product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2)
    # l1 p1 + l2 p2 cancels when l1 ~ l2 and p1 ~ -p2: the summed vector carries
    # float32 rounding of the larger term, so errors are relative to l1 + l2.
    assert record_error("sg product sharpness, relative to l1 + l2",
                        (np.abs(out_scalars[:, 0] - sharpness) / (sharpness1 + sharpness2)).max()) <= 1e-6
    well_separated = sharpness > 1e-2 * (sharpness1 + sharpness2)
    assert record_error("sg product axis (lambda_m > 0.01 (l1 + l2)), absolute",
                        np.abs(out_axis - axis)[well_separated].max()) <= 1e-4
    log_amplitude = np.log(np.maximum(amplitude, 1e-300) / np.maximum(amplitude1 * amplitude2, 1e-300))
    well_conditioned = (log_amplitude > -60) & (amplitude1 * amplitude2 > 0)
    error = fuzz.relative_error(out_scalars[:, 1], amplitude, 1e-30)
    # relative error of exp(-E) grows like E * eps: 60 * 1.2e-7 * a few
    assert record_error("sg product amplitude (log > -60), relative", error[well_conditioned].max()) <= 3e-5
    assert np.all(np.abs(out_scalars[:, 1] - amplitude)[~well_conditioned] <= 1e-20)


def test_inner_product(glsl, fuzz, record_error):
    axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2 = _product_inputs(fuzz)
    out = glsl(LIB, "vec4(sg_inner_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y))",
               {"p1": np.c_[axis1, sharpness1], "p2": np.c_[axis2, sharpness2],
                "m": np.c_[amplitude1, amplitude2]}, 1)
    expected = sg.inner_product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2)
    _, _, product_amplitude = sg.product(axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2)
    log_amplitude = np.log(np.maximum(product_amplitude, 1e-300) / np.maximum(amplitude1 * amplitude2, 1e-300))
    well_conditioned = (log_amplitude > -60) & (amplitude1 * amplitude2 > 0)
    error = fuzz.relative_error(out, expected, 1e-30)
    assert record_error("sg inner_product (log amplitude > -60), relative", error[well_conditioned].max()) <= 3e-5
    assert np.all(np.abs(out - expected)[~well_conditioned] <= 1e-20)


def test_integrals(glsl, fuzz, record_error):
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-4, 0.125, 1e6], fuzz.log_uniform(1e-4, 1e6, N)]))
    amplitude = fuzz.uniform(0.0, 5.0, sharpness.size)
    out = glsl(LIB, "vec4(sg_sphere_integral(a.x, a.y), sg_axis_hemisphere_integral(a.x, a.y),"
                    " sg_support_area(a.x + 1.0, 0.1), sg_sharpness_from_area(a.x + 1.0, 0.1))",
               {"a": np.c_[sharpness, amplitude]}, 4)
    shifted = fuzz.f32(sharpness + 1.0)
    expected = np.c_[sg.sphere_integral(sharpness, amplitude), sg.axis_hemisphere_integral(sharpness, amplitude),
                     sg.support_area(shifted), sg.sharpness_from_area(shifted)]
    assert record_error("sg integrals, support area, relative", fuzz.relative_error(out, expected, 1e-30).max()) <= 2e-6


def test_rotate(glsl, fuzz, record_error):
    axis = fuzz.unit_vectors(N)
    angle = fuzz.uniform(-np.pi, np.pi, N)
    c, s = np.cos(angle), np.sin(angle)
    rotation = np.zeros((N, 3, 3))
    rotation[:, 0, 0], rotation[:, 0, 1], rotation[:, 1, 0], rotation[:, 1, 1] = c, -s, s, c
    rotation[:, 2, 2] = 1.0
    # GLSL mat3(c0, c1, c2) takes columns
    call = "vec4(sg_rotate(p.xyz, mat3(c0.xyz, c1.xyz, c2.xyz)), 0.0)"
    out = glsl(LIB, call, {"p": axis, "c0": rotation[:, :, 0], "c1": rotation[:, :, 1],
                           "c2": rotation[:, :, 2]}, 3)
    assert record_error("sg rotate, absolute", np.abs(out - sg.rotate(axis, rotation)).max()) <= 1e-6


def test_product_is_symmetric_and_inner_product_bounded(glsl, fuzz):
    """Properties of the GLSL itself: G1 (x) G2 = G2 (x) G1, and Cauchy-Schwarz
    <G1, G2>^2 <= <G1, G1> <G2, G2>."""
    axis1, sharpness1, amplitude1, axis2, sharpness2, amplitude2 = _product_inputs(fuzz)
    call = ("vec4(sg_inner_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y),"
            " sg_inner_product(p2.xyz, p2.w, m.y, p1.xyz, p1.w, m.x),"
            " sg_inner_product(p1.xyz, p1.w, m.x, p1.xyz, p1.w, m.x),"
            " sg_inner_product(p2.xyz, p2.w, m.y, p2.xyz, p2.w, m.y))")
    out = glsl(LIB, call, {"p1": np.c_[axis1, sharpness1], "p2": np.c_[axis2, sharpness2],
                           "m": np.c_[amplitude1, amplitude2]}, 4).astype(np.float64)
    # l1 + l2 and l2 + l1 round alike, but (lambda_m + l1) + l2 does not: the exponent's
    # rounding (relative 1e-7 of |log amplitude|) is all the asymmetry there may be
    log_amplitude = np.abs(np.log(np.maximum(out[:, 0], 1e-300) / np.maximum(amplitude1 * amplitude2, 1e-300)))
    tolerance = (1e-6 + 3e-7 * log_amplitude) * out[:, 0] + 1e-37
    assert np.all(np.abs(out[:, 0] - out[:, 1]) <= tolerance)
    assert np.all(out[:, 0] ** 2 <= out[:, 2] * out[:, 3] * (1 + 1e-5) + 1e-37)
