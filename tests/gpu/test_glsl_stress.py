"""Float32 fuzz stress: ~1e6 rows per kernel of shaders/lib, asserting no NaN/Inf.

Inputs cover the contract of docs/ARCHITECTURE.md: sharpness 0 and 1e-4..1e6,
equal and exactly opposite axes, poles, zero and tiny vectors, zero
amplitudes, grazing angles.  Kernels that take unit axes get unit, zero or
tiny axes; safe_normalize also gets huge ones.
"""
import numpy as np
import pytest

from sg_prt_addon.lighting import lights

ROWS = 1 << 20


def _axis_pairs(fuzz, count):
    """(axis1, axis2): random, with 1/4 equal, 1/4 exactly opposite, 1/8 zero/tiny axis1."""
    axis1 = fuzz.stress_vectors(count)
    huge = np.abs(axis1).max(axis=1) > 1e10
    axis1[huge] = fuzz.unit_vectors(int(huge.sum()))
    axis2 = fuzz.unit_vectors(count)
    kind = fuzz.rng.integers(0, 4, count)
    axis2[kind == 1] = axis1[kind == 1]
    axis2[kind == 2] = -axis1[kind == 2]
    return axis1, axis2


def _assert_finite(out, what):
    bad = ~np.isfinite(out)
    columns = np.flatnonzero(bad.reshape(len(out), -1).any(axis=0))
    assert not bad.any(), f"{what}: {int(bad.reshape(len(out), -1).any(axis=1).sum())} non-finite rows, columns {columns}"


def test_sg_stress(glsl, fuzz):
    axis1, axis2 = _axis_pairs(fuzz, ROWS)
    sharpness1 = fuzz.stress_sharpness(ROWS)
    sharpness2 = np.where(fuzz.rng.integers(0, 4, ROWS) == 0, sharpness1, fuzz.stress_sharpness(ROWS))
    amplitude1 = fuzz.stress_amplitude(ROWS)
    amplitude2 = fuzz.stress_amplitude(ROWS)
    inputs = {"p1": np.c_[axis1, sharpness1], "p2": np.c_[axis2, sharpness2],
              "m": np.c_[amplitude1, amplitude2]}
    product = """
    vec3 axis; float sharpness, amplitude;
    sg_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y, axis, sharpness, amplitude);
    result = vec4(axis.x + axis.y + axis.z, sharpness, amplitude,
                  sg_inner_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y));
    """
    out = glsl(["sg.glsl"], product, inputs, 4)
    _assert_finite(out, "sg_product / sg_inner_product")
    assert out[:, 1].min() >= 0 and out[:, 2].min() >= 0 and out[:, 3].min() >= 0
    others = ("vec4(sg_evaluate(p2.xyz, p1.xyz, p1.w, m.x), sg_sphere_integral(p1.w, m.x),"
              " sg_axis_hemisphere_integral(p1.w, m.x), one_minus_exp_over_x(p1.w))")
    out = glsl(["sg.glsl"], others, inputs, 4)
    _assert_finite(out, "sg_evaluate / integrals")
    assert out.min() >= 0
    # precise_asin: any argument (clamped to [-1, 1]); near 0 relative precision where GLSL's asin has 1e-4
    x = _f32(np.concatenate([[0.0, 1e-30, -1e-8, 0.2499, 0.25, 1.0, -1.0, 3e38, -3e38],
                             np.sign(fuzz.rng.normal(size=ROWS)) * 10.0 ** fuzz.uniform(-8.0, 0.3, ROWS)]))
    out = glsl(["sg.glsl"], "vec4(precise_asin(a.x), 0.0, 0.0, 0.0)", {"a": x[:, None]}, 1)
    _assert_finite(out, "precise_asin")
    exact = np.arcsin(np.clip(x.astype(np.float64), -1, 1))
    small = np.abs(x) < 0.25
    assert np.abs(out[small] / np.where(exact[small] == 0, 1, exact[small]) - 1)[exact[small] != 0].max() <= 1e-6
    assert np.abs(out - exact).max() <= 2e-5       # llvmpipe's atan: 3e-6 (its asin: 4e-4)


def test_safe_normalize_stress(glsl, fuzz):
    v = fuzz.stress_vectors(ROWS)
    v[:3] = [[3e38, 3e38, -3e38], [1e-38, 0, 0], [0, 0, 0]]
    out = glsl(["sg.glsl"], "vec4(safe_normalize(a.xyz), 0.0)", {"a": v}, 3)
    _assert_finite(out, "safe_normalize")
    assert np.abs(np.linalg.norm(out, axis=1) - 1).max() <= 1e-6


def test_hemisphere_stress(glsl, fuzz):
    axis, normal = _axis_pairs(fuzz, ROWS)
    sharpness = fuzz.stress_sharpness(ROWS)
    amplitude = fuzz.stress_amplitude(ROWS)
    # theta_d and sin(theta_d) beyond their ranges, and exactly at +-pi/2, +-1
    theta = fuzz.uniform(-4.0, 4.0, ROWS)
    kind = fuzz.rng.integers(0, 6, ROWS)
    theta[kind == 1] = np.float32(np.pi / 2)
    theta[kind == 2] = -np.float32(np.pi / 2)
    theta[kind == 3] = 0.0
    inputs = {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude], "t": theta}
    call = ("vec4(fh_normalized_from_sine(t.x, p.w), fh(t.x, p.w),"
            " hemisphere_integral(p.xyz, p.w, n.w, n.xyz), visibility_product_amplitude(p.w, n.w, t.x)"
            " + visibility_product_integral_preserving_amplitude(p.w, n.w, t.x))")
    out = glsl(["sg.glsl", "hemisphere.glsl"], call, inputs, 4)
    _assert_finite(out, "hemisphere.glsl")
    assert out.min() >= 0 and out[:, 0].max() <= 1


def test_brdf_stress(glsl, fuzz):
    wo, wi = fuzz.stress_vectors(ROWS), fuzz.stress_vectors(ROWS)
    h = fuzz.stress_vectors(ROWS)
    huge = np.abs(h).max(axis=1) > 1e10  # ndf(h) takes unit (or zero) h; m_factor normalises
    h[huge] = fuzz.unit_vectors(int(huge.sum()))
    for v in (wo, wi, h):  # grazing: z in [-1e-6, 1e-6]
        grazing = fuzz.rng.integers(0, 8, ROWS) == 0
        v[grazing, 2] = fuzz.uniform(-1e-6, 1e-6, int(grazing.sum()))
    wi[fuzz.rng.integers(0, 8, ROWS) == 0] *= -1  # some exactly opposite pairs through reflection
    roughness = fuzz.f32(np.where(fuzz.rng.integers(0, 4, ROWS) == 0, 0.0, fuzz.log_uniform(1e-6, 1.0, ROWS)))
    ior = fuzz.uniform(0.0, 4.0, ROWS)
    exponent = fuzz.f32(np.where(fuzz.rng.integers(0, 4, ROWS) == 0, 0.0, fuzz.log_uniform(1e-3, 1e6, ROWS)))
    rf0 = fuzz.uniform(0.0, 1.0, ROWS)
    inputs = {"wo": np.c_[wo, roughness], "wi": np.c_[wi, ior], "h": np.c_[h, exponent], "e": rf0}
    ndfs = """
    float r = wo.w, n = h.w;
    result = vec4(cook_torrance_ndf(h.xyz, r) + cook_torrance_beckmann_ndf(h.xyz, r) + ggx_ndf(h.xyz, r),
                  blinn_phong_ndf(h.xyz, n) + ashikhmin_shirley_ndf(h.xyz, n, n * 7.0 + 1.0)
                  + ggx_anisotropic_ndf(h.xyz, r, 1.0 - r) + ggx_anisotropic_smith_lambda(wo.xyz, r, 1.0 - r),
                  ward_isotropic_ndf(h.xyz, r) + ward_anisotropic_ndf(h.xyz, r, 1.0 - r),
                  fresnel_dielectric(h.z, wi.w) + fresnel_schlick(h.z, e.x));
    """
    out = glsl(["sg.glsl", "brdf.glsl"], ndfs, inputs, 4)
    _assert_finite(out, "brdf ndfs / fresnel")
    assert out.min() >= 0
    m_factors = """
    float r = wo.w, n = h.w;
    result = vec4(cook_torrance_m_factor(wo.xyz, wi.xyz, r, wi.w) + cook_torrance_beckmann_m_factor(wo.xyz, wi.xyz, r, wi.w),
                  blinn_phong_m_factor(wo.xyz, wi.xyz, n) + ward_anisotropic_m_factor(wo.xyz, wi.xyz),
                  ashikhmin_shirley_m_factor(wo.xyz, wi.xyz, n, 1.0, e.x) + ggx_m_factor(wo.xyz, wi.xyz, r)
                  + ggx_anisotropic_m_factor(wo.xyz, wi.xyz, r, 1.0 - r) + beckmann_m_factor(wo.xyz, wi.xyz, r),
                  lambert_m_factor(wo.xyz, wi.xyz, e.x));
    """
    out = glsl(["sg.glsl", "brdf.glsl"], m_factors, inputs, 4)
    _assert_finite(out, "brdf m_factors")
    assert out.min() >= 0
    lobes = """
    float r = wo.w, n = h.w;
    result = vec4(cook_torrance_ndf_lobe(r) + cook_torrance_beckmann_ndf_lobe(r),
                  blinn_phong_ndf_lobe(n) + ward_isotropic_ndf_lobe(r) + ggx_ndf_lobe(r) + beckmann_ndf_lobe(r));
    """
    out = glsl(["sg.glsl", "brdf.glsl"], lobes, inputs, 4)
    _assert_finite(out, "brdf ndf lobes")


def test_lights_stress(glsl, fuzz):
    position = fuzz.stress_vectors(ROWS)  # includes 1e30-sized positions and the origin
    light = fuzz.stress_vectors(ROWS)
    same = fuzz.rng.integers(0, 8, ROWS) == 0
    light[same] = position[same]  # shading point at the light's centre
    radius = fuzz.f32(np.where(fuzz.rng.integers(0, 4, ROWS) == 0, 0.0, fuzz.log_uniform(1e-6, 1e6, ROWS)))
    intensity = fuzz.stress_amplitude(ROWS)
    spot = fuzz.stress_vectors(ROWS)
    angle = fuzz.uniform(-1.0, 4.0, ROWS)
    inputs = {"x": np.c_[position, angle], "l": np.c_[light, radius], "s": np.c_[spot, intensity]}
    calls = {
        "sphere_light_sg": "sphere_light_sg(x.xyz, l.xyz, l.w, s.w, axis, sharpness, amplitude)",
        "sphere_light_sg_paper": "sphere_light_sg_paper(x.xyz, l.xyz, l.w, s.w, axis, sharpness, amplitude)",
        "soft_light_sg": "soft_light_sg(x.xyz, l.xyz, l.w, x.w > 1.0, s.w, axis, sharpness, amplitude)",
        "spot_light_sg": "spot_light_sg(x.xyz, l.xyz, s.xyz, x.w, fract(x.w), s.w, l.w, axis, sharpness, amplitude)",
        "directional_light_sg": "directional_light_sg(s.xyz, x.w, s.w, axis, sharpness, amplitude)",
    }
    for name, call in calls.items():
        body = ("vec3 axis; float sharpness, amplitude; " + call +
                "; result = vec4(axis.x + axis.y + axis.z, sharpness, amplitude, 0.0);")
        out = glsl(["sg.glsl", "lights.glsl"], body, inputs, 3)
        _assert_finite(out, name)
        assert out[:, 1].min() > 0 and out[:, 2].min() >= 0, name


def test_light_emission_stress(glsl, fuzz):
    """light_emission_factor on any axis and direction (zero, 1e30-sized), spot sizes and blends out of range,
    area patches with spreads from none to 1e-3 rad (normalization 3 / h^3 = 2.4e10): finite, within [0, peak]."""
    axis = fuzz.stress_vectors(ROWS)
    direction = fuzz.stress_vectors(ROWS)
    size = fuzz.uniform(-1.0, 7.0, ROWS)
    blend = fuzz.uniform(-0.5, 1.5, ROWS)
    spread = np.where(fuzz.rng.integers(0, 4, ROWS) == 0, np.pi, fuzz.log_uniform(1e-3, np.pi, ROWS))
    tan_half, normalization = np.array([lights.spread_parameters(s) for s in spread]).T
    area = (fuzz.rng.integers(0, 2, ROWS) == 0).astype(np.float64)
    inputs = {"a": np.c_[axis, size], "d": np.c_[direction, blend], "s": np.c_[area, tan_half, normalization]}
    body = "result = vec4(light_emission_factor(a.xyz, d.xyz, a.w, d.w, s.x > 0.5, s.y, s.z));"
    out = glsl(["sg.glsl", "lights.glsl"], body, inputs, 1).ravel()
    _assert_finite(out, "light_emission_factor")
    peak = np.where(area > 0.5, np.where(normalization > 0, tan_half * normalization, 1.0), 1.0)
    assert out.min() >= 0 and np.all(out <= peak * (1 + 1e-5)), "light_emission_factor"


