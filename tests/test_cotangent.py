"""Cotangent weights: hand-computed values, naive loop, obtuse/sliver/boundary/degenerate cases."""

import numpy as np
import pytest
from geometry_fixtures import bumpy, icosphere, tube

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.cotangent import corner_cotangents, cotangent_weights
from meshvae_lib.geometry.topology import edge_index, edges


def _naive_weights(V, F):
    E = edges(F)
    c = np.zeros(len(E))
    for f in F:
        for k in range(3):
            i, j, o = f[(k + 1) % 3], f[(k + 2) % 3], f[k]
            a, b = V[i] - V[o], V[j] - V[o]
            angle = np.arccos(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b))
            c[edge_index(E, i, j)] += 1.0 / np.tan(angle)
    return c


def test_square_by_hand():
    # two right isosceles triangles; the diagonal (0, 2) faces two right angles: cot 90 = 0
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    # edges: (0,1) (0,2) (0,3) (1,2) (2,3); boundary edges see one 45-degree angle: cot = 1
    raw = cotangent_weights(V, F, clamp=False)
    np.testing.assert_allclose(raw, [1, 0, 1, 1, 1], atol=1e-15)
    np.testing.assert_allclose(cotangent_weights(V, F), [1, tol.COT_WEIGHT_MIN, 1, 1, 1],
                               atol=1e-15)


def test_regular_tetrahedron_by_hand():
    V = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    np.testing.assert_allclose(cotangent_weights(V, F), 2 / np.sqrt(3), rtol=1e-14)


def test_vectorised_matches_naive_loop():
    V, F = tube(6, 4)
    V = bumpy(V, 0.2, seed=3)
    np.testing.assert_allclose(cotangent_weights(V, F, clamp=False), _naive_weights(V, F),
                               rtol=1e-10, atol=1e-12)


def test_obtuse_pair_is_negative_then_clamped():
    # edge (0, 1) with both opposite vertices close to it: two obtuse angles
    V = np.array([[0.0, 0, 0], [2, 0, 0], [1, 0.2, 0], [1, -0.2, 0]])
    F = np.array([[0, 1, 2], [1, 0, 3]])
    E = edges(F)
    k = edge_index(E, 0, 1)
    raw = cotangent_weights(V, F, clamp=False)
    expected = 2 * (0.2**2 - 1) / (2 * 0.2)  # 2 cot(angle), angle = pi - 2 atan(0.2)
    assert raw[k] == pytest.approx(expected, rel=1e-12)
    assert raw[k] < 0
    assert cotangent_weights(V, F)[k] == tol.COT_WEIGHT_MIN


def test_sliver_and_zero_area_faces_fall_back():
    # a sliver with a tiny angle opposite edge (1, 2): cot > 100 -> fallback 1
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1e-4, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    E = edges(F)
    raw = cotangent_weights(V, F, clamp=False)
    assert raw[edge_index(E, 1, 2)] > tol.COT_WEIGHT_MAX
    assert cotangent_weights(V, F)[edge_index(E, 1, 2)] == tol.COT_WEIGHT_FALLBACK
    # zero-area face (collinear): infinite / NaN cotangents -> fallback, never NaN
    Vz = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    cot = corner_cotangents(Vz, [[0, 1, 2]])
    assert not np.all(np.isfinite(cot))
    w = cotangent_weights(Vz, [[0, 1, 2]])
    assert np.all(np.isfinite(w)) and np.all(w > 0)


def test_weights_positive_and_scale_invariant():
    V, F = icosphere(2)
    w = cotangent_weights(V, F)
    assert np.all(w >= tol.COT_WEIGHT_MIN) and np.all(w <= tol.COT_WEIGHT_MAX)
    np.testing.assert_allclose(cotangent_weights(3.7 * V + 1, F), w, rtol=1e-12)
