"""Spiral sequences and the quadric-error mesh hierarchy of the spiral network (geometry/spirals.py)."""

import numpy as np
import pytest

from geometry_fixtures import grid, icosphere
from meshvae_lib.geometry.spirals import closest_point_barycentric, mesh_hierarchy, spiral_indices
from meshvae_lib.geometry.topology import edges, one_rings


def _hexagon_fan():
    """A centre vertex 0 with six neighbours 1..6 counter-clockwise in the plane z = 0 (normal +z)."""
    ang = np.arange(6) * np.pi / 3
    V = np.vstack([[0, 0, 0], np.c_[np.cos(ang), np.sin(ang), np.zeros(6)]])
    F = np.array([[0, 1 + k, 1 + (k + 1) % 6] for k in range(6)])
    return V, F


def test_the_spiral_of_a_fan_centre_is_its_ring_counter_clockwise_from_the_smallest_neighbour():
    V, F = _hexagon_fan()
    S = spiral_indices(V, F, 7)
    np.testing.assert_array_equal(S[0], [0, 1, 2, 3, 4, 5, 6])      # by hand: 1 is the start, then CCW
    # a mirrored mesh (faces reversed: normal -z) walks the other way round
    S_flip = spiral_indices(V, F[:, ::-1], 7)
    np.testing.assert_array_equal(S_flip[0], [0, 1, 6, 5, 4, 3, 2])


def test_spirals_list_rings_in_order_and_consecutive_ring_members_are_neighbours():
    V, F = icosphere(2)
    n = len(V)
    S = spiral_indices(V, F, 13)
    starts, ring = one_rings(F, n)
    E = {tuple(e) for e in edges(F)}
    for v in range(0, n, 7):
        ring1 = set(ring[starts[v]:starts[v + 1]])
        k = len(ring1)
        assert S[v, 0] == v and set(S[v, 1:1 + k]) == ring1                        # the whole one-ring first
        assert not set(S[v, 1 + k:]) & (ring1 | {v})                                # then the next ring
        for a, b in zip(S[v, 1:k], S[v, 2:1 + k]):
            assert (min(a, b), max(a, b)) in E                                      # walking round the ring
    assert S.shape == (n, 13) and S.dtype == np.int64


def test_short_spirals_are_padded_with_their_centre_and_bad_lengths_are_refused():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    S = spiral_indices(V, np.array([[0, 1, 2]]), 5)
    np.testing.assert_array_equal(S[0], [0, 1, 2, 0, 0])
    with pytest.raises(ValueError, match="length"):
        spiral_indices(V, np.array([[0, 1, 2]]), 0)


def _closest_naive(p, a, b, c):
    """Closest point on triangle abc by brute force over a fine barycentric grid, then refined on the
    three edges: the reference for the closed form."""
    best = None
    u = np.linspace(0, 1, 201)
    U, W = np.meshgrid(u, u)
    keep = U + W <= 1
    cand = np.stack([1 - U[keep] - W[keep], U[keep], W[keep]], 1)
    pts = cand @ np.stack([a, b, c])
    i = np.argmin(np.linalg.norm(pts - p, axis=1))
    best = cand[i]
    return best


def test_closest_point_barycentrics_agree_with_a_brute_force_search():
    rng = np.random.default_rng(0)
    tri = rng.normal(size=(40, 3, 3))
    p = rng.normal(size=(40, 3)) * 1.5
    w = closest_point_barycentric(p, tri)
    assert np.all(w >= -1e-12) and np.allclose(w.sum(1), 1, atol=1e-12)
    for k in range(40):
        ref = _closest_naive(p[k], *tri[k])
        got_pt, ref_pt = w[k] @ tri[k], ref @ tri[k]
        # the closed form is never farther than the grid's best and lies within a grid cell of it
        assert np.linalg.norm(got_pt - p[k]) <= np.linalg.norm(ref_pt - p[k]) + 1e-12
        assert np.linalg.norm(got_pt - ref_pt) < 0.05 * np.ptp(tri[k], axis=0).max()
    # a point above the interior projects straight down: exact
    tri0 = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    np.testing.assert_allclose(closest_point_barycentric(np.array([0.2, 0.3, 5.0]), tri0), [0.5, 0.2, 0.3], atol=1e-15)


def test_the_hierarchy_divides_the_vertices_and_its_sampling_matrices_are_averages_and_interpolations():
    V, F = icosphere(4)                                   # 2,562 vertices
    levels = mesh_hierarchy(V, F, (4, 4), 9)
    sizes = [len(lv.vertices) for lv in levels]
    assert sizes[0] == len(V) and all(3.5 < a / b < 4.5 for a, b in zip(sizes, sizes[1:]))
    for fine, coarse in zip(levels, levels[1:]):
        D, U = fine.down.toarray(), fine.up.toarray()
        assert D.shape == (len(coarse.vertices), len(fine.vertices)) and U.shape == D.T.shape
        np.testing.assert_allclose(D.sum(1), 1, atol=1e-12)
        assert np.all(D >= 0) and np.all((D > 0).sum(0) == 1)          # every fine vertex in one average
        np.testing.assert_allclose(U.sum(1), 1, atol=1e-12)
        assert np.all(U >= -1e-12) and np.all((U > 0).sum(1) <= 3)     # barycentric on one triangle
        np.testing.assert_allclose(D @ fine.vertices, coarse.vertices, atol=1e-12)
        # up-sampling lands on the coarse surface, close to where the fine vertex was
        back = U @ coarse.vertices
        edge = np.mean(np.linalg.norm(np.diff(coarse.vertices[coarse.faces[:, :2]], axis=1), axis=-1))
        assert np.max(np.linalg.norm(back - fine.vertices, axis=1)) < edge
    assert levels[-1].down is None and levels[-1].up is None


def test_a_planar_grid_is_reproduced_by_up_sampling_where_it_lies_inside_the_coarse_mesh():
    V, F = grid(30, 30)
    lv = mesh_hierarchy(V, F, (4,), 5)[0]
    back = lv.up @ (lv.down @ V)
    assert np.allclose(back[:, 2], 0, atol=1e-15)                  # stays in the plane: affine exactness
    inside = np.linalg.norm(back - V, axis=1) < 1e-12
    assert inside.mean() > 0.7


def test_a_mesh_too_small_for_the_levels_is_refused_with_its_size():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="42 vertices"):
        mesh_hierarchy(V, F, (4, 4, 4), 9)
    with pytest.raises(ValueError, match="at least 2"):
        mesh_hierarchy(V, F, (1,), 9)
