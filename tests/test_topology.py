"""Topology: edges, one-rings, boundaries, normals, areas."""

import numpy as np
import pytest
from geometry_fixtures import grid, icosphere, random_rotation, tube

from meshvae_lib.geometry import topology as T
from meshvae_lib.geometry import boundaries as B

# two triangles sharing edge (0, 2): a unit square in the z = 0 plane
SQUARE_V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def test_edges_of_square_by_hand():
    np.testing.assert_array_equal(T.edges(SQUARE_F), [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]])
    D = T.directed_edges(SQUARE_F)
    assert D.shape == (10, 2)
    np.testing.assert_array_equal(D[:3], [[0, 1], [0, 2], [0, 3]])
    indptr, indices = T.one_rings(SQUARE_F, 5)  # vertex 4 isolated
    np.testing.assert_array_equal(indptr, [0, 3, 5, 8, 10, 10])
    np.testing.assert_array_equal(indices[indptr[2]:indptr[3]], [0, 1, 3])


def test_euler_characteristic_and_closed_mesh():
    V, F = icosphere(2)
    E = T.edges(F)
    assert len(V) - len(E) + len(F) == 2  # genus 0
    assert np.all(E[:, 0] < E[:, 1])
    assert len(np.unique(E, axis=0)) == len(E)
    assert B.boundary_vertices(F).size == 0
    assert B.boundary_loops(F) == []


def test_one_rings_match_a_naive_loop():
    V, F = tube(7, 4)
    indptr, indices = T.one_rings(F)
    for i in range(len(V)):
        naive = sorted({int(v) for f in F if i in f for v in f if v != i})
        assert indices[indptr[i]:indptr[i + 1]].tolist() == naive


def test_edge_index_and_face_edges():
    V, F = icosphere(1)
    E = T.edges(F)
    FE = T.face_edge_indices(F)
    for f, fe in zip(F[:10], FE[:10]):
        for k in range(3):
            assert set(E[fe[k]]) == {f[(k + 1) % 3], f[(k + 2) % 3]}
    np.testing.assert_array_equal(T.edge_index(E, E[:, 1], E[:, 0]), np.arange(len(E)))
    with pytest.raises(ValueError, match="not an edge"):
        T.edge_index(E, 0, 0)


def test_boundary_loops_of_open_tube_and_grid():
    V, F = tube(8, 3, capped=False)
    loops = B.boundary_loops(F)
    assert len(loops) == 2
    assert sorted(len(lp) for lp in loops) == [8, 8]
    assert set(np.concatenate(loops).tolist()) == set(B.boundary_vertices(F).tolist())
    Vg, Fg = grid(4, 3)
    (loop,) = B.boundary_loops(Fg)
    assert len(loop) == 2 * (4 + 3)
    # consecutive loop vertices are mesh edges
    E = T.edges(Fg)
    T.edge_index(E, loop, np.roll(loop, -1))


def test_face_normals_areas_by_hand():
    np.testing.assert_allclose(T.face_areas(SQUARE_V, SQUARE_F), [0.5, 0.5], atol=1e-15)
    np.testing.assert_allclose(T.face_normals(SQUARE_V, SQUARE_F), [[0, 0, 1], [0, 0, 1]])
    np.testing.assert_allclose(T.vertex_normals(SQUARE_V, SQUARE_F), np.tile([0, 0, 1.0], (4, 1)))


def test_vertex_normals_sphere_batched_and_rotation_equivariant():
    V, F = icosphere(3)
    N = T.vertex_normals(V, F)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-14)
    assert np.min(np.einsum("ij,ij->i", N, V)) > 0.999  # outward, close to radial
    R = random_rotation(4)
    batch = np.stack([V, 2.0 * V @ R.T + 1.0])
    Nb = T.vertex_normals(batch, F)
    assert Nb.shape == batch.shape
    np.testing.assert_allclose(Nb[0], N, atol=1e-14)
    np.testing.assert_allclose(Nb[1], N @ R.T, atol=1e-13)
    np.testing.assert_allclose(T.face_areas(batch, F)[1], 4 * T.face_areas(V, F), rtol=1e-12)


def test_vertex_normals_area_weighting_against_a_loop():
    V, F = tube(5, 3)
    V = V + 0.1 * np.random.default_rng(0).standard_normal(V.shape)
    c = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    naive = np.zeros_like(V)
    for f, cf in zip(F, c):
        for v in f:
            naive[v] += cf
    naive /= np.linalg.norm(naive, axis=1, keepdims=True)
    np.testing.assert_allclose(T.vertex_normals(V, F), naive, atol=1e-14)


def test_degenerate_face_gets_zero_normal_not_nan():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
    assert np.all(T.face_normals(V, [[0, 1, 2]]) == 0)
    assert np.all(np.isfinite(T.vertex_normals(V, [[0, 1, 2]])))


def test_bad_input_errors():
    with pytest.raises(ValueError, match=r"\(n_faces, 3\)"):
        T.edges(np.zeros((3, 4), int))
    with pytest.raises(ValueError, match="negative"):
        T.edges([[0, 1, -1]])
    with pytest.raises(ValueError, match="vertices"):
        T.vertex_normals(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(ValueError, match="3 vertices"):
        T.face_normals(np.zeros((3, 3)), [[0, 1, 3]])


def test_edge_lengths_and_vertex_face_incidence():
    L = T.edge_lengths(SQUARE_V, SQUARE_F)  # edges (0,1), (0,2), (0,3), (1,2), (2,3)
    np.testing.assert_allclose(L, [1, np.sqrt(2), 1, 1, 1], atol=1e-15)
    Lb = T.edge_lengths(np.stack([SQUARE_V, 2 * SQUARE_V]), SQUARE_F)
    assert Lb.shape == (2, 5) and np.allclose(Lb[1], 2 * L)
    inc = T.vertex_face_incidence(SQUARE_F, 5).toarray()
    np.testing.assert_array_equal(inc, [[1, 1], [1, 0], [1, 1], [0, 1], [0, 0]])
    with pytest.raises(ValueError, match="4 vertices"):
        T.edge_lengths(SQUARE_V, [[0, 1, 4]])
