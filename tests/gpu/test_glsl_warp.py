"""shaders/lib/warp.glsl (float32) against sg_prt_addon/spherical/warp.py (float64)."""
import numpy as np
import pytest

from sg_prt_addon.reflectance import brdf
from sg_prt_addon.spherical import warp

N = 20000
LIB = ["sg.glsl", "brdf.glsl", "warp.glsl"]

SPLIT = """
    vec3 axes[{n}]; float sharpnesses[{n}], amplitudes[{n}];
    warp_lobes_split{n}(p.xyz, p.w, m.x, wo.xyz, axes, sharpnesses, amplitudes);
    int k = int(m.y);
    result = m.z > 0.5 ? vec4(sharpnesses[k], amplitudes[k], 0.0, 0.0) : vec4(axes[k], 0.0);
"""
PAPER = """
    vec3 axis; float sharpness, amplitude;
    warp_lobes_paper(p.xyz, p.w, m.x, wo.xyz, axis, sharpness, amplitude);
    result = m.z > 0.5 ? vec4(sharpness, amplitude, 0.0, 0.0) : vec4(axis, 0.0);
"""


def _inputs(fuzz):
    """NDF lobes near the normal (some anywhere), views from normal to grazing (some below)."""
    axis = fuzz.near(np.tile([0.0, 0.0, 1.0], (N, 1)), 0.4)
    axis[: N // 8] = fuzz.unit_vectors(N // 8)
    sharpness = fuzz.f32(np.concatenate([[0.0, 1e-4, 8.0, 1e6], fuzz.log_uniform(0.1, 1e5, N - 4)]))
    amplitude = fuzz.uniform(0.0, 5.0, N)
    wo = fuzz.unit_vectors(N)
    wo[:, 2] = np.abs(wo[:, 2])
    grazing = fuzz.rng.integers(0, 4, N) == 0
    wo[grazing, 2] = fuzz.log_uniform(1e-6, 1e-2, int(grazing.sum()))
    wo[fuzz.rng.integers(0, 16, N) == 0, 2] *= -1
    return axis, sharpness, amplitude, fuzz.f32(wo / np.linalg.norm(wo, axis=1, keepdims=True))


def _glsl_lobes(glsl, body, axis, sharpness, amplitude, wo, index):
    inputs = {"p": np.c_[axis, sharpness], "wo": wo, "m": np.c_[amplitude, np.full(N, index), np.zeros(N)]}
    axes = glsl(LIB, body, inputs, 3)
    inputs["m"] = np.c_[amplitude, np.full(N, index), np.ones(N)]
    scalars = glsl(LIB, body, inputs, 2)
    return axes, scalars[:, 0], scalars[:, 1]


def _compare(record_error, label, got, expected, sharpness):
    got_axis, got_sharpness, got_amplitude = got
    axis, warped_sharpness, warped_amplitude = expected
    # a sub-lobe centre within float32 rounding of h.wo = 0 may land on either side;
    # those are the lobes at the grazing floor, whose sharpness is lambda / (4 COS_FLOOR) or capped
    differs = (got_amplitude > 0) != (warped_amplitude > 0)
    at_floor = warped_sharpness >= np.minimum(sharpness / (4 * warp.COS_FLOOR), warp.MAX_WARPED_SHARPNESS) * (1 - 1e-3)
    assert differs.mean() <= 1e-3 and np.all(at_floor[differs]), label
    same = ~differs
    assert record_error(f"warp {label} amplitude, relative",
                        (np.abs(got_amplitude - warped_amplitude) / np.maximum(warped_amplitude, 1e-30))[same].max()) <= 1e-6
    assert record_error(f"warp {label} axis, absolute", np.abs(got_axis - axis)[same].max()) <= 1e-5
    # lambda / (4 |c|): float32 c has ~1e-7 absolute error, so 1e-7 / |c| >= 1e-4 relative at the floor
    error = np.abs(got_sharpness - warped_sharpness) / np.maximum(warped_sharpness, 1e-30)
    assert record_error(f"warp {label} sharpness, relative", error[same].max()) <= 2e-4


def test_warp_paper(glsl, fuzz, record_error):
    axis, sharpness, amplitude, wo = _inputs(fuzz)
    got = _glsl_lobes(glsl, PAPER, axis, sharpness, amplitude, wo, 0)
    expected = warp.warp_lobes(axis[:, None], sharpness[:, None], amplitude[:, None], wo, mode="paper")
    _compare(record_error, "paper", got, [a[:, 0] for a in expected], sharpness)


@pytest.mark.parametrize("mode, index", [("split2", 0), ("split2", 1), ("split3", 0), ("split3", 1), ("split3", 2)])
def test_warp_split(glsl, fuzz, record_error, mode, index):
    axis, sharpness, amplitude, wo = _inputs(fuzz)
    body = SPLIT.format(n=len(warp.SPLIT_RULES[mode][0]))
    got = _glsl_lobes(glsl, body, axis, sharpness, amplitude, wo, index)
    expected = warp.warp_lobes(axis[:, None], sharpness[:, None], amplitude[:, None], wo, mode=mode)
    _compare(record_error, f"{mode}[{index}]", got, [a[:, index] for a in expected], sharpness)


def test_brdf_slice_ggx(glsl, fuzz, record_error):
    """eq. 22 end to end for one GGX lobe: warp_lobes_split3 (the default) then ggx_m_factor at each warped axis."""
    roughness = fuzz.uniform(0.1, 1.0, N)
    _, lobe_sharpness, lobe_amplitude = brdf.GGX(roughness=roughness).ndf_lobes()
    axis = np.tile([0.0, 0.0, 1.0], (N, 1))
    _, _, _, wo = _inputs(fuzz)
    body = """
    vec2 lobe = m.xy;  /* numpy's lobe: the mapping's own float32 error is tested in test_glsl_brdf */
    vec3 axes[3]; float sharpnesses[3], amplitudes[3];
    warp_lobes_split3(vec3(0.0, 0.0, 1.0), lobe.x, lobe.y, wo.xyz, axes, sharpnesses, amplitudes);
    result = vec4(brdf_slice_amplitude(amplitudes[0], ggx_m_factor(wo.xyz, axes[0], m.w)),
                  brdf_slice_amplitude(amplitudes[1], ggx_m_factor(wo.xyz, axes[1], m.w)),
                  brdf_slice_amplitude(amplitudes[2], ggx_m_factor(wo.xyz, axes[2], m.w)), 0.0);
    """
    out = glsl(LIB, body, {"wo": wo, "m": np.c_[lobe_sharpness, lobe_amplitude, np.zeros(N), roughness]}, 3)
    model = brdf.GGX(roughness=roughness)  # brdf_slice_lobes calls m_factor with the lobe axis first
    warped_axis, _, expected = warp.brdf_slice_lobes(axis[:, None], lobe_sharpness, lobe_amplitude, wo,
                                                     model.m_factor, mode="split3")
    # Mo ~ 1/(n.wi (n.o)): relative error ~ 1e-7 / (n.wi) near the horizon; compare above 0.05
    clear = (warped_axis[..., 2] > 0.05) & (wo[:, 2:3] > 0.05)
    error = np.abs(out - expected) / np.maximum(np.abs(expected), 1e-30)
    assert record_error("warp brdf_slice (split3, GGX, n.wi and n.o > 0.05) amplitude, relative",
                        error[clear].max()) <= 1e-4
