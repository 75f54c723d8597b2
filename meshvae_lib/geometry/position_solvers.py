"""Positions from per-vertex deformation gradients ``T_i = R_i S_i``: the paper's solve and the
exact one.

The second step of every reconstruction (:mod:`meshvae_lib.geometry.reconstruction`). Both solvers
factorise one sparse symmetric matrix per reference mesh, when they are built, and then cost one
3-column solve per mesh; one vertex per connected component is pinned (the feature has no
translation).

- :class:`PaperPositionSolver` minimises Eq. 1 over the deformed positions with ``T_i`` fixed,
  ``sum_ij c_ij |e'_ij - T_i e_ij|^2``: a cotangent-Laplacian system ``L p' = b``
  (:func:`eq1_system`). :meth:`PaperPositionSolver.local_step` is the reference implementation's
  local step for its local/global rounds: re-estimate each ``R_i`` as the rotation agreeing best
  with the current positions (normalised ``sum_j c_ij e'_ij (S_i e_ij)^T``) and the neighbours'
  ``R_j dR_ji`` (averaged).
- :class:`ExactPositionSolver` inverts the feature extraction: ``T_i`` is linear in the deformed
  positions ``p'`` and the deformed normal edges ``m'`` (``T_i = (K p')_i^T + m'_i h_i^T``, see
  :mod:`meshvae_lib.geometry.deformation_gradient`). Taking both as unknowns and minimising
  ``sum_i |T_i(p', m') - R_i S_i|_F^2``, the ``m'_i`` drop out in closed form (projection
  orthogonal to ``h_i``), leaving one sparse symmetric system ``M p' = r``, plus
  ``EXACT_REGULARIZATION`` times Eq. 1 for the null modes of perfectly symmetric one-rings, and up
  to ``EXACT_REFINE_MAX_STEPS`` Gauss-Newton steps with the true ``m'(p')`` (matrix ``K^T K``)
  where the linear solve alone is not exact (``refine``).

Gradients are passed in the structure-of-arrays layout ``(9, n_vertices)`` of
:mod:`meshvae_lib.geometry.rotations`.
"""

from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator
from meshvae_lib.geometry.polar import polar_rs_soa
from meshvae_lib.geometry.rotations import exp_soa, matmul_soa
from meshvae_lib.geometry.spd_factor import factorize_spd, pinning
from meshvae_lib.geometry.topology import edge_index

__all__ = ["eq1_system", "gradient_columns", "PaperPositionSolver", "ExactPositionSolver"]

logger = logging.getLogger(__name__)

#: permutation of the 9 SoA entries that transposes a 3x3 matrix.
_TRANSPOSE = np.array([0, 3, 6, 1, 4, 7, 2, 5, 8])


def gradient_columns(T: np.ndarray) -> np.ndarray:
    """SoA gradients ``(9, n)`` to the right-hand-side layout ``(3 n, 3)`` float64:
    ``[3 i + b, a] = T_i[a, b]``."""
    n = T.shape[1]
    return np.ascontiguousarray(T.reshape(3, 3, n).transpose(2, 1, 0)).reshape(3 * n, 3)


