"""shaders/lib/clamped_cosine.glsl and clamped_cosine_table.glsl (float32) against sg_prt_addon/spherical/clamped_cosine.py
and clamped_cosine_table.py (float64)."""
import re

import numpy as np
import pytest

from sg_prt_addon.spherical import clamped_cosine
from validation import paper_forms

# the numpy closed form evaluates both sides of its np.where (e.g. c / tiny squared)
pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")

N = 20000
LIB = ["sg.glsl", "hemisphere.glsl", "clamped_cosine.glsl"]


def test_pole_integrals(glsl, fuzz, record_error):
    sharpness = fuzz.f32(np.concatenate([[1e-6, 0.0099999, 0.01, 0.2499999, 0.25, 1e6],
                                         fuzz.log_uniform(1e-6, 1e6, N)]))
    out = glsl(LIB, "vec4(clamped_cosine_pole_integrals(a.x), 0.0, 0.0)", {"a": sharpness}, 2)
    upper, lower = clamped_cosine._pole_integrals(sharpness)
    # lower = e^-l (...) reaches float32 denormals for l > ~80: absolute floor there
    error = fuzz.relative_error(out, np.c_[upper, lower], 1e-30)
    # e^-l carries ~l * 6e-8 relative float32 error (l up to ~70 above the floor)
    assert record_error("clamped_cosine pole_integrals, relative", error.max()) <= 1e-5
    moments = glsl(LIB, "vec4(clamped_cosine_langevin_moments(a.x), 0.0, 0.0)", {"a": sharpness}, 2)
    mean, variance = clamped_cosine._langevin_moments(sharpness)
    # coth(l) - 1/l and 1/l^2 - 1/sinh^2 cancel by ~5/L just above the series cutoff 0.2
    error = np.abs(moments - np.c_[mean, variance]) / np.c_[np.maximum(mean, 1e-30), np.full(mean.size, 1 / 3)]
    assert record_error("clamped_cosine langevin_moments, L relative, V relative to 1/3", error.max()) <= 2e-5


def test_clamped_cosine_integral(glsl, fuzz, record_error):
    axis = fuzz.unit_vectors(N)
    normal = fuzz.f32(fuzz.near(axis, 2.0) * fuzz.log_uniform(1e-2, 1e2, N)[:, None])
    normal[:100] = -axis[:100]
    normal[100:200] = axis[100:200]
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-7], fuzz.log_uniform(1e-4, 1e6, N - 2)]))
    amplitude = fuzz.uniform(0.0, 3.0, N)
    out = glsl(LIB, "vec4(sg_clamped_cosine_integral(p.xyz, p.w, n.w, n.xyz),"
                    " sg_clamped_cosine_integral_paper(p.xyz, p.w, n.w, n.xyz), 0.0, 0.0)",
               {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude]}, 2)
    expected = clamped_cosine.sg_clamped_cosine_integral(axis, sharpness, amplitude, normal)
    # scale: the integral with the normal on the axis, mu (2 pi / lambda) I_up
    scale = amplitude * clamped_cosine.clamped_cosine_from_cosine(np.ones(N), sharpness) + 1e-30
    assert record_error("clamped_cosine sg_clamped_cosine_integral, relative to I(c = 1)",
                        (np.abs(out[:, 0] - expected) / scale).max()) <= 1e-5
    paper = paper_forms.sg_clamped_cosine_integral_paper(axis, sharpness, amplitude, normal)
    error = fuzz.relative_error(out[:, 1], paper, 1e-30)
    log_amplitude = np.log(np.maximum(paper, 1e-300) / np.maximum(amplitude, 1e-300))
    well_conditioned = (log_amplitude > -60) & (amplitude > 0)
    assert record_error("clamped_cosine sg_clamped_cosine_integral_paper (log > -60), relative",
                        error[well_conditioned].max()) <= 3e-5


def test_from_terms(glsl, fuzz, record_error):
    """The lambda-only terms as the renderer computes them (numpy float32, in the scene block) and as
    the GLSL does, each through clamped_cosine_from_terms: against numpy's I(c, lambda)."""
    cosine = fuzz.f32(np.concatenate([[-1.0, 1.0, 0.0, 0.5], fuzz.uniform(-1.0, 1.0, N)]))
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-4, 0.3, 1e6], fuzz.log_uniform(1e-4, 1e6, N)]))
    terms = clamped_cosine.sharpness_terms(sharpness, np.float32)
    body = """
    vec4 poles_moments, shape;
    clamped_cosine_sharpness_terms(a.y, poles_moments, shape);
    result = vec4(clamped_cosine_from_terms(a.x, a.y, t0, t1), clamped_cosine_from_terms(a.x, a.y, poles_moments, shape),
                  0.0, 0.0);
    """
    out = glsl(LIB, body, {"a": np.c_[cosine, sharpness], "t0": terms[:, :4], "t1": terms[:, 4:]}, 4)
    expected = clamped_cosine.clamped_cosine_from_cosine(cosine, sharpness)
    np.testing.assert_array_equal(                   # the split is the same arithmetic
        clamped_cosine.clamped_cosine_from_terms(cosine, sharpness, clamped_cosine.sharpness_terms(sharpness)), expected)
    scale = clamped_cosine.clamped_cosine_from_cosine(np.ones_like(cosine), sharpness)
    assert record_error("clamped_cosine from_terms (numpy terms), relative to I(c = 1)",
                        (np.abs(out[:, 0] - expected) / scale).max()) <= 1e-5
    assert record_error("clamped_cosine from_terms (GLSL terms), relative to I(c = 1)",
                        (np.abs(out[:, 1] - expected) / scale).max()) <= 1e-5


