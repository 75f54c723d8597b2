"""Self-intersection count: hand-made pairs, brute force on triangle soups, the broad phase."""

from __future__ import annotations

import numpy as np

from meshvae_lib.geometry.intersections import candidate_triangle_pairs, self_intersections


def _grid_mesh(n=6, size=1.0):
    """A flat (n x n)-vertex square grid in the z = 0 plane, two triangles per cell."""
    x, y = np.meshgrid(np.linspace(0, size, n), np.linspace(0, size, n), indexing="ij")
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(n * n)])
    idx = np.arange(n * n).reshape(n, n)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(), idx[:-1, 1:].ravel()
    F = np.concatenate([np.column_stack([a, b, c]), np.column_stack([a, c, d])])
    return V, F.astype(np.int64)


# ---------------------------------------------------------------------------------------------
# self-intersections
# ---------------------------------------------------------------------------------------------


def _segment_hits_triangle(p, q, a, b, c):
    """Naive Moller-Trumbore test of segment pq against triangle abc (strict interior)."""
    d = q - p
    e1, e2 = b - a, c - a
    h = np.cross(d, e2)
    det = e1 @ h
    if abs(det) < 1e-14:
        return False
    s = p - a
    u = (s @ h) / det
    qv = np.cross(s, e1)
    v = (d @ qv) / det
    t = (e2 @ qv) / det
    return 0 < u and 0 < v and u + v < 1 and 0 < t < 1


def _naive_count(V, F):
    """All pairs, one by one: non-coplanar triangles in general position cross iff an edge of one
    pierces the other."""
    n = 0
    for i in range(len(F)):
        for j in range(i + 1, len(F)):
            if set(F[i]) & set(F[j]):
                continue
            A, B = V[F[i]], V[F[j]]
            hit = any(_segment_hits_triangle(A[k], A[(k + 1) % 3], *B) for k in range(3)) or any(
                _segment_hits_triangle(B[k], B[(k + 1) % 3], *A) for k in range(3)
            )
            n += hit
    return n


def test_two_triangles_hand_made():
    F = np.array([[0, 1, 2], [3, 4, 5]])
    A = np.array([[0.0, 0, 0], [2, 0, 0], [0, 2, 0]])
    crossing = np.array([[0.5, 0.5, -1], [0.5, 0.5, 1], [3, 3, 1]])  # pierces A at (0.5, 0.5, 0)
    assert self_intersections(np.vstack([A, crossing]), F) == 1
    above = crossing + [0, 0, 1.5]
    assert self_intersections(np.vstack([A, above]), F) == 0
    # coplanar triangles count as touching (no thickness), overlapping or not; a slight tilt that
    # makes the smaller one pass through A is a crossing
    assert self_intersections(np.vstack([A, A * 0.5 + [0.2, 0.2, 0]]), F) == 0
    tilted = A * 0.5 + [0.2, 0.2, 0]
    tilted[:, 2] = [-0.1, 0.1, 0.1]
    assert self_intersections(np.vstack([A, tilted]), F) == 1
    assert self_intersections(np.vstack([A, A + [5, 0, 0]]), F) == 0
    # touching at a point (corner on the face) is not crossing
    touch = np.array([[0.5, 0.5, 0], [0.5, 0.5, 1], [1, 2, 1]])
    assert self_intersections(np.vstack([A, touch]), F) == 0


def test_adjacent_faces_never_count():
    V, F = _grid_mesh(5)
    assert self_intersections(V, F) == 0
    # folding the grid sharply keeps adjacent faces touching; still no crossing
    V2 = V.copy()
    V2[:, 2] = np.where(V[:, 0] > 0.5, (V[:, 0] - 0.5) * 3, 0)
    assert self_intersections(V2, F) == 0


def test_triangle_soup_against_brute_force(rng):
    m = 90
    centers = rng.uniform(0, 3, size=(m, 1, 3))
    V = (centers + 0.4 * rng.normal(size=(m, 3, 3))).reshape(-1, 3)
    F = np.arange(3 * m).reshape(m, 3)
    count, pairs = self_intersections(V, F, return_pairs=True)
    assert count == _naive_count(V, F)
    assert count > 10  # the case is not trivial
    assert pairs.shape == (count, 2) and np.all(pairs[:, 0] < pairs[:, 1])


def test_folded_sheet_counts_crossings():
    # a grid whose right half is folded back through the left half crosses itself
    V, F = _grid_mesh(7)
    V2 = V.copy()
    right = V[:, 0] > 0.5
    V2[right, 0] = 1.0 - V[right, 0] - 0.05
    V2[right, 2] = 0.3 * np.sin(3 * V[right, 1]) - 0.1
    V2[~right, 2] = 0.2 * np.sin(4 * V[~right, 1] + 1)
    assert self_intersections(V2, F) == _naive_count(V2, F) > 0


def test_candidate_pairs_are_a_superset(rng):
    m = 80
    V = (rng.uniform(0, 2, size=(m, 1, 3)) + 0.3 * rng.normal(size=(m, 3, 3))).reshape(-1, 3)
    F = np.arange(3 * m).reshape(m, 3)
    cand = {tuple(p) for p in candidate_triangle_pairs(V, F)}
    tri = V[F]
    lo, hi = tri.min(1), tri.max(1)
    for i in range(m):
        for j in range(i + 1, m):
            overlap = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]))
            assert ((i, j) in cand) == overlap