def test_clamped_cosine_stress(glsl, fuzz):
    axis, normal = _axis_pairs(fuzz, ROWS)
    sharpness = fuzz.stress_sharpness(ROWS)
    tiny = fuzz.rng.integers(0, 8, ROWS) == 0
    sharpness[tiny] = fuzz.log_uniform(1e-38, 1e-4, int(tiny.sum()))  # below the contract's range too
    amplitude = fuzz.stress_amplitude(ROWS)
    cosine = fuzz.uniform(-1.5, 1.5, ROWS)
    inputs = {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude], "c": cosine}
    call = ("vec4(sg_clamped_cosine_integral(p.xyz, p.w, n.w, n.xyz), sg_clamped_cosine_integral_paper(p.xyz, p.w, n.w, n.xyz),"
            " clamped_cosine_from_cosine(clamp(c.x, -1.0, 1.0), p.w), clamped_cosine_lobe_evaluate(p.xyz, n.xyz))")
    out = glsl(["sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl"], call, inputs, 4)
    _assert_finite(out, "clamped_cosine.glsl")
    assert out.min() >= 0
    # never above the cosine's own integral pi times the amplitude (its sharpness-0 limit)
    assert np.all(out[:, 0] <= np.pi * amplitude * (1 + 1e-5) + 1e-30)


def test_clamped_cosine_table_stress(glsl, fuzz):
    """The tabulated integral over the same hostile lobes (NaN-free, lambda from 1e-38 to the cap, zero
    axes and normals, cosines outside [-1, 1]): finite, non-negative, at most pi times the amplitude."""
    from sg_prt_addon.spherical import clamped_cosine_table

    axis, normal = _axis_pairs(fuzz, ROWS)
    sharpness = fuzz.stress_sharpness(ROWS)
    tiny = fuzz.rng.integers(0, 8, ROWS) == 0
    sharpness[tiny] = fuzz.log_uniform(1e-38, 1e-4, int(tiny.sum()))
    amplitude = fuzz.stress_amplitude(ROWS)
    cosine = fuzz.uniform(-1.5, 1.5, ROWS)
    inputs = {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude], "c": cosine}
    call = ("vec4(sg_clamped_cosine_integral_tabulated(clamped_cosine_table, p.xyz, p.w, n.w, n.xyz),"
            " clamped_cosine_tabulated(clamped_cosine_table, c.x, p.w), 0.0, 0.0)")
    out = glsl(["sg.glsl", "clamped_cosine_table.glsl"], call, inputs, 2,
               textures={"clamped_cosine_table": clamped_cosine_table.clamped_cosine_table()})
    _assert_finite(out, "clamped_cosine_table.glsl")
    assert out.min() >= 0
    assert np.all(out[:, 0] <= np.pi * amplitude * (1 + 1e-5) + 1e-30)
    assert np.all(out[:, 1] <= np.pi * (1 + 1e-5))


def test_warp_stress(glsl, fuzz):
    axis, wo = _axis_pairs(fuzz, ROWS)  # includes wo = axis, wo = -axis, zero axes
    grazing = fuzz.rng.integers(0, 4, ROWS) == 0
    wo[grazing, 2] = fuzz.uniform(-1e-6, 1e-6, int(grazing.sum()))
    sharpness = fuzz.stress_sharpness(ROWS)
    amplitude = fuzz.stress_amplitude(ROWS)
    roughness = fuzz.uniform(0.0, 1.0, ROWS)
    inputs = {"p": np.c_[axis, sharpness], "wo": np.c_[wo, roughness], "m": amplitude}
    body = """
    vec3 axes[2]; float sharpnesses[2], amplitudes[2];
    warp_lobes_split2(p.xyz, p.w, m.x, wo.xyz, axes, sharpnesses, amplitudes);
    vec3 axes3[3]; float sharpnesses3[3], amplitudes3[3];
    warp_lobes_split3(p.xyz, p.w, m.x, wo.xyz, axes3, sharpnesses3, amplitudes3);
    vec3 paper_axis; float paper_sharpness, paper_amplitude;
    warp_lobes_paper(p.xyz, p.w, m.x, wo.xyz, paper_axis, paper_sharpness, paper_amplitude);
    float slice = brdf_slice_amplitude(amplitudes3[0], ggx_m_factor(wo.xyz, axes3[0], wo.w))
                + brdf_slice_amplitude(amplitudes3[1], ggx_m_factor(wo.xyz, axes3[1], wo.w))
                + brdf_slice_amplitude(amplitudes3[2], ggx_m_factor(wo.xyz, axes3[2], wo.w));
    result = vec4(dot(axes[0] + axes[1] + paper_axis + axes3[0] + axes3[1] + axes3[2], vec3(1.0)),
                  sharpnesses[0] + sharpnesses[1] + paper_sharpness + sharpnesses3[0] + sharpnesses3[1] + sharpnesses3[2],
                  amplitudes[0] + amplitudes[1] + paper_amplitude + amplitudes3[0] + amplitudes3[1] + amplitudes3[2],
                  slice);
    """
    out = glsl(["sg.glsl", "brdf.glsl", "warp.glsl"], body, inputs, 4)
    _assert_finite(out, "warp.glsl")
    assert out[:, 1:].min() >= 0
    assert out[:, 1].max() <= 6 * 1e6 * (1 + 1e-6)  # each warped sharpness capped at 1e6


def test_env_prefilter_stress(glsl, fuzz):
    """Lookups with degenerate axes and any sharpness in a 2-layer 8x8 array of random radiance."""
    layers = np.random.default_rng(1).random((2, 8, 8, 4)).astype(np.float32) * 1e3
    axis = fuzz.stress_vectors(ROWS)
    sharpness = fuzz.stress_sharpness(ROWS)
    amplitude = fuzz.stress_amplitude(ROWS)
    transforms = "const vec2 TRANSFORMS[32] = vec2[32](vec2(0.375, 0.5), vec2(0.375, 0.5)" + ", vec2(0.0)" * 30 + ");"
    call = ("env_prefilter_lookup(environment, p.xyz, p.w, -3.0, 2.0, 2, TRANSFORMS, vec4(500.0))"
            " + env_prefilter_lookup_integral(environment, p.xyz, p.w, a.x, -3.0, 2.0, 2, TRANSFORMS, vec4(500.0))")
    out = glsl(["sg.glsl", "env_prefilter.glsl", transforms], call, {"p": np.c_[axis, sharpness], "a": amplitude},
               4, {"environment": layers})
    _assert_finite(out, "env_prefilter.glsl")
    assert out.min() >= 0


# =========================================================================== every kernel
# The kernels above are the ones the shaders call per pixel; the tests below fuzz every other
# function of shaders/lib/*.glsl (helpers included) and the per-pixel pieces of shaders/techniques/sg that
# can be called alone, over the numpy stress suite's own inputs (tests/core/test_stress_*.py: its
# hostile SG set and BRDF directions, sub-sampled), in float32 on llvmpipe.  test_every_kernel_is_fuzzed
# parses the function names of shaders/lib and fails when one is missing from COVERED.

import functools
import importlib.util
import inspect
import os
import re

SMALL_ROWS = 1 << 17
SHADERS = os.path.join(os.path.dirname(__file__), os.pardir, os.pardir, "shaders")


def _f32(values):
    """float64 values exactly representable in float32 (what the kernels see)."""
    return np.asarray(values, np.float32).astype(np.float64)


