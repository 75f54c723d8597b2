"""Deformation gradients ``T_i`` (paper Eq. 1, with the reference implementation's normal term).

For vertex ``i`` with one-ring ``N_i``, ``T_i`` minimises (Eq. 1)::

    E(T_i) = sum_{j in N_i} c_ij |e'_ij - T_i e_ij|^2  +  w_n |m'_i - T_i m_i|^2

with ``e_ij = p_i - p_j`` on the reference mesh, ``e'_ij`` on the deformed one, ``c_ij`` the clamped
cotangent weights (:mod:`meshvae_lib.geometry.cotangent`). The second term is the reference implementation's
extra "edge" along the vertex normal: ``m_i = l n_i`` with ``n`` the unit area-weighted vertex
normal and ``l = NORMAL_EDGE_SCALE x mean edge length`` of the reference, and ``m'_i = l'_i n'_i``
on the deformed mesh with ``l'_i = l sqrt(a'_i / a_i)`` (``a`` the local one-ring area), so that
rigid motions and uniform scalings give ``T_i`` exactly (the reference keeps ``l' = l``, which makes
a uniform scale ``s`` show up as ``T_i n_i = n_i`` instead of ``s n_i``). The term keeps the fit
well conditioned where a one-ring is nearly flat. The price: for a general affine map ``A`` the
deformed normal is ``A^{-T} n`` (not ``A n``), so ``T_i = A`` holds exactly only for similarities
and for pure Eq. 1 (``normal_term=False``) on curved one-rings; a flat one-ring cannot observe how
``A`` acts along its normal at all. The minimiser is::

    T_i = B_i A_i^{-1},  A_i = sum_j c_ij e_ij e_ij^T + w_n m_i m_i^T,
                         B_i = sum_j c_ij e'_ij e_ij^T + w_n m'_i m_i^T.

``A_i`` depends only on the reference, so :class:`DeformationGradientOperator` precomputes
``A_i^{-1}`` and one sparse matrix ``K`` (``3 n x n``) with ``sum_j c_ij e'_ij (A_i^{-1} e_ij)^T = K p'``
(the same for each coordinate); a batch of deformed meshes then costs one sparse product and the
deformed normals. ``T_i`` is linear in ``(p', m')``, which :mod:`meshvae_lib.geometry.reconstruction` uses
for its exact inverse.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from meshvae_lib import defaults as hp
from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.cotangent import cotangent_weights
from meshvae_lib.geometry.rotations import from_soa
from meshvae_lib.geometry.topology import MeshTopology, edge_index, vertex_normal_sums
from meshvae_lib.validation import check_vertices

__all__ = ["DeformationGradientOperator", "deformation_gradients"]


class DeformationGradientOperator:
    """Precomputed map from deformed positions to deformation gradients, for one reference mesh.

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        Reference mesh.
    F : (n_faces, 3) int
    normal_term : bool
        Include the normal term (default, as the reference implementation). Without it the fit is
        pure Eq. 1 and fails (``ValueError``) at vertices whose one-ring is flat.
    clamp : bool
        Clamp the cotangent weights from below (default, see
        :func:`meshvae_lib.geometry.cotangent.cotangent_weights`). ``False`` uses the raw weights of Eq. 1,
        which are negative across edges opposite obtuse angles and can make ``A_i`` indefinite
        (for teaching and comparison; notebook 01 shows what goes wrong).

    Attributes
    ----------
    topology : MeshTopology
        The reference mesh's connectivity, checked and computed once (passed on to whatever else
        is built for this mesh: the RIMD layout, the reconstructor).
    n_vertices : int
    faces : (n_faces, 3) int64
    edges : (n_edges, 2) int64
        Undirected edges (:func:`meshvae_lib.geometry.topology.edges`).
    directed : (2 n_edges, 2) int64
        Directed edges ``(i, j)`` sorted by ``i`` (:func:`meshvae_lib.geometry.topology.directed_edges`).
    weights : (n_edges,) float64
        Cotangent weights ``c_ij`` (clamped unless ``clamp=False``).
    normal_length : float
        ``l``, length of the normal edge.
    normals : (n_vertices, 3) float64
        Reference unit vertex normals ``n_i``.
    A : (n_vertices, 3, 3) float64
        The matrices ``A_i``.
    A_inv : (n_vertices, 3, 3) float64
    K : scipy.sparse.csr_matrix, shape (3 n_vertices, n_vertices)
        ``(K p')[3 i + b, a] = sum_j c_ij e'_ij[a] (A_i^{-1} e_ij)[b]`` for positions ``p' (n, 3)``.
    h : (n_vertices, 3) float64
        ``w_n A_i^{-1} m_i``: ``T_i = (K p')_i^T + m'_i h_i^T``.
    """

    def __init__(self, V0, F, normal_term: bool = True, clamp: bool = True):
        V0 = check_vertices(V0, "V0", batch=False)
        n = V0.shape[0]
        self.topology = topo = MeshTopology(F, n)  # the faces checked (indices below n) once
        F = topo.faces
        self.n_vertices = n
        self.faces = topo.faces
        self.edges = topo.edges
        D = topo.directed
        self.directed = D
        counts = np.bincount(D[:, 0], minlength=n)
        if np.any(counts == 0):
            k = int(np.flatnonzero(counts == 0)[0])
            raise ValueError(f"vertex {k} belongs to no face (unreferenced vertices are not allowed)")
        self.weights = cotangent_weights(V0, F, clamp=clamp, topology=topo)
        c = self.weights[edge_index(self.edges, D[:, 0], D[:, 1])]  # (2E,)
        e = V0[D[:, 0]] - V0[D[:, 1]]  # e_ij = p_i - p_j, (2E, 3)
        lengths = np.linalg.norm(V0[self.edges[:, 0]] - V0[self.edges[:, 1]], axis=1)
        self.normal_length = float(hp.NORMAL_EDGE_SCALE * lengths.mean())
        self._normal_sums = vertex_normal_sums(V0, F, topology=topo)
        ns = np.linalg.norm(self._normal_sums, axis=1)
        if np.any(ns <= 0):
            k = int(np.flatnonzero(ns <= 0)[0])
            raise ValueError(f"vertex {k} has no normal (all its faces have zero area)")
        self._normal_sum_norms = ns
        self.normals = self._normal_sums / ns[:, None]
        m = self.normal_length * self.normals
        wn = hp.NORMAL_EDGE_WEIGHT if normal_term else 0.0
        self.normal_term = bool(normal_term)
        outer = c[:, None, None] * e[:, :, None] * e[:, None, :]
        A = np.stack(
            [np.bincount(D[:, 0], weights=outer[:, a, b], minlength=n) for a in range(3)
             for b in range(3)],
            axis=-1,
        ).reshape(n, 3, 3)
        A += wn * m[:, :, None] * m[:, None, :]
        self.A = A
        det = np.linalg.det(A)
        scale = np.einsum("nij,nij->n", A, A) ** 1.5
        bad = ~(np.abs(det) > tol.ONE_RING_SINGULAR_RTOL * scale)
        if bad.any():
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(
                f"the one-ring fit at vertex {k} is singular (det A = {det[k]:.3g}); "
                "is the reference mesh degenerate there?"
            )
        self.A_inv = np.linalg.inv(A)
        g = c[:, None] * np.einsum("dij,dj->di", self.A_inv[D[:, 0]], e)  # (2E, 3)
        self.h = wn * np.einsum("nij,nj->ni", self.A_inv, m)
        gsum = np.stack([np.bincount(D[:, 0], weights=g[:, b], minlength=n) for b in range(3)], 1)
        rows = np.concatenate([
            (3 * np.arange(n)[:, None] + np.arange(3)).reshape(-1),
            (3 * D[:, 0][:, None] + np.arange(3)).reshape(-1),
        ])
        cols = np.concatenate([np.repeat(np.arange(n), 3), np.repeat(D[:, 1], 3)])
        vals = np.concatenate([gsum.reshape(-1), -g.reshape(-1)])
        self.K = sp.csr_matrix((vals, (rows, cols)), shape=(3 * n, n))
        self.K.sum_duplicates()

    def check_deformed(self, V) -> np.ndarray:
        """Deformed positions this operator accepts.

        Parameters
        ----------
        V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
            Finite, with this operator's number of vertices.

        Returns
        -------
        V : float64 array of the input's shape
        """
        return check_vertices(V, "deformed vertices", n_vertices=self.n_vertices, finite=True)

    def apply_soa(self, V) -> np.ndarray:
        """Deformation gradients in structure-of-arrays form.

        Parameters
        ----------
        V : (n_meshes, n_vertices, 3) float64 (already checked)

        Returns
        -------
        t : (9, n_meshes * n_vertices) float64
            ``t[3 a + b, k * n + i] = T_i[a, b]`` of mesh ``k``.
        """
        N, n = V.shape[0], self.n_vertices
        P = V.transpose(1, 2, 0).reshape(n, 3 * N)  # column a * N + k
        Y = (self.K @ P).reshape(n, 3, 3, N)  # (i, b, a, k)
        t = np.ascontiguousarray(Y.transpose(2, 1, 3, 0)).reshape(9, N * n)  # (a, b, k, i)
        if not self.normal_term:
            return t
        mp = self.deformed_normal_edges(V)  # (N, n, 3) = m'
        h = self.h
        for a in range(3):
            ma = mp[:, :, a]  # (N, n)
            for b in range(3):
                t[3 * a + b] += (ma * h[:, b]).reshape(-1)
        return t

    def _normal_sums_batch(self, V: np.ndarray) -> np.ndarray:
        """:func:`vertex_normal_sums` of ``(N, n, 3)`` with the incidence matrix built once."""
        F = self.faces
        p0 = V[:, F[:, 0], :]
        a = V[:, F[:, 1], :] - p0
        b = V[:, F[:, 2], :] - p0
        c = np.empty_like(a)
        c[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
        c[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
        c[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
        N, m = V.shape[0], len(F)
        acc = self.topology.incidence @ c.transpose(1, 0, 2).reshape(m, N * 3)
        return np.asarray(acc).reshape(self.n_vertices, N, 3).transpose(1, 0, 2)

    def deformed_normal_edges(self, V) -> np.ndarray:
        """Deformed normal edges ``m'_i = l' n'_i``.

        ``n'_i`` is the deformed unit vertex normal and ``l' = l sqrt(a'_i / a_i)`` scales with the
        local size (``a_i`` is the norm of the area-weighted normal sum, twice the one-ring area of
        a flat ring), so a rigid motion or a uniform scale ``s`` of the deformed mesh gives exactly
        ``m'_i = s R m_i`` and hence ``T_i = s R``.

        Parameters
        ----------
        V : (n_meshes, n_vertices, 3) float64

        Returns
        -------
        m : (n_meshes, n_vertices, 3) float64
        """
        acc = self._normal_sums_batch(V)
        na = np.sqrt(np.einsum("...k,...k->...", acc, acc))[..., None]
        scale = self.normal_length / np.sqrt(np.maximum(na, tol.DIVISION_FLOOR) * self._normal_sum_norms[:, None])
        return acc * scale

    def __call__(self, V) -> np.ndarray:
        """Deformation gradients of deformed mesh(es) (Eq. 1 with the normal term).

        Parameters
        ----------
        V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float

        Returns
        -------
        T : (n_vertices, 3, 3) or (n_meshes, n_vertices, 3, 3) float64
        """
        V = self.check_deformed(V)
        single = V.ndim == 2
        Vb = V[None] if single else V
        T = from_soa(self.apply_soa(Vb)).reshape(Vb.shape[0], self.n_vertices, 3, 3)
        return T[0] if single else T


def deformation_gradients(V0, V, F, normal_term: bool = True, clamp: bool = True) -> np.ndarray:
    """Deformation gradients ``T_i`` taking the reference one-rings to the deformed ones (Eq. 1).

    Builds a :class:`DeformationGradientOperator`; keep one yourself to process many meshes.

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        Reference mesh.
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        Deformed mesh(es), same connectivity.
    F : (n_faces, 3) int
    normal_term, clamp : bool
        See :class:`DeformationGradientOperator`.

    Returns
    -------
    T : (n_vertices, 3, 3) or (n_meshes, n_vertices, 3, 3) float64
    """
    return DeformationGradientOperator(V0, F, normal_term=normal_term, clamp=clamp)(V)
