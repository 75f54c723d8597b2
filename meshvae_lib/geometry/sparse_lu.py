"""Sparse LU factorisations of the reconstruction's symmetric positive definite systems.

The rotation synchronisation and both position solves of :mod:`meshvae_lib.geometry.reconstruction`
are graph-Laplacian-like systems that depend on the reference mesh only: they are factorised once
(:func:`factorize_spd`) and then solved for every mesh. Each is singular up to one translation or
rotation per connected component, fixed by adding a diagonal entry at one pinned vertex per
component (:func:`pinning`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

__all__ = ["factorize_spd", "pinning"]


def factorize_spd(M: sp.spmatrix):
    """Sparse LU of a symmetric positive definite matrix, keeping the symmetric fill-reducing
    ordering (no pivoting off the diagonal): 2-10x less time and fill than SuperLU's default.

    Parameters
    ----------
    M : scipy.sparse matrix, shape (n, n), float64

    Returns
    -------
    scipy.sparse.linalg.SuperLU
        ``.solve(b)`` for ``b (n,)`` or ``(n, k)`` float64.
    """
    return splu(sp.csc_matrix(M), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options=dict(SymmetricMode=True))


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