def _directed_edge_terms(op: DeformationGradientOperator, V0: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Directed edges ``D (2E, 2)``, their cotangent weights ``(2E,)`` and reference vectors
    ``e_ij = p_i - p_j (2E, 3)``."""
    D = op.directed
    cd = op.weights[edge_index(op.edges, D[:, 0], D[:, 1])]
    return D, cd, V0[D[:, 0]] - V0[D[:, 1]]


def eq1_system(op: DeformationGradientOperator, V0: np.ndarray
               ) -> tuple[sp.csr_matrix, sp.csr_matrix]:
    """The normal equations ``L p' = Q t`` of the paper's Eq. 1 with the ``T_i`` fixed.

    Parameters
    ----------
    op : DeformationGradientOperator
        Of the reference mesh (its edges and cotangent weights).
    V0 : (n_vertices, 3) float64
        The reference mesh.

    Returns
    -------
    L : scipy.sparse.csr_matrix, shape (n, n)
        Cotangent Laplacian.
    Q : scipy.sparse.csr_matrix, shape (n, 3 n)
        ``(Q t)_k[a] = sum_{j in N_k} c_kj / 2 (T_k + T_j)[a, :] e_kj`` for gradients in the layout
        of :func:`gradient_columns`.
    """
    n, E = op.n_vertices, op.edges
    c = op.weights
    W = sp.csr_matrix((c, (E[:, 0], E[:, 1])), shape=(n, n))
    W = W + W.T
    L = (sp.diags(np.asarray(W.sum(axis=1)).ravel()) - W).tocsr()
    D, cd, e = _directed_edge_terms(op, V0)
    val = 0.5 * cd[:, None] * e
    rows = np.repeat(D[:, 0], 3)
    cols_k = (3 * D[:, 0][:, None] + np.arange(3)).reshape(-1)
    cols_j = (3 * D[:, 1][:, None] + np.arange(3)).reshape(-1)
    Q = sp.csr_matrix(
        (np.concatenate([val.reshape(-1)] * 2),
         (np.concatenate([rows, rows]), np.concatenate([cols_k, cols_j]))),
        shape=(n, 3 * n),
    )
    return L, Q


class _PinnedSolve:
    """``(A + pin) p' = rhs t``, factorised once; one pinned vertex per component."""

    def __init__(self, A: sp.spmatrix, rhs: sp.csr_matrix, roots: np.ndarray):
        scale = float(A.diagonal().mean())
        self._system = (A + pinning(A.shape[0], roots, scale)).tocsr()
        self._pos_lu = factorize_spd(self._system)
        self._rhs_op = rhs  # (n, 3n)

    def system_matrix(self) -> sp.csr_matrix:
        """The pinned position system ``(n, n)`` float64 that is factorised (for benchmarks)."""
        return self._system

    def linear_solve(self, tcols: np.ndarray) -> np.ndarray:
        """Positions ``(n, 3)`` for gradients in the layout of :func:`gradient_columns`."""
        return self._pos_lu.solve(np.ascontiguousarray(self._rhs_op @ tcols))

    def solve_gradients(self, dT: np.ndarray) -> np.ndarray:
        """The linear solve for many gradient fields: ``dT (n, 9, d)`` (row-major 3x3 per vertex)
        -> positions ``(n, 3, d)`` float64. Linear in ``dT``: the derivative of the positions."""
        n, _, d = dT.shape
        tcols = dT.reshape(n, 3, 3, d).transpose(0, 2, 1, 3).reshape(3 * n, 3 * d)
        return self._pos_lu.solve(self._rhs_op @ tcols).reshape(n, 3, d)

    def solve_gradients_adjoint(self, dP: np.ndarray) -> np.ndarray:
        """The transpose of :meth:`solve_gradients`: ``dP (n, 3, d) -> (n, 9, d)`` float64 (the
        pinned system is symmetric, so its factorisation serves the adjoint)."""
        n, _, d = dP.shape
        lam = self._pos_lu.solve(dP.reshape(n, 3 * d))
        t = (self._rhs_op.T @ lam).reshape(n, 3, 3, d)
        return t.transpose(0, 2, 1, 3).reshape(n, 9, d)


class PaperPositionSolver(_PinnedSolve):
    """The paper's position solve (Eq. 1 with ``T_i`` fixed) and the reference's local step.

    Parameters
    ----------
    op : DeformationGradientOperator
        Of the reference mesh.
    V0 : (n_vertices, 3) float64
    roots : (n_components,) int64
        Pinned vertices.
    """

    def __init__(self, op: DeformationGradientOperator, V0: np.ndarray, roots: np.ndarray):
        L, Q = eq1_system(op, V0)
        super().__init__(L, Q, roots)
        n, E = op.n_vertices, op.edges
        D, cd, e = _directed_edge_terms(op, V0)
        self.n_vertices = n
        self._directed = D
        self._directed_w = cd
        self._directed_e = e
        self._edge_norm = np.bincount(D[:, 0], weights=cd * np.einsum("dk,dk->d", e, e),
                                      minlength=n)
        self._degree = np.bincount(D[:, 0], minlength=n).astype(float)
        self._directed_u = edge_index(E, D[:, 0], D[:, 1])
        self._directed_flip = D[:, 0] > D[:, 1]

    def __call__(self, T: np.ndarray) -> np.ndarray:
        """Positions ``(n_vertices, 3)`` float64 (not aligned) from SoA gradients ``T (9, n)``."""
        return self.linear_solve(gradient_columns(T))

    def local_step(self, P: np.ndarray, S: np.ndarray, R: np.ndarray, dR: np.ndarray) -> np.ndarray:
        """Reference-style local step: best rotation per vertex for positions and neighbours.

        Parameters
        ----------
        P : (n_vertices, 3) float64
            Current positions.
        S : (9, n_vertices) float64
            Symmetric factors of the feature.
        R : (9, n_vertices) float64
            Current rotations.
        dR : (9, n_edges) float64
            Edge rotations ``dR_ij`` of the undirected edges.

        Returns
        -------
        R : (9, n_vertices) float64
        """
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
        Rn, _ = polar_rs_soa(C)
        return Rn


class ExactPositionSolver(_PinnedSolve):
    """The exact inverse of the feature extraction (see the module docstring).

    Parameters
    ----------
    op : DeformationGradientOperator
        Of the reference mesh.
    V0 : (n_vertices, 3) float64
    roots : (n_components,) int64
        Pinned vertices.
    refine : {"auto", True, False}
        Gauss-Newton steps after the linear solve: ``"auto"`` runs a self-test here (a twist of the
        reference about its main axis, ``EXACT_SELFTEST_TOL``) and refines only if the linear solve
        misses it; ``True`` always refines, ``False`` never.

    Attributes
    ----------
    regularization_ : float
        Weight of Eq. 1 added to the exact system.
    refine_active : bool
        Whether Gauss-Newton steps are taken.
    """

    def __init__(self, op: DeformationGradientOperator, V0: np.ndarray, roots: np.ndarray,
                 refine="auto"):
        L, Q = eq1_system(op, V0)
        n = op.n_vertices
        self.operator = op
        self.V0 = V0
        h = op.h
        hn2 = np.einsum("ij,ij->i", h, h)
        P = np.tile(np.eye(3), (n, 1, 1))
        nz = hn2 > 0
        P[nz] -= h[nz, :, None] * h[nz, None, :] / hn2[nz, None, None]
        PK = _block_diag3(P) @ op.K
        M = (op.K.T @ PK).tocsr()
        lam = tol.EXACT_REGULARIZATION * float(M.diagonal().mean() / L.diagonal().mean())
        self.regularization_ = lam
        # Gauss-Newton refinement with the true normal edges m'(p'): matrix K^T K, once
        KtK = (op.K.T @ op.K).tocsr()
        self._gn_lu = factorize_spd(KtK + pinning(n, roots, float(KtK.diagonal().mean())))
        self._Kt = op.K.T.tocsr()
        self._diag = float(np.linalg.norm(V0.max(0) - V0.min(0)))
        super().__init__(M + lam * L, (PK.T + lam * Q).tocsr(), roots)
        self.refine_active = True if refine == "auto" else bool(refine)
        if refine == "auto":
            self.refine_active = self._linear_solve_is_inexact()
            logger.info("exact reconstruction: Gauss-Newton refinement %s for this mesh",
                        "on" if self.refine_active else "off")

    def __call__(self, T: np.ndarray) -> np.ndarray:
        """Positions ``(n_vertices, 3)`` float64 (not aligned) from SoA gradients ``T (9, n)``."""
        tcols = gradient_columns(T)
        P = self.linear_solve(tcols)
        if self.refine_active:
            P, steps = self.refine(P, tcols)
            logger.debug("exact reconstruction: %d Gauss-Newton steps", steps)
        return P

    def _linear_solve_is_inexact(self) -> bool:
        """Self-test: does the linear solve reproduce a twist of the reference to
        ``EXACT_SELFTEST_TOL`` of the diagonal (max over vertices)?"""
        X = self.V0 - self.V0.mean(axis=0)
        u = np.linalg.svd(X, full_matrices=False)[2][0]
        t = X @ u
        t = (t - t.min()) / max(float(np.ptp(t)), tol.DIVISION_FLOOR)
        w = (np.pi * t)[:, None] * u  # twist by up to 180 degrees about the main axis
        Rt = np.ascontiguousarray(exp_soa(np.ascontiguousarray(w.T)).T).reshape(-1, 3, 3)
        Vt = np.einsum("nab,nb->na", Rt, X)
        T = self.operator(Vt)
        P = self.linear_solve(gradient_columns(np.ascontiguousarray(T.reshape(-1, 9).T)))
        err = np.linalg.norm(rigid_align(P, Vt) - Vt, axis=1).max()
        return bool(err > tol.EXACT_SELFTEST_TOL * self._diag)

    def refine(self, P: np.ndarray, tcols: np.ndarray) -> tuple[np.ndarray, int]:
        """Gauss-Newton on ``sum_i |T_i(p') - T_i|^2`` with the true ``m'(p')``.

        Parameters
        ----------
        P : (n_vertices, 3) float64
            Start (the linear solve).
        tcols : (3 n_vertices, 3) float64
            Target gradients (:func:`gradient_columns`).

        Returns
        -------
        P : (n_vertices, 3) float64
        steps : int
            Steps taken.
        """
        op = self.operator
        n = op.n_vertices
        steps = 0
        tscale = max(float(np.max(np.abs(tcols))), tol.DIVISION_FLOOR)
        for steps in range(1, tol.EXACT_REFINE_MAX_STEPS + 1):
            m = op.deformed_normal_edges(P[None])[0]  # (n, 3)
            res = op.K @ P
            res += (op.h[:, :, None] * m[:, None, :]).reshape(3 * n, 3)
            res -= tcols
            if np.max(np.abs(res)) < tol.EXACT_RESIDUAL_TOL * tscale:
                steps -= 1
                break
            dP = self._gn_lu.solve(np.ascontiguousarray(self._Kt @ res))
            if not np.isfinite(dP).all():
                raise ValueError("exact reconstruction: a Gauss-Newton step gave NaN or infinite positions;"
                                 " the features are too large for float64")
            P = P - dP
            if np.max(np.abs(dP)) < tol.EXACT_REFINE_TOL * self._diag:
                break
        return P, steps


def _block_diag3(P: np.ndarray) -> sp.csr_matrix:
    """Block-diagonal sparse matrix from ``(n, 3, 3)`` blocks."""
    n = P.shape[0]
    rows = (3 * np.arange(n)[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2)
    cols = (3 * np.arange(n)[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1)
    return sp.csr_matrix((P.reshape(-1), (rows.reshape(-1), cols.reshape(-1))), shape=(3 * n, 3 * n))
