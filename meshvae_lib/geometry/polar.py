"""Polar decomposition ``T = R S`` of deformation gradients into a rotation and a symmetric stretch.

:func:`polar_decomposition` uses the scaled Newton iteration ``X <- (g X + X^{-T} / g) / 2``
(Higham 1986) with the 3x3 inverse-transpose from cofactors, vectorised over leading axes
``(..., 3, 3)`` and written in closed form (no SVD in the hot path); it converges quadratically to
the orthogonal polar factor. Where ``det T < 0`` that factor is a reflection; as in the reference
implementation the reflection is moved into ``S`` by flipping the eigenvector of ``S`` with the
smallest eigenvalue, so ``R`` is always a rotation (``det R = +1``) and ``S`` stays symmetric.
Singular or badly conditioned ``T`` fall back to ``numpy.linalg.svd``.

:func:`polar_rs_soa` is the same on the structure-of-arrays layout ``(9, m)`` of
:mod:`meshvae_lib.geometry.rotations`, for the feature extraction and reconstruction hot paths.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.rotations import from_soa, matmul_soa, to_soa
from meshvae_lib.validation import check_finite, check_matrices

__all__ = ["polar_decomposition", "project_to_so3", "polar_rs_soa"]


def _cofactor_soa(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Cofactor matrix and determinant, structure-of-arrays: ``x`` is ``(9, m)``, row-major entries.

    ``X^{-T} = cof / det``. Written component-wise because ``np.cross`` on ``(m, 3)`` arrays is an
    order of magnitude slower.
    """
    a, b, c, d, e, f, g, h, i = x
    cof = np.empty_like(x)
    cof[0] = e * i - f * h
    cof[1] = f * g - d * i
    cof[2] = d * h - e * g
    cof[3] = c * h - b * i
    cof[4] = a * i - c * g
    cof[5] = b * g - a * h
    cof[6] = b * f - c * e
    cof[7] = c * d - a * f
    cof[8] = a * e - b * d
    det = a * cof[0] + b * cof[1] + c * cof[2]
    return cof, det


