"""The pure parts of benchmarks/error_vs_time.py (no bpy): noise-corrected error, Pareto front,
rows, target check, the markdown table and the ERROR_VS_TIME.md section replacement."""
import math

import pytest

from benchmarks import error_vs_time as evt


def test_corrected_error_removes_the_noise_floor_in_quadrature():
    assert evt.corrected_error(0.05, 0.03) == pytest.approx(0.04)
    assert evt.corrected_error(0.02, 0.03) == 0.0          # the reference's noise explains it all
    assert evt.corrected_error(0.1, 0.0) == pytest.approx(0.1)
    assert evt.corrected_error(None, 0.03) is None
    assert evt.quadrature_difference(0.05, None) is None     # a missing part: nothing to take out


def test_pareto_front_keeps_the_points_nothing_beats():
    points = [(1.0, 0.5), (2.0, 0.4), (0.5, 0.9), (3.0, 0.45), (2.0, 0.3), (None, 0.1), (5.0, None), (10.0, 0.3)]
    # (2, 0.4) loses to (2, 0.3); (3, 0.45) to (2, 0.3); (10, 0.3) ties in error but is slower
    assert evt.pareto_front(points) == [2, 0, 4]
    assert evt.pareto_front([]) == []


def test_rows_and_target_check():
    rows = [evt.make_row("s", "SG-PRT", "bake R=32", 0.4, 0.05, 0.03, frame_seconds=0.2, bake_seconds=30.0,
                         parameters={"target": True}),
            evt.make_row("s", "SG-PRT", "no bake", 0.3, 0.2, 0.03),
            evt.make_row("s", "EEVEE", "1 sample", 5.0, 0.13, 0.03, relative_bias=0.3, parameters={"samples": 1}),
            evt.make_row("s", "EEVEE", "16 samples", 20.0, 0.1, 0.03, parameters={"samples": 16}),
            evt.make_row("s", "reference", "100 spp (error reference)", 300.0, None, 0.03)]
    assert rows[0]["corrected_rmse"] == pytest.approx(0.04)
    assert rows[0]["frame_seconds"] == 0.2 and rows[0]["bake_seconds"] == 30.0
    assert rows[4]["corrected_rmse"] == 0.03 and rows[4]["relative_rmse"] is None   # its own noise
    check = evt.target_check(rows, "s")
    assert check["time_ratio"] == pytest.approx(0.08) and check["time_target_met"]
    assert check["engine_error"] == pytest.approx(0.04)
    assert check["eevee16_error"] == pytest.approx(math.sqrt(0.1 ** 2 - 0.03 ** 2))
    assert check["error_target_met"]
    # the fastest shadowed setting below EEVEE 16's error (0.095): the bake (the unshadowed row is faster)
    assert check["matched_setting"] == "bake R=32" and check["matched_time_ratio"] == pytest.approx(0.08)
    assert "(target lower: met); fastest shadowed setting below EEVEE 16's error: bake R=32, error 0.040" \
        in evt.target_lines([check])[0]
    assert evt.target_check(rows, "other") == {"scene": "other", "engine_setting": None}

    table = evt.markdown_table(rows).splitlines()
    assert len(table) == 2 + len(rows)
    # front by (seconds, corrected): no bake 0.3 s / 0.198, bake 0.4 s / 0.04; the rest are slower and worse
    assert "| **no bake** |" in table[3] and "| **bake R=32** |" in table[2] and "**" not in table[4]
    assert "| 0.400 | 0.200 | 30.0 | 0.050 | 0.040 | 0.030 | - |" in table[2]
    assert "| 0.030 | +0.300 |" in table[4]

    data = {"command": "python -m benchmarks.error_vs_time", "size": 512, "runtime_seconds": 1200.0,
            "machine": {"cpu": "cpu", "cores": 2, "gl": "llvmpipe"}, "blender": "5.0.1", "date": "today",
            "load_average_start": 1.0, "load_average_end": 2.0, "eevee_settings": {"use_raytracing": False},
            "scenes": {"s": {"triangles": 10, "reference_spp": 100, "reference_noise": 0.02, "noise_floor": 0.03,
                             "reference_seconds": 300.0}},
            "rows": rows, "targets": [check]}
    section = evt.markdown_section(data)
    assert section.startswith("## Error vs time\n") and "20.0 min" in section
    assert "render() / EEVEE 1 sample = 0.080 (target <= 0.1: met)" in section
    assert "error 0.040 vs EEVEE 16 samples 0.095 (target lower: met)" in section


def test_replace_section_touches_only_its_own_section():
    text = "# Performance\n\nintro\n\n## Other\n\nkeep\n\n## Error vs time\n\nold\n\n## Later\n\nkeep too\n"
    new = evt.replace_section(text, "## Error vs time\n\nnew\n")
    assert new == "# Performance\n\nintro\n\n## Other\n\nkeep\n\n## Error vs time\n\nnew\n\n## Later\n\nkeep too\n"
    appended = evt.replace_section("# Performance\n\nintro\n", "## Error vs time\n\nnew\n")
    assert appended == "# Performance\n\nintro\n\n## Error vs time\n\nnew\n"
    assert evt.replace_section(appended, "## Error vs time\n\nnewer\n") == \
        "# Performance\n\nintro\n\n## Error vs time\n\nnewer\n"


def test_merge_runs_equals_one_run_of_all_the_samples():
    import numpy as np

    rng = np.random.default_rng(4)
    samples = rng.exponential(2.0, (10, 3, 2))            # 10 samples of a 3 x 2 "image"

    def run(part):
        return len(part), part.mean(axis=0), part.std(axis=0, ddof=1) / np.sqrt(len(part))

    image, error = evt.merge_runs([run(samples[:3]), run(samples[3:7]), run(samples[7:])])
    whole = run(samples)
    np.testing.assert_allclose(image, whole[1], rtol=1e-12)
    np.testing.assert_allclose(error, whole[2], rtol=1e-12)
