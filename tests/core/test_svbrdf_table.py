"""The tabulated SVBRDF format (measured.svbrdf_table): round trip, validation, evaluation."""
import dataclasses
import os

import numpy as np
import pytest

from sg_prt_addon.measured import svbrdf_table
from sg_prt_addon.reflectance import brdf
from validation import brdf_generators


@pytest.fixture(scope="module")
def table():
    return brdf_generators.generate_svbrdf_table(8, seed=2)[0]


def test_round_trip(tmp_path, table):
    path = tmp_path / "table.npz"
    svbrdf_table.write_svbrdf_table(path, table)
    back = svbrdf_table.read_svbrdf_table(path)
    for field in dataclasses.fields(table):
        np.testing.assert_array_equal(getattr(back, field.name), getattr(table, field.name))
    assert back.shape == (8, 8) and back.isotropic


@pytest.mark.parametrize("change, message", [
    (lambda t: dataclasses.replace(t, ndf=t.ndf[:, :, :-1]), "ndf: expected shape"),
    (lambda t: dataclasses.replace(t, specular=t.specular[:4]), "specular: expected shape"),
    (lambda t: dataclasses.replace(t, shadowing=np.where(np.arange(90) == 3, np.nan, t.shadowing)), "NaN"),
    (lambda t: dataclasses.replace(t, diffuse=-t.diffuse), "diffuse: negative"),
    (lambda t: dataclasses.replace(t, eta=t.eta.astype(np.int32)), "eta: expected a floating"),
    (lambda t: dataclasses.replace(t, ndf_theta=t.ndf_theta[::-1].copy()), "ndf_theta"),
    (lambda t: dataclasses.replace(t, ndf_phi=np.array([0.0, 1.0])), "ndf_phi"),
])
def test_writer_validates_and_writes_nothing(tmp_path, table, change, message):
    with pytest.raises(svbrdf_table.SvbrdfTableError, match=message):
        svbrdf_table.write_svbrdf_table(tmp_path / "bad.npz", change(table))
    assert os.listdir(tmp_path) == []


def test_reader_rejects_foreign_and_damaged_files(tmp_path, table):
    other = tmp_path / "other.npz"
    np.savez(other, format=np.array("something else"), version=np.array(1))
    with pytest.raises(svbrdf_table.SvbrdfTableError, match="not an SVBRDF table"):
        svbrdf_table.read_svbrdf_table(other)
    good = tmp_path / "good.npz"
    svbrdf_table.write_svbrdf_table(good, table)
    cut = tmp_path / "cut.npz"
    cut.write_bytes(good.read_bytes()[:1000])
    with pytest.raises(svbrdf_table.SvbrdfTableError, match="cannot read"):
        svbrdf_table.read_svbrdf_table(cut)
    with np.load(good) as data:
        arrays = dict(data)
    arrays["version"] = np.array(7)
    newer = tmp_path / "newer.npz"
    np.savez(newer, **arrays)
    with pytest.raises(svbrdf_table.SvbrdfTableError, match="version 7"):
        svbrdf_table.read_svbrdf_table(newer)
    del arrays["shadowing"]
    arrays["version"] = np.array(1)
    np.savez(newer, **arrays)
    with pytest.raises(svbrdf_table.SvbrdfTableError, match="missing arrays"):
        svbrdf_table.read_svbrdf_table(newer)


def test_evaluation_matches_eq13():
    """A one-texel table holding GGX's D and the Smith G1 as S equals the separable-Smith GGX
    with Fresnel and a Lambert term (the microfacet 4 of GGX becomes the table's pi via ks)."""
    theta = svbrdf_table.default_ndf_theta(400)
    shadow_theta = np.linspace(0, np.pi / 2, 400)[:-1]
    alpha, eta = 0.25, 1.45
    model = brdf.GGX(roughness=0.5)
    ndf = model.ndf(np.stack([np.sin(theta), 0 * theta, np.cos(theta)], -1))
    g1 = 1 / (1 + brdf.GGX.smith_lambda(np.stack([np.sin(shadow_theta), 0 * shadow_theta,
                                                  np.cos(shadow_theta)], -1), alpha))
    table = svbrdf_table.SvbrdfTable(
        diffuse=np.full((1, 1, 3), 0.3), specular=np.full((1, 1, 3), np.pi / 4), eta=np.full((1, 1), eta),
        ndf_theta=theta, ndf_phi=np.zeros(1), ndf=ndf[None, None, :, None], shadowing_theta=shadow_theta,
        shadowing=g1[None, None]).validate()
    material = brdf_generators.AnalyticMaterial(diffuse=(0.3,) * 3, oren_nayar_sigma=0.0, roughness=0.5, eta=eta,
                                                retro=(0, 0, 0), separable_shadowing=True)
    rng = np.random.default_rng(1)
    wo, wi = rng.normal(size=(2, 2000, 3))
    wo[:, 2], wi[:, 2] = np.abs(wo[:, 2]) + 0.05, np.abs(wi[:, 2]) + 0.05
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    np.testing.assert_allclose(table.evaluate(wo, wi)[0], material.evaluate(wo, wi), rtol=5e-3)
    below = wi * np.array([1, 1, -1])
    assert np.all(table.evaluate(wo, below) == 0)


def test_anisotropic_ndf_interpolation_is_periodic():
    theta = svbrdf_table.default_ndf_theta(30)
    phi = 2 * np.pi * np.arange(8) / 8
    values = (1 + np.cos(phi))[None, :] * np.ones((30, 1))
    h_near_2pi = np.array([[np.sin(0.3) * np.cos(-1e-9), np.sin(0.3) * np.sin(-1e-9), np.cos(0.3)]])
    got = svbrdf_table.interpolate_ndf(values[None], theta, phi, h_near_2pi)
    assert got[0, 0] == pytest.approx(2.0, abs=1e-6)
    between = np.array([[np.sin(0.3) * np.cos(np.pi / 8), np.sin(0.3) * np.sin(np.pi / 8), np.cos(0.3)]])
    expected = 0.5 * (values[0, 0] + values[0, 1])
    assert svbrdf_table.interpolate_ndf(values[None], theta, phi, between)[0, 0] == pytest.approx(expected)
