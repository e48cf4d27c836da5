"""Precomputed radiance transfer (visibility/transfer.py, kautz2002 section 5): the diffuse vector and the
glossy matrix against exact integrals where the visibility is known (nothing around; a roof over half the
sky), their PCA compression, and the per-frame products the shader weighs."""
import math

import numpy as np
import pytest

from sg_prt_addon.harmonics import basis, projection
from sg_prt_addon.visibility import transfer
from sg_prt_addon.visibility.raytrace import RayTracer


def _rule(z_low, z_high, phi_low, phi_high, count=48):
    """Gauss-Legendre over z in [z_low, z_high] x phi in [phi_low, phi_high]: exact for polynomials."""
    t, w = np.polynomial.legendre.leggauss(count)
    z = z_low + (z_high - z_low) * 0.5 * (t + 1)
    wz = (z_high - z_low) * 0.5 * w
    p, wp = np.polynomial.legendre.leggauss(count)
    phi = phi_low + (phi_high - phi_low) * 0.5 * (p + 1)
    wphi = (phi_high - phi_low) * 0.5 * wp
    r = np.sqrt(1 - z * z)
    d = np.stack(np.broadcast_arrays(r[:, None] * np.cos(phi), r[:, None] * np.sin(phi), z[:, None]), -1)
    return d.reshape(-1, 3), (wz[:, None] * wphi[None, :]).reshape(-1)


def _exact(directions, weights, normal, order):
    y = basis.evaluate(directions, order)
    cosine = np.maximum(directions @ normal, 0.0)
    return (weights * cosine) @ y, (y * weights[:, None]).T @ y


def _bake(vertices, normals, occluders, order=5, count=8192):
    tracer = RayTracer(*occluders) if occluders is not None else RayTracer(np.zeros((0, 3)), np.zeros((0, 3), int))
    try:
        samples = transfer.transfer_vectors(vertices, normals, tracer, order, count)
    finally:
        tracer.close()
    return transfer.unpack(samples.astype(np.float64), order)


def test_unoccluded_vertex_has_the_clamped_cosine_and_the_hemisphere():
    """Nothing around: t is the clamped cosine about n (Funk-Hecke, exact) and T the hemisphere's Gram
    matrix: exact (the open sky is integrated exactly, only occluded directions are sampled) up to the
    rotation into the world frame in float32 storage (measured 3e-8)."""
    normal = np.array([0.3, -0.4, 0.866])
    normal /= np.linalg.norm(normal)
    diffuse, glossy = _bake(np.zeros((1, 3)), normal[None], None)
    exact_diffuse = projection.rotate_zonal(projection.clamped_cosine_zonal(5), normal)
    # the hemisphere about n: the rule about +z turned to n (z -> n)
    directions, weights = _rule(0.0, 1.0, 0.0, 2 * math.pi)
    from scipy.spatial.transform import Rotation
    frame = Rotation.align_vectors([normal], [[0, 0, 1]])[0].as_matrix()
    _, exact_glossy = _exact(directions @ frame.T, weights, normal, 5)
    error_d = np.max(np.abs(diffuse[0] - exact_diffuse)) / np.max(np.abs(exact_diffuse))
    error_g = np.max(np.abs(glossy[0] - exact_glossy)) / np.max(np.abs(exact_glossy))
    print(error_d, error_g)
    assert error_d < 1e-6 and error_g < 1e-6


def test_a_roof_over_half_the_sky():
    """A vertex under a large roof covering x > 0 at height 1: visible is {z > 0, x < 0} (up to the roof's
    finite size: 1e3 wide, 0.06 degrees), a quarter sphere with exact integrals; 4096 hemisphere lattice
    points reach them to 1e-2 of the largest entry (measured 1.1e-3 and 3.1e-3)."""
    roof = np.array([[0.0, -1000.0, 1.0], [1000.0, -1000.0, 1.0], [1000.0, 1000.0, 1.0], [0.0, 1000.0, 1.0]])
    triangles = np.array([[0, 1, 2], [0, 2, 3]])
    diffuse, glossy = _bake(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), (roof, triangles))
    directions, weights = _rule(0.0, 1.0, math.pi / 2, 3 * math.pi / 2)
    exact_diffuse, exact_glossy = _exact(directions, weights, np.array([0.0, 0.0, 1.0]), 5)
    error_d = np.max(np.abs(diffuse[0] - exact_diffuse)) / np.max(np.abs(exact_diffuse))
    error_g = np.max(np.abs(glossy[0] - exact_glossy)) / np.max(np.abs(exact_glossy))
    print(error_d, error_g)
    assert error_d < 1e-2 and error_g < 1e-2