def _numpy_suite(name):
    """tests/core/<name>.py, imported by path (its generators are the numpy stress inputs)."""
    path = os.path.join(os.path.dirname(__file__), os.pardir, "core", name + ".py")
    spec = importlib.util.spec_from_file_location("_numpy_" + name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@functools.lru_cache(maxsize=1)
def _sg_inputs():
    """test_stress_sg's hostile set (opposite / nearly opposite / equal axes, grazing, zero and
    opposite normals, theta_d at +-pi/2 and beyond, sharpness 0, 1e-4..1e6), every 8th row, float32."""
    inputs = _numpy_suite("test_stress_sg")._hostile_inputs_float64()
    return {key: np.asarray(value[::8], np.float32).astype(np.float64) for key, value in inputs.items()}


@functools.lru_cache(maxsize=1)
def _brdf_inputs():
    """test_stress_brdf's hostile directions (grazing at 0, +-1e-8, 1e-4, 1e-30, the pole, zero,
    tiny 1e-20 vectors, opposite pairs) and parameters (roughness 1e-4..1, exponents 1e-2..1e8)."""
    suite = _numpy_suite("test_stress_brdf")
    rng = np.random.default_rng(11)
    wo, kind = suite.hostile_directions(rng, SMALL_ROWS, np.float32)
    wi, _ = suite.hostile_directions(rng, SMALL_ROWS, np.float32)
    wi = np.where((kind == 5)[:, None], -wo, wi)
    h, _ = suite.hostile_directions(rng, SMALL_ROWS, np.float32)
    roughness = suite.log_uniform(rng, 1e-4, 1.0, SMALL_ROWS).astype(np.float32)
    roughness[::9] = 0.0
    exponent = suite.log_uniform(rng, 1e-2, 1e8, SMALL_ROWS).astype(np.float32)
    exponent[::11] = 0.0
    f = lambda a: np.asarray(a, np.float32).astype(np.float64)       # noqa: E731
    return f(wo), f(wi), f(h), f(roughness), f(exponent), rng


def _light_inputs(count):
    """test_stress_lighting's point/sphere light set: scales 1e-6..1e6, zero distance, radius 0,
    shading points on the light's surface, intensities 1e-3..1e6."""
    rng = np.random.default_rng(1)
    scale = 10.0 ** rng.uniform(-6, 6, (count, 1))
    light = rng.normal(size=(count, 3)) * scale
    offset = rng.normal(size=(count, 3)) * scale * 10.0 ** rng.uniform(-8, 2, (count, 1))
    x = light + offset
    x[:1000] = light[:1000]
    radius = scale[:, 0] * 10.0 ** rng.uniform(-3, 1, count)
    radius[1000:2000] = 0
    radius[2000:3000] = np.linalg.norm(offset[2000:3000], axis=1)
    intensity = 10.0 ** rng.uniform(-3, 6, count)
    f = lambda a: np.asarray(a, np.float32).astype(np.float64)       # noqa: E731
    return f(x), f(light), f(radius), f(intensity), rng


def _glsl_function(source, name):
    """The full definition of GLSL function `name` (first overload) cut out of `source`."""
    match = re.search(r"^[A-Za-z_][\w]*\s+" + name + r"\s*\(", source, re.M)
    assert match, name
    depth, position = 0, source.index("{", match.end())
    for index in range(position, len(source)):
        depth += {"{": 1, "}": -1}.get(source[index], 0)
        if depth == 0:
            return source[match.start():index + 1] + "\n"
    raise AssertionError(f"unbalanced {name}")


def _resource(file_name, technique="sg"):
    with open(os.path.join(SHADERS, "techniques", technique, file_name), encoding="utf-8") as handle:
        return handle.read()


def test_sg_helpers_stress(glsl):
    x = _sg_inputs()
    positive = np.maximum(x["sharpness"], 1e-4)     # the support area of sharpness > 0 (as numpy's suite)
    epsilon = np.where(np.arange(len(positive)) % 2 == 0, 0.1, 1e-6)
    inputs = {"p": np.c_[x["axis1"], positive], "e": epsilon}
    body = """
    vec3 r = sg_rotate(p.xyz, mat3(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0));
    float area = sg_support_area(p.w, e.x);
    result = vec4(r.x + r.y + r.z, area, sg_sharpness_from_area(area, e.x), length(r));
    """
    out = glsl(["sg.glsl"], body, inputs, 4)
    _assert_finite(out, "sg_rotate / sg_support_area / sg_sharpness_from_area")
    assert out[:, 1].min() > 0 and np.abs(out[:, 3] - 1).max() < 1e-5


def test_hemisphere_helpers_stress(glsl):
    x = _sg_inputs()
    inputs = {"t": np.c_[x["theta_d"], x["sharpness"], x["theta_d"] * x["sharpness"]]}
    out = glsl(["sg.glsl", "hemisphere.glsl"], "vec4(erf_approx(t.z), fh_k(t.y), fh_normalized(t.x, t.y), "
               "disc_coverage(t.x, t.z))", inputs, 4)      # radius: any sign and size, zero included
    _assert_finite(out, "erf_approx / fh_k / fh_normalized / disc_coverage")
    assert np.abs(out[:, 0]).max() <= 1 and out[:, 1].min() > 0.59
    assert out[:, 2].min() >= 0 and out[:, 2].max() <= 1
    assert out[:, 3].min() >= 0 and out[:, 3].max() <= 1


def test_clamped_cosine_helpers_stress(glsl):
    x = _sg_inputs()
    cosine = np.clip(np.sum(x["axis1"] * x["normal"], axis=1), -1, 1)
    inputs = {"s": np.c_[x["sharpness"], cosine]}
    body = """
    vec2 lobe = clamped_cosine_lobe();
    vec2 poles = clamped_cosine_pole_integrals(s.x);
    vec2 moments = clamped_cosine_langevin_moments(s.x);
    float positive = clamped_cosine_gaussian_positive_mean(s.y * moments.x, s.y * s.y * moments.y);
    float at_zero_variance = clamped_cosine_gaussian_positive_mean(s.y, 0.0);
    vec4 poles_moments, shape;
    clamped_cosine_sharpness_terms(s.x, poles_moments, shape);
    float from_terms = clamped_cosine_from_terms(s.y, s.x, poles_moments, shape);
    result = vec4(poles.x + poles.y, moments.x + moments.y, positive + at_zero_variance,
                  lobe.x * lobe.y + from_terms + dot(poles_moments, shape));
    """
    out = glsl(["sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl"], body, inputs, 4)
    _assert_finite(out, "clamped_cosine pole integrals / Langevin moments / Gaussian positive mean")
    # E[max(0, X)] through erf_approx (1e-4 absolute) dips a few 1e-8 below 0; its caller clamps
    assert out[:, [0, 1, 3]].min() >= 0 and out[:, 2].min() >= -1e-6


def test_brdf_helpers_stress(glsl):
    wo, wi, h, roughness, exponent, rng = _brdf_inputs()
    width = _f32(np.where(rng.integers(0, 8, SMALL_ROWS) == 0, 0.0, np.exp(rng.uniform(np.log(1e-6), np.log(10.0), SMALL_ROWS))))
    alpha_y = _f32(np.exp(rng.uniform(np.log(1e-6), 0.0, SMALL_ROWS)))
    inputs = {"wo": np.c_[wo, roughness], "wi": np.c_[wi, exponent], "h": np.c_[h, width], "a": alpha_y}
    body = """
    vec3 half_vector = brdf_half_vector(wo.xyz, wi.xyz);
    vec3 reflected = reflect_about(safe_normalize(wo.xyz), half_vector);
    float alpha = ggx_alpha(wo.w);
    vec2 mappings = isotropic_mapping_beckmann(h.w) + isotropic_mapping_blinn_phong(h.w)
                  + isotropic_mapping_ward_iso(h.w) + isotropic_mapping_ggx(h.w)
                  + isotropic_polynomial(GGX_SHARPNESS, GGX_AMPLITUDE, min(h.w, 1.0));
    result = vec4(dot(reflected, vec3(1.0)) + brdf_theta(h.xyz) + brdf_log_cosine(max(h.z, BRDF_FLOAT_TINY)),
                  shadowing_cook_torrance(safe_normalize(wo.xyz), safe_normalize(wi.xyz), half_vector)
                  + ward_isotropic_m_factor(wo.xyz, wi.xyz),
                  beckmann_ndf(h.xyz, max(wo.w, 1.0e-6), max(a.x, 1.0e-6))
                  + ggx_smith_lambda(safe_normalize(wo.xyz), alpha) + ggx_smith_lambda(wi.xyz, alpha)
                  + beckmann_smith_lambda(safe_normalize(wo.xyz), beckmann_alpha(wo.w))
                  + beckmann_smith_lambda(wi.xyz, beckmann_alpha(wo.w)),
                  mappings.x + mappings.y);
    """
    out = glsl(["sg.glsl", "brdf.glsl"], body, inputs, 4)
    _assert_finite(out, "brdf helpers")
    assert out[:, 1:].min() >= 0


def test_warp_helpers_stress(glsl):
    x = _sg_inputs()
    wo = x["normal"]          # zero, grazing, on and opposite the axis
    inputs = {"p": np.c_[x["axis1"], x["sharpness"]], "wo": np.c_[wo, x["amplitude1"]]}
    body = """
    vec3 unit_axis, unit_wo, in_plane;
    float offset, across;
    warp_split_frame(p.xyz, p.w, wo.xyz, true, unit_axis, unit_wo, in_plane, offset, across);
    vec3 node_axis; float node_sharpness, node_amplitude;
    warp_split_node(unit_axis, in_plane, unit_wo, offset, across, 1.7320508075688772, 1.0 / 6.0, p.w, wo.w,
                    node_axis, node_sharpness, node_amplitude);
    vec3 at_axis; float at_sharpness;
    warp_at(unit_axis, p.w, unit_wo, clamp(dot(unit_axis, unit_wo), -1.0, 1.0), across, at_axis, at_sharpness);
    result = vec4(dot(in_plane + node_axis + at_axis, vec3(1.0)) + offset, node_sharpness + at_sharpness,
                  node_amplitude, across);
    """
    out = glsl(["sg.glsl", "brdf.glsl", "warp.glsl"], body, inputs, 4)
    _assert_finite(out, "warp_split_frame / warp_split_node / warp_at")
    assert out[:, 1:3].min() >= 0 and out[:, 1].max() <= 2e6 * (1 + 1e-6)
    assert out[:, 3].min() >= 0.5 and out[:, 3].max() <= 1.0       # m = max(c, 1 - c), widened to 1 at most


def test_lights_helpers_stress(glsl):
    x, light, radius, intensity, rng = _light_inputs(SMALL_ROWS)
    sin2 = _f32(np.where(rng.integers(0, 4, SMALL_ROWS) == 0, 0.0, rng.uniform(0.0, 1.0, SMALL_ROWS)))
    inputs = {"x": np.c_[x, sin2], "l": np.c_[light, radius], "i": intensity}
    body = """
    float effective2; vec3 cap_axis;
    float cap = sphere_light_cap(x.xyz, l.xyz, l.w, effective2, cap_axis);
    float soft_effective2; vec3 soft_axis;
    cap += light_cap(x.xyz, l.xyz, l.w, true, soft_effective2, soft_axis);
    effective2 += soft_effective2;
    float cap_sharpness, cap_amplitude;
    light_cap_energy_lobe(x.w, blender_point_light_intensity(i.x * 12.566370614359172), cap_sharpness, cap_amplitude);
    vec3 axis; float sharpness, amplitude;
    point_light_sg(x.xyz, l.xyz, i.x, l.w, axis, sharpness, amplitude);
    result = vec4(cap + effective2 + dot(cap_axis + axis, vec3(1.0)), cap_sharpness + sharpness,
                  cap_amplitude + amplitude, light_cap_radius(sharpness) + light_cap_radius(x.w));
    """
    out = glsl(["sg.glsl", "lights.glsl"], body, inputs, 4)
    _assert_finite(out, "sphere_light_cap / light_cap_energy_lobe / point_light_sg / light_cap_radius")
    assert out[:, 1].min() > 0 and out[:, 2].min() >= 0
    assert out[:, 3].min() >= 0 and out[:, 3].max() <= np.pi + 1e-5       # two half-angles of at most pi / 2


def test_env_prefilter_helpers_stress(glsl, fuzz):
    axis = fuzz.stress_vectors(SMALL_ROWS)
    axis[:1000] = 0
    axis[1000:2000] = [0, 0, -1]
    axis[2000:3000] = [1, 0, 0]
    sharpness = _f32(10.0 ** fuzz.rng.uniform(-12, 9, SMALL_ROWS))   # test_stress_lighting's lookups
    sharpness[:500] = 0
    body = """
    vec2 coords = oct_encode(safe_normalize(p.xyz));
    vec2 raw = oct_encode(p.xyz);
    result = vec4(coords + raw + env_sign_not_zero(p.xy), env_prefilter_blend_parameter(p.w, -3.0, 2.0, 31), 0.0);
    """
    out = glsl(["sg.glsl", "env_prefilter.glsl"], body, {"p": np.c_[axis, sharpness]}, 3)
    _assert_finite(out, "oct_encode / env_sign_not_zero / env_prefilter_blend_parameter")
    assert out[:, 2].min() >= 0 and out[:, 2].max() <= 30


def _ssdf_basis(rng, resolution=8, terms=9):
    from sg_prt_addon.visibility import decode

    basis = np.asarray(rng.normal(size=(terms, resolution, resolution)) * 0.3, np.float32)
    mean = np.asarray(rng.uniform(-1.5, 1.5, (resolution, resolution)), np.float32)
    return decode.pack_basis_texture(mean, basis)


def test_ssdf_stress(glsl, fuzz):
    """Every function of ssdf.glsl: degenerate directions and normals (zero, tiny, huge, poles, the
    frame's reference axis), points on the disc's axes and centre, any sharpness and theta_d."""
    from sg_prt_addon.visibility import hemisphere_map

    x = _sg_inputs()
    count = len(x["sharpness"])
    direction = fuzz.stress_vectors(count)
    normal = fuzz.stress_vectors(count)
    normal[::17] = hemisphere_map.FRAME_REFERENCE_AXIS
    disc = fuzz.uniform(-1.0, 1.0, 2 * count).reshape(count, 2)
    disc[::5, 0] = 0.0
    disc[::7] = 0.0
    unit = direction / np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-300)
    coefficients = _f32(fuzz.rng.normal(size=(count, 12)))
    coefficients[:, 0] = 1.0
    inputs = {"d": np.c_[direction, x["sharpness"]], "n": np.c_[normal, x["theta_d"]], "u": np.c_[_f32(unit), np.zeros(count)],
              "q": np.c_[disc, x["amplitude1"], np.zeros(count)], "c0": coefficients[:, :4], "c1": coefficients[:, 4:8],
              "c2": coefficients[:, 8:]}
    body = """
    vec4 c[SSDF_MAX_LAYERS];
    c[0] = c0; c[1] = c1; c[2] = c2;
    vec3 t, b, unit_normal;
    ssdf_local_frame(n.xyz, t, b, unit_normal);
    vec3 local = ssdf_to_local(d.xyz, n.xyz);
    vec3 lookup = ssdf_horizon_lookup(u.xyz);
    vec2 square = hemisphere_map_disc_to_square(q.xy) + hemisphere_map_to_square(vec3(u.xy, abs(u.z)));
    float leading;
    float theta_d = ssdf_decode(ssdf_basis, c, 3, local) + 0.0 * ssdf_decode_leading(ssdf_basis, c, 3, 2, local, leading);
    result = vec4(dot(t + b + unit_normal + local + lookup, vec3(1.0)) + square.x + square.y + leading,
                  theta_d,
                  ssdf_visibility_amplitude(d.w, q.z, n.w) + ssdf_visibility_amplitude(d.w, q.z, theta_d),
                  ssdf_shadowed_integral(local, d.w, q.z, ssdf_basis, c, 3));
    """
    library = ["sg.glsl", "hemisphere.glsl", "hemisphere_map.glsl", "#define SSDF_MAX_LAYERS 3\n", "ssdf.glsl"]
    out = glsl(library, body, inputs, 4, textures={"ssdf_basis": _ssdf_basis(fuzz.rng)})
    _assert_finite(out, "ssdf.glsl")
    assert out[:, 2:].min() >= 0


