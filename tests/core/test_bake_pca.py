"""sg_prt_addon.visibility.pca (wang2009 eq. 24): error falls with terms, the chosen terms meet the target,
the reported RMS error is the measured one."""
import numpy as np
import pytest

from sg_prt_addon.visibility import hemisphere_map, pca, ssdf


@pytest.fixture(scope="module")
def ssdf_samples():
    """SSDFs (V, 16 * 16) of spherical-cap occluders of random centre and size (plus the open plane)."""
    resolution, refinement = 16, 3
    fine = hemisphere_map.texel_directions(resolution * refinement)
    rng = np.random.default_rng(6)
    count = 400
    centre = rng.normal(size=(count, 3))
    centre[:, 2] = np.abs(centre[:, 2])
    centre /= np.linalg.norm(centre, axis=1, keepdims=True)
    radius = rng.uniform(0.05, 0.8, count)
    radius[:20] = 0.0
    visible = np.einsum("rcx,bx->brc", fine, centre) < np.cos(radius)[:, None, None]
    values = ssdf.ssdf_from_fine(visible, resolution).reshape(count, -1)
    return values.astype(np.float16)


def test_error_falls_with_terms_and_matches_the_reconstruction(ssdf_samples):
    model = pca.fit(ssdf_samples, terms=40)
    errors = model.rms_error_by_terms
    assert np.all(np.diff(errors) <= 1e-12)
    assert errors[40] < 0.25 * errors[0]
    data = ssdf_samples.astype(np.float64)
    for terms in (1, 5, 20, 40):
        truncated = pca.PcaModel(model.mean, model.basis[:terms], model.eigenvalues, errors, model.total_variance)
        measured = np.sqrt(np.mean((pca.reconstruct(truncated, pca.project(truncated, ssdf_samples)) - data) ** 2))
        assert abs(measured - errors[terms]) < 1e-5 + 1e-4 * errors[terms], (terms, measured, errors[terms])


def test_error_target_picks_the_fewest_terms(ssdf_samples):
    target = 0.05
    model = pca.fit(ssdf_samples, terms=None, error_target=target, max_terms=64)
    assert model.rms_error <= target
    assert model.rms_error_by_terms[model.terms - 1] > target
    capped = pca.fit(ssdf_samples, terms=None, error_target=1e-9, max_terms=6)
    assert capped.terms == 6


def test_basis_is_orthonormal_and_deterministic(ssdf_samples):
    a = pca.fit(ssdf_samples, terms=10)
    b = pca.fit(ssdf_samples[::-1].copy(), terms=10)   # order of vertices does not matter
    assert np.abs(a.basis @ a.basis.T - np.eye(10)).max() < 1e-10
    assert np.abs(a.basis - b.basis).max() < 1e-6
