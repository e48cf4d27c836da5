"""shaders/lib/lights.glsl (float32) against sg_prt_addon/lighting/lights.py (float64)."""
import numpy as np

from sg_prt_addon.lighting import lights

N = 20000
LIB = ["sg.glsl", "lights.glsl"]

LOBE_OUT = """
    vec3 axis; float sharpness, amplitude;
    {call};
    result = m.w > 0.5 ? vec4(sharpness, amplitude, 0.0, 0.0) : vec4(axis, 0.0);
"""


def _run(glsl, call, inputs):
    """(axis (N, 3), sharpness (N,), amplitude (N,)) of a lobe-returning GLSL call; `m.w` selects."""
    inputs = dict(inputs)
    m = np.array(inputs["m"], np.float64)
    m[:, 3] = 0.0
    inputs["m"] = m
    axis = glsl(LIB, LOBE_OUT.format(call=call), inputs, 3)
    m = m.copy()
    m[:, 3] = 1.0
    inputs["m"] = m
    scalars = glsl(LIB, LOBE_OUT.format(call=call), inputs, 2)
    return axis, scalars[:, 0], scalars[:, 1]


def _check(record_error, label, got, expected, direction_bound=1e-6, bound=5e-6):
    axis, sharpness, amplitude = got
    axis_expected, sharpness_expected, amplitude_expected = (np.asarray(a, np.float64) for a in expected)
    assert record_error(f"lights {label} axis, absolute", np.abs(axis - axis_expected).max()) <= direction_bound
    for what, value, reference in (("sharpness", sharpness, sharpness_expected),
                                   ("amplitude", amplitude, amplitude_expected)):
        error = np.abs(value - reference) / np.maximum(np.abs(reference), 1e-30)
        assert record_error(f"lights {label} {what}, relative", error.max()) <= bound


def _scene(fuzz):
    position = fuzz.uniform(-1.0, 1.0, (N * 3)).reshape(N, 3)
    # lights 0.01..10 away, radius from 0 (points) to beyond the distance (inside the light)
    light = fuzz.f32(position + fuzz.unit_vectors(N) * fuzz.log_uniform(1e-2, 10.0, N)[:, None])
    radius = fuzz.f32(np.where(fuzz.rng.integers(0, 5, N) == 0, 0.0, fuzz.log_uniform(1e-4, 3.0, N)))
    intensity = fuzz.log_uniform(1e-2, 1e3, N)
    return position, light, radius, intensity


def test_sphere_light(glsl, fuzz, record_error):
    position, light, radius, intensity = _scene(fuzz)
    inputs = {"x": position, "l": np.c_[light, radius], "m": np.c_[intensity, np.zeros((N, 3))]}
    got = _run(glsl, "sphere_light_sg(x.xyz, l.xyz, l.w, m.x, axis, sharpness, amplitude)", inputs)
    _check(record_error, "sphere_light_sg", got, lights.sphere_light_sg(position, light, radius, intensity))
    got = _run(glsl, "sphere_light_sg_paper(x.xyz, l.xyz, l.w, m.x, axis, sharpness, amplitude)", inputs)
    _check(record_error, "sphere_light_sg_paper", got,
           lights.sphere_light_sg(position, light, radius, intensity, model="paper"))
    got = _run(glsl, "point_light_sg(x.xyz, l.xyz, m.x, l.w, axis, sharpness, amplitude)", inputs)
    _check(record_error, "point_light_sg", got, lights.point_light_sg(position, light, intensity, radius))
    got = _run(glsl, "soft_light_sg(x.xyz, l.xyz, l.w, true, m.x, axis, sharpness, amplitude)", inputs)
    _check(record_error, "soft_light_sg (Soft Falloff)", got,         # measured 6.0e-6: d^2 + r^2 rounded in float32
           lights.sphere_light_sg(position, light, radius, intensity, soft_falloff=True), bound=1e-5)