def test_ssdf_quadrature_stress(glsl, fuzz):
    """ssdf_quadrature.glsl: every point index, signed distances of any size (theta_d's hostile set, the
    infinities), radii from tiny to wide, any sharpness."""
    from sg_prt_addon.techniques.sg import sg_lobes

    x = _sg_inputs()
    count = len(x["sharpness"])
    distance = np.array(x["theta_d"], np.float64)
    distance[::13] = np.inf
    distance[1::13] = -np.inf
    distance[2::13] = 3e38
    radius = fuzz.stress_sharpness(count) + 1e-30
    index = np.arange(count) % 64
    inputs = {"a": np.c_[distance, radius, x["sharpness"], index]}
    defines = "".join(f"#define {name} {value}\n" for name, value in sg_lobes.quadrature_defines().items())
    body = """
    vec3 point = ssdf_quadrature_point(int(a.w) % SSDF_QUADRATURE_POINTS);
    result = vec4(dot(point, vec3(1.0)), ssdf_cell_coverage(a.x, a.y), ssdf_quadrature_weight(a.z),
                  ssdf_cell_radius());
    """
    out = glsl(["sg.glsl", "hemisphere.glsl", defines, "ssdf_quadrature.glsl"], body, inputs, 4)
    _assert_finite(out, "ssdf_quadrature.glsl")
    assert out[:, 1:3].min() >= 0 and out[:, 1:3].max() <= 1


def test_numpy_suite_inputs_through_per_pixel_kernels(glsl):
    """The kernels the shaders call per pixel (fuzzed above with this file's generators) over the
    numpy suite's own hostile sets too: SG algebra, fh, clamped cosine, the split warp, M_o."""
    x = _sg_inputs()
    inputs = {"p1": np.c_[x["axis1"], x["sharpness"]], "p2": np.c_[x["axis2"], x["sharpness2"]],
              "n": np.c_[x["normal"], x["theta_d"]], "m": np.c_[x["amplitude1"], x["amplitude2"]]}
    body = """
    vec3 axis; float sharpness, amplitude;
    sg_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y, axis, sharpness, amplitude);
    vec3 axes[3]; float sharpnesses[3], amplitudes[3];
    warp_lobes_split3(p1.xyz, p1.w, m.x, n.xyz, axes, sharpnesses, amplitudes);
    float slice = 0.0;
    for (int j = 0; j < 3; j++) {
      slice += brdf_slice_amplitude(amplitudes[j], ggx_m_factor(n.xyz, axes[j], 0.5))
             * sg_clamped_cosine_integral(axes[j], sharpnesses[j], 1.0, p2.xyz);
    }
    result = vec4(sg_inner_product(p1.xyz, p1.w, m.x, p2.xyz, p2.w, m.y) + sg_evaluate(p2.xyz, p1.xyz, p1.w, m.x),
                  sg_clamped_cosine_integral(axis, sharpness, amplitude, n.xyz)
                  + sg_clamped_cosine_integral_paper(axis, sharpness, amplitude, n.xyz),
                  hemisphere_integral(p1.xyz, p1.w, m.x, n.xyz) + fh(n.w, p1.w)
                  + visibility_product_integral_preserving_amplitude(p1.w, m.x, n.w),
                  slice);
    """
    out = glsl(LIBRARY_ORDER, body, inputs, 4)
    _assert_finite(out, "per-pixel kernels over the numpy suite's SG inputs")
    assert out.min() >= 0
    wo, wi, h, roughness, exponent, _ = _brdf_inputs()
    inputs = {"wo": np.c_[wo, roughness], "wi": np.c_[wi, exponent], "h": h}
    body = """
    float r = wo.w, e = wi.w;
    result = vec4(ggx_m_factor(wo.xyz, wi.xyz, r) + cook_torrance_m_factor(wo.xyz, wi.xyz, r, 1.5)
                  + blinn_phong_m_factor(wo.xyz, wi.xyz, e) + ashikhmin_shirley_m_factor(wo.xyz, wi.xyz, e, e, 0.04),
                  ggx_ndf(h.xyz, r) + cook_torrance_ndf(h.xyz, r) + blinn_phong_ndf(h.xyz, e)
                  + ashikhmin_shirley_ndf(h.xyz, e, 1.0) + ward_anisotropic_ndf(h.xyz, r, 0.5),
                  ggx_ndf_lobe(r) + blinn_phong_ndf_lobe(e));
    """
    out = glsl(LIBRARY_ORDER, body, inputs, 4)
    _assert_finite(out, "BRDF kernels over the numpy suite's directions")
    assert out[:, :2].min() >= 0


# ---- shaders/techniques/sg: the per-pixel pieces that can be called alone

RESOURCE_KERNELS = {
    "../common/lobe_visibility.glsl": ["set_visibility_frame", "lobe_visibility", "light_cap_visibility"],
    "sg_models.glsl": ["model_ndf_lobe", "model_m_factor", "fitted_m_factor"],
    "sg_shading.glsl": ["probit", "visible_part_offset", "visible_part_narrowing", "lobe_visibility_side"],
    "../common/fitted_texels.glsl": ["fitted_layer", "fitted_select_texel", "fitted_node_theta", "fitted_node_value",
                                     "fitted_shadowing_at", "fitted_shadowing_of"],
    "anisotropic_lobes.glsl": ["anisotropic_lobes"],
    "ggx_two_lobes.glsl": ["ggx_two_lobes"],
    "../common/surface_common.glsl": ["shading_frame", "apply_normal_map", "rotate_tangent"],
    "../factored/factored_shading.glsl": ["parabolic_uv", "factored_brdf"],
    "../sh/sh_library.glsl": ["sh_basis", "sh_rotate_z", "sh_rotate", "sh_cap_factors", "sh_sg_factors",
                              "sh_zonal_sum"],
    "../sh/sh_shading.glsl": ["sh_parameter_coordinate", "sh_table_lookup", "sh_fitted_lookup", "sh_product"],
}
LIBRARY_ORDER = ["sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl", "brdf.glsl", "warp.glsl", "lights.glsl"]


def test_lobe_visibility_stress(glsl, fuzz):
    """lobe_visibility.glsl's lobe_visibility and light_cap_visibility after set_visibility_frame: any lobe or
    cap (radius zero to past pi), any normal and SSDF normal (zero, tiny, huge, opposite), random bake rows: a
    fraction in [0, 1]."""
    x = _sg_inputs()
    count = len(x["sharpness"])
    rows = _f32(fuzz.rng.normal(size=(count, 12)))
    rows[:, 0] = 1.0
    ssdf_normal = fuzz.stress_vectors(count)
    ssdf_normal[::3] = x["normal"][::3]
    source = _resource("lobe_visibility.glsl", "common")          # its globals, set_visibility_frame, lobe_visibility
    body = """
    visibility_rows[0] = c0; visibility_rows[1] = c1; visibility_rows[2] = c2;
    set_visibility_frame(s.xyz);
    result = vec4(lobe_visibility(p.xyz, p.w, n.xyz), light_cap_visibility(p.xyz, abs(n.w)), 0.0, 0.0);
    """
    library = LIBRARY_ORDER + ["hemisphere_map.glsl", "#define SSDF_MAX_LAYERS 3\n", "ssdf.glsl", source]
    radius = _f32(np.concatenate([[0.0, 1e-30, 1e-6, 4.0], fuzz.rng.uniform(0.0, 1.6, count - 4)]))
    inputs = {"p": np.c_[x["axis1"], x["sharpness"]], "n": np.c_[x["normal"], radius], "s": ssdf_normal,
              "c0": rows[:, :4], "c1": rows[:, 4:8], "c2": rows[:, 8:]}
    out = glsl(library, body, inputs, 2, textures={"visibility_basis": _ssdf_basis(fuzz.rng)})
    _assert_finite(out, "lobe_visibility / light_cap_visibility")
    assert out.min() >= 0 and out.max() <= 1


def test_visible_part_stress(glsl, fuzz):
    """sg_shading.glsl's visible-part lookup (VISIBLE_PART_LOOKUP): lobe_visibility_side after set_visibility_frame
    for any lobe, normal and SSDF normal, random bake rows -- a fraction in [0, 1] and a side of length 0 or 1
    perpendicular to a unit axis; probit, visible_part_offset and visible_part_narrowing for any fraction
    (0, tiny, 1, beyond) -- finite, the narrowing in [1, 2 / (1 + VISIBLE_PART_MIN_VARIANCE)], and the numpy
    mirror's within float32's reach."""
    from sg_prt_addon.techniques.sg import sg_lobes, sg_shading

    x = _sg_inputs()
    count = len(x["sharpness"])
    rows = _f32(fuzz.rng.normal(size=(count, 12)))
    rows[:, 0] = 1.0
    ssdf_normal = fuzz.stress_vectors(count)
    ssdf_normal[::3] = x["normal"][::3]
    fractions = _f32(np.concatenate([[0.0, 1e-30, 1e-6, 1e-4, 0.5, 1.0 - 1e-7, 1.0, 2.0, -1.0],
                                     fuzz.rng.uniform(0.0, 1.0, count - 9)]))
    shading = _resource("sg_shading.glsl")
    source = (sg_lobes._constants_source() + _resource("lobe_visibility.glsl", "common")
              + "".join(_glsl_function(shading, name) for name in ("probit", "truncated_moments", "visible_part_offset",
                                                                  "visible_part_narrowing", "lobe_visibility_side")))
    body = """
    visibility_rows[0] = c0; visibility_rows[1] = c1; visibility_rows[2] = c2;
    set_visibility_frame(s.xyz);
    vec3 axis = safe_normalize(p.xyz);
    vec3 side;
    float visible = lobe_visibility_side(axis, p.w, n.xyz, side);
    float v = n.w;
    result = vec4(visible, length(side) + abs(dot(side, axis)), visible_part_offset(v) + probit(clamp(v, 1e-4, 0.9999)),
                  visible_part_narrowing(v));
    """
    library = LIBRARY_ORDER + ["hemisphere_map.glsl", "#define SSDF_MAX_LAYERS 3\n", "ssdf.glsl", source]
    inputs = {"p": np.c_[x["axis1"], x["sharpness"]], "n": np.c_[x["normal"], fractions], "s": ssdf_normal,
              "c0": rows[:, :4], "c1": rows[:, 4:8], "c2": rows[:, 8:]}
    out = glsl(library, body, inputs, 4, textures={"visibility_basis": _ssdf_basis(fuzz.rng)})
    _assert_finite(out, "lobe_visibility_side / visible_part_offset / visible_part_narrowing")
    assert out[:, 0].min() >= 0 and out[:, 0].max() <= 1
    side = out[:, 1]
    assert np.all((side < 1e-6) | (np.abs(side - 1) < 1e-3)), "a side neither zero nor unit across the axis"
    assert ((side > 0.5) & (out[:, 0] < sg_shading.VISIBLE_SIDE_MAX_FRACTION)).mean() > 0.3   # the random rows occlude
    top = 2 / (1 + sg_shading.VISIBLE_PART_MIN_VARIANCE)
    assert out[:, 3].min() >= 1 - 1e-5 and out[:, 3].max() <= top + 1e-5
    expected = sg_shading.visible_part_offset(fractions) + sg_shading.probit(np.clip(fractions, 1e-4, 0.9999))
    np.testing.assert_allclose(out[:, 2], expected, rtol=2e-3, atol=2e-3)
    np.testing.assert_allclose(out[:, 3], sg_shading.visible_part_narrowing(fractions), rtol=2e-3)


def test_factored_brdf_stress(glsl, fuzz):
    """The factored BRDF's lookups (techniques/factored): any view and light (zero, tiny, huge, below the
    horizon, opposite), random log-factor maps: parabolic coordinates in [0, 1]^2, finite values, and the
    numpy mirror's within 1e-4."""
    from sg_prt_addon.techniques.homomorphic import factored_shading

    wo = fuzz.stress_vectors(SMALL_ROWS)
    wi = fuzz.stress_vectors(SMALL_ROWS)
    wi[::4] = -wo[::4]
    maps = {name: _f32(np.concatenate([fuzz.rng.normal(scale=0.7, size=shape + (3,)), np.zeros(shape + (1,))], -1))
            for name, shape in (("p", (16, 16)), ("q", (16, 16)), ("r", (1, 16)))}
    shading = _resource("factored_shading.glsl", "factored")
    source = ("#define FACTOR_P_LIGHT 1\n#define FACTOR_R 1\nconst vec4 factor_scale = vec4(1.0);\n"
              + "".join(_glsl_function(shading, name) for name in ("parabolic_uv", "factored_brdf")))
    body = """
    vec2 uv_o = parabolic_uv(wo.xyz);
    result = vec4(factored_brdf(wo.xyz, wi.xyz), min(min(uv_o.x, uv_o.y), 1.0 - max(uv_o.x, uv_o.y)));
    """
    out = glsl(["sg.glsl", source], body, {"wo": wo, "wi": wi}, 4,
               textures={"factor_p": maps["p"], "factor_q": maps["q"], "factor_r": maps["r"]})
    _assert_finite(out, "factored_brdf")
    assert out[:, 3].min() >= 0.0, "parabolic coordinates outside [0, 1]"
    # the mirror on ordinary inputs: unit-ish lengths, away from the horizon and from o = -i (h undefined)
    def unit(v):
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    with np.errstate(all="ignore"):
        lengths = np.stack([np.linalg.norm(wo, axis=1), np.linalg.norm(wi, axis=1)], 1)
        h = unit(unit(wo) + unit(wi))
        finite = np.all((lengths > 1e-3) & (lengths < 1e3), axis=1) & (np.linalg.norm(unit(wo) + unit(wi), axis=1) > 1e-2) \
            & (np.abs(unit(wo)[:, 2]) > 1e-3) & (np.abs(unit(wi)[:, 2]) > 1e-3) & (np.abs(h[:, 2]) > 1e-3)
    assert finite.mean() > 0.15          # the stress vectors are mostly extreme by design
    expected = factored_shading.factored_brdf(maps, "pqpr", wo[finite], wi[finite])[:, :3]
    np.testing.assert_allclose(out[finite][:, :3], expected, rtol=1e-4)

