"""Principal directions of feature rows through their Gram matrix: the linear decoder's directions."""

from __future__ import annotations

import numpy as np

from meshvae_lib.tolerances import GRAM_RANK_RTOL

__all__ = ["principal_directions"]


def principal_directions(Y: np.ndarray, max_rank: int,
                         rtol: float = GRAM_RANK_RTOL) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rows' mean and principal directions, through the small Gram matrix.

    Y : (N >= 2, K) float64 rows; max_rank : the most directions to keep; rtol : singular values below
    ``rtol`` times the largest are dropped (and the kept ones floored there).
    Returns ``mean (K,)``, ``basis (r, K)`` with orthonormal rows, most variance first, and
    ``scale (r,)`` the coefficients' standard deviations (singular value / sqrt(N - 1)), where
    r = min(max_rank, N - 1, the numerical rank) >= 1.
    """
    Y = np.asarray(Y, dtype=np.float64)
    n = len(Y)
    mean = Y.mean(axis=0)
    Yc = Y - mean
    w, U = np.linalg.eigh(Yc @ Yc.T)
    order = np.argsort(w)[::-1]
    s = np.sqrt(np.clip(w[order], 0.0, None))
    U = U[:, order]
    r = int(min(max_rank, n - 1, np.sum(s > s[0] * rtol))) if s[0] > 0 else 1
    r = max(r, 1)
    s_r = np.maximum(s[:r], s[0] * rtol if s[0] > 0 else 1.0)
    basis = (U[:, :r].T @ Yc) / s_r[:, None]
    return mean, basis, s_r / np.sqrt(max(n - 1, 1))