def test_pack_and_unpack_are_inverse_and_symmetric():
    rng = np.random.default_rng(0)
    diffuse = rng.normal(size=(3, 16))
    glossy = rng.normal(size=(3, 16, 16))
    glossy = glossy + np.swapaxes(glossy, 1, 2)
    vector = transfer.pack(diffuse, glossy)
    assert vector.shape == (3, transfer.vector_size(4))
    d, g = transfer.unpack(vector, 4)
    np.testing.assert_array_equal(d, diffuse)
    np.testing.assert_array_equal(g, glossy)


def test_compression_error_falls_with_terms_and_meets_its_target():
    """A floor's vertices under a sphere (the shadow varies over the floor): the relative RMS of the PCA
    reconstruction meets the error target with the fewest terms, and falls with more."""
    grid = np.stack(np.meshgrid(np.linspace(-2, 2, 24), np.linspace(-2, 2, 24)), -1).reshape(-1, 2)
    vertices = np.c_[grid, np.zeros(len(grid))]
    normals = np.tile([0.0, 0.0, 1.0], (len(grid), 1))
    sphere = projection.sphere_quadrature(10, 20)[0] * 0.7 + [0.0, 0.0, 1.0]
    from scipy.spatial import ConvexHull
    hull = ConvexHull(sphere)
    tracer = RayTracer(sphere, hull.simplices)
    try:
        samples = transfer.transfer_vectors(vertices, normals, tracer, 4, 1024)
    finally:
        tracer.close()
    model, errors = transfer.compress(samples, error_target=0.02)
    assert np.all(np.diff(errors) <= 1e-12) and errors[model.terms] <= 0.02 < errors[model.terms - 1]
    reconstructed = model.mean + (samples - model.mean) @ model.basis.T @ model.basis
    relative = np.sqrt(np.mean(np.sum((reconstructed - samples) ** 2, 1)) / np.mean(np.sum(samples ** 2, 1)))
    np.testing.assert_allclose(relative, errors[model.terms], rtol=1e-3)


def test_transferred_radiance_is_the_products_the_shader_weighs():
    rng = np.random.default_rng(1)
    order = 4
    mean = rng.normal(size=transfer.vector_size(order))
    basis_vectors = rng.normal(size=(3, transfer.vector_size(order)))
    lighting = rng.normal(size=(36, 3))            # more bands than the order: truncated
    out = transfer.transferred_radiance(np.concatenate([mean[None], basis_vectors]), lighting, order, order)
    weights = np.array([1.0, 0.3, -0.2, 0.5])
    vector = weights[0] * mean + weights[1:] @ basis_vectors
    diffuse, glossy = transfer.unpack(vector, order)
    combined = np.einsum("k,kic->ic", weights, out)
    np.testing.assert_allclose(combined[:16], glossy @ lighting[:16], rtol=1e-5, atol=1e-5)
    np.testing.assert_allclose(combined[16], diffuse @ lighting[:16], rtol=1e-5, atol=1e-5)


def test_a_lower_order_reads_the_leading_block():
    """Shading at order 3 from an order-5 transfer: the same as transferring at order 3."""
    rng = np.random.default_rng(2)
    diffuse, glossy = _bake(rng.normal(size=(2, 3)) * 0.1, np.tile([0.0, 0.0, 1.0], (2, 1)), None, order=5, count=512)
    low_diffuse, low_glossy = _bake(rng.normal(size=(2, 3)) * 0.0, np.tile([0.0, 0.0, 1.0], (2, 1)), None, order=3,
                                    count=512)
    np.testing.assert_allclose(diffuse[:, :9], low_diffuse, atol=1e-6)
    np.testing.assert_allclose(glossy[:, :9, :9], low_glossy, atol=1e-6)
    lighting = rng.normal(size=(25, 3))
    terms = transfer.pack(diffuse, glossy)
    out = transfer.transferred_radiance(terms, lighting, 5, 3)
    np.testing.assert_allclose(out[:, :9], np.einsum("kij,jc->kic", low_glossy, lighting[:9]), atol=1e-5)
    texture = transfer.basis_texture(terms[0], terms[1:])
    np.testing.assert_array_equal(transfer.basis_terms(texture)[:2], terms.astype(np.float32))
    assert transfer.order_of(terms.shape[1]) == 5


def test_bake_cancels_and_rejects_orders():
    vertices = np.zeros((4, 3))
    normals = np.tile([0.0, 0.0, 1.0], (4, 1))
    with pytest.raises(transfer.BakeCancelled):
        transfer.bake_transfer(vertices, np.zeros((0, 3), int), normals, np.zeros((0, 3)), np.zeros((0, 3), int),
                               progress=lambda fraction, message: True)
    with pytest.raises(ValueError, match="transfer order 9"):
        transfer.bake_transfer(vertices, np.zeros((0, 3), int), normals, np.zeros((0, 3)), np.zeros((0, 3), int),
                               transfer.TransferOptions(order=9))
