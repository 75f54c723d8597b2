"""Connectivity of a triangle mesh: edges, one-rings, normals and areas (boundaries:
:mod:`~meshvae_lib.geometry.boundaries`).

Everything here depends only on the faces ``F`` (and, for normals, areas and edge lengths, on
positions ``V``).
Edge order is fixed once and for all: :func:`edges` returns the undirected edges ``(i, j)`` with
``i < j`` in lexicographic order, and :func:`directed_edges` returns every ``(i, j)`` and ``(j, i)``
sorted by source vertex then target vertex, which is exactly the concatenation of the one-rings
(:func:`one_rings`). Cotangent weights and the RIMD feature layout follow these orders.

All functions are vectorised (no Python loop over vertices, edges or faces). :class:`MeshTopology`
holds the connectivity of one mesh, checked and computed once, for the classes that precompute
things for a reference mesh.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from meshvae_lib.validation import check_faces, check_mesh, check_vertices

__all__ = [
    "MeshTopology",
    "edges",
    "directed_edges",
    "face_edge_indices",
    "edge_index",
    "one_rings",
    "face_normals",
    "vertex_normals",
    "vertex_normal_sums",
    "vertex_face_incidence",
    "face_areas",
    "edge_lengths",
]


class MeshTopology:
    """The connectivity of one triangle mesh, checked once and computed once.

    The classes that precompute things for one reference mesh (the deformation-gradient operator,
    the RIMD layout, the reconstructor) build one and pass it along instead of checking the faces
    and computing the edge list again and again.

    Parameters
    ----------
    F : (n_faces, 3) int
    n_vertices : int
        Every face index must be below it.

    Attributes
    ----------
    faces : (n_faces, 3) int64, checked
    n_vertices : int
    edges : (n_edges, 2) int64, as :func:`edges`
    directed : (2 n_edges, 2) int64, as :func:`directed_edges`
    face_edges : (n_faces, 3) int64, as :func:`face_edge_indices`
    incidence : (n_vertices, n_faces) csr_matrix, as :func:`vertex_face_incidence`
    """

    def __init__(self, F, n_vertices: int):
        self.faces = check_faces(F, n_vertices=int(n_vertices))
        self.n_vertices = int(n_vertices)
        self.edges = _edges(self.faces)
        self.directed = _directed(self.edges)
        self._face_edges = None
        self._incidence = None

    @property
    def face_edges(self) -> np.ndarray:
        if self._face_edges is None:
            self._face_edges = _face_edge_indices(self.faces, self.edges)
        return self._face_edges

    @property
    def incidence(self) -> sp.csr_matrix:
        if self._incidence is None:
            self._incidence = _incidence(self.faces, self.n_vertices)
        return self._incidence

    def __repr__(self) -> str:
        return f"MeshTopology(n_vertices={self.n_vertices}, n_faces={len(self.faces)}, n_edges={len(self.edges)})"


def _face_half_edges(F: np.ndarray) -> np.ndarray:
    """Half-edges of every face in face order, ``(3 * n_faces, 2) int64``.

    Row ``3 * f + k`` is the edge from corner ``k`` to corner ``k + 1`` of face ``f``.
    """
    return np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)


def edges(F) -> np.ndarray:
    """Undirected edges of the mesh.

    Parameters
    ----------
    F : (n_faces, 3) int
        Triangles.

    Returns
    -------
    E : (n_edges, 2) int64
        Each edge once as ``(i, j)`` with ``i < j``, sorted lexicographically.
    """
    return _edges(check_faces(F))


def _edges(F: np.ndarray) -> np.ndarray:
    he = np.sort(_face_half_edges(F), axis=1)
    return np.unique(he, axis=0) if len(he) else np.zeros((0, 2), np.int64)


def edge_index(E: np.ndarray, i, j) -> np.ndarray:
    """Index of the undirected edge ``{i, j}`` in the sorted edge list ``E`` (from :func:`edges`).

    Parameters
    ----------
    E : (n_edges, 2) int64
        Output of :func:`edges`.
    i, j : int or (k,) int
        End points, in either order.

    Returns
    -------
    idx : int64 array of the broadcast shape of ``i`` and ``j``.

    Raises
    ------
    ValueError
        If some pair is not an edge of the mesh.
    """
    i = np.asarray(i, dtype=np.int64)
    j = np.asarray(j, dtype=np.int64)
    lo, hi = np.minimum(i, j), np.maximum(i, j)
    n = int(E.max()) + 1 if len(E) else 1
    n = max(n, int(hi.max()) + 1 if hi.size else 0)
    keys = E[:, 0] * n + E[:, 1]
    q = lo * n + hi
    pos = np.searchsorted(keys, q)
    pos_c = np.minimum(pos, len(keys) - 1)
    ok = (pos < len(keys)) & (keys[pos_c] == q)
    if not np.all(ok):
        bad = np.stack([lo, hi], -1).reshape(-1, 2)[~ok.reshape(-1)][0]
        raise ValueError(f"({bad[0]}, {bad[1]}) is not an edge of the mesh")
    return pos_c


def face_edge_indices(F) -> np.ndarray:
    """For each face corner ``k``, the index (in :func:`edges`) of the edge *opposite* to it.

    Parameters
    ----------
    F : (n_faces, 3) int

    Returns
    -------
    FE : (n_faces, 3) int64
        ``FE[f, k]`` is the edge joining ``F[f, k+1]`` and ``F[f, k+2]`` (indices mod 3).
    """
    F = check_faces(F)
    return _face_edge_indices(F, _edges(F))


def _face_edge_indices(F: np.ndarray, E: np.ndarray) -> np.ndarray:
    opp = np.stack([F[:, [1, 2]], F[:, [2, 0]], F[:, [0, 1]]], axis=1)  # (m, 3, 2)
    return edge_index(E, opp[..., 0], opp[..., 1])


def directed_edges(F) -> np.ndarray:
    """Directed edges: every undirected edge in both directions.

    Parameters
    ----------
    F : (n_faces, 3) int

    Returns
    -------
    D : (2 * n_edges, 2) int64
        Rows ``(i, j)`` sorted by ``i`` then ``j``; the rows with source ``i`` are the one-ring of
        ``i`` (see :func:`one_rings`).
    """
    return _directed(edges(F))


def _directed(E: np.ndarray) -> np.ndarray:
    D = np.concatenate([E, E[:, ::-1]], axis=0)
    order = np.lexsort((D[:, 1], D[:, 0]))
    return D[order]


def one_rings(F, n_vertices: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One-ring neighbourhoods in compressed (CSR) form.

    Parameters
    ----------
    F : (n_faces, 3) int
    n_vertices : int, optional
        Number of vertices (default ``F.max() + 1``); isolated vertices get empty rings.

    Returns
    -------
    indptr : (n_vertices + 1,) int64
        The neighbours of vertex ``i`` are ``indices[indptr[i]:indptr[i + 1]]``.
    indices : (2 * n_edges,) int64
        Neighbour vertex ids, ascending within each ring; equal to ``directed_edges(F)[:, 1]``.
    """
    F = check_faces(F)
    n = int(F.max()) + 1 if F.size else 0
    if n_vertices is None:
        n_vertices = n
    if n_vertices < n:
        raise ValueError(f"n_vertices={n_vertices} but faces reference vertex {n - 1}")
    D = directed_edges(F)
    counts = np.bincount(D[:, 0], minlength=n_vertices)
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return indptr, D[:, 1].copy()


