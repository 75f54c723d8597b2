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
    exp_soa, matmul_soa, quat_exp_soa, quat_from_soa, quat_mul_soa, right_jacobian)
from meshvae_lib.geometry.spd_factor import factorize_spd, pinning
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
        self._sync_system = (G.T @ G + pinning(n, self.roots, 1.0)).tocsr()
        self._sync_lu = factorize_spd(self._sync_system)

    def system_matrix(self) -> sp.csr_matrix:
        """The pinned synchronisation Laplacian ``(n, n)`` float64 that is factorised (for benchmarks)."""
        return self._sync_system

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

    def synchronize(self, R: np.ndarray, w: np.ndarray, steps: list | None = None) -> tuple[np.ndarray, int]:
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
        steps : list or None
            If given, each applied correction is appended as ``(R before it (9, n), omega (n, 3))``
            (what :meth:`linear_response` differentiates), and a zero correction where the edges
            were consistent (any perturbation makes that sweep run).

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
            if sweeps == tol.ROTATION_SYNC_MAX_SWEEPS:
                break
            if np.max(np.abs(delta)) < tol.ROTATION_SYNC_TOL:
                if steps is not None:
                    # consistent edges: nothing to correct here, but any perturbation makes this
                    # sweep run, so the derivative includes it (with a zero correction)
                    steps.append((R, np.zeros((self.n_vertices, 3))))
                break
            omega = self._sync_lu.solve(np.ascontiguousarray(self._Gt @ delta.T))  # (n, 3)
            if not np.isfinite(omega).all():
                raise ValueError("rotation recovery: a global sweep gave NaN or infinite corrections; the"
                                 f" features' rotations overflow float64 (log dR up to {np.abs(w).max():.3g})")
            if steps is not None:
                steps.append((R, omega))
            R = matmul_soa(exp_soa(np.ascontiguousarray(omega.T)), R)
            if np.max(np.abs(omega)) < tol.ROTATION_SYNC_STEP_TOL:
                sweeps += 1
                break
        return R, sweeps

    def __call__(self, w: np.ndarray) -> np.ndarray:
        """Rotations ``(9, n_vertices)`` from ``log dR_ij`` ``(3, n_edges)``: the walk, then (for
        ``"global"``) the sweeps."""
        return self.recover(w)[0]

    def recover(self, w: np.ndarray) -> tuple[np.ndarray, dict]:
        """:meth:`__call__` and a record of its steps for :meth:`linear_response`: ``(R (9, n),
        {"w", "bfs": the walk's R (9, n), "steps": [(R, omega), ...]})``."""
        R = self.bfs(w)
        record = {"w": w, "bfs": R, "steps": []}
        if self.method == "global":
            R, sweeps = self.synchronize(R, w, record["steps"])
            logger.debug("rotation sync: %d sweeps", sweeps)
        return R, record

    # -- first-order response (geometry.reconstruction_linearization) -------------------------
    def _edge_terms(self, R: np.ndarray, dR: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """At rotations R (9, n) and edge rotations ``dR (n_edges, 3, 3)``: ``R`` as (n, 3, 3) and, per
        edge, the matrices that map a global rotation of ``R_i`` / of ``R_j dR_ij^-1`` to the change of
        the residual ``vee(skew(D))``, ``D = R_i dR_ij R_j^T``: ``(tr D I - D) / 2`` and
        ``(tr D I - D^T) / 2``."""
        n, E = self.n_vertices, self.edges
        Rm = np.ascontiguousarray(R.T).reshape(n, 3, 3)
        D = Rm[E[:, 0]] @ dR @ Rm[E[:, 1]].transpose(0, 2, 1)
        tr = np.trace(D, axis1=1, axis2=2)[:, None, None] * np.eye(3)
        return Rm, 0.5 * (tr - D), 0.5 * (tr - D.transpose(0, 2, 1))

    def _response_terms(self, record: dict) -> dict:
        """What :meth:`linear_response` and its adjoint need of a record that does not depend on the
        directions pushed through (computed once per record and kept in it under ``"terms"``): the
        walk's ``c_child = B_child eta_u`` maps, and per sweep ``M_l``, ``M_r``, ``M_r R_j``, ``J_l(omega)``
        and ``exp(hat(omega))``, all as (m, 3, 3) stacks."""
        terms = record.get("terms")
        if terms is not None:
            return terms
        n = self.n_vertices
        Rb = np.ascontiguousarray(record["bfs"].T).reshape(n, 3, 3)
        child = np.flatnonzero(self._parent >= 0)
        u, flip, par = self._parent_edge[child], self._parent_flip[child], self._parent[child]
        walk = np.where(flip[:, None, None], -Rb[par], Rb[child])
        steps = []
        dR = np.ascontiguousarray(exp_soa(record["w"]).T).reshape(-1, 3, 3) if record["steps"] else None
        for R, omega in record["steps"]:
            Rm, Ml, Mr = self._edge_terms(R, dR)
            Ex = np.ascontiguousarray(exp_soa(np.ascontiguousarray(omega.T)).T).reshape(n, 3, 3)
            steps.append({"Ml": Ml, "Mr": Mr, "MrR": Mr @ Rm[self.edges[:, 1]], "Rj": Rm[self.edges[:, 1]],
                          "Jl": right_jacobian(-omega), "Ex": Ex})
        terms = record["terms"] = {"child": child, "u": u, "walk": walk, "steps": steps}
        return terms

    def linear_response(self, record: dict, eta: np.ndarray) -> np.ndarray:
        """Global-frame changes ``g`` of the recovered rotations (``R_i <- exp(hat(g_i)) R_i``) for
        body-frame changes ``eta`` of the edge rotations (``dR_ij <- dR_ij exp(hat(eta_ij))``),
        through the steps :meth:`recover` took: the walk, ``g_child = g_parent + R_child eta``
        (``- R_parent eta`` for edges walked against their order), then each sweep: the residual
        ``delta_ij = vee(skew(R_i dR_ij R_j^T))`` changes by ``M_l g_i + M_r (R_j eta_ij - g_j)``, the
        correction ``omega = L^-1 G^T delta`` by ``L^-1 G^T d(delta)`` (the factorised Laplacian) and
        ``exp(hat(omega)) R`` by ``g <- J_l(omega) d(omega) + exp(hat(omega)) g``. All ``d`` directions
        go through together: one multi-column solve per sweep.

        Parameters
        ----------
        record : the dict of :meth:`recover`.
        eta : (n_edges, 3, d) float64

        Returns
        -------
        g : (n_vertices, 3, d) float64
        """
        n, (E, _, d) = self.n_vertices, eta.shape
        terms = self._response_terms(record)
        g = np.zeros((n, 3, d))
        g[terms["child"]] = terms["walk"] @ eta[terms["u"]]
        for lv in self._levels[1:]:
            g[lv] += g[self._parent[lv]]
        E0, E1 = self.edges[:, 0], self.edges[:, 1]
        for st in terms["steps"]:
            dd = st["Ml"] @ g[E0]
            dd -= st["Mr"] @ g[E1]
            dd += st["MrR"] @ eta
            dw = self._sync_lu.solve(self._Gt @ dd.reshape(E, 3 * d)).reshape(n, 3, d)
            g = st["Ex"] @ g
            g += st["Jl"] @ dw
        return g

    def linear_response_adjoint(self, record: dict, g_adj: np.ndarray) -> np.ndarray:
        """The transpose of :meth:`linear_response`: ``(n_vertices, 3, d) -> (n_edges, 3, d)``."""
        n, d = self.n_vertices, g_adj.shape[2]
        E = len(self.edges)
        E0, E1 = self.edges[:, 0], self.edges[:, 1]
        terms = self._response_terms(record)
        eta_adj = np.zeros((E, 3, d))
        g = np.array(g_adj, dtype=np.float64)
        for st in reversed(terms["steps"]):
            dw_adj = st["Jl"].transpose(0, 2, 1) @ g
            g = st["Ex"].transpose(0, 2, 1) @ g
            b = self._sync_lu.solve(dw_adj.reshape(n, 3 * d))     # the Laplacian is symmetric
            dd_adj = (self._G @ b).reshape(E, 3, d)
            np.add.at(g, E0, st["Ml"].transpose(0, 2, 1) @ dd_adj)
            r_adj = st["Mr"].transpose(0, 2, 1) @ dd_adj
            np.add.at(g, E1, -r_adj)
            eta_adj += st["Rj"].transpose(0, 2, 1) @ r_adj
        for lv in reversed(self._levels[1:]):
            np.add.at(g, self._parent[lv], g[lv])
        np.add.at(eta_adj, terms["u"], terms["walk"].transpose(0, 2, 1) @ g[terms["child"]])
        return eta_adj
