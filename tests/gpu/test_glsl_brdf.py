"""shaders/lib/brdf.glsl (float32) against sg_prt_addon/reflectance/brdf.py (float64).

ndf values are compared relative to the model's peak D(n) (exp(-E) loses
~E * 1e-7 relative far in the tail, where the value is negligible);
m_factor and lobes relative to themselves.
"""
import numpy as np
import pytest

from sg_prt_addon.reflectance import brdf

N = 20000
LIB = ["sg.glsl", "brdf.glsl"]


def _directions(fuzz, count, below_fraction=0.1):
    """Unit vectors, mostly above the horizon, some grazing (z ~ 1e-4) and some below."""
    v = fuzz.unit_vectors(count)
    v[:, 2] = np.abs(v[:, 2])
    kind = fuzz.rng.random(count)
    v[kind < below_fraction, 2] *= -1
    grazing = (kind >= below_fraction) & (kind < 2 * below_fraction)
    v[grazing, 2] = fuzz.log_uniform(1e-5, 1e-2, int(grazing.sum()))
    return fuzz.f32(v / np.linalg.norm(v, axis=1, keepdims=True))


def _half_vectors(fuzz, count, spread):
    """Half vectors clustered at the pole (width ~ spread) plus uniform ones, some below."""
    h = fuzz.near(np.tile([0.0, 0.0, 1.0], (count, 1)), spread)
    h[: count // 4] = _directions(fuzz, count // 4)
    return h


# (model factory from (p1, p2, p3) arrays, GLSL ndf call, GLSL m_factor call, lobe call or None, parameter ranges)
MODELS = {
    "cook_torrance": (lambda a, b, c: brdf.CookTorrance(roughness=a, ior=b),
                      "cook_torrance_ndf(h.xyz, q.x)", "cook_torrance_m_factor(wo.xyz, wi.xyz, q.x, q.y)",
                      "cook_torrance_ndf_lobe(q.x)", [(0.01, 1.0), (1.01, 3.0), (0, 0)]),
    "cook_torrance_beckmann": (lambda a, b, c: brdf.CookTorranceBeckmann(roughness=a, ior=b),
                               "cook_torrance_beckmann_ndf(h.xyz, q.x)",
                               "cook_torrance_beckmann_m_factor(wo.xyz, wi.xyz, q.x, q.y)",
                               "cook_torrance_beckmann_ndf_lobe(q.x)", [(0.01, 1.0), (1.01, 3.0), (0, 0)]),
    "blinn_phong": (lambda a, b, c: brdf.BlinnPhong(exponent=a),
                    "blinn_phong_ndf(h.xyz, q.x)", "blinn_phong_m_factor(wo.xyz, wi.xyz, q.x)",
                    "blinn_phong_ndf_lobe(q.x)", [(0.5, 1e4), (0, 0), (0, 0)]),
    "ward_isotropic": (lambda a, b, c: brdf.WardIsotropic(alpha_x=a),
                       "ward_isotropic_ndf(h.xyz, q.x)", "ward_isotropic_m_factor(wo.xyz, wi.xyz)",
                       "ward_isotropic_ndf_lobe(q.x)", [(0.01, 1.0), (0, 0), (0, 0)]),
    "ward_anisotropic": (lambda a, b, c: brdf.WardAnisotropic(alpha_x=a, alpha_y=b),
                         "ward_anisotropic_ndf(h.xyz, q.x, q.y)", "ward_anisotropic_m_factor(wo.xyz, wi.xyz)",
                         None, [(0.01, 1.0), (0.01, 1.0), (0, 0)]),
    "ashikhmin_shirley": (lambda a, b, c: brdf.AshikhminShirley(nu=a, nv=b, rf0=c),
                          "ashikhmin_shirley_ndf(h.xyz, q.x, q.y)",
                          "ashikhmin_shirley_m_factor(wo.xyz, wi.xyz, q.x, q.y, q.z)",
                          None, [(1.0, 1e4), (1.0, 1e4), (0.0, 1.0)]),
    "beckmann": (lambda a, b, c: brdf.Beckmann(roughness=a),
                 "beckmann_ndf(h.xyz, beckmann_alpha(q.x), beckmann_alpha(q.x))",
                 "beckmann_m_factor(wo.xyz, wi.xyz, q.x)", "beckmann_ndf_lobe(q.x)", [(0.03, 1.0), (0, 0), (0, 0)]),
    "ggx": (lambda a, b, c: brdf.GGX(roughness=a),
            "ggx_ndf(h.xyz, q.x)", "ggx_m_factor(wo.xyz, wi.xyz, q.x)",
            "ggx_ndf_lobe(q.x)", [(0.03, 1.0), (0, 0), (0, 0)]),
}


def _parameters(fuzz, ranges, count):
    columns = []
    for low, high in ranges:
        if low == high:
            columns.append(np.zeros(count))
        elif low > 0 and high / low > 50:
            columns.append(fuzz.log_uniform(low, high, count))
        else:
            columns.append(fuzz.uniform(low, high, count))
    return np.stack(columns, axis=1)


@pytest.mark.parametrize("name", sorted(MODELS))
def test_model(glsl, fuzz, record_error, name):
    factory, ndf_call, m_call, lobe_call, ranges = MODELS[name]
    q = _parameters(fuzz, ranges, N)
    model = factory(q[:, 0], q[:, 1], q[:, 2])
    wo, wi = _directions(fuzz, N), _directions(fuzz, N)
    h = _half_vectors(fuzz, N, 0.3)
    lobe = lobe_call or "vec2(0.0)"
    out = glsl(LIB, f"vec4({ndf_call}, {m_call}, {lobe})", {"q": q, "wo": wo, "wi": wi, "h": h}, 4)

    peak = model.ndf(np.tile([0.0, 0.0, 1.0], (N, 1)))
    ndf_error = np.abs(out[:, 0] - model.ndf(h)) / peak
    assert record_error(f"brdf {name}_ndf, relative to D(n)", ndf_error.max()) <= 4e-5

    expected_m = model.m_factor(wo, wi)
    assert np.array_equal(out[:, 1] > 0, expected_m > 0)
    m_error = fuzz.relative_error(out[:, 1], expected_m, 1e-30)
    # o ~ -i (both grazing) makes h = (o + i)/|o + i| ill-conditioned for any float32 code
    well_conditioned = np.linalg.norm(wo + wi, axis=1) > 0.05
    assert record_error(f"brdf {name}_m_factor (|o + i| > 0.05), relative",
                        m_error[well_conditioned].max()) <= 1e-4
    assert m_error.max() <= 1e-2

    if lobe_call:
        _, sharpness, amplitude = model.ndf_lobes()
        expected = np.c_[sharpness[:, 0], amplitude[:, 0]]
        # GGX's frozen polynomial crosses zero near alpha = 1 (its terms, up to ~160,
        # cancel): there the error is measured against 0.1 / width^2
        floor = np.c_[0.1 / _lobe_width(name, q) ** 2, np.full(N, 1e-30)]
        lobe_error = np.abs(out[:, 2:] - expected) / np.maximum(np.abs(expected), floor)
        bound = 5e-4 if name == "ggx" else 1e-4
        assert record_error(f"brdf {name}_ndf_lobe, relative", lobe_error.max()) <= bound


def _lobe_width(name, q):
    """The width w whose 1/w^2 scales each model's lobe sharpness."""
    if name == "blinn_phong":
        return np.clip(np.sqrt(2 / np.maximum(q[:, 0], 1e-6)), 0, 1.5)
    if name == "ggx":
        return np.maximum(q[:, 0] ** 2, 1e-9)
    return np.maximum(q[:, 0], 1e-6)


def test_fresnel(glsl, fuzz, record_error):
    cos_theta = fuzz.uniform(-1.0, 1.0, N)
    eta = fuzz.f32(np.where(np.arange(N) % 2 == 0, fuzz.uniform(1.001, 3.0, N), fuzz.uniform(0.3, 0.999, N)))
    rf0 = fuzz.uniform(0.0, 1.0, N)
    out = glsl(LIB, "vec4(fresnel_dielectric(a.x, a.y), fresnel_schlick(a.x, a.z), 0, 0)",
               {"a": np.c_[cos_theta, eta, rf0]}, 2)
    dielectric = brdf.fresnel_dielectric(cos_theta, eta)
    assert record_error("brdf fresnel_dielectric, relative",
                        fuzz.relative_error(out[:, 0], dielectric, 1e-30).max()) <= 1e-4
    assert record_error("brdf fresnel_schlick, absolute",
                        np.abs(out[:, 1] - brdf.fresnel_schlick(cos_theta, rf0)).max()) <= 1e-6


def test_half_vector_reflect_shadowing(glsl, fuzz, record_error):
    wo, wi = _directions(fuzz, N), _directions(fuzz, N)
    out = glsl(LIB, "vec4(brdf_half_vector(wo.xyz, wi.xyz), shadowing_cook_torrance(wo.xyz, wi.xyz,"
                    " brdf_half_vector(wo.xyz, wi.xyz)))", {"wo": wo, "wi": wi}, 4)
    h = brdf.half_vector(wo, wi)
    well_defined = np.linalg.norm(wo + wi, axis=1) > 1e-3
    assert record_error("brdf half_vector (|o + i| > 1e-3), absolute",
                        np.abs(out[:, :3] - h)[well_defined].max()) <= 1e-4
    shadowing = brdf.shadowing_cook_torrance(wo, wi, h)
    assert record_error("brdf shadowing_cook_torrance, absolute",
                        np.abs(out[:, 3] - shadowing)[well_defined].max()) <= 1e-4
    reflected = glsl(LIB, "vec4(reflect_about(wo.xyz, wi.xyz), 0)", {"wo": wo, "wi": wi}, 3)
    assert np.abs(reflected - brdf.reflect(wo, wi)).max() <= 1e-6


def test_lambert(glsl, fuzz):
    wo, wi = _directions(fuzz, N), _directions(fuzz, N)
    kd = fuzz.uniform(0.0, 1.0, N)
    out = glsl(LIB, "vec4(lambert_m_factor(wo.xyz, wi.xyz, wo.w))", {"wo": np.c_[wo, kd], "wi": wi}, 1)
    expected = brdf.Lambert(kd=kd).m_factor(wo, wi)
    assert np.abs(out - expected).max() <= 1e-7