def test_spot_light(glsl, fuzz, record_error):
    position, light, radius, intensity = _scene(fuzz)
    spot_direction = fuzz.near(position - light, 0.5)
    size = fuzz.uniform(0.1, 3.0, N)
    blend = fuzz.uniform(0.0, 1.0, N)
    inputs = {"x": np.c_[position, size], "l": np.c_[light, radius], "s": np.c_[spot_direction, blend],
              "m": np.c_[intensity, np.zeros((N, 3))]}
    got = _run(glsl, "spot_light_sg(x.xyz, l.xyz, s.xyz, x.w, s.w, m.x, l.w, axis, sharpness, amplitude)", inputs)
    expected = lights.spot_light_sg(position, light, spot_direction, size, blend, intensity, radius)
    # the smoothstep edge amplifies float32 cosines by 1/width: compare amplitudes to the unfalloffed lobe
    unfalloffed = lights.sphere_light_sg(position, light, radius, intensity)[2]
    assert np.abs(got[0] - expected[0]).max() <= 2e-6
    assert fuzz.relative_error(got[1], expected[1], 1e-30).max() <= 2e-5
    error = np.abs(got[2] - expected[2]) / unfalloffed
    wide = (1 - np.cos(0.5 * size)) * blend > 1e-3
    assert record_error("lights spot_light_sg amplitude (blend width > 1e-3), relative to no falloff",
                        error[wide].max()) <= 1e-3


def test_directional_light(glsl, fuzz, record_error):
    direction = fuzz.f32(fuzz.unit_vectors(N) * fuzz.log_uniform(1e-3, 1e3, N)[:, None])
    angular_radius = fuzz.f32(np.where(fuzz.rng.integers(0, 5, N) == 0, 0.0, fuzz.uniform(0.0, 2.0, N)))
    irradiance = fuzz.log_uniform(1e-2, 1e3, N)
    inputs = {"d": np.c_[direction, angular_radius], "m": np.c_[irradiance, np.zeros((N, 3))]}
    got = _run(glsl, "directional_light_sg(d.xyz, d.w, m.x, axis, sharpness, amplitude)", inputs)
    _check(record_error, "directional_light_sg", got,
           lights.directional_light_sg(direction, angular_radius, irradiance))
    power = fuzz.log_uniform(1e-2, 1e4, N)
    out = glsl(LIB, "vec4(blender_point_light_intensity(p.x))", {"p": power}, 1)
    assert fuzz.relative_error(out, lights.blender_point_light_intensity(power), 1e-30).max() <= 1e-6


def test_area_patch_emission(glsl, fuzz, record_error):
    """light_emission_factor for area lights' patches: the one-sided cosine, times the spread's attenuation
    (spreads from 5 degrees to none), against lights.emission_factor in float64."""
    axis = fuzz.unit_vectors(N)
    normal = fuzz.near(-axis, 1.2)
    spread = np.where(fuzz.rng.integers(0, 4, N) == 0, np.pi, fuzz.uniform(np.radians(5.0), np.pi, N))
    tan_half, normalization = np.array([lights.spread_parameters(s) for s in spread]).T
    inputs = {"a": np.c_[axis, tan_half], "n": np.c_[normal, normalization]}
    got = glsl(LIB, "result = vec4(light_emission_factor(a.xyz, n.xyz, -1.0, 0.0, true, a.w, n.w));",
               inputs, 1).ravel()
    cos_angle = np.sum(-axis * normal / np.linalg.norm(normal, axis=-1, keepdims=True), axis=-1)
    expected = lights.emission_factor(cos_angle, -1.0, 0.0, True, tan_half, normalization)
    # the attenuation's slope is the normalization: compare to the on-axis value tan_half N (1 without spread)
    scale = np.where(normalization > 0, tan_half * normalization, 1.0)
    assert record_error("lights light_emission_factor (area patch), relative to its peak",
                        (np.abs(got - expected) / scale).max()) <= 2e-5
    assert np.all(got[cos_angle < -1e-6] == 0)                    # one-sided


def test_cap_radius(glsl, fuzz, record_error):
    """light_cap_radius: the half-angle of the cap an SG of any sharpness stands for (sharpness ln 10 to the
    point lights' 1e6), relative: a small light's radius sets its penumbra's width."""
    sharpness = fuzz.f32(np.log(10.0) * 10.0 ** fuzz.rng.uniform(0.0, 5.7, N))
    out = glsl(LIB, "vec4(light_cap_radius(a.x), 0.0, 0.0, 0.0)", {"a": sharpness[:, None]}, 1)
    expected = lights.cap_radius(sharpness.astype(np.float64))
    # measured 3e-6 (llvmpipe's atan beyond sin 0.25; its asin would give 1e-4 absolute, 7% at sharpness 1e6)
    assert record_error("lights cap_radius, relative", np.abs(out / expected - 1).max()) <= 2e-5
