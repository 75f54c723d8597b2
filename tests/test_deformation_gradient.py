"""Deformation gradients T_i (Eq. 1 with the normal term)."""

import numpy as np
import pytest
from geometry_fixtures import bumpy, grid, icosphere, random_rotation, tube, twist_bend

from meshvae_lib import defaults as hp
from meshvae_lib.geometry.cotangent import cotangent_weights
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator, deformation_gradients
from meshvae_lib.geometry.topology import edge_index, edges, one_rings, vertex_normal_sums

AFFINE = np.array([[1.2, 0.3, 0.1], [-0.2, 0.9, 0.4], [0.1, 0.2, 1.1]])


def _naive(V0, V, F, normal_term=True):
    """Per-vertex weighted least squares, written as a loop."""
    E = edges(F)
    c = cotangent_weights(V0, F)
    indptr, ring = one_rings(F, len(V0))
    l = hp.NORMAL_EDGE_SCALE * np.mean(np.linalg.norm(V0[E[:, 0]] - V0[E[:, 1]], axis=1))
    s0, s1 = vertex_normal_sums(V0, F), vertex_normal_sums(V, F)
    out = []
    for i in range(len(V0)):
        rows_a, rows_b, wts = [], [], []
        for j in ring[indptr[i]:indptr[i + 1]]:
            rows_a.append(V0[i] - V0[j])
            rows_b.append(V[i] - V[j])
            wts.append(c[edge_index(E, i, j)])
        if normal_term:
            n0, n1 = np.linalg.norm(s0[i]), np.linalg.norm(s1[i])
            rows_a.append(l * s0[i] / n0)
            rows_b.append(l * np.sqrt(n1 / n0) * s1[i] / n1)
            wts.append(hp.NORMAL_EDGE_WEIGHT)
        sw = np.sqrt(np.array(wts))[:, None]
        # minimise sum w |b - T a|^2  <=>  (sw a) T^T = (sw b)
        Tt, *_ = np.linalg.lstsq(sw * np.array(rows_a), sw * np.array(rows_b), rcond=None)
        out.append(Tt.T)
    return np.array(out)


def test_vectorised_operator_matches_naive_loop():
    V0, F = tube(6, 4)
    V0 = bumpy(V0, seed=1)
    V = twist_bend(V0, 200, 90)
    for normal_term in (True, False):
        np.testing.assert_allclose(deformation_gradients(V0, V, F, normal_term=normal_term),
                                   _naive(V0, V, F, normal_term), atol=1e-11)


def test_raw_weights_match_normal_equations_and_stay_affine_exact():
    """clamp=False: Eq. (1) with the raw, partly negative cotangent weights, as a loop over vertices
    (T_i = (sum_j c_ij e'_ij e_ij^T)(sum_j c_ij e_ij e_ij^T)^-1); an affine map is still exact."""
    V0, F = tube(8, 6)
    V0 = bumpy(V0, amount=0.5, seed=1)
    raw = cotangent_weights(V0, F, clamp=False)
    assert np.sum(raw < 0) >= 10  # the case clamping exists for
    V = twist_bend(V0, 120, 60)
    E = edges(F)
    indptr, ring = one_rings(F, len(V0))
    expected = []
    for i in range(len(V0)):
        A, B = np.zeros((3, 3)), np.zeros((3, 3))
        for j in ring[indptr[i]:indptr[i + 1]]:
            c, e, e_def = raw[edge_index(E, i, j)], V0[i] - V0[j], V[i] - V[j]
            A += c * np.outer(e, e)
            B += c * np.outer(e_def, e)
        expected.append(B @ np.linalg.inv(A))
    T = deformation_gradients(V0, V, F, normal_term=False, clamp=False)
    np.testing.assert_allclose(T, np.array(expected), atol=1e-9)
    assert not np.allclose(T, deformation_gradients(V0, V, F, normal_term=False), atol=1e-3)  # clamping matters here
    T_aff = deformation_gradients(V0, V0 @ AFFINE.T, F, normal_term=False, clamp=False)
    np.testing.assert_allclose(T_aff, np.broadcast_to(AFFINE, T_aff.shape), atol=1e-9)


def test_affine_map_gives_its_matrix_at_every_vertex():
    # pure Eq. 1 reproduces any affine map on curved one-rings
    V0, F = icosphere(2)
    V0 = bumpy(V0)
    T = deformation_gradients(V0, V0 @ AFFINE.T + [1.0, -2.0, 0.5], F, normal_term=False)
    np.testing.assert_allclose(T, np.broadcast_to(AFFINE, T.shape), atol=1e-12)


@pytest.mark.parametrize("mesh", ["sphere", "grid"])
def test_similarity_gives_its_matrix_with_normal_term(mesh):
    V0, F = icosphere(2) if mesh == "sphere" else grid(5, 4)
    V0 = bumpy(V0) if mesh == "sphere" else V0
    A = 2.5 * random_rotation(3)
    T = deformation_gradients(V0, V0 @ A.T + 3.0, F)
    np.testing.assert_allclose(T, np.broadcast_to(A, T.shape), atol=1e-12)


def test_in_plane_affine_on_flat_grid_with_normal_term():
    # a flat one-ring sees only the in-plane part; with det = 1 in-plane and z kept, T = A exactly
    V0, F = grid(5, 4)
    A = np.array([[1.25, 0.3, 0.0], [0.0, 0.8, 0.0], [0.0, 0.0, 1.0]])  # in-plane det = 1
    T = deformation_gradients(V0, V0 @ A.T, F)
    np.testing.assert_allclose(T, np.broadcast_to(A, T.shape), atol=1e-12)


def test_flat_one_ring_needs_the_normal_term():
    V0, F = grid(3, 3)
    with pytest.raises(ValueError, match="singular"):
        DeformationGradientOperator(V0, F, normal_term=False)
    op = DeformationGradientOperator(V0, F)
    assert np.max(np.linalg.cond(op.A)) < 100


def test_conditioning_and_linearity_in_positions_and_normal_edges():
    V0, F = icosphere(2)
    V0 = bumpy(V0, seed=2)
    op = DeformationGradientOperator(V0, F)
    assert np.median(np.linalg.cond(op.A)) < 50
    V = twist_bend(V0, 90, 60)
    T = op(V)
    m = op.deformed_normal_edges(V[None])[0]
    Kp = (op.K @ V).reshape(len(V0), 3, 3)  # [i, b, a]
    np.testing.assert_allclose(T, np.swapaxes(Kp, 1, 2) + m[:, :, None] * op.h[:, None, :],
                               atol=1e-13)


def test_batch_equals_single_and_identity():
    V0, F = tube(8, 5)
    op = DeformationGradientOperator(V0, F)
    V = np.stack([V0, twist_bend(V0), 0.5 * V0])
    Tb = op(V)
    assert Tb.shape == (3, len(V0), 3, 3)
    for k in range(3):
        np.testing.assert_allclose(Tb[k], op(V[k]), atol=1e-15)
    np.testing.assert_allclose(Tb[0], np.broadcast_to(np.eye(3), Tb[0].shape), atol=1e-13)


def test_bad_input():
    V0, F = tube(8, 5)
    op = DeformationGradientOperator(V0, F)
    with pytest.raises(ValueError, match=r"got \(10, 3\)"):
        op(np.zeros((10, 3)))
    bad = V0.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        op(bad)
    with pytest.raises(ValueError, match="no face"):
        DeformationGradientOperator(np.concatenate([V0, [[9.0, 9, 9]]]), F)
