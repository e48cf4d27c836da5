"""The pure parts of benchmarks/truth_suite.py (no bpy): rows, the truth's noise floor, equal-time
samples, the issue's goals, the markdown section, tone mapping and HDR-FLIP."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from benchmarks import truth_suite as ts

ROOT = Path(__file__).resolve().parents[2]


def test_importing_the_suite_does_not_import_bpy():
    code = "import sys; import benchmarks.truth_suite; assert 'bpy' not in sys.modules, 'bpy imported'"
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True)


def test_every_scene_records_its_kind_and_roughness():
    assert len(ts.SCENES) == 17
    for name, scene in ts.SCENES.items():
        assert scene.kind in ("diffuse", "glossy"), name
        assert (scene.roughness is None) == (scene.kind == "diffuse"), name
        assert callable(scene.build) and scene.description, name
    assert ts.SCENES["ggx010_hdri"].roughness == 0.10 and ts.SCENES["diffuse_sun"].kind == "diffuse"
    # Ashikhmin-Shirley nv 800: alpha sqrt(2 / 802) = 0.050, Blender roughness sqrt(alpha) = 0.22
    assert ts.SCENES["aniso_torus_hdri"].roughness == pytest.approx(0.223, abs=1e-3)


def test_make_row_keeps_the_fields_and_extras():
    row = ts.make_row("s", "SG-PRT", "bake R=32", 0.25, 0.08, -0.01, 0.12, 0.01, bake_seconds=12.0)
    assert row == {"scene": "s", "method": "SG-PRT", "setting": "bake R=32", "seconds": 0.25,
                   "relative_rmse": 0.08, "relative_bias": -0.01, "hdr_flip": 0.12, "noise_floor": 0.01,
                   "bake_seconds": 12.0}
    empty = ts.make_row("s", "Cycles", "truth", 3)
    assert empty["relative_rmse"] is None and empty["hdr_flip"] is None and isinstance(empty["seconds"], float)


def test_noise_floor_is_the_rmse_of_the_mean_of_two_seeds():
    rng = np.random.default_rng(1)
    clean = rng.uniform(0.5, 1.5, (200, 200, 3))
    sigma = 0.05
    first = clean + rng.normal(0.0, sigma, clean.shape)
    second = clean + rng.normal(0.0, sigma, clean.shape)
    truth, floor = ts.truth_and_noise_floor(first, second)
    np.testing.assert_allclose(truth, 0.5 * (first + second))
    # the mean has noise sigma / sqrt(2): its RMSE against the clean image, relative to the mean
    expected = sigma / np.sqrt(2.0) / clean.mean()
    assert floor == pytest.approx(expected, rel=0.02)
    actual = np.sqrt(np.mean((truth - clean) ** 2)) / clean.mean()
    assert floor == pytest.approx(actual, rel=0.02)
    mask = np.zeros((200, 200), bool)
    mask[:50] = True
    _, masked = ts.truth_and_noise_floor(first, second, mask)
    assert masked == pytest.approx(expected, rel=0.05)
    assert ts.truth_and_noise_floor(first, first)[1] == 0.0


def test_equal_time_samples_fits_a_fixed_cost_and_a_cost_per_sample():
    # 1 spp: 0.3 s, 101 spp: 10.3 s -> 0.1 s a sample, 0.2 s fixed
    assert ts.equal_time_samples(1.2, 0.3, 10.3, 101) == 10
    assert ts.equal_time_samples(0.05, 0.3, 10.3, 101) == 1          # at least one sample
    assert ts.equal_time_samples(100.0, 0.3, 10.3, 101) == 998       # beyond the truth's samples is fine
    # no measurable growth (the fixed cost dominates): the mean cost a sample, the rest of the
    # 1-sample render fixed: 0.1 s a sample, 0.9 s fixed
    assert ts.equal_time_samples(2.0, 1.0, 1.0, 10) == 11
    assert ts.equal_time_samples(0.5, 0.1, 0.1, 1) == 5


def test_rmse_goals():
    assert ts.rmse_goal("diffuse", None) == 0.05
    assert ts.rmse_goal("glossy", 0.1) == 0.10 and ts.rmse_goal("glossy", 0.6) == 0.10
    assert ts.rmse_goal("glossy", 0.05) is None
    assert ts.rmse_goal("glossy", None) is None


def _rows():
    return [ts.make_row("a", "SG-PRT", "bake R=32", 0.2, 0.04, 0.01, 0.05, 0.01),
            ts.make_row("a", "SG-PRT unshadowed", "no bake", 0.15, 0.2, 0.1, 0.2, 0.01),
            ts.make_row("a", "EEVEE", "1 sample", 2.0, 0.3, 0.0, 0.3, 0.01, samples=1),
            ts.make_row("a", "EEVEE", "16 samples", 8.0, 0.1, 0.0, 0.08, 0.01, samples=16),
            ts.make_row("a", "Cycles", "512 spp x 2 seeds (truth)", 30.0, None, None, None, 0.01, samples=512),
            ts.make_row("a", "Cycles equal time", "3 spp", 0.25, 0.5, 0.0, 0.4, 0.01, samples=3),
            ts.make_row("a", "Factored BRDF", "bake R=32, technique FACTORED", 0.1, 0.07, 0.02, 0.06, 0.01),
            ts.make_row("b", "SG-PRT", "bake R=32", 0.3, 0.12, -0.05, 0.2, 0.02),
            ts.make_row("b", "EEVEE", "16 samples", 8.0, 0.3, 0.0, 0.15, 0.02, samples=16),
            ts.make_row("c", "SG-PRT", "bake R=32", 0.3, 0.3, 0.0, None, 0.02)]


def test_goal_check_per_scene():
    rows = _rows()
    a = ts.goal_check(rows, "a", "diffuse", None)
    assert a["flip_met"] is True and a["rmse_met"] is True and a["rmse_goal"] == 0.05
    b = ts.goal_check(rows, "b", "glossy", 0.3)
    assert b["flip_met"] is False and b["rmse_met"] is False and b["eevee16_flip"] == 0.15
    c = ts.goal_check(rows, "c", "glossy", 0.05)            # no EEVEE row, no FLIP, no RMSE goal
    assert c["flip_met"] is None and c["rmse_met"] is None and c["rmse_goal"] is None
    missing = ts.goal_check(rows, "d", "diffuse", None)
    assert missing["flip_met"] is None and missing["rmse_met"] is None
    assert ts.goal_summary([a, b, c]) == ("SG-PRT HDR-FLIP below EEVEE 16 samples': 1/2 scenes; "
                                          "relative RMSE goal: 1/2 scenes")
    lines = ts.goal_lines([a, b, c])
    assert lines[0] == "a: HDR-FLIP 0.050 vs EEVEE 16 0.080 (met); RMSE 0.040 < 0.05 (met)"
    assert "(NOT met)" in lines[1] and "no RMSE goal" in lines[2] and "(n/a)" in lines[2]


def test_markdown_table_has_a_line_per_scene_in_order():
    scenes = {"b": {"kind": "glossy", "roughness": 0.3}, "a": {"kind": "diffuse", "roughness": None}}
    table = ts.markdown_table(_rows(), scenes).splitlines()
    assert len(table) == 4 and table[0].count("|") == table[1].count("|") == table[2].count("|")
    assert table[2].startswith("| b | glossy 0.3 | 0.120 | -0.050 | 0.200 | - | 0.150 | 0.300 | - | 0.020 |")
    assert table[3].startswith("| a | diffuse | 0.040 | +0.010 | 0.050 | 0.200 | 0.080 | 0.100 | 0.400 (3) | "
                               "0.010 | 0.200 | 30.0 |")


def test_techniques_table_puts_each_technique_beside_the_sg_lobes():
    scenes = {"a": {"kind": "diffuse", "roughness": None}, "b": {"kind": "glossy", "roughness": 0.3}}
    table = ts.techniques_table(_rows(), scenes).splitlines()
    assert table[0] == ("| scene | kind | SG lobes RMSE / HDR-FLIP / s | Factored BRDF RMSE / HDR-FLIP / s "
                        "| Spherical harmonics RMSE / HDR-FLIP / s | noise floor |")
    assert table[2] == "| a | diffuse | 0.040 / 0.050 / 0.200 | 0.070 / 0.060 / 0.100 | - / - / - | 0.010 |"
    assert table[3] == "| b | glossy 0.3 | 0.120 / 0.200 / 0.300 | - / - / - | - / - / - | - |"


def _data():
    return {"command": "python -m benchmarks.truth_suite --quick", "size": 64, "cycles_samples": 32,
            "eevee_samples": [1, 16], "runtime_seconds": 90.0, "blender": "5.0.1", "date": "2026-01-01 00:00 UTC",
            "machine": {"cpu": "Test CPU", "cores": 2, "gl": "Mesa llvmpipe (no GPU)"},
            "scenes": {"a": {"kind": "diffuse", "roughness": None}, "b": {"kind": "glossy", "roughness": 0.3}},
            "rows": _rows()}


def test_markdown_section_and_its_replacement_in_accuracy_md():
    section = ts.markdown_section(_data())
    assert section.startswith(ts.SECTION_TITLE + "\n")
    assert "`.venv/bin/python -m benchmarks.truth_suite --quick` (64x64; Cycles 32 spp x 2 seeds" in section
    assert "noise floor" in section.lower() and "/ 2" in section
    assert "- a: HDR-FLIP 0.050 vs EEVEE 16 0.080 (met)" in section
    assert "1/2 scenes" in section
    text = "# Accuracy\n\nintro\n\n## clamped_cosine\n\ntable\n\n## warp\n\nrows\n"
    once = ts.replace_section(text, section)
    assert once.startswith(text.rstrip("\n")) and once.endswith(section)
    twice = ts.replace_section(once, ts.markdown_section({**_data(), "size": 128}))
    assert twice.count(ts.SECTION_TITLE) == 1 and "(128x128;" in twice and "## warp\n\nrows\n" in twice
    middle = ts.replace_section(text.replace("## warp", ts.SECTION_TITLE + "\n\nold\n\n## warp"), section)
    assert "old" not in middle and middle.index(ts.SECTION_TITLE) < middle.index("## warp")


def test_a_later_run_of_some_scenes_goes_into_the_earlier_json():
    earlier = {**_data(), "goals": [{"scene": "a"}, {"scene": "b"}]}
    later_rows = [ts.make_row("b", "SG-PRT", "again", 0.2, 0.01, 0.0, 0.02), ts.make_row("c", "SG-PRT", "new", 0.3)]
    later = {**_data(), "command": "python -m benchmarks.truth_suite --scenes b,c", "runtime_seconds": 30.0,
             "date": "2026-01-02 00:00 UTC", "scenes": {"b": {"kind": "glossy", "roughness": 0.3},
                                                        "c": {"kind": "diffuse", "roughness": None}},
             "rows": later_rows, "goals": [{"scene": "b", "new": True}, {"scene": "c"}]}
    merged = ts.merged_run(earlier, later)
    assert [row["scene"] for row in merged["rows"]].count("b") == 1 and merged["rows"][-2:] == later_rows
    assert set(merged["scenes"]) == {"a", "b", "c"} and {"scene": "b", "new": True} in merged["goals"]
    assert merged["command"] == earlier["command"] and len(merged["goals"]) == 3
    assert merged["added_runs"] == [{"command": later["command"], "scenes": ["b", "c"], "date": later["date"],
                                     "runtime_seconds": 30.0}]
    section = ts.markdown_section(merged)
    assert "; b, c: `.venv/bin/python -m benchmarks.truth_suite --scenes b,c` (0.5 min; 2026-01-02" in section
    with pytest.raises(ValueError, match="cycles_samples"):
        ts.merged_run(earlier, {**later, "cycles_samples": 64})


def test_before_sentence_names_a_change_of_truth_samples():
    rows = _rows()
    same = ts.markdown_section(_data(), ("4 lobes", rows, 32))
    assert "SG-PRT before and after (4 lobes; the same scenes, size and truth samples):" in same
    assert "(4 lobes; the same scenes, size and truth samples)" in ts.markdown_section(_data(), ("4 lobes", rows, None))
    other = ts.markdown_section(_data(), ("the same engine", rows, 8))
    assert "(the same engine; the same scenes and size; the truth at 8 spp a seed then, 32 now):" in other


def test_tone_map_and_side_by_side():
    image = np.array([[[0.0, 0.5, 1.0], [2.0, -1.0, np.nan]]])
    mapped = ts.tone_map(image)
    assert mapped.dtype == np.uint8
    np.testing.assert_array_equal(mapped, [[[0, round(255 * 0.5 ** (1 / 2.2)), 255], [255, 0, 0]]])
    panel = ts.side_by_side([np.ones((4, 5, 3)), None, np.zeros((4, 5, 3))], gap=2)
    assert panel.shape == (4, 5 * 3 + 2 * 2, 3)
    assert (panel[:, :5] == 255).all() and (panel[:, 5:7] == 255).all() and (panel[:, 7:12] == 0).all()


def test_parse_scene_list():
    known = {"x": 1, "y": 2, "z": 3}
    assert ts.parse_scene_list(None, known) == ["x", "y", "z"]
    assert ts.parse_scene_list("z, x", known) == ["z", "x"]
    with pytest.raises(ValueError, match="unknown scene"):
        ts.parse_scene_list("x,w", known)


def test_hdr_flip_is_zero_for_equal_images_and_grows_with_the_error():
    pytest.importorskip("flip_evaluator")
    rng = np.random.default_rng(2)
    reference = rng.uniform(0.0, 2.0, (48, 64, 3))
    assert ts.hdr_flip(reference, reference) == pytest.approx(0.0, abs=1e-6)
    small = ts.hdr_flip(reference, reference * 1.05)
    large = ts.hdr_flip(reference, reference * 1.5)
    assert 0.0 < small < large <= 1.0
    mask = np.zeros((48, 64), bool)
    mask[:, :32] = True
    test = reference.copy()
    test[:, 40:] *= 3.0                  # wrong only far from the scored half
    assert ts.hdr_flip(reference, test, mask) < 0.01 < ts.hdr_flip(reference, test)
    # the background (not scored) taken from the reference: no error left
    assert ts.hdr_flip(reference, test, background_mask=~mask) < 1e-6


def test_hdr_flip_without_the_package_returns_none(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "flip_evaluator", None)       # import raises ImportError
    monkeypatch.setattr(ts, "_FLIP_WARNED", [])
    image = np.ones((8, 8, 3))
    assert ts.hdr_flip(image, image) is None
    assert ts.hdr_flip(image, image) is None
    out = capsys.readouterr().out
    assert out.count("HDR-FLIP skipped") == 1 and "flip-evaluator" in out


def test_before_after_table_lists_both_versions():
    from benchmarks import truth_suite

    before = [truth_suite.make_row("s", "SG-PRT", "bake", 0.1, relative_rmse=0.5, relative_bias=-0.08, hdr_flip=0.2)]
    after = [truth_suite.make_row("s", "SG-PRT", "bake", 0.1, relative_rmse=0.25, relative_bias=0.01, hdr_flip=0.1),
             truth_suite.make_row("s", "SG-PRT 2x2", "2x", 0.4, relative_rmse=0.1)]
    table = truth_suite.before_after_table(before, after, ["s"]).splitlines()
    assert table[2] == "| s | 0.500 | 0.250 | -0.080 | +0.010 | 0.200 | 0.100 | - | 0.100 |"


def test_error_budget_splits_the_shading_from_the_rest():
    rows = [ts.make_row("s", "SG-PRT", "bake", 0.1, relative_rmse=0.5, noise_floor=0.14),
            ts.make_row("s", "SG-PRT unshadowed", "no bake", 0.1, relative_rmse=0.9, shading_relative_rmse=0.3,
                        shading_relative_bias=-0.02),
            ts.make_row("s", "Cycles unshadowed", "truth", 1.0, unshadowed_noise_floor=0.01),
            ts.make_row("t", "SG-PRT", "bake", 0.1, relative_rmse=0.1)]          # no unshadowed truth
    table = ts.error_budget_table(rows, {"s": {"kind": "glossy", "roughness": 0.3}, "t": {"kind": "diffuse"}})
    lines = table.splitlines()
    # visibility's share sqrt(0.5^2 - 0.3^2); less the truth's noise sqrt(0.5^2 - 0.14^2)
    assert lines[2] == "| s | glossy 0.3 | 0.500 / 0.480 | 0.300 / -0.020 | 0.400 | 0.010 |"
    assert lines[3] == "| t | diffuse | 0.100 / - | - / - | - | - |"
    assert ts.corrected_error(0.1, 0.2) == 0.0                 # a floor above the RMSE leaves nothing, not NaN