def _face_cross(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """``(p1 - p0) x (p2 - p0)`` per face: ``(..., n_faces, 3)``, length twice the face area."""
    p0 = V[..., F[:, 0], :]
    return np.cross(V[..., F[:, 1], :] - p0, V[..., F[:, 2], :] - p0)


def _unit_or_zero(c: np.ndarray) -> np.ndarray:
    """Rows of ``c (..., 3)`` scaled to unit length; zero rows stay zero (not NaN)."""
    norm = np.linalg.norm(c, axis=-1, keepdims=True)
    return np.divide(c, norm, out=np.zeros_like(c), where=norm > 0)


def face_areas(V, F) -> np.ndarray:
    """Triangle areas.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    A : (n_faces,) or (n_meshes, n_faces) float64
    """
    V, F = check_mesh(V, F)
    return 0.5 * np.linalg.norm(_face_cross(V, F), axis=-1)


def face_normals(V, F) -> np.ndarray:
    """Unit face normals (right-hand rule on the corner order).

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    N : (n_faces, 3) or (n_meshes, n_faces, 3) float64
        Zero-area faces get the zero vector (not NaN).
    """
    V, F = check_mesh(V, F)
    return _unit_or_zero(_face_cross(V, F))


def vertex_normals(V, F) -> np.ndarray:
    """Area-weighted unit vertex normals.

    Each vertex normal is the normalised sum of the area-weighted normals of its faces.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    N : (n_vertices, 3) or (n_meshes, n_vertices, 3) float64
        Unit vectors; a vertex with no face (or only zero-area faces) gets the zero vector.
    """
    return _unit_or_zero(vertex_normal_sums(V, F))


def vertex_normal_sums(V, F, topology: MeshTopology | None = None) -> np.ndarray:
    """Unnormalised area-weighted vertex normals: sum over incident faces of ``2 area_f n_f``.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    S : (n_vertices, 3) or (n_meshes, n_vertices, 3) float64
        Sum of the face cross products ``(p1 - p0) x (p2 - p0)`` around each vertex; it scales with
        the square of the mesh size.
    topology : MeshTopology of ``F``, optional
        Precomputed (then ``F`` is not checked again).
    """
    if topology is None:
        V, F = check_mesh(V, F)
        inc = _incidence(F, V.shape[-2])
    else:
        V = check_vertices(V, "V", n_vertices=topology.n_vertices)
        F, inc = topology.faces, topology.incidence
    n = V.shape[-2]
    m = len(F)
    c = _face_cross(V, F)  # (..., m, 3)
    if V.ndim == 2:
        return np.asarray(inc @ c)
    N = V.shape[0]
    acc = (inc @ c.transpose(1, 0, 2).reshape(m, N * 3)).reshape(n, N, 3).transpose(1, 0, 2)
    return np.ascontiguousarray(acc)


def vertex_face_incidence(F, n_vertices: int) -> sp.csr_matrix:
    """Which faces each vertex belongs to, as a sparse 0/1 matrix.

    Parameters
    ----------
    F : (n_faces, 3) int
    n_vertices : int

    Returns
    -------
    I : scipy.sparse.csr_matrix, shape (n_vertices, n_faces), float64
        ``I[i, f] = 1`` when vertex ``i`` is a corner of face ``f``; ``I @ x`` sums a per-face
        quantity ``x (n_faces, k)`` around every vertex.
    """
    return _incidence(check_faces(F, n_vertices=n_vertices), n_vertices)


def _incidence(F: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    m = len(F)
    return sp.csr_matrix(
        (np.ones(3 * m), (F.reshape(-1), np.repeat(np.arange(m), 3))), shape=(n_vertices, m)
    )


def edge_lengths(V, F) -> np.ndarray:
    """Lengths of the undirected edges :func:`edges` ``(F)``.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    L : (n_edges,) or (n_meshes, n_edges) float64
        ``L[..., e] = |p_j - p_i|`` for ``edges(F)[e] = (i, j)``.
    """
    V, F = check_mesh(V, F, name="V")
    E = edges(F)
    return np.linalg.norm(V[..., E[:, 1], :] - V[..., E[:, 0], :], axis=-1)