def test_from_cosine_and_lobe(glsl, fuzz, record_error):
    cosine = fuzz.f32(np.concatenate([[-1.0, 1.0, 0.0], fuzz.uniform(-1.0, 1.0, N)]))
    sharpness = fuzz.log_uniform(1e-4, 1e6, cosine.size)
    direction = fuzz.unit_vectors(cosine.size)
    normal = fuzz.near(direction, 1.0)
    out = glsl(LIB, "vec4(clamped_cosine_from_cosine(a.x, a.y), clamped_cosine_lobe_evaluate(d.xyz, n.xyz),"
                    " clamped_cosine_lobe())",
               {"a": np.c_[cosine, sharpness], "d": direction, "n": normal}, 4)
    expected = clamped_cosine.clamped_cosine_from_cosine(cosine, sharpness)
    scale = clamped_cosine.clamped_cosine_from_cosine(np.ones_like(cosine), sharpness)
    assert record_error("clamped_cosine from_cosine, relative to I(c = 1)",
                        (np.abs(out[:, 0] - expected) / scale).max()) <= 1e-5
    lobe = clamped_cosine.clamped_cosine_lobe_evaluate(direction, normal)
    assert fuzz.relative_error(out[:, 1], lobe, 1e-30).max() <= 2e-6
    assert np.allclose(out[:, 2:], clamped_cosine.clamped_cosine_lobe(), rtol=1e-7)


def test_tabulated(glsl, fuzz, record_error):
    """shaders/lib/clamped_cosine_table.glsl reading the uploaded table through the hardware's bilinear
    filter, against the numpy mirror of that filter (whose own error against quadrature
    tests/core/test_clamped_cosine_table.py bounds); and its constants against the module's."""
    from sg_prt_addon.spherical import clamped_cosine_table
    from sg_prt_addon.techniques import shader_sources

    source = shader_sources.library_source("clamped_cosine_table.glsl")
    constants = dict(re.findall(r"const float CLAMPED_COSINE_TABLE_(\w+) = ([-0-9.e]+);", source))
    assert {name: float(value) for name, value in constants.items()} == pytest.approx({
        "LOG_MIN": np.log(clamped_cosine_table.SHARPNESS_RANGE[0]),
        "LOG_MAX": np.log(clamped_cosine_table.SHARPNESS_RANGE[1]),
        "KNEE_WEIGHT": clamped_cosine_table.KNEE_WEIGHT, "MIN_SHARPNESS": clamped_cosine_table.MIN_SHARPNESS},
        rel=1e-12)

    axis = fuzz.unit_vectors(N)
    normal = fuzz.f32(fuzz.near(axis, 2.0) * fuzz.log_uniform(1e-2, 1e2, N)[:, None])
    normal[:100] = -axis[:100]
    normal[100:200] = axis[100:200]
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-7, -1.0, 1e9], fuzz.log_uniform(1e-6, 1e8, N - 4)]))
    amplitude = fuzz.uniform(0.0, 3.0, N)
    table = clamped_cosine_table.clamped_cosine_table()
    out = glsl(["sg.glsl", "clamped_cosine_table.glsl"],
               "vec4(sg_clamped_cosine_integral_tabulated(clamped_cosine_table, p.xyz, p.w, n.w, n.xyz))",
               {"p": np.c_[axis, sharpness], "n": np.c_[normal, amplitude]}, 1,
               textures={"clamped_cosine_table": table})
    expected = clamped_cosine_table.sg_clamped_cosine_integral_tabulated(axis, sharpness, amplitude, normal)
    scale = amplitude * clamped_cosine_table.clamped_cosine_from_table(np.ones(N), sharpness) + 1e-30
    assert np.all(np.isfinite(out))
    assert record_error("clamped_cosine_table sg_clamped_cosine_integral_tabulated, relative to I(c = 1)",
                        (np.abs(out - expected) / scale).max()) <= 2e-5
