"""Meshes from RIMD features: the paper's way and an exact inverse.

Both methods first recover the per-vertex rotations ``R_i`` from the edge rotations
``dR_ij = R_i^T R_j``, then positions from ``T_i = R_i S_i``, and finally align the result rigidly
to the reference (the feature carries no global pose).

Rotation recovery (``rotations=``):

- ``"bfs"``: the reference implementation's walk, ``R_j = R_parent dR_parent,j`` along a
  breadth-first spanning tree (here rooted at a central vertex, so paths are as short as possible).
  Exact for exact features, but noise accumulates along the tree paths.
- ``"global"`` (default): the BFS result, then a few Gauss-Newton sweeps of a global least-squares
  fit of all rotations to all edges: write ``R_i <- exp(hat(w_i)) R_i`` and solve
  ``w_j - w_i = log(R_i dR_ij R_j^T)`` over every edge in the least-squares sense. That is a
  graph-Laplacian system whose matrix depends only on the mesh, so it is factorised once and each
  sweep costs one 3-column solve. For exact features the first sweep finds nothing to correct.

Positions (``method=``):

- ``"paper"``: minimise Eq. 1 over the deformed positions with ``T_i`` fixed,
  ``sum_ij c_ij |e'_ij - T_i e_ij|^2``, a cotangent-Laplacian system ``L p' = b`` (factorised once),
  optionally followed by the reference's local/global rounds (``iterations``, off by default):
  re-estimate each ``R_i`` as the rotation agreeing best with the current positions (normalised
  ``sum_j c_ij e'_ij (S_i e_ij)^T``) and the neighbours' ``R_j dR_ji`` (averaged), then solve
  again. Not an exact inverse: per-vertex ``T_i`` are not integrable in general.
- ``"exact"`` (default): the feature extraction is inverted exactly. ``T_i`` is linear in the
  deformed positions ``p'`` and the deformed normal edges ``m'`` (see
  :mod:`meshvae_lib.geometry.deformation_gradient`): ``T_i = (K p')_i^T + m'_i h_i^T``. Taking both as
  unknowns and minimising ``sum_i |T_i(p', m') - R_i S_i|_F^2``, the ``m'_i`` drop out in closed
  form (projection orthogonal to ``h_i``), leaving one sparse symmetric system ``M p' = r`` in the
  positions, the same matrix for the three coordinates and for every mesh. On generic meshes exact
  features give the mesh back to rounding error. Where one-rings are perfectly symmetric (regular
  procedural meshes) ``M`` has extra null modes (fields whose one-ring fit changes only along
  ``h_i``, which free ``m'`` absorbs); a tiny multiple of the paper's Eq. 1 system
  (``EXACT_REGULARIZATION``) decides them, and up to ``EXACT_REFINE_MAX_STEPS`` Gauss-Newton
  steps on ``sum_i |T_i(p') - R_i S_i|^2`` with the true ``m'(p')`` (matrix ``K^T K``, also
  factorised once) remove what is left. With ``refine="auto"`` a self-test when the reconstructor
  is built decides whether the steps are needed for this mesh (``EXACT_SELFTEST_TOL``); a step is
  skipped when the residual is already below ``EXACT_RESIDUAL_TOL``.

One vertex per connected component is pinned (the feature has no translation); components are
then placed by the final rigid alignment only, so several components keep their relative
placement only up to a translation each.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.sparse import csgraph
from scipy.sparse.linalg import splu

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator
from meshvae_lib.geometry.rimd import RIMDLayout
from meshvae_lib.geometry.rotations import _exp_soa, _polar_rs_soa, _quat_from_soa, matmul_soa
from meshvae_lib.geometry.topology import edge_index

__all__ = ["METHODS", "ROTATION_RECOVERY", "RIMDReconstructor"]

logger = logging.getLogger(__name__)

from meshvae_lib.defaults import RECONSTRUCTION_METHODS as METHODS, ROTATION_RECOVERY  # noqa: E402  (re-exported)
#: permutation of the 9 SoA entries that transposes a 3x3 matrix.
_TRANSPOSE = np.array([0, 3, 6, 1, 4, 7, 2, 5, 8])


def _factorize(M: sp.spmatrix):
    """Sparse LU of a symmetric positive definite matrix, keeping the symmetric fill-reducing
    ordering (no pivoting off the diagonal): 2-10x less time and fill than SuperLU's default."""
    return splu(sp.csc_matrix(M), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options=dict(SymmetricMode=True))


