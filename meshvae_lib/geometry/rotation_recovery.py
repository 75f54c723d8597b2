"""Per-vertex rotations ``R_i`` from the edge rotations ``dR_ij = R_i^T R_j`` of a RIMD feature.

The first step of every reconstruction (:mod:`meshvae_lib.geometry.reconstruction`), up to one
global rotation per connected component:

- ``"bfs"``: the reference implementation's walk, ``R_j = R_parent dR_parent,j`` along a
  breadth-first spanning tree rooted at a central vertex of each component (middle of a
  pseudo-diameter path, so paths are as short as possible). Exact for exact features, but noise
  accumulates along the tree paths.
- ``"global"`` (default): the BFS result, then a few Gauss-Newton sweeps of a global least-squares
  fit of all rotations to all edges: write ``R_i <- exp(hat(w_i)) R_i`` and solve
  ``w_j - w_i = log(R_i dR_ij R_j^T)`` over every edge in the least-squares sense. That is a
  graph-Laplacian system whose matrix depends only on the mesh, so it is factorised once and each
  sweep costs one 3-column solve. For exact features the first sweep finds nothing to correct.

Rotations are handled in the structure-of-arrays layout of :mod:`meshvae_lib.geometry.rotations`:
``(9, n)`` matrices, ``(3, n_edges)`` rotation vectors.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph

from meshvae_lib import tolerances as tol
from meshvae_lib.defaults import ROTATION_RECOVERY
from meshvae_lib.geometry.rotations import (
    exp_soa, matmul_soa, quat_exp_soa, quat_from_soa, quat_mul_soa)
from meshvae_lib.geometry.sparse_lu import factorize_spd, pinning, solve_columns
from meshvae_lib.geometry.topology import edge_index
from meshvae_lib.validation import check_choice

__all__ = ["RotationRecovery", "central_roots"]

logger = logging.getLogger(__name__)


def central_roots(adj: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """One central vertex per connected component (middle of a pseudo-diameter path).

    Parameters
    ----------
    adj : scipy.sparse.csr_matrix, shape (n_vertices, n_vertices)
        Symmetric adjacency of the mesh graph.

    Returns
    -------
    roots : (n_components,) int64
        Root vertex of each component.
    labels : (n_vertices,) int
        Component label of each vertex.
    """
    n_comp, labels = csgraph.connected_components(adj, directed=False)
    roots = []
    for c in range(n_comp):
        start = int(np.flatnonzero(labels == c)[0])
        d = csgraph.shortest_path(adj, indices=start, unweighted=True, directed=False)
        a = int(np.argmax(np.where(np.isfinite(d), d, -1)))
        d, pred = csgraph.shortest_path(adj, indices=a, unweighted=True, directed=False,
                                        return_predecessors=True)
        b = int(np.argmax(np.where(np.isfinite(d), d, -1)))
        path = [b]
        while path[-1] != a:
            path.append(int(pred[path[-1]]))
        roots.append(path[len(path) // 2])
    return np.asarray(roots, np.int64), labels


class RotationRecovery:
    """Rotation recovery for one mesh graph: spanning trees and the synchronisation system, built
    once.

    Parameters
    ----------
    E : (n_edges, 2) int64
        Undirected edges ``(i, j)``, ``i < j``, sorted
        (:func:`meshvae_lib.geometry.topology.edges`).
    n_vertices : int
    method : {"global", "bfs"}
        See the module docstring.

    Attributes
    ----------
    roots : (n_components,) int64
        Root of the walk (``R = I`` there) in each connected component; the global sweeps keep them
        fixed.
    component : (n_vertices,) int
        Connected component of each vertex.
    """

    def __init__(self, E: np.ndarray, n_vertices: int, method: str = "global"):
        self.method = check_choice(method, ROTATION_RECOVERY, "rotations")
        n = int(n_vertices)
        nE = len(E)
        self.n_vertices = n
        self.edges = E
        # --- graph, roots, BFS levels --------------------------------------------------------
        adj = sp.csr_matrix((np.ones(nE), (E[:, 0], E[:, 1])), shape=(n, n))
        adj = adj + adj.T
        self.roots, self.component = central_roots(adj)
        depth = np.zeros(n)
        parent = np.full(n, -1, np.int64)
        for r in self.roots:
            d, pred = csgraph.shortest_path(adj, indices=int(r), unweighted=True, directed=False,
                                            return_predecessors=True)
            mask = np.isfinite(d)
            depth[mask] = d[mask]
            parent[mask] = pred[mask]
        parent[self.roots] = -1
        depth = depth.astype(np.int64)
        order = np.argsort(depth, kind="stable")
        bounds = np.searchsorted(depth[order], np.arange(0, depth.max() + 2))
        levels = [order[bounds[k]:bounds[k + 1]] for k in range(len(bounds) - 1)]
        self._levels = [lv for lv in levels if len(lv)]
        child = np.flatnonzero(parent >= 0)
        self._parent = parent
        self._parent_edge = np.zeros(n, np.int64)
        self._parent_flip = np.zeros(n, bool)
        self._parent_edge[child] = edge_index(E, parent[child], child)
        self._parent_flip[child] = parent[child] > child  # dR_parent,child = dR_u^T
        # --- rotation synchronisation: uniform graph Laplacian, factorised once ----------------
        G = sp.csr_matrix(
            (np.concatenate([-np.ones(nE), np.ones(nE)]),
             (np.concatenate([np.arange(nE)] * 2), np.concatenate([E[:, 0], E[:, 1]]))),
            shape=(nE, n),
        )
        self._G = G
        self._Gt = G.T.tocsr()
        self._sync_lu = factorize_spd(G.T @ G + pinning(n, self.roots, 1.0))

    def bfs(self, w: np.ndarray) -> np.ndarray:
        """Walk the spanning tree: ``R_child = R_parent dR_parent,child``.

        One batched product per BFS level (the walk is sequential in depth only); only the tree
        edges are exponentiated (``exp(-w) = exp(w)^T`` for edges walked against their order).

        Parameters
        ----------
        w : (3, n_edges) float64
            ``log dR_ij`` of the undirected edges.

        Returns
        -------
        R : (9, n_vertices) float64
        """
        n = self.n_vertices
        sign = np.where(self._parent_flip, -1.0, 1.0)
        d = exp_soa(w[:, self._parent_edge] * sign)  # (9, n): dR of each vertex's tree edge
        dm = np.ascontiguousarray(d.T).reshape(n, 3, 3)
        R = np.zeros((n, 3, 3))
        R[self.roots] = np.eye(3)
        for lv in self._levels[1:]:
            R[lv] = R[self._parent[lv]] @ dm[lv]
        return np.ascontiguousarray(R.reshape(n, 9).T)

    def synchronize(self, R: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, int]:
        """Global Gauss-Newton sweeps on all edges.

        The residual of edge (i, j) is the axial vector of ``D = R_i dR_ij R_j^T`` (``sin`` of the
        angle times the axis, equal to ``log D`` to third order, exactly zero when consistent),
        computed with unit quaternions: ``D ~ q_i dq_ij conj(q_j)``, axial part ``2 w v``.

        Parameters
        ----------
        R : (9, n_vertices) float64
            Starting rotations (the BFS walk).
        w : (3, n_edges) float64
            ``log dR_ij`` of the undirected edges.

        Returns
        -------
        R : (9, n_vertices) float64
        sweeps : int
            Sweeps solved.
        """
        E = self.edges
        dq = quat_exp_soa(w)  # (4, E)
        sweeps = 0
        for sweeps in range(tol.ROTATION_SYNC_MAX_SWEEPS + 1):
            q = quat_from_soa(R)
            a = quat_mul_soa(q[:, E[:, 0]], dq)
            qj = q[:, E[:, 1]]
            qj[1:] *= -1.0  # conjugate
            d = quat_mul_soa(a, qj)
            delta = 2.0 * d[0] * d[1:]  # (3, E)
            if sweeps == tol.ROTATION_SYNC_MAX_SWEEPS or (
                    np.max(np.abs(delta)) < tol.ROTATION_SYNC_TOL):
                break
            omega = self._sync_lu.solve(np.ascontiguousarray(self._Gt @ delta.T))  # (n, 3)
            R = matmul_soa(exp_soa(np.ascontiguousarray(omega.T)), R)
            if np.max(np.abs(omega)) < tol.ROTATION_SYNC_STEP_TOL:
                sweeps += 1
                break
        return R, sweeps

    def __call__(self, w: np.ndarray) -> np.ndarray:
        """Rotations ``(9, n_vertices)`` from ``log dR_ij`` ``(3, n_edges)``: the walk, then (for
        ``"global"``) the sweeps."""
        R = self.bfs(w)
        if self.method == "global":
            R, sweeps = self.synchronize(R, w)
            logger.debug("rotation sync: %d sweeps", sweeps)
        return R

    # -- first-order response (geometry.reconstruction_linearization) -------------------------
    def linear_response(self, rho: np.ndarray) -> np.ndarray:
        """Global-frame rotation increments ``g`` for edge-rotation changes ``rho``.

        Where the edge rotations are consistent (``R_i dR_ij = R_j``), the synchronisation's
        least-squares optimality condition is linear with the factorised graph Laplacian:
        ``L g = G^T rho``, ``R_i <- exp(hat(g_i)) R_i``.

        Parameters
        ----------
        rho : (n_edges, 3, d) float64
            Per edge, the change of ``R_j``'s direction requested by the edge, in the global frame.

        Returns
        -------
        g : (n_vertices, 3, d) float64
        """
        E, _, d = rho.shape
        return solve_columns(self._sync_lu, self._Gt @ rho.reshape(E, 3 * d)).reshape(self.n_vertices, 3, d)

    def linear_response_adjoint(self, g_adj: np.ndarray) -> np.ndarray:
        """The transpose of :meth:`linear_response`: ``(n_vertices, 3, d) -> (n_edges, 3, d)``."""
        n, _, d = g_adj.shape
        mu = solve_columns(self._sync_lu, g_adj.reshape(n, 3 * d))   # the Laplacian is symmetric
        return (self._G @ mu).reshape(-1, 3, d)
