"""Factorisations of the reconstruction's sparse symmetric positive definite systems.

The rotation synchronisation and both position solves of :mod:`meshvae_lib.geometry.reconstruction`
are graph-Laplacian-like systems that depend on the reference mesh only: they are factorised once
(:func:`factorize_spd`) and then solved for every mesh, and for every column of an inference
Jacobian. Each is singular up to one translation or rotation per connected component, fixed by
adding a diagonal entry at one pinned vertex per component (:func:`pinning`).

The factorisation is CHOLMOD's supernodal Cholesky through ``cholespy`` (a self-contained wheel: its
own reference BLAS, so the same digits on every CPU). Measured for issue 38 on samba (10k vertices,
the synchronisation Laplacian, ``benchmarks/bench_inference.py --solvers``): 417 right-hand sides in
0.11 s against 0.23 s for SuperLU in its best chunks of 12 and 0.72 s for SuperLU all at once. Where
``cholespy`` cannot be imported, SciPy's SuperLU with the symmetric ordering serves, 12 columns at a
time (it slows sharply beyond about 16).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from meshvae_lib.tolerances import SPARSE_SOLVE_CHUNK

__all__ = ["SPDFactor", "factorize_spd", "pinning", "spd_backend"]


def spd_backend() -> str:
    """``"cholmod"`` when ``cholespy`` imports, else ``"superlu"``."""
    try:
        import cholespy  # noqa: F401
    except ImportError:
        return "superlu"
    return "cholmod"


class SPDFactor:
    """A factorised sparse symmetric positive definite matrix: ``solve(B)`` for ``B (n,)`` or ``(n, k)``.

    Parameters
    ----------
    M : scipy.sparse matrix, shape (n, n), float64, symmetric positive definite.
    backend : {"cholmod", "superlu"} or None (None: :func:`spd_backend`).
    chunk : int or None
        SuperLU only: right-hand sides per solve (None: all at once).

    Attributes
    ----------
    backend : str
    shape : (n, n)
    """

    def __init__(self, M: sp.spmatrix, backend: str | None = None, chunk: int | None = SPARSE_SOLVE_CHUNK):
        self.chunk = chunk
        self.backend = spd_backend() if backend is None else backend
        if self.backend not in ("cholmod", "superlu"):
            raise ValueError(f"backend must be 'cholmod' or 'superlu', got {backend!r}")
        M = sp.coo_matrix(M, dtype=np.float64)
        if M.shape[0] != M.shape[1]:
            raise ValueError(f"M must be square, got shape {M.shape}")
        self.shape = M.shape
        if self.backend == "cholmod":
            import cholespy

            M.sum_duplicates()
            self._solver = cholespy.CholeskySolverD(M.shape[0], M.row.astype(np.int32), M.col.astype(np.int32),
                                                    np.ascontiguousarray(M.data), cholespy.MatrixType.COO)
        else:
            # SuperLU keeping the symmetric fill-reducing ordering (no pivoting off the diagonal):
            # 2-10x less time and fill than its default
            self._solver = splu(M.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                options=dict(SymmetricMode=True))

    def solve(self, B: np.ndarray) -> np.ndarray:
        """``M^-1 B`` for ``B (n,)`` or ``(n, k)`` float; returns a new float64 array of B's shape."""
        B = np.ascontiguousarray(B, dtype=np.float64)
        if B.shape[0] != self.shape[0] or B.ndim not in (1, 2):
            raise ValueError(f"B must have shape ({self.shape[0]},) or ({self.shape[0]}, k), got {B.shape}")
        if self.backend == "cholmod":
            X = np.empty_like(B)
            self._solver.solve(B, X)
            return X
        if B.ndim == 1 or self.chunk is None or B.shape[1] <= self.chunk:
            return self._solver.solve(B)
        return np.concatenate([self._solver.solve(np.ascontiguousarray(B[:, k:k + self.chunk]))
                               for k in range(0, B.shape[1], self.chunk)], axis=1)


def factorize_spd(M: sp.spmatrix, backend: str | None = None) -> SPDFactor:
    """The factorisation of a sparse symmetric positive definite matrix ``M (n, n)`` float64
    (:class:`SPDFactor`; the module docstring says which backend and why)."""
    return SPDFactor(M, backend)


def pinning(n: int, vertices: np.ndarray, value: float) -> sp.csr_matrix:
    """Diagonal matrix with ``value`` at the pinned ``vertices`` and zero elsewhere.

    Parameters
    ----------
    n : int
        Size of the system.
    vertices : (k,) int64
        One vertex per connected component.
    value : float
        Weight of the pin (usually the mean diagonal of the system it is added to).

    Returns
    -------
    P : scipy.sparse.csr_matrix, shape (n, n), float64
    """
    return sp.csr_matrix((np.full(len(vertices), float(value)), (vertices, vertices)), shape=(n, n))