def _polar_soa(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Orthogonal polar factor by scaled Newton on ``(9, m)``.

    Returns ``(u, det_t, ok, n_iter)``: ``u`` (9, m) orthogonal factor, ``det T``, a mask of the
    matrices Newton handled (non-singular, converged) and the iterations used.
    """
    x = t.copy()
    m = x.shape[1]
    cof, det_t = _cofactor_soa(x)
    nx = np.sqrt(np.einsum("km,km->m", x, x))
    ok = np.abs(det_t) > tol.POLAR_SINGULAR_RTOL * nx**3
    det = np.where(ok, det_t, 1.0)
    scaled = True
    it = 0
    for it in range(1, tol.POLAR_MAX_ITERATIONS + 1):
        if scaled:
            nc = np.sqrt(np.einsum("km,km->m", cof, cof))
            g = np.sqrt(nc / (np.abs(det) * np.where(nx > 0, nx, 1.0)))
            g = np.where(ok, g, 1.0)
            x *= 0.5 * g
            cof *= 0.5 / (det * g)
            x += cof
            if it >= tol.POLAR_SCALED_ITERATIONS or np.max(np.abs(g - 1.0)) < tol.POLAR_SCALING_OFF:
                scaled = False
        else:
            x_old = x
            x = 0.5 * x_old + cof * (0.5 / det)
            if m == 0 or np.max(np.abs(x - x_old)) < tol.POLAR_CONVERGENCE:
                break
        cof, det = _cofactor_soa(x)
        det = np.where(ok, det, 1.0)
        if scaled:
            nx = np.sqrt(np.einsum("km,km->m", x, x))
    return x, det_t, ok, it


def polar_decomposition(T) -> tuple[np.ndarray, np.ndarray]:
    """Polar decomposition ``T = R S`` with ``R`` a rotation and ``S`` symmetric.

    For ``det T > 0``, ``S`` is the symmetric positive definite stretch ``sqrt(T^T T)``. For
    ``det T < 0`` the orthogonal factor would be a reflection; instead ``R`` stays in SO(3) and ``S``
    takes the reflection (its eigenvalue of smallest magnitude becomes negative), as in the RIMD
    reference implementation. Used for ``T_i = R_i S_i`` (paper Sec. 3).

    Parameters
    ----------
    T : (..., 3, 3) float

    Returns
    -------
    R : (..., 3, 3) float64
        Rotations, ``det R = +1``.
    S : (..., 3, 3) float64
        Symmetric, ``R @ S == T``.
    """
    T = check_finite(check_matrices(T, "T"), "T", "entries")
    shape = T.shape[:-2]
    r, s = polar_rs_soa(to_soa(T))
    return from_soa(r).reshape(shape + (3, 3)), from_soa(s).reshape(shape + (3, 3))


def polar_rs_soa(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`polar_decomposition` on structure-of-arrays.

    Parameters
    ----------
    t : (9, m) float64
        Row-major entries of ``m`` matrices (:func:`~meshvae_lib.geometry.rotations.to_soa`),
        finite.

    Returns
    -------
    r : (9, m) float64
        Rotations (``det = +1``).
    s : (9, m) float64
        Symmetric factors, ``r @ s == t``.

    Raises
    ------
    ValueError
        If some matrix has NaN or infinite entries (the Newton iteration is capped at
        ``POLAR_MAX_ITERATIONS``; a matrix it does not handle goes to the SVD, which needs finite
        entries).
    """
    bad_t = ~np.isfinite(t).all(axis=0)
    if bad_t.any():  # LAPACK's SVD may never return on NaN or infinite entries
        k = int(np.flatnonzero(bad_t)[0])
        raise ValueError(f"polar decomposition: {int(bad_t.sum())} of {t.shape[1]} matrices have NaN or infinite"
                         f" entries (first: matrix {k}); the coordinates or features they come from overflowed")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        u, det_t, ok, _ = _polar_soa(t)
    ok &= np.isfinite(u).all(axis=0) & np.isfinite(det_t)  # Newton overflowed: SVD instead
    s = matmul_soa(u, t, transpose_a=True)
    # symmetrise
    for i, j in ((0, 1), (0, 2), (1, 2)):
        v = 0.5 * (s[3 * i + j] + s[3 * j + i])
        s[3 * i + j] = v
        s[3 * j + i] = v
    bad = ~ok
    if bad.any():
        idx = np.flatnonzero(bad)
        Us, sig, Vt = np.linalg.svd(from_soa(t[:, idx]))
        u[:, idx] = to_soa(Us @ Vt)
        s[:, idx] = to_soa((np.swapaxes(Vt, -1, -2) * sig[:, None, :]) @ Vt)
        det_t = det_t.copy()
        det_t[idx] = np.linalg.det(Us @ Vt)
    neg = det_t < 0
    if neg.any():
        # the orthogonal factor is a reflection: flip the eigenvector of S with the smallest
        # eigenvalue, moving the reflection into S (R = U F, S = F S, F = I - 2 v v^T).
        idx = np.flatnonzero(neg)
        Sn = from_soa(s[:, idx])
        _, vecs = np.linalg.eigh(Sn)
        v = vecs[:, :, 0]
        Fm = np.eye(3) - 2.0 * v[:, :, None] * v[:, None, :]
        Rn = from_soa(u[:, idx]) @ Fm
        Sn = Fm @ Sn
        u[:, idx] = to_soa(Rn)
        s[:, idx] = to_soa(0.5 * (Sn + np.swapaxes(Sn, -1, -2)))
    return u, s


def project_to_so3(M) -> np.ndarray:
    """Closest rotation to each matrix (Frobenius norm): the rotation part of its polar factor.

    Parameters
    ----------
    M : (..., 3, 3) float

    Returns
    -------
    R : (..., 3, 3) float64
    """
    return polar_decomposition(M)[0]