def _central_roots(adj: sp.csr_matrix) -> tuple[np.ndarray, np.ndarray]:
    """One central vertex per connected component (middle of a pseudo-diameter path).

    Returns ``(roots, labels)``: root ids and the component label of each vertex.
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


class RIMDReconstructor:
    """Meshes from RIMD features, for one reference mesh; all factorisations happen here, once.

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        The reference mesh the features were computed against.
    F : (n_faces, 3) int
    method : {"exact", "paper"}
        Position solve, see the module docstring. ``"exact"`` (default) inverts the extraction;
        ``"paper"`` minimises Eq. 1.
    layout : {"paper", "compact"}
        Feature layout (:class:`meshvae_lib.geometry.rimd.RIMDLayout`).
    rotations : {"global", "bfs"}
        Rotation recovery, see the module docstring. ``"global"`` (default) is robust to noise.
    iterations : int, optional
        ``method="paper"`` only: local/global refinement rounds after the first solve (the
        reference does 10). Default 0: in our measurements (docs/geometry.md) the rounds move the
        result away from the true mesh, with exact or noisy features alike.
    refine : {"auto", True, False}
        ``method="exact"`` only: Gauss-Newton steps after the linear solve (see the module
        docstring). ``"auto"`` (default) tests once, here, whether the linear solve alone is exact
        for this reference mesh (a twist of the reference about its main axis) and refines only if
        not; ``True`` always checks and refines, ``False`` never. Without them, meshes with
        perfectly symmetric one-rings (procedural meshes) keep errors around 1e-5 of the diagonal.

    Attributes
    ----------
    layout : RIMDLayout
    operator : DeformationGradientOperator
    roots : (n_components,) int64
        Root vertex of the rotation walk and pinned vertex, one per connected component.
    refine_active : bool
        ``method="exact"``: whether Gauss-Newton steps are taken (see ``refine``).
    """

    def __init__(self, V0, F, method: str = "exact", layout: str = "paper",
                 rotations: str = "global", iterations: int | None = None, refine="auto"):
        if method not in METHODS:
            raise ValueError(f"method must be one of {METHODS}, got {method!r}")
        if rotations not in ROTATION_RECOVERY:
            raise ValueError(f"rotations must be one of {ROTATION_RECOVERY}, got {rotations!r}")
        if iterations is not None and (int(iterations) != iterations or iterations < 0):
            raise ValueError(f"iterations must be a non-negative integer, got {iterations!r}")
        self.method = method
        if refine not in ("auto", True, False):
            raise ValueError(f"refine must be 'auto', True or False, got {refine!r}")
        self.refine = refine
        self.refine_active = False
        self.rotations = rotations
        self.iterations = 0 if iterations is None else int(iterations)
        op = DeformationGradientOperator(V0, F)
        self.operator = op
        self.V0 = np.asarray(V0, dtype=np.float64)
        self.faces = op.faces
        n = op.n_vertices
        self.n_vertices = n
        self.layout = RIMDLayout(op.faces, n, layout)
        E = self.layout.edges
        nE = len(E)
        # --- graph, roots, BFS levels --------------------------------------------------------
        adj = sp.csr_matrix((np.ones(nE), (E[:, 0], E[:, 1])), shape=(n, n))
        adj = adj + adj.T
        self.roots, self._component = _central_roots(adj)
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
        self._levels = [order[bounds[k]:bounds[k + 1]] for k in range(len(bounds) - 1)]
        self._levels = [lv for lv in self._levels if len(lv)]
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
        self._Gt = G.T.tocsr()
        pin = sp.csr_matrix((np.ones(len(self.roots)), (self.roots, self.roots)), shape=(n, n))
        self._sync_lu = _factorize(G.T @ G + pin)
        # --- position solve --------------------------------------------------------------------
        # the paper's Eq. 1 normal equations L p' = Q t (cotangent Laplacian); "exact" uses them
        # as a tiny regulariser (see the class docstring), "paper" solves them.
        c = op.weights
        W = sp.csr_matrix((c, (E[:, 0], E[:, 1])), shape=(n, n))
        W = W + W.T
        L = (sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()
        D = op.directed
        cd = c[edge_index(E, D[:, 0], D[:, 1])]
        e = self.V0[D[:, 0]] - self.V0[D[:, 1]]
        # b_k[a] = sum_{j in N_k} c_kj / 2 (T_k + T_j)[a, :] e_kj, as Q @ Tcols
        val = 0.5 * cd[:, None] * e
        rows = np.repeat(D[:, 0], 3)
        cols_k = (3 * D[:, 0][:, None] + np.arange(3)).reshape(-1)
        cols_j = (3 * D[:, 1][:, None] + np.arange(3)).reshape(-1)
        Q = sp.csr_matrix(
            (np.concatenate([val.reshape(-1)] * 2),
             (np.concatenate([rows, rows]), np.concatenate([cols_k, cols_j]))),
            shape=(n, 3 * n),
        )
        if method == "exact":
            h = op.h
            hn2 = np.einsum("ij,ij->i", h, h)
            P = np.tile(np.eye(3), (n, 1, 1))
            nz = hn2 > 0
            P[nz] -= h[nz, :, None] * h[nz, None, :] / hn2[nz, None, None]
            PK = _block_diag3(P) @ op.K
            M = (op.K.T @ PK).tocsr()
            lam = tol.EXACT_REGULARIZATION * float(M.diagonal().mean() / L.diagonal().mean())
            self.regularization_ = lam
            A = M + lam * L
            rhs = (PK.T + lam * Q).tocsr()
            # Gauss-Newton refinement with the true normal edges m'(p'): matrix K^T K, once
            KtK = (op.K.T @ op.K).tocsr()
            pin = sp.csr_matrix(
                (np.full(len(self.roots), float(KtK.diagonal().mean())), (self.roots, self.roots)),
                shape=(n, n))
            self._gn_lu = _factorize(KtK + pin)
            self._Kt = op.K.T.tocsr()
            self._diag = float(np.linalg.norm(self.V0.max(0) - self.V0.min(0)))
        else:
            A, rhs = L, Q
        scale = float(A.diagonal().mean())
        pin = sp.csr_matrix((np.full(len(self.roots), scale), (self.roots, self.roots)),
                            shape=(n, n))
        self._pos_lu = _factorize(A + pin)
        self._rhs_op = rhs  # (n, 3n)
        if method == "exact":
            self.refine_active = True if refine == "auto" else bool(refine)
            if refine == "auto":
                self.refine_active = self._linear_solve_is_inexact()
                logger.info("exact reconstruction: Gauss-Newton refinement %s for this mesh",
                            "on" if self.refine_active else "off")
        if method == "paper":
            self._directed = D
            self._directed_w = cd
            self._directed_e = e
            self._edge_norm = np.bincount(D[:, 0], weights=cd * np.einsum("dk,dk->d", e, e),
                                          minlength=n)
            self._degree = np.bincount(D[:, 0], minlength=n).astype(float)
            self._directed_u = edge_index(E, D[:, 0], D[:, 1])
            self._directed_flip = D[:, 0] > D[:, 1]

    def __repr__(self) -> str:
        return (f"RIMDReconstructor(method={self.method!r}, layout={self.layout.layout!r}, "
                f"rotations={self.rotations!r}, n_vertices={self.n_vertices})")

    # ------------------------------------------------------------------------------------------
    # rotations

    def _rotations_bfs(self, w: np.ndarray) -> np.ndarray:
        """Walk the spanning tree: ``R_child = R_parent dR_parent,child``; ``w`` (3, E) holds
        ``log dR_ij`` of the undirected edges. Returns ``R`` as (9, n).

        One batched product per BFS level (the walk is sequential in depth only); only the tree
        edges are exponentiated (``exp(-w) = exp(w)^T`` for edges walked against their order).
        """
        n = self.n_vertices
        sign = np.where(self._parent_flip, -1.0, 1.0)
        d = _exp_soa(w[:, self._parent_edge] * sign)  # (9, n): dR of each vertex's tree edge
        dm = np.ascontiguousarray(d.T).reshape(n, 3, 3)
        R = np.zeros((n, 3, 3))
        R[self.roots] = np.eye(3)
        for lv in self._levels[1:]:
            R[lv] = R[self._parent[lv]] @ dm[lv]
        return np.ascontiguousarray(R.reshape(n, 9).T)

    def _rotations_sync(self, R: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, int]:
        """Global Gauss-Newton sweeps on all edges; returns (R, sweeps solved).

        The residual of edge (i, j) is the axial vector of ``D = R_i dR_ij R_j^T`` (``sin`` of the
        angle times the axis, equal to ``log D`` to third order, exactly zero when consistent),
        computed with unit quaternions: ``D ~ q_i dq_ij conj(q_j)``, axial part ``2 w v``.
        """
        E = self.layout.edges
        dq = _quat_exp(w)  # (4, E)
        sweeps = 0
        for sweeps in range(tol.ROTATION_SYNC_MAX_SWEEPS + 1):
            q = _quat_from_soa(R)
            a = _quat_mul(q[:, E[:, 0]], dq)
            qj = q[:, E[:, 1]]
            qj[1:] *= -1.0  # conjugate
            d = _quat_mul(a, qj)
            delta = 2.0 * d[0] * d[1:]  # (3, E)
            if sweeps == tol.ROTATION_SYNC_MAX_SWEEPS or (
                    np.max(np.abs(delta)) < tol.ROTATION_SYNC_TOL):
                break
            omega = self._sync_lu.solve(np.ascontiguousarray(self._Gt @ delta.T))  # (n, 3)
            R = matmul_soa(_exp_soa(np.ascontiguousarray(omega.T)), R)
            if np.max(np.abs(omega)) < tol.ROTATION_SYNC_STEP_TOL:
                sweeps += 1
                break
        return R, sweeps

    def recover_rotations(self, log_dR) -> np.ndarray:
        """Per-vertex rotations from edge rotation vectors, up to one global rotation.

        Parameters
        ----------
        log_dR : (n_edges, 3) float
            ``log dR_ij`` of each undirected edge ``(i, j)``, ``i < j`` (``layout.edges`` order).

        Returns
        -------
        R : (n_vertices, 3, 3) float64
            ``R[root] = I`` for the BFS walk; the global sweeps keep the roots fixed.
        """
        log_dR = np.asarray(log_dR, dtype=np.float64)
        if log_dR.shape != (self.layout.n_edges, 3):
            raise ValueError(f"log_dR must have shape ({self.layout.n_edges}, 3), got {log_dR.shape}")
        r = self._recover(np.ascontiguousarray(log_dR.T))
        return np.ascontiguousarray(r.T).reshape(-1, 3, 3)

    def _recover(self, w: np.ndarray) -> np.ndarray:
        R = self._rotations_bfs(w)
        if self.rotations == "global":
            R, sweeps = self._rotations_sync(R, w)
            logger.debug("rotation sync: %d sweeps", sweeps)
        return R

    # ------------------------------------------------------------------------------------------
    # positions

    @staticmethod
    def _tcols(T: np.ndarray) -> np.ndarray:
        """(9, n) SoA gradients to (3n, 3) with ``[3 i + b, a] = T_i[a, b]``."""
        n = T.shape[1]
        return np.ascontiguousarray(T.reshape(3, 3, n).transpose(2, 1, 0)).reshape(3 * n, 3)

    def _solve_positions(self, T: np.ndarray) -> np.ndarray:
        return self._pos_lu.solve(np.ascontiguousarray(self._rhs_op @ self._tcols(T)))

    def _local_step(self, P: np.ndarray, S: np.ndarray, R: np.ndarray, dR: np.ndarray
                    ) -> np.ndarray:
        """Reference-style local step: best rotation per vertex for positions and neighbours."""
        n = self.n_vertices
        D = self._directed
        ep = P[D[:, 0]] - P[D[:, 1]]  # (2E, 3) e'_ij
        Se = np.einsum("dab,db->da",
                       np.ascontiguousarray(S.T).reshape(n, 3, 3)[D[:, 0]], self._directed_e)
        w = self._directed_w
        C = np.zeros((9, n))
        for a in range(3):
            for b in range(3):
                C[3 * a + b] = np.bincount(D[:, 0], weights=w * ep[:, a] * Se[:, b], minlength=n)
        C /= self._edge_norm
        # neighbours' votes: R_i ~ R_j dR_ji, dR_ji = dR_u^T when i < j else dR_u
        u = self._directed_u
        d = dR[:, u]
        notflip = ~self._directed_flip  # i < j: need dR_u^T
        d[:, notflip] = d[_TRANSPOSE][:, notflip]
        votes = matmul_soa(R[:, D[:, 1]], d)
        for k in range(9):
            C[k] += np.bincount(D[:, 0], weights=votes[k], minlength=n) / self._degree
        Rn, _ = _polar_rs_soa(C)
        return Rn

    def _linear_solve_is_inexact(self) -> bool:
        """Self-test: does the linear solve reproduce a twist of the reference to
        ``EXACT_SELFTEST_TOL`` of the diagonal (max over vertices)?"""
        X = self.V0 - self.V0.mean(axis=0)
        u = np.linalg.svd(X, full_matrices=False)[2][0]
        t = X @ u
        t = (t - t.min()) / max(float(np.ptp(t)), 1e-300)
        w = (np.pi * t)[:, None] * u  # twist by up to 180 degrees about the main axis
        Rt = np.ascontiguousarray(_exp_soa(np.ascontiguousarray(w.T)).T).reshape(-1, 3, 3)
        Vt = np.einsum("nab,nb->na", Rt, X)
        T = self.operator(Vt)
        tcols = self._tcols(np.ascontiguousarray(T.reshape(-1, 9).T))
        P = self._pos_lu.solve(np.ascontiguousarray(self._rhs_op @ tcols))
        err = np.linalg.norm(rigid_align(P, Vt) - Vt, axis=1).max()
        return bool(err > tol.EXACT_SELFTEST_TOL * self._diag)

    def _refine_exact(self, P: np.ndarray, tcols: np.ndarray) -> tuple[np.ndarray, int]:
        """Gauss-Newton on ``sum_i |T_i(p') - T_i|^2`` with the true ``m'(p')``; (P, steps)."""
        op = self.operator
        n = self.n_vertices
        steps = 0
        tscale = max(float(np.max(np.abs(tcols))), 1e-300)
        for steps in range(1, tol.EXACT_REFINE_MAX_STEPS + 1):
            m = op.deformed_normal_edges(P[None])[0]  # (n, 3)
            res = op.K @ P
            res += (op.h[:, :, None] * m[:, None, :]).reshape(3 * n, 3)
            res -= tcols
            if np.max(np.abs(res)) < tol.EXACT_RESIDUAL_TOL * tscale:
                steps -= 1
                break
            dP = self._gn_lu.solve(np.ascontiguousarray(self._Kt @ res))
            P = P - dP
            if np.max(np.abs(dP)) < tol.EXACT_REFINE_TOL * self._diag:
                break
        return P, steps

    def _reconstruct_one(self, w: np.ndarray, S: np.ndarray) -> np.ndarray:
        """``w`` (3, E) undirected log dR, ``S`` (9, n) -> positions (n, 3), not yet aligned."""
        R = self._recover(w)
        T = matmul_soa(R, S)
        tcols = self._tcols(T)
        P = self._pos_lu.solve(np.ascontiguousarray(self._rhs_op @ tcols))
        if self.method == "exact" and self.refine_active:
            P, steps = self._refine_exact(P, tcols)
            logger.debug("exact reconstruction: %d Gauss-Newton steps", steps)
        if self.method == "paper" and self.iterations:
            dR = _exp_soa(w)
            for _ in range(self.iterations):
                R = self._local_step(P, S, R, dR)
                P = self._solve_positions(matmul_soa(R, S))
        return P

    def reconstruct(self, features, align: bool = True, progress: bool = False) -> np.ndarray:
        """Mesh(es) from RIMD feature(s).

        Parameters
        ----------
        features : (K,) or (n_meshes, K) float
            In this reconstructor's layout (``self.layout.K`` numbers per mesh).
        align : bool
            Align each result rigidly (Kabsch, no scale) to the reference ``V0`` (default).
        progress : bool
            Show a progress bar (stderr).

        Returns
        -------
        V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float64
        """
        f = self.layout._check_features(features)
        if not np.all(np.isfinite(f)):
            raise ValueError("features hold NaN or infinite values")
        single = f.ndim == 1
        f = f.reshape(-1, self.layout.K)
        N, n = f.shape[0], self.n_vertices
        out = np.empty((N, n, 3))
        it = range(N)
        if progress:
            from tqdm.auto import tqdm

            it = tqdm(it, desc="reconstructing", unit="mesh")
        for k in it:
            log_dR, S = self.layout.unpack(f[k])
            w = np.ascontiguousarray(log_dR[0].T)
            Ssoa = np.ascontiguousarray(S[0].reshape(n, 9).T)
            out[k] = self._reconstruct_one(w, Ssoa)
        if align:
            out = rigid_align(out, self.V0)
        return out[0] if single else out


def _quat_exp(w: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(4, m)`` of rotation vectors ``(3, m)``: ``(cos(t/2), sin(t/2) w / t)``."""
    t = np.sqrt(np.einsum("km,km->m", w, w))
    small = t < tol.SO3_SMALL_ANGLE
    half = 0.5 * t
    s = np.where(small, 0.5 - t * t / 48.0, np.sin(half) / np.where(small, 1.0, t))
    return np.concatenate([np.cos(half)[None], w * s], axis=0)


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions ``(4, m)``."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ])


def _block_diag3(P: np.ndarray) -> sp.csr_matrix:
    """Block-diagonal sparse matrix from ``(n, 3, 3)`` blocks."""
    n = P.shape[0]
    rows = (3 * np.arange(n)[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
    cols = (3 * np.arange(n)[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)
    return sp.csr_matrix((P.reshape(-1), (rows.reshape(-1), cols.reshape(-1))), shape=(3 * n, 3 * n))