def _sh_weights(count, seed):
    return np.random.default_rng(seed).uniform(-1, 1, count)


def test_sh_library_stress(glsl, fuzz):
    """The SH technique's library (shaders/techniques/sh/sh_library.glsl, order 8, with its generated x90
    blocks): sh_basis at any direction the shader gives it (safe_normalize of zero, tiny, huge vectors),
    sh_rotate (with sh_rotate_z) by random frames and the Euler angles' singular ones (beta 0 and pi, the
    identity), sh_cap_factors for 1 - cos 0..2 and beyond, sh_sg_factors for sharpness 0..1e9 and
    sh_zonal_sum at cosines beyond [-1, 1]: finite; the numpy mirrors within 2e-5 of the sums' scale."""
    from scipy.spatial.transform import Rotation

    from sg_prt_addon.harmonics import basis, projection, rotation
    from sg_prt_addon.techniques.sh import sh_glsl

    order, count = 8, SMALL_ROWS // 8
    d = fuzz.stress_vectors(count)
    frames = Rotation.random(count, random_state=3).as_matrix()
    frames[::7] = np.eye(3)
    frames[1::7] = rotation.axis_rotation(2, 0.4)
    frames[2::7] = rotation.axis_rotation(0, np.pi) @ rotation.axis_rotation(2, 1.3)
    frames = _f32(frames)
    epsilon = _f32(np.concatenate([fuzz.log_uniform(1e-9, 2.0, count - 4), [0.0, 1e-3, 2.0, 3.0]]))
    sharpness = _f32(np.concatenate([fuzz.log_uniform(1e-6, 1e9, count - 3), [0.0, 10.0, 1e30]]))
    cosine = _f32(fuzz.rng.uniform(-1.5, 1.5, count))
    w1, w2, c = _sh_weights(order * order, 1), _sh_weights(order * order, 2), _sh_weights(order * order, 3)
    g_weights = _sh_weights(order, 4)

    def constants(name, values):
        return f"const float {name}[{len(values)}] = float[](" + ", ".join(f"{v:.9e}" for v in values) + ");\n"

    source = (sh_glsl.constants_source(order, None) + _resource("sh_library.glsl", "sh")
              + constants("W1", w1) + constants("W2", w2) + constants("C", c) + constants("GW", g_weights))
    body = """
    float y[SH_COUNT];
    sh_basis(safe_normalize(d.xyz, vec3(0.0, 0.0, 1.0)), y);
    float turned[SH_COUNT];
    for (int i = 0; i < SH_COUNT; i++) { turned[i] = C[i]; }
    sh_rotate(turned, mat3(c0.xyz, c1.xyz, c2.xyz));
    float g[SH_ORDER];
    float s[SH_ORDER];
    sh_cap_factors(e.x, g);
    sh_sg_factors(e.y, s);
    float zonal = sh_zonal_sum(GW, e.z);
    float spun[SH_COUNT];
    for (int i = 0; i < SH_COUNT; i++) { spun[i] = C[i]; }
    sh_rotate_z(spun, 3.0 * e.z);
    float z = 0.0;
    for (int i = 0; i < SH_COUNT; i++) { z += W1[i] * spun[i]; }
    float a = 0.0, b = 0.0, u = 0.0, v = 0.0, gc = 0.0, gs = 0.0;
    for (int i = 0; i < SH_COUNT; i++) { a += W1[i] * y[i]; b += W2[i] * y[i]; u += W1[i] * turned[i]; v += W2[i] * turned[i]; }
    for (int l = 0; l < SH_ORDER; l++) { gc += GW[l] * g[l]; gs += GW[l] * s[l]; }
    result = row % 2 == 0 ? vec4(a, b, u, v) : vec4(gc, gs, zonal, z);
    """
    inputs = {"d": d, "c0": frames[:, :, 0], "c1": frames[:, :, 1], "c2": frames[:, :, 2],
              "e": np.c_[epsilon, sharpness, cosine]}
    out = glsl(["sg.glsl", source], body, inputs, 4)
    _assert_finite(out, "SH library")
    even, odd = slice(0, None, 2), slice(1, None, 2)
    with np.errstate(all="ignore"):
        length = np.linalg.norm(d, axis=1, keepdims=True)
        unit = np.where((length > 0) & np.isfinite(length), d / length, [[0.0, 0.0, 1.0]])
    y = basis.evaluate(unit[even], order)
    turned = rotation.rotate_zyz_many(np.broadcast_to(c, (len(frames[even]), order * order)), frames[even])
    expected = np.stack([y @ w1, y @ w2, turned @ w1, turned @ w2], -1)
    scale = np.sum(np.abs(w1)) * 2.0
    ordinary = (length[even, 0] > 1e-20) & (length[even, 0] < 1e20)
    np.testing.assert_allclose(out[even][ordinary], expected[ordinary], atol=2e-5 * scale)
    np.testing.assert_allclose(out[even][:, 2:], expected[:, 2:], atol=2e-5 * scale)
    cap = projection.cap_factors(np.minimum(epsilon[odd], 2.0), order) @ g_weights
    sg_expected = projection.sg_factors(np.minimum(sharpness[odd], 1e30), order) @ g_weights
    bands = np.arange(order)
    p = np.stack(projection.legendre_polynomials(cosine[odd], order - 1)[:order], -1)
    zonal = p @ (g_weights * (2 * bands + 1) / (4 * np.pi))
    inside = epsilon[odd] <= 2.0                     # beyond a hemisphere's 1 - cos = 2 no cap exists
    np.testing.assert_allclose(out[odd][inside, 0], cap[inside], atol=2e-5 * np.sum(np.abs(g_weights)))
    np.testing.assert_allclose(out[odd][:, 1], sg_expected, atol=2e-5 * np.sum(np.abs(g_weights)))
    np.testing.assert_allclose(out[odd][:, 2], zonal, atol=2e-5 * np.max(np.abs(zonal)))
    spun = rotation.rotate_z_many(np.broadcast_to(c, (len(cosine[odd]), order * order)), 3.0 * cosine[odd]) @ w1
    np.testing.assert_allclose(out[odd][:, 3], spun, atol=2e-5 * scale)


def test_sh_table_lookup_stress(glsl, fuzz):
    """sh_table_lookup and sh_parameter_coordinate (sh_shading.glsl) on any view (zero, tiny, huge, below
    the horizon) and parameter (0, negative, beyond the axis, NaN-free huge values), both layouts: finite,
    and the mirror's lookup within 1e-5 of the table's scale on ordinary inputs."""
    from sg_prt_addon.harmonics import brdf_table
    from sg_prt_addon.techniques.sh import sh_glsl, sh_shading, spherical_harmonics

    count = SMALL_ROWS // 4
    o = fuzz.stress_vectors(count)
    parameter = _f32(np.concatenate([fuzz.rng.uniform(-0.5, 1.5, count - 4), [0.0, -1.0, 1e30, 1e-30]]))
    shading = _resource("sh_shading.glsl", "sh")
    weights = _sh_weights(25, 5)
    for model, params in (("GGX", {}), ("ASHIKHMIN_SHIRLEY", {"nu": 20.0, "nv": 200.0})):
        table = brdf_table.table_for(model, order=5, resolution=16 if model != "GGX" else None, **params)
        isotropic = table.layout == "theta"
        axis = spherical_harmonics.axis_constants(table)
        source = ("#define SH_ISOTROPIC 1\n" if isotropic else "") + sh_glsl.constants_source(5, None) \
            + f"const vec4 sh_axis = vec4({', '.join(f'{v:.9e}' for v in axis)});\n" \
            + "const float W[25] = float[](" + ", ".join(f"{v:.9e}" for v in weights) + ");\n" \
            + "".join(_glsl_function(shading, name) for name in ("sh_parameter_coordinate", "sh_table_lookup"))
        body = """
        float c[SH_COUNT];
        float p = sh_parameter_coordinate(q.x);
        sh_table_lookup(o.xyz, p, c);
        float a = 0.0;
        for (int i = 0; i < SH_COUNT; i++) { a += W[i] * c[i]; }
        result = vec4(a, p, c[0], c[6]);
        """
        out = glsl(["sg.glsl", source], body, {"o": o, "q": parameter}, 4,
                   textures={"sh_table": brdf_table.texture_layers(table)})
        _assert_finite(out, f"sh_table_lookup {model}")
        assert out[:, 1].min() >= 0 and out[:, 1].max() <= 1
        with np.errstate(all="ignore"):
            length = np.linalg.norm(o, axis=1)
        ordinary = (length > 1e-3) & (length < 1e3)
        expected = sh_shading._table_coefficients(table, (o[ordinary] / length[ordinary, None]).astype(np.float32),
                                                  np.clip(parameter[ordinary], 0.0, 1e3))
        scale = np.abs(table.coefficients).max()
        np.testing.assert_allclose(out[ordinary, 0], expected @ weights, atol=1e-5 * scale * np.abs(weights).sum())
        np.testing.assert_allclose(out[ordinary, 2], expected[:, 0], atol=1e-5 * scale)


