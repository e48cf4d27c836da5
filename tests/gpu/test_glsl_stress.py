"""Float32 fuzz stress: ~1e6 rows per kernel of shaders/lib, asserting no NaN/Inf.

Inputs cover the contract of docs/ARCHITECTURE.md: sharpness 0 and 1e-4..1e6,
equal and exactly opposite axes, poles, zero and tiny vectors, zero
amplitudes, grazing angles.  Kernels that take unit axes get unit, zero or
tiny axes; safe_normalize also gets huge ones.
"""
import numpy as np
import pytest

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
                  blinn_phong_ndf(h.xyz, n) + ashikhmin_shirley_ndf(h.xyz, n, n * 7.0 + 1.0),
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
                  ashikhmin_shirley_m_factor(wo.xyz, wi.xyz, n, 1.0, e.x) + ggx_m_factor(wo.xyz, wi.xyz, r),
                  lambert_m_factor(wo.xyz, wi.xyz, e.x));
    """
    out = glsl(["sg.glsl", "brdf.glsl"], m_factors, inputs, 4)
    _assert_finite(out, "brdf m_factors")
    assert out.min() >= 0
    lobes = """
    float r = wo.w, n = h.w;
    result = vec4(cook_torrance_ndf_lobe(r) + cook_torrance_beckmann_ndf_lobe(r),
                  blinn_phong_ndf_lobe(n) + ward_isotropic_ndf_lobe(r) + ggx_ndf_lobe(r));
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
        "spot_light_sg": "spot_light_sg(x.xyz, l.xyz, s.xyz, x.w, fract(x.w), s.w, l.w, axis, sharpness, amplitude)",
        "directional_light_sg": "directional_light_sg(s.xyz, x.w, s.w, axis, sharpness, amplitude)",
    }
    for name, call in calls.items():
        body = ("vec3 axis; float sharpness, amplitude; " + call +
                "; result = vec4(axis.x + axis.y + axis.z, sharpness, amplitude, 0.0);")
        out = glsl(["sg.glsl", "lights.glsl"], body, inputs, 3)
        _assert_finite(out, name)
        assert out[:, 1].min() > 0 and out[:, 2].min() >= 0, name


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
