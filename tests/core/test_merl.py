"""MERL binary BRDF files (measured.merl): round trip, validation errors, sample cleaning, lookup."""
import os

import numpy as np
import pytest

from sg_prt_addon.measured import merl
from validation import brdf_generators


@pytest.fixture(scope="module")
def valid_file(tmp_path_factory):
    """A MERL file of smooth positive data with a few -1, NaN and Inf samples; (path, rho written)."""
    rng = np.random.default_rng(3)
    rho = rng.uniform(0.01, 2.0, merl.DIMENSIONS + (3,))
    rho[0, 0, :5, 0] = -1.0
    rho[1, 2, 3, 1] = np.nan
    rho[4, 5, 6, 2] = np.inf
    rho[7, 8, 9, :] = -np.inf
    path = tmp_path_factory.mktemp("merl") / "test.binary"
    merl.write_merl(path, rho)
    return path, rho


def test_round_trip_and_layout(valid_file):
    path, rho = valid_file
    assert os.path.getsize(path) == merl.FILE_BYTES == 12 + 3 * 1_458_000 * 8
    raw = np.fromfile(path, "<i4", count=3)
    assert tuple(raw) == (90, 90, 180)
    # planar float64 after the header: the first value is red sample 0 divided by the red scale
    first_red = np.fromfile(path, "<f8", count=1, offset=12)[0]
    assert first_red == pytest.approx(rho[0, 0, 0, 0] * 1500, rel=1e-12)
    blue_start = 12 + 8 * 2 * merl.SAMPLE_COUNT
    first_blue = np.fromfile(path, "<f8", count=1, offset=blue_start)[0]
    assert first_blue == pytest.approx(rho[0, 0, 0, 2] * 1500 / 1.66, rel=1e-12)
    brdf = merl.read_merl(path)
    ok = np.all(np.isfinite(rho) & (rho >= 0), axis=-1)
    np.testing.assert_allclose(brdf.rho[ok], rho[ok], rtol=1e-12)
    assert np.array_equal(brdf.valid, ok)


def test_invalid_samples_counted_and_cleaned(valid_file):
    path, _ = valid_file
    brdf = merl.read_merl(path)
    assert brdf.counts == {"negative": 5, "nan": 1, "inf": 4}
    assert np.all(np.isfinite(brdf.rho)) and np.all(brdf.rho >= 0)
    assert brdf.rho[0, 0, 0, 0] == 0 and brdf.rho[1, 2, 3, 1] == 0 and np.all(brdf.rho[7, 8, 9] == 0)
    assert (~brdf.valid).sum() == 5 + 1 + 1 + 1


def _corrupt(tmp_path, valid_file, name, mutate):
    data = bytearray(valid_file[0].read_bytes())
    path = tmp_path / name
    path.write_bytes(bytes(mutate(data)))
    return path


@pytest.mark.parametrize("name, mutate, words", [
    ("truncated.binary", lambda d: d[:-8], ["truncated", str(merl.FILE_BYTES), str(merl.FILE_BYTES - 8)]),
    ("cut_header.binary", lambda d: d[:7], ["header", "12", "7"]),
    ("trailing.binary", lambda d: d + b"\0" * 16, ["wrong size", str(merl.FILE_BYTES)]),
    ("dims.binary", lambda d: np.array([90, 90, 360], "<i4").tobytes() + d[12:], ["dimensions", "(90, 90, 180)",
                                                                                  "(90, 90, 360)"]),
    ("big_endian.binary", lambda d: np.array([90, 90, 180], ">i4").tobytes() + d[12:], ["dimensions"]),
])
def test_corrupt_files_raise_named_errors(tmp_path, valid_file, name, mutate, words):
    path = _corrupt(tmp_path, valid_file, name, mutate)
    before = sorted(os.listdir(tmp_path))
    with pytest.raises(merl.MerlFormatError) as info:
        merl.read_merl(path)
    assert isinstance(info.value, ValueError)
    for word in words:
        assert word in str(info.value)
    assert sorted(os.listdir(tmp_path)) == before  # nothing written


def test_unreadable_paths(tmp_path):
    with pytest.raises(merl.MerlFormatError, match="cannot read"):
        merl.read_merl(tmp_path / "missing.binary")
    with pytest.raises(merl.MerlFormatError, match="cannot read"):
        merl.read_merl(tmp_path)  # a directory


def test_writer_rejects_wrong_shape_and_writes_nothing(tmp_path):
    with pytest.raises(merl.MerlFormatError, match=r"\(90, 90, 180, 3\)"):
        merl.write_merl(tmp_path / "bad.binary", np.zeros((90, 90, 90, 3)))
    assert os.listdir(tmp_path) == []


def test_angles_round_trip_and_bins():
    rng = np.random.default_rng(0)
    theta_h, theta_d = rng.uniform(0, 1.5, 500), rng.uniform(0, 1.5, 500)
    phi_d, phi_h = rng.uniform(-3, 3, 500), rng.uniform(-3, 3, 500)
    wo, wi = merl.directions_from_half_difference(theta_h, theta_d, phi_d, phi_h)
    got = merl.half_difference_angles(wo, wi)
    np.testing.assert_allclose(got[0], theta_h, atol=1e-12)
    np.testing.assert_allclose(got[2], theta_d, atol=1e-12)
    assert np.max(np.abs(np.angle(np.exp(1j * (got[3] - phi_d))))) < 1e-9
    # every bin centre maps back to its own bin
    (t, d, p), (ih, jd, kp) = merl.bin_centre_angles(3, 5, 7)
    wo, wi = merl.directions_from_half_difference(t, d, p, 0.7)
    bins = merl.bin_indices(wo, wi)
    assert np.array_equal(bins[0], ih) and np.array_equal(bins[1], jd) and np.array_equal(bins[2], kp)


def test_reciprocity_and_evaluation(tmp_path):
    """A generated material read back evaluates like the analytic one at bin centres,
    symmetrically in (o, i), and 0 below the horizon."""
    material = brdf_generators.AnalyticMaterial(roughness=0.4)
    path = tmp_path / "material.binary"
    clean = brdf_generators.generate_merl(path, material, relative_noise=0.0, corrupt_fraction=0.0)
    brdf = merl.read_merl(path)
    assert brdf.counts["nan"] == 0 and brdf.counts["inf"] == 0
    assert brdf.counts["negative"] == 3 * np.sum(np.all(clean < 0, axis=-1))  # the below-horizon markers
    (t, d, p), _ = merl.bin_centre_angles(4, 4, 8)
    wo, wi = merl.directions_from_half_difference(t, d, p, 1.1)
    wo, wi = wo.reshape(-1, 3), wi.reshape(-1, 3)
    above = (wo[:, 2] > 0) & (wi[:, 2] > 0)
    np.testing.assert_allclose(brdf.evaluate(wo, wi)[above], material.evaluate(wo, wi)[above], rtol=1e-9)
    np.testing.assert_array_equal(brdf.evaluate(wo, wi), brdf.evaluate(wi, wo))
    assert np.all(brdf.evaluate(wo[~above], wi[~above]) == 0)