def test_sh_fitted_product_stress(glsl, fuzz):
    """sh_product of a lobe fit's table (SH_FITTED, sh_shading.glsl: sh_fitted_lookup of each lobe, rotated,
    weighed by its colour and S(o) / (pi o.z)) with random layers and table, any UV (outside [0, 1] too), any
    view (zero, tiny, huge, below the horizon: normalized as shade_sh's is) and random frames: finite, and the
    mirror's (sh_shading._product) within 1e-5 of the sums' scale where o.z > 0.05."""
    from scipy.spatial.transform import Rotation

    from sg_prt_addon.blender.export import FittedLobes
    from sg_prt_addon.harmonics import fitted_table
    from sg_prt_addon.techniques.sg import fitted_texels
    from sg_prt_addon.techniques.sh import sh_glsl, sh_shading

    order, lobes, components, views, count = 5, 2, 5, 16, SMALL_ROWS // 8
    rng = fuzz.rng
    layers = _f32(rng.normal(size=(1 + 2 * lobes + 2, 8, 8, 4)))
    table = np.zeros((components + 2, 16, 4), np.float32)
    table[0, :, 0] = np.linspace(0.0, 1.4, 16)
    table[1, :, 0] = np.linspace(1.0, 0.2, 16)
    table[2:, :, 0] = rng.normal(size=(components, 16)) * 0.1
    fitted = FittedLobes(lobes, components, layers, table)
    stored = len(fitted_table.positive_m_indices(order))
    sh_table = fitted_table.FittedTable(order, (8, 8), _f32(rng.normal(size=(64, lobes, views, stored))))
    o = fuzz.stress_vectors(count)
    frames = _f32(Rotation.random(count, random_state=5).as_matrix())
    uv = _f32(rng.uniform(-0.5, 1.5, (count, 2)))
    theta = _f32(rng.uniform(-0.2, 1.8, count))
    weights = _sh_weights(order * order, 6)
    shading = _resource("sh_shading.glsl", "sh")
    source = (f"#define SH_FITTED 1\n#define SH_VALUE vec3\n#define FITTED_LOBES {lobes}\n"
              f"#define FITTED_COMPONENTS {components}\n#define FITTED_SHADOWING_LAYERS 2\n"
              + sh_glsl.constants_source(order, None) + _resource("sh_library.glsl", "sh")
              + _resource("fitted_texels.glsl", "common")
              + "const float W[SH_COUNT] = float[](" + ", ".join(f"{v:.9e}" for v in weights) + ");\n"
              + "".join(_glsl_function(shading, name) for name in ("sh_fitted_lookup", "sh_product")))
    body = """
    fitted_select_texel(t.xy);
    vec3 c[SH_COUNT];
    sh_product(safe_normalize(o.xyz), 0.0, mat3(c0.xyz, c1.xyz, c2.xyz), c);
    float lobe[SH_COUNT];
    sh_fitted_lookup(t.z, 1, lobe);
    vec3 a = vec3(0.0);
    float b = 0.0;
    for (int i = 0; i < SH_COUNT; i++) { a += W[i] * c[i]; b += W[i] * lobe[i]; }
    result = vec4(a, b);
    """
    inputs = {"t": np.c_[uv, theta], "o": o, "c0": frames[:, :, 0], "c1": frames[:, :, 1], "c2": frames[:, :, 2]}
    out = glsl(["sg.glsl", source], body, inputs, 4,
               textures={"sh_table": fitted_table.texture_layers(sh_table), "fitted_layers": layers,
                         "fitted_shadowing": table})
    _assert_finite(out, "sh_product (SH_FITTED)")
    texels = fitted_texels.texel_indices(fitted, uv)
    scale = np.abs(sh_table.coefficients).max() * np.abs(weights).sum()
    looked_up = fitted_table.lookup(sh_table, texels, theta)[:, 1] @ weights
    np.testing.assert_allclose(out[:, 3], looked_up, atol=1e-5 * scale)
    with np.errstate(all="ignore"):
        length = np.linalg.norm(o, axis=1)
        unit = _f32(o / length[:, None])
    ordinary = (length > 1e-3) & (length < 1e3) & (unit[:, 2] > 0.05)
    values, _ = fitted_texels.fitted_texel_values(fitted, uv[ordinary])
    expected = np.einsum("nic,i->nc", sh_shading._product(sh_table, unit[ordinary], frames[ordinary],
                                                          (texels[ordinary], values)), weights)
    colour_scale = np.abs(layers[2::2, ..., :3]).max() * 20 / np.pi       # S <= 1.2 here, o.z > 0.05
    np.testing.assert_allclose(out[ordinary, :3], expected, atol=1e-5 * scale * colour_scale)


def test_shading_frame_stress(glsl, fuzz):
    """shading_frame, apply_normal_map and rotate_tangent with zero / parallel / huge tangents, zero
    normals, any normal-map sample (also outside [0, 1]) and strength 0..10."""
    normal = fuzz.stress_vectors(SMALL_ROWS)
    tangent = fuzz.stress_vectors(SMALL_ROWS)
    parallel = fuzz.rng.integers(0, 8, SMALL_ROWS) == 0
    tangent[parallel] = normal[parallel] * 3.0
    sign = np.where(fuzz.rng.integers(0, 2, SMALL_ROWS) == 0, -1.0, 1.0)
    sample = fuzz.uniform(-1.0, 2.0, 3 * SMALL_ROWS).reshape(-1, 3)
    sample[::5] = 0.5                                   # maps to the zero vector
    strength = fuzz.uniform(0.0, 10.0, SMALL_ROWS)
    rotation = fuzz.uniform(-100.0, 100.0, SMALL_ROWS)
    shading = _resource("surface_common.glsl", "common")
    source = "".join(_glsl_function(shading, name) for name in ("shading_frame", "apply_normal_map", "rotate_tangent"))
    body = """
    vec3 n, t, b;
    shading_frame(n_in.xyz, t_in.xyz, n, t, b);
    vec3 mapped = apply_normal_map(n_in.xyz, vec4(t_in.xyz, t_in.w), m.xyz, m.w);
    vec3 rotated = rotate_tangent(n_in.xyz, t_in.xyz, n_in.w);
    result = vec4(length(n) + length(t) + length(b), length(mapped), length(rotated), abs(dot(n, t)));
    """
    inputs = {"n_in": np.c_[normal, rotation], "t_in": np.c_[tangent, sign], "m": np.c_[sample, strength]}
    out = glsl(["sg.glsl", source], body, inputs, 4)
    _assert_finite(out, "shading_frame / apply_normal_map / rotate_tangent")
    np.testing.assert_allclose(out[:, 1], 1.0, atol=1e-5)
    assert out[:, 2].max() <= 1 + 1e-5
    # orthonormal everywhere, tangents parallel to the normal included (they take the fallback)
    np.testing.assert_allclose(out[:, :3], np.broadcast_to([3.0, 1.0, 1.0], out[:, :3].shape), atol=1e-4)
    assert out[:, 3].max() < 1e-5, out[parallel, 3].max()


MODEL_VARIANTS = [("GGX", 1), ("GGX", 2), ("COOK_TORRANCE", 1), ("BLINN_PHONG", 1), ("WARD_ISO", 1),
                  ("WARD_ANISO", 3), ("ASHIKHMIN_SHIRLEY", 3), ("GGX_ANISO", 1), ("GGX_ANISO", 4), ("BECKMANN", 1)]


@pytest.mark.parametrize("model,lobes", MODEL_VARIANTS, ids=[f"{m}-{k}" for m, k in MODEL_VARIANTS])
def test_model_lobes_stress(glsl, model, lobes):
    """sg_models.glsl's model_ndf_lobe (through ggx_two_lobes / anisotropic_lobes and their tables)
    and model_m_factor, per model, over the numpy suite's parameters (0 included) and directions."""
    import types

    from sg_prt_addon.techniques.sg import sg_parametric

    wo, wi, h, roughness, exponent, rng = _brdf_inputs()
    alpha_y = _f32(np.where(rng.integers(0, 8, SMALL_ROWS) == 0, 0.0, np.exp(rng.uniform(np.log(1e-4), 0.0, SMALL_ROWS))))
    nv = _f32(np.exp(rng.uniform(np.log(1e-2), np.log(1e8), SMALL_ROWS)))
    rf0 = _f32(rng.uniform(0.0, 1.0, SMALL_ROWS))
    ior = _f32(rng.uniform(0.0, 4.0, SMALL_ROWS))
    # p = (roughness, ior, exponent, alpha_x), q = (alpha_y, nu, nv, rf0)
    inputs = {"p": np.c_[roughness, ior, exponent, roughness], "q": np.c_[alpha_y, exponent, nv, rf0],
              "wo": wo, "wi": wi}
    shading = _resource("sg_models.glsl")
    defines = f"#define MODEL_{model} 1\n#define NDF_LOBES {lobes}\n"
    pieces = [defines]
    textures = {}
    if lobes >= 2 and model == "GGX":      # GGX's two lobes
        pieces.append(_resource("ggx_two_lobes.glsl"))
        textures["ggx_table"] = sg_parametric.ggx_table()
    if model in ("WARD_ANISO", "ASHIKHMIN_SHIRLEY", "GGX_ANISO"):
        # the table and defines the engine binds for this model and count (what a variant key's model and lobes
        # decide)
        key = types.SimpleNamespace(model=model, ndf_lobes=lobes, has_specular=True)
        pieces[0] += "".join(f"#define {name} {value}\n"
                             for name, value in sg_parametric.TECHNIQUE.model_defines(key).items()
                             if name.startswith("GGX_ANISOTROPY"))
        pieces.append(_resource("anisotropic_lobes.glsl"))
        textures["anisotropy_table"] = sg_parametric.anisotropy_table_texture(key)
    pieces += [_glsl_function(shading, "model_ndf_lobe"), _glsl_function(shading, "model_m_factor")]
    body = """
    vec3 axis_sum = vec3(0.0);
    float sharpness_sum = 0.0, amplitude_sum = 0.0;
    for (int k = 0; k < NDF_LOBES; k++) {
      vec3 axis; float sharpness, amplitude;
      model_ndf_lobe(p, q, k, axis, sharpness, amplitude);
      axis_sum += axis; sharpness_sum += sharpness; amplitude_sum += amplitude;
    }
    result = vec4(dot(axis_sum, vec3(1.0)), sharpness_sum, amplitude_sum, model_m_factor(wo.xyz, wi.xyz, p, q));
    """
    out = glsl(LIBRARY_ORDER + pieces, body, inputs, 4, textures)
    _assert_finite(out, f"model_ndf_lobe / model_m_factor ({model}, {lobes} lobes)")
    assert out[:, 1:].min() >= 0


def test_table_lobes_stress(glsl, fuzz):
    """ggx_two_lobes, anisotropic_lobes and ggx_anisotropic_lobes called alone: roughness / widths 0..1e3, any
    peak."""
    import types

    from sg_prt_addon.reflectance import ndf_fit
    from sg_prt_addon.techniques.sg import sg_parametric

    roughness = _f32(np.where(fuzz.rng.integers(0, 8, SMALL_ROWS) == 0, 0.0, fuzz.log_uniform(1e-6, 10.0, SMALL_ROWS)))
    width_x = _f32(np.where(fuzz.rng.integers(0, 8, SMALL_ROWS) == 0, 0.0, fuzz.log_uniform(1e-6, 1e3, SMALL_ROWS)))
    width_y = _f32(np.where(fuzz.rng.integers(0, 8, SMALL_ROWS) == 0, 0.0, fuzz.log_uniform(1e-6, 1e3, SMALL_ROWS)))
    peak = fuzz.stress_amplitude(SMALL_ROWS)
    body = """
    float s0, a0, s1, a1;
    ggx_two_lobes(ggx_table, a.x, 0, s0, a0);
    ggx_two_lobes(ggx_table, a.x, 1, s1, a1);
    vec3 axis; float sharpness, amplitude;
    anisotropic_lobes(anisotropy_table, a.y, a.z, a.w, 1, axis, sharpness, amplitude);
    vec3 ggx_axis; float ggx_sharpness, ggx_amplitude;
    ggx_anisotropic_lobes(ggx_anisotropy_table, a.y, a.z, 1, ggx_axis, ggx_sharpness, ggx_amplitude);
    result = vec4(s0 + s1, a0 + a1, sharpness + amplitude + ggx_sharpness + ggx_amplitude,
                  length(axis) + length(ggx_axis));
    """
    defines = "".join(f"#define {name} {value}\n" for name, value in sg_parametric.TECHNIQUE.model_defines(
        types.SimpleNamespace(model="GGX_ANISO", ndf_lobes=2, has_specular=False)).items())
    library = ["sg.glsl", "brdf.glsl", _resource("ggx_two_lobes.glsl"), defines, _resource("anisotropic_lobes.glsl")]
    ggx_key = types.SimpleNamespace(model="GGX_ANISO", ndf_lobes=2)
    out = glsl(library, body, {"a": np.c_[roughness, width_x, width_y, peak]}, 4,
               {"ggx_table": sg_parametric.ggx_table(), "anisotropy_table": ndf_fit.anisotropy_table_array(2),
                "ggx_anisotropy_table": sg_parametric.anisotropy_table_texture(ggx_key)})
    _assert_finite(out, "ggx_two_lobes / anisotropic_lobes / ggx_anisotropic_lobes")
    assert out[:, :3].min() >= 0 and np.abs(out[:, 3] - 2).max() < 2e-5


def test_fitted_pieces_stress(glsl, fuzz):
    """common/fitted_texels.glsl and sg_models.glsl's fitted_m_factor with a random 2-lobe, 5-component fit (shadowing nodes
    stopping short of the horizon, so the appended S(pi/2) = 0 node is used): any UV (outside [0, 1]
    too), the numpy suite's directions, eta 0..4."""
    wo, wi, _, _, _, rng = _brdf_inputs()
    lobes, components, nodes = 2, 5, 16
    shadowing_layers = -(-components // 4)
    layers = rng.normal(size=(1 + 2 * lobes + shadowing_layers, 8, 8, 4)).astype(np.float32)
    table = np.zeros((components + 2, nodes, 4), np.float32)
    table[0, :, 0] = np.linspace(0.0, 1.4, nodes)
    table[1, :, 0] = np.linspace(1.0, 0.2, nodes)
    table[2:, :, 0] = rng.normal(size=(components, nodes)) * 0.1
    uv = _f32(rng.uniform(-0.5, 1.5, (SMALL_ROWS, 2)))
    eta = _f32(rng.uniform(0.0, 4.0, SMALL_ROWS))
    source = (f"#define NDF_LOBES {lobes}\n#define FITTED_LOBES {lobes}\n#define FITTED_COMPONENTS {components}\n"
              f"#define FITTED_SHADOWING_LAYERS {shadowing_layers}\n" + _resource("fitted_texels.glsl", "common")
              + _glsl_function(_resource("sg_models.glsl"), "fitted_m_factor"))
    body = """
    fitted_select_texel(t.xy);
    vec4 lobe = fitted_layer(1);
    float s_o = fitted_shadowing_of(wo.xyz);
    float theta = t.z * 2.0;
    result = vec4(fitted_m_factor(wo.xyz, wi.xyz, t.w, s_o), fitted_shadowing_at(theta) + s_o,
                  fitted_node_theta(nodes_count(), nodes_count()) + fitted_node_value(3, nodes_count()),
                  dot(lobe, vec4(1.0)));
    """.replace("nodes_count()", str(nodes))
    inputs = {"t": np.c_[uv, _f32(rng.uniform(-1.0, 2.0, SMALL_ROWS)), eta], "wo": wo, "wi": wi}
    out = glsl(["sg.glsl", "brdf.glsl", source], body, inputs, 4,
               {"fitted_layers": layers, "fitted_shadowing": table})
    _assert_finite(out, "fitted_* (MODEL_FITTED)")
    assert out[:, :3].min() >= 0


def _shadow_atlas(light_data):
    """(plan, depths, RGBA atlas with the depth in r) of validation.shadow_map_scene's blocker for `light_data`."""
    from sg_prt_addon.lighting import shadow_maps
    from validation import shadow_map_scene

    shadow_plan = shadow_maps.plan(light_data, shadow_map_scene.BOUNDS, 256)
    depth = shadow_map_scene.draw_atlas(shadow_plan)
    return shadow_plan, depth, np.repeat(depth[..., None], 4, axis=-1)


def test_shadow_maps_stress(glsl, fuzz):
    """shadow_maps.glsl on a ray-cast atlas (validation/shadow_map_scene.py), a point light of radius 0.1 and a sun
    of 0.02 rad: on the floor and blocker around the shadow, GLSL against the numpy mirror
    (lighting.shadow_maps.light_visibility), (fraction, softness) within 1e-4 but where float32 and float64 could
    round a depth comparison or a texel apart (allowed on 1% of the points, measured none of 131072); with hostile
    positions and
    normals (zero, huge, NaN-free extremes) finite and in [0, 1].  The two entry points run the rest:
    shadow_tile_visibility(), shadow_fetch(), shadow_linear(), shadow_window() and shadow_penumbra()."""
    from sg_prt_addon.lighting import shadow_maps
    from sg_prt_addon.techniques import shader_sources
    from validation import shadow_map_scene

    rng = fuzz.rng
    count = SMALL_ROWS
    position = _f32(np.c_[rng.uniform(-3.0, 3.0, (count, 2)), rng.choice([0.0, 2.0, 1.0], count)])
    normal = _f32(np.tile([0.0, 0.0, 1.0], (count, 1)))
    hostile = fuzz.stress_vectors(count)
    library = [shader_sources.shadow_map_constants(), "shadow_maps.glsl"]
    for light_data, call in ((shadow_map_scene.lights(radius=0.1),
                          "vec4(shadow_point_visibility(shadow_atlas, a, l.xyz, l.w, int(t.x), t.yz, p.xyz, n.xyz), "
                          "0.0, 0.0)"),
                         (shadow_map_scene.lights(sun_radius=0.02),
                          "vec4(shadow_sun_visibility(shadow_atlas, a, rx, ry, rz, int(t.x), t.y, t.z, t.w, p.xyz, "
                          "n.xyz), 0.0, 0.0)")):
        shadow_plan, depth, atlas = _shadow_atlas(light_data)
        constant = {"a": [shadow_plan.size, shadow_plan.columns, shadow_plan.inner, len(shadow_plan.slot_lights)]}
        if len(light_data.point_radius):
            constant["l"] = list(light_data.point_position[0]) + [float(light_data.point_radius[0])]
            constant["t"] = [shadow_plan.point_first_tile[0], *shadow_plan.point_near_far[0], 0.0]
        else:
            constant["rx"], constant["ry"], constant["rz"] = (list(row) for row in shadow_plan.sun_rows[0])
            constant["t"] = [shadow_plan.sun_tile[0], shadow_plan.sun_texel[0], shadow_plan.sun_range[0],
                             np.tan(float(light_data.sun_radius[0]))]
        rows = {name: _f32(np.tile(np.asarray(value, np.float64), (count, 1))) for name, value in constant.items()}
        out = glsl(library, call, dict(rows, p=position, n=normal), 2, {"shadow_atlas": atlas})
        expected = shadow_maps.light_visibility(depth, shadow_plan, light_data, position, normal)[:, 0]
        differs = np.any(np.abs(out - expected) > 1e-4, axis=1)
        print(f"{call[:30]}: shadowed {float((expected[:, 0] < 0.5).mean()):.3f}, differing {differs.mean():.4%}")
        assert (expected[:, 0] < 0.5).mean() > 0.05 and differs.mean() < 0.01
        hostile_out = glsl(library, call, dict(rows, p=hostile * 3.0, n=hostile[::-1]), 2, {"shadow_atlas": atlas})
        _assert_finite(hostile_out, "shadow_maps.glsl")
        assert hostile_out.min() >= 0.0 and hostile_out.max() <= 1.0


# ---- node_functions.glsl: a node tree's computed values

NODE_ROWS = 1 << 16
NODE_MATH = ["divide", "power", "logarithm", "sqrt", "inverse_sqrt", "absolute", "exponent", "minimum", "maximum",
             "less_than", "greater_than", "sign", "compare", "smooth_min", "smooth_max", "round", "floor", "ceil", "trunc",
             "fract", "modulo", "floored_modulo", "wrap", "snap", "pingpong", "sine", "cosine", "tangent", "sinh", "cosh",
             "tanh", "arcsine", "arccosine", "arctangent", "arctan2", "radians", "degrees"]
NODE_MIX = ["screen", "overlay", "divide", "difference", "exclusion", "darken", "lighten", "dodge", "burn", "soft_light",
            "linear_light", "hue", "saturation", "value", "color"]
NODE_VECTOR = ["cross_product", "project", "reflect", "dot_product", "distance", "length", "normalize"]


def _node_inputs(fuzz, count):
    """Inputs of the node functions: values over [-30, 30] with zeros, tiny, integer and half values, (count, 4)."""
    x = fuzz.rng.uniform(-30.0, 30.0, (count, 4))
    kind = fuzz.rng.integers(0, 6, (count, 4))
    x = np.where(kind == 0, 0.0, np.where(kind == 1, 1e-30, np.where(kind == 2, np.round(x),
                                                                      np.where(kind == 3, np.round(x) + 0.5, x))))
    return _f32(x)


def test_node_functions_stress(glsl, fuzz):
    """Every kernel of node_functions.glsl over values of +-30, zeros and tiny ones: finite wherever its numpy
    twin (reflectance/node_functions.py) is (exp(30) is, 30^30 is not)."""
    from sg_prt_addon.reflectance import node_functions
    from sg_prt_addon.techniques import material_textures

    library = [material_textures.noise_offsets_source(), "node_functions.glsl"]
    a, b, c = (_node_inputs(fuzz, NODE_ROWS) for _ in range(3))
    inputs = {"a": a, "b": b, "c": c}

    def check(call, expected):
        out = glsl(library, f"vec4({call}, 0.0)", inputs, 3)
        finite = np.isfinite(np.asarray(expected, np.float64))
        assert np.isfinite(out[finite]).all(), call

    for operation in NODE_MATH:
        check(f"node_math_{operation}(a.xyz, b.xyz, c.xyz)", node_functions.math(operation.upper(), a[:, :3], b[:, :3],
                                                                                c[:, :3]))
    t = np.clip(np.abs(c[:, :3]) / 30.0, 0.0, 1.0)
    inputs["t"] = _f32(np.c_[t, np.zeros(NODE_ROWS)])
    for blend in NODE_MIX:
        check(f"node_mix_{blend}(t.xyz, a.xyz, b.xyz)", node_functions.mix(blend.upper(), t, a[:, :3], b[:, :3]))
    for operation in NODE_VECTOR:
        check(f"node_vector_{operation}(a.xyz, b.xyz)", node_functions.vector_math(operation.upper(), a[:, :3], b[:, :3]))
    everything = np.zeros((NODE_ROWS, 3))            # the rest: finite on finite inputs
    for call in ("node_clamp(a.xyz, b.xyz, c.xyz)", "node_clamp_range(a.xyz, b.xyz, c.xyz)",
                 "node_map_range(a.xyz, b.xyz, c.xyz, a.zxy, b.zxy, abs(c.zxy), 1, true)",
                 "node_map_range(a.xyz, b.xyz, c.xyz, a.zxy, b.zxy, c.zxy, 3, false)",
                 "node_hue_saturation_value(abs(a.xyz), b.xxx, abs(c.yyy), abs(a.www), t.xxx)",
                 "node_hsv_to_rgb(node_rgb_to_hsv(abs(a.xyz)))", "node_gamma(a.xyz, t.xyz * 4.0)",
                 "node_brightness_contrast(a.xyz, b.xyz, c.xyz)", "node_safe_divide(a.xyz, b.xyz)",
                 "vec3(node_signed_pow(a.x, round(t.x * 8.0)), node_smooth_min(a.xyz, b.xyz, c.xyz).xy)",
                 "node_mapping(a.xyz, b.xyz, c.xyz, a.wzy, 1)", "node_mapping(a.xyz, b.xyz, c.xyz, a.wzy, 3)",
                 "node_euler_matrix(c.xyz) * node_safe_normalize(a.xyz)",
                 "node_tex_checker(a.xyz, b.xyz, c.xyz, t.xyz * 5.0, true)", "node_tex_gradient(a.xyz * 0.1, 4)",
                 "vec3(float(node_hash_uint3(uint(a.x), uint(b.x), node_rot(uint(abs(c.x)), 7u)) >> 8u), "
                 "node_fade(t.x), node_grad3(uint(abs(a.y)), a.x, b.x, c.x))",
                 "vec3(node_perlin_3d(a.xyz), node_snoise_3d(a.xyz * 1e6), "
                 "node_noise_fractal(a.xyz, t.x * 15.0, t.y, 2.0, 0.5, 1.0, 2, true))",
                 "node_tex_noise(a.xyz, t.xxx * 10.0, t.yyy * 15.0, t.zzz, vec3(2.0), vec3(0.5), vec3(1.0), b.xyz, 0, "
                 "true, true)",
                 "node_tex_wave(a.xyz, t.xxx * 5.0, b.xyz, t.yyy * 15.0, t.zzz * 5.0, t.xyz, c.xyz, 1, 0, 4, 2)",
                 "node_tex_magic(a.xyz, t.xxx * 5.0, b.xyz, 10, true)",
                 "node_fresnel(abs(a.xyz), node_safe_normalize(b.xyz), node_safe_normalize(c.xyz))",
                 "node_layer_weight(t.xyz, node_safe_normalize(b.xyz), node_safe_normalize(c.xyz), true) + "
                 "node_layer_weight(t.xyz, b.xyz * 0.0, node_safe_normalize(c.xyz), false) + "
                 "vec3(node_fresnel_dielectric_cos(t.x, 0.0)) + node_mix_hue_of(t.xyz, abs(a.xyz), abs(b.xyz), true)",
                 "node_tex_white_noise(a.xyz, b.xyz, 3, true) + node_tex_white_noise(a.xyz, b.xyz, 0, true) + "
                 "node_tex_white_noise(a.xyz, b.xyz, 1, false) + node_tex_white_noise(a.xyz, b.xyz, 2, true)",
                 "vec3(node_hash_to_float(node_hash_final(uint(abs(a.x)), node_hash_uint1(uint(abs(b.x))), "
                 "node_hash_uint2(uint(abs(c.x)), 3u))), node_hash_float1(a.x) + node_hash_float2(a.x, b.x), "
                 "node_hash_float3(a.x, b.x, c.x) + node_hash_float4(a.x, b.x, c.x, a.y) + "
                 "node_hash_to_float(node_hash_uint4(1u, 2u, 3u, uint(abs(a.z)))))",
                 "node_tex_brick(a.xyz, b.xyz, c.xyz, a.zxy, t.xxx * 5.0, t.yyy, t.zzz, b.zxy, abs(c.zxy), "
                 "abs(a.yzx), 0.5, 2, 0.7, 3, true) + vec3(node_brick_noise(uint(abs(a.x) * 1e6)))",
                 "node_bump(b.xxx, c.xxx, a.xyz, node_safe_normalize(b.xyz), a.xyz * 1e-3, true) + "
                 "node_bump_normal(t.xxx, c.yyy, a.x, b.x, c.xyz * 1e-6, a.yzx * 1e-6, b.xyz * 0.0, false)"):
        check(call, everything)


def test_voronoi_stress(glsl, fuzz):
    """Every kernel of voronoi.glsl over coordinates of +-3e5, zeros, tiny steps, Exponents from 0.1 to 30,
    Smoothness down to 1e-30 and Detail up to 15: finite (a Minkowski distance of points 60 apart overflows
    float32, as numpy's does, past an Exponent of 21: the direct check of voronoi_distance keeps it under 3.1)."""
    a, b, c = (_node_inputs(fuzz, NODE_ROWS) for _ in range(3))
    t = np.clip(np.abs(c[:, :3]) / 30.0, 0.0, 1.0)
    inputs = {"a": a, "b": b, "c": c, "t": _f32(np.c_[t, np.zeros(NODE_ROWS)])}
    for feature in range(5):
        for metric in range(4):
            call = (f"node_tex_voronoi(a.xyz * 1e4, vec3(1.0), t.xxx * 15.0, t.yyy, vec3(2.0) + t.zzz, t.xxx * 2.0, "
                    f"vec3(0.1) + abs(b.xxx), t.yyy, {feature}, {metric}, true, {feature % 4})")
            out = glsl(["voronoi.glsl"], f"vec4({call}, 0.0)", inputs, 3)
            assert np.isfinite(out).all(), call
    out = glsl(["voronoi.glsl"], "vec4(voronoi_cell_hash(ivec3(a.xyz)) + vec3(voronoi_distance(a.xyz, b.xyz, 3, "
               "t.z * 3.0 + 0.1), voronoi_distance_to_edge(a.xyz, t.x), voronoi_n_sphere_radius(a.xyz, t.y)), 0.0)",
               inputs, 3)
    assert np.isfinite(out).all()
    # the kernels with out parameters, through a wrapper
    wrapper = """
vec3 voronoi_outputs(vec3 coord, float randomness, float smoothness)
{
  float d1, d2, d3;
  vec3 c1, c2, c3, p1, p2, p3;
  voronoi_f1_f2(coord, 3, 0.5, randomness, true, d1, c1, p1);
  voronoi_smooth_f1(coord, 1, 1.0, randomness, smoothness, d2, c2, p2);
  voronoi_octave(coord, 2, 0, 1.0, randomness, smoothness, d3, c3, p3);
  return vec3(d1 + d2 + d3) + c1 + c2 + c3 + p1 + p2 + p3;
}
"""
    out = glsl(["voronoi.glsl", wrapper], "vec4(voronoi_outputs(a.xyz * 1e4, t.x, t.y * 0.5 + 1e-30), 0.0)", inputs, 3)
    assert np.isfinite(out).all()


# ---- coverage: every function of shaders/lib is fuzzed

COVERED = {
    test_sg_stress: ["sg_product", "sg_inner_product", "sg_evaluate", "sg_sphere_integral",
                     "sg_axis_hemisphere_integral", "one_minus_exp_over_x", "precise_asin"],
    test_safe_normalize_stress: ["safe_normalize"],
    test_hemisphere_stress: ["fh_normalized_from_sine", "fh", "hemisphere_integral", "visibility_product_amplitude",
                             "visibility_product_integral_preserving_amplitude"],
    test_brdf_stress: ["cook_torrance_ndf", "cook_torrance_beckmann_ndf", "ggx_ndf", "blinn_phong_ndf",
                       "ashikhmin_shirley_ndf", "ward_isotropic_ndf", "ward_anisotropic_ndf", "fresnel_dielectric",
                       "fresnel_schlick", "cook_torrance_m_factor", "cook_torrance_beckmann_m_factor",
                       "blinn_phong_m_factor", "ward_anisotropic_m_factor", "ashikhmin_shirley_m_factor",
                       "ggx_m_factor", "lambert_m_factor", "cook_torrance_ndf_lobe",
                       "cook_torrance_beckmann_ndf_lobe", "blinn_phong_ndf_lobe", "ward_isotropic_ndf_lobe",
                       "ggx_ndf_lobe", "ggx_anisotropic_ndf", "ggx_anisotropic_smith_lambda",
                       "ggx_anisotropic_m_factor", "beckmann_m_factor", "beckmann_ndf_lobe"],
    test_lights_stress: ["sphere_light_sg", "sphere_light_sg_paper", "soft_light_sg", "spot_light_sg",
                         "directional_light_sg"],
    test_light_emission_stress: ["light_emission_factor"],
    test_shadow_maps_stress: ["shadow_point_visibility", "shadow_sun_visibility", "shadow_tile_visibility",
                              "shadow_fetch", "shadow_linear", "shadow_window", "shadow_penumbra"],
    test_clamped_cosine_stress: ["sg_clamped_cosine_integral", "sg_clamped_cosine_integral_paper",
                                 "clamped_cosine_from_cosine", "clamped_cosine_lobe_evaluate"],
    test_clamped_cosine_table_stress: ["sg_clamped_cosine_integral_tabulated", "clamped_cosine_tabulated"],
    test_warp_stress: ["warp_lobes_split2", "warp_lobes_split3", "warp_lobes_paper", "brdf_slice_amplitude"],
    test_env_prefilter_stress: ["env_prefilter_lookup", "env_prefilter_lookup_integral"],
    test_sg_helpers_stress: ["sg_rotate", "sg_support_area", "sg_sharpness_from_area"],
    test_hemisphere_helpers_stress: ["erf_approx", "fh_k", "fh_normalized", "disc_coverage"],
    test_clamped_cosine_helpers_stress: ["clamped_cosine_lobe", "clamped_cosine_pole_integrals",
                                         "clamped_cosine_langevin_moments", "clamped_cosine_gaussian_positive_mean",
                                         "clamped_cosine_sharpness_terms", "clamped_cosine_from_terms"],
    test_brdf_helpers_stress: ["brdf_half_vector", "reflect_about", "brdf_theta", "brdf_log_cosine",
                               "shadowing_cook_torrance", "isotropic_polynomial", "isotropic_mapping_beckmann",
                               "isotropic_mapping_blinn_phong", "isotropic_mapping_ward_iso", "isotropic_mapping_ggx",
                               "beckmann_ndf", "ward_isotropic_m_factor", "ggx_alpha", "ggx_smith_lambda",
                               "beckmann_alpha", "beckmann_smith_lambda"],
    test_warp_helpers_stress: ["warp_at", "warp_split_frame", "warp_split_node"],
    test_lights_helpers_stress: ["blender_point_light_intensity", "light_cap_energy_lobe", "sphere_light_cap", "light_cap",
                                 "point_light_sg", "light_cap_radius"],
    test_env_prefilter_helpers_stress: ["env_sign_not_zero", "oct_encode", "env_prefilter_blend_parameter"],
    test_ssdf_stress: ["hemisphere_map_disc_to_square", "hemisphere_map_to_square", "ssdf_horizon_lookup", "ssdf_local_frame",
                       "ssdf_to_local", "ssdf_decode", "ssdf_decode_leading", "ssdf_visibility_amplitude",
                       "ssdf_shadowed_integral"],
    test_ssdf_quadrature_stress: ["ssdf_quadrature_point", "ssdf_cell_radius", "ssdf_cell_coverage",
                                  "ssdf_quadrature_weight"],
    test_lobe_visibility_stress: ["set_visibility_frame", "lobe_visibility", "light_cap_visibility"],
    test_visible_part_stress: ["probit", "visible_part_offset", "visible_part_narrowing", "lobe_visibility_side"],
    test_shading_frame_stress: ["shading_frame", "apply_normal_map", "rotate_tangent"],
    test_factored_brdf_stress: ["parabolic_uv", "factored_brdf"],
    test_sh_library_stress: ["sh_basis", "sh_rotate_z", "sh_rotate", "sh_cap_factors", "sh_sg_factors",
                             "sh_zonal_sum"],
    test_sh_table_lookup_stress: ["sh_parameter_coordinate", "sh_table_lookup"],
    test_sh_fitted_product_stress: ["sh_fitted_lookup", "sh_product"],
    test_model_lobes_stress: ["model_ndf_lobe", "model_m_factor"],
    test_table_lobes_stress: ["ggx_two_lobes", "anisotropic_lobes"],
    test_fitted_pieces_stress: ["fitted_layer", "fitted_select_texel", "fitted_node_theta", "fitted_node_value",
                                "fitted_shadowing_at", "fitted_shadowing_of", "fitted_m_factor"],
    test_node_functions_stress: [f"node_math_{name}" for name in NODE_MATH] + [f"node_mix_{name}" for name in NODE_MIX]
    + [f"node_vector_{name}" for name in NODE_VECTOR]
    + ["node_clamp", "node_clamp_range", "node_map_range", "node_hue_saturation_value", "node_hsv_to_rgb",
       "node_rgb_to_hsv", "node_gamma", "node_brightness_contrast", "node_safe_divide", "node_signed_pow",
       "node_smooth_min", "node_mapping", "node_euler_matrix", "node_safe_normalize", "node_tex_checker",
       "node_tex_gradient", "node_hash_uint3", "node_rot", "node_fade", "node_grad3", "node_perlin_3d",
       "node_snoise_3d", "node_noise_fractal", "node_tex_noise", "node_tex_wave", "node_tex_magic", "node_fresnel",
       "node_layer_weight", "node_fresnel_dielectric_cos", "node_mix_hue_of", "node_tex_white_noise",
       "node_hash_final", "node_hash_to_float", "node_hash_uint1", "node_hash_uint2", "node_hash_uint4",
       "node_hash_float1", "node_hash_float2", "node_hash_float3", "node_hash_float4", "node_bump",
       "node_bump_normal", "node_tex_brick", "node_brick_noise"],
    test_voronoi_stress: ["node_tex_voronoi", "voronoi_cell_hash", "voronoi_distance", "voronoi_distance_to_edge",
                          "voronoi_n_sphere_radius", "voronoi_f1_f2", "voronoi_smooth_f1", "voronoi_octave"],
}

_DEFINITION = re.compile(r"^\s*(?:float|int|uint|bool|void|vec[234]|ivec[234]|mat[234])\s+([A-Za-z_]\w*)\s*\(", re.M)


def _defined_functions(path):
    with open(path, encoding="utf-8") as handle:
        return set(_DEFINITION.findall(handle.read()))


def test_every_kernel_is_fuzzed():
    """Every function defined in shaders/lib/*.glsl (and the listed per-pixel pieces of
    shaders/techniques/sg) is in COVERED, and every name COVERED gives a test is called in that test's
    GLSL: a new kernel without a stress test fails here."""
    library_dir = os.path.join(SHADERS, "lib")
    defined = set()
    for file_name in sorted(os.listdir(library_dir)):
        if file_name.endswith(".glsl"):
            defined |= _defined_functions(os.path.join(library_dir, file_name))
    assert len(defined) > 80, sorted(defined)          # the parse found the library
    for file_name, names in RESOURCE_KERNELS.items():
        missing = set(names) - _defined_functions(os.path.join(SHADERS, "techniques", "sg", file_name))
        assert not missing, f"techniques/sg/{file_name} no longer defines {sorted(missing)}"
        defined |= set(names)
    covered = set()
    module_source = inspect.getsource(inspect.getmodule(test_every_kernel_is_fuzzed))

    def called(name, source):
        """Called by name, or through an f-string prefix ("node_math_{operation}(") over a listed suffix."""
        if re.search(r"\b" + name + r"\s*\(", source):
            return True
        return any(f'{name[:k]}{{' in source and f'"{name[k:]}"' in module_source for k in range(1, len(name)))

    for test, names in COVERED.items():
        source = inspect.getsource(test)
        not_called = [name for name in names if not called(name, source)]
        assert not not_called, f"{test.__name__} does not call {not_called}"
        covered |= set(names)
    assert not defined - covered, f"GLSL kernels without a stress test: {sorted(defined - covered)}"
    assert not covered - defined, f"COVERED names no kernel: {sorted(covered - defined)}"
