"""Rotations: polar decomposition T = R S, and the SO(3) logarithm and exponential.

Everything is vectorised over leading axes ``(..., 3, 3)`` and written in closed form (no SVD in
the hot path):

- :func:`polar_decomposition` uses the scaled Newton iteration ``X <- (g X + X^{-T} / g) / 2``
  (Higham 1986) with the 3x3 inverse-transpose from cross products; it converges quadratically to
  the orthogonal polar factor. Where ``det T < 0`` that factor is a reflection; as in the reference
  implementation the reflection is moved into ``S`` by flipping the eigenvector of ``S`` with the
  smallest eigenvalue, so ``R`` is always a rotation (``det R = +1``) and ``S`` stays symmetric.
  Singular or badly conditioned ``T`` fall back to ``numpy.linalg.svd``.
- :func:`so3_log` uses ``theta = atan2(|v| / 2, (tr R - 1) / 2)`` with ``v`` the axial vector of
  ``R - R^T``, a series for small angles, and the symmetric part ``R + R^T`` for the axis near
  ``theta = pi`` (where ``v`` vanishes). Accurate to ~1e-15 everywhere, no NaN at ``pi``.
- :func:`so3_exp` is Rodrigues' formula with series for small angles.

Convention: ``so3_exp(w)`` rotates by ``|w|`` radians about ``w / |w|`` (right-hand rule), and
``hat(w) @ x = w x x`` (cross product).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol

__all__ = [
    "hat",
    "vee",
    "polar_decomposition",
    "so3_log",
    "so3_exp",
    "rotation_angle",
    "project_to_so3",
]


def _check_mats(T, name: str) -> np.ndarray:
    T = np.asarray(T, dtype=np.float64)
    if T.ndim < 2 or T.shape[-2:] != (3, 3):
        raise ValueError(f"{name} must have shape (..., 3, 3), got {T.shape}")
    return T


def hat(w) -> np.ndarray:
    """Skew-symmetric matrix of a 3-vector: ``hat(w) @ x == np.cross(w, x)``.

    Parameters
    ----------
    w : (..., 3) float

    Returns
    -------
    W : (..., 3, 3) float64
    """
    w = np.asarray(w, dtype=np.float64)
    if w.shape[-1:] != (3,):
        raise ValueError(f"w must have shape (..., 3), got {w.shape}")
    W = np.zeros(w.shape[:-1] + (3, 3))
    W[..., 0, 1], W[..., 0, 2] = -w[..., 2], w[..., 1]
    W[..., 1, 0], W[..., 1, 2] = w[..., 2], -w[..., 0]
    W[..., 2, 0], W[..., 2, 1] = -w[..., 1], w[..., 0]
    return W


def vee(W) -> np.ndarray:
    """Axial vector of the skew-symmetric part of ``W``: inverse of :func:`hat`.

    Parameters
    ----------
    W : (..., 3, 3) float

    Returns
    -------
    w : (..., 3) float64
    """
    W = _check_mats(W, "W")
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]],
        axis=-1,
    )


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


def to_soa(M: np.ndarray) -> np.ndarray:
    """``(m, 3, 3)`` matrices to structure-of-arrays ``(9, m)`` (row-major entries)."""
    return np.ascontiguousarray(M.reshape(-1, 9).T)


def from_soa(x: np.ndarray) -> np.ndarray:
    """Structure-of-arrays ``(9, m)`` back to ``(m, 3, 3)``."""
    return np.ascontiguousarray(x.T).reshape(-1, 3, 3)


def matmul_soa(a: np.ndarray, b: np.ndarray, transpose_a: bool = False,
               transpose_b: bool = False) -> np.ndarray:
    """Batched 3x3 products on ``(9, m)`` arrays: ``a @ b`` (optionally transposed factors).

    Faster than ``np.matmul`` on ``(m, 3, 3)`` for large ``m``.
    """
    def at(i, k):
        return a[3 * k + i] if transpose_a else a[3 * i + k]

    def bt(k, j):
        return b[3 * j + k] if transpose_b else b[3 * k + j]

    m = max(a.shape[1], b.shape[1])
    out = np.empty((9, m))
    tmp = np.empty(m)
    for i in range(3):
        for j in range(3):
            o = out[3 * i + j]
            np.multiply(at(i, 0), bt(0, j), out=o)
            np.multiply(at(i, 1), bt(1, j), out=tmp)
            o += tmp
            np.multiply(at(i, 2), bt(2, j), out=tmp)
            o += tmp
    return out


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
            if it >= tol.POLAR_SCALED_ITERATIONS or np.max(np.abs(g - 1.0)) < 1e-3:
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
    T = _check_mats(T, "T")
    if not np.all(np.isfinite(T)):
        raise ValueError("T holds NaN or infinite entries")
    shape = T.shape[:-2]
    r, s = _polar_rs_soa(to_soa(T))
    return from_soa(r).reshape(shape + (3, 3)), from_soa(s).reshape(shape + (3, 3))


def _polar_rs_soa(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Polar decomposition on ``(9, m)``: rotation ``r`` and symmetric ``s``, both ``(9, m)``."""
    u, det_t, ok, _ = _polar_soa(t)
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


def rotation_angle(R) -> np.ndarray:
    """Rotation angle in ``[0, pi]``, by ``atan2`` (accurate near 0 and near pi).

    Parameters
    ----------
    R : (..., 3, 3) float
        Rotation matrices.

    Returns
    -------
    theta : (...) float64
    """
    R = _check_mats(R, "R")
    v = 2.0 * vee(R)  # 2 sin(theta) u
    s = 0.5 * np.linalg.norm(v, axis=-1)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    return np.arctan2(s, c)


def so3_log(R) -> np.ndarray:
    """Logarithm of rotations as rotation vectors (axis times angle, angle in ``[0, pi]``).

    ``log R`` is the skew-symmetric matrix ``hat(w)``; the RIMD feature stores ``w``.

    Parameters
    ----------
    R : (..., 3, 3) float
        Rotation matrices (not checked; the result for a non-rotation is the log of a nearby one).

    Returns
    -------
    w : (..., 3) float64
        ``so3_exp(w) == R``. At exactly ``pi`` the axis sign is arbitrary (``w`` and ``-w`` give the
        same rotation); near ``pi`` the sign follows the antisymmetric part of ``R``.
    """
    R = _check_mats(R, "R")
    shape = R.shape[:-2]
    return np.ascontiguousarray(_log_soa(to_soa(R)).T).reshape(shape + (3,))


def _log_soa(r: np.ndarray) -> np.ndarray:
    """:func:`so3_log` on structure-of-arrays: ``r`` (9, m) -> ``w`` (3, m)."""
    v = np.stack([r[7] - r[5], r[2] - r[6], r[3] - r[1]])  # 2 sin(theta) u
    nv = np.sqrt(np.einsum("km,km->m", v, v))
    c = 0.5 * (r[0] + r[4] + r[8] - 1.0)
    theta = np.arctan2(0.5 * nv, c)
    # general and small-angle branch: w = theta / (2 sin theta) * v
    small = theta < tol.SO3_SMALL_ANGLE
    factor = np.where(small, 0.5 + theta**2 / 12.0,
                      0.5 * theta / np.where(small, 1.0, np.sin(theta)))
    w = v * factor
    # near pi: axis from the symmetric part, u u^T = (R + R^T - 2c I) / (2 (1 - c))
    near_pi = c < tol.SO3_NEAR_PI_COS
    if np.any(near_pi):
        idx = np.flatnonzero(near_pi)
        Rn = from_soa(r[:, idx])
        cn = c[idx]
        B = (0.5 * (Rn + np.swapaxes(Rn, -1, -2)) - cn[:, None, None] * np.eye(3)) / (
            1.0 - cn
        )[:, None, None]
        d = np.diagonal(B, axis1=-2, axis2=-1)
        k = np.argmax(d, axis=-1)
        col = np.take_along_axis(B, k[:, None, None], axis=-1)[..., 0]  # (m, 3) = u_k u
        u = col / np.sqrt(np.maximum(np.take_along_axis(d, k[:, None], axis=-1), 1e-300))
        u /= np.linalg.norm(u, axis=-1, keepdims=True)
        sign = np.sign(np.einsum("mk,km->m", u, v[:, idx]))
        sign = np.where(sign == 0, 1.0, sign)
        w[:, idx] = ((sign * theta[idx])[:, None] * u).T
    return w


def so3_exp(w) -> np.ndarray:
    """Exponential of rotation vectors (Rodrigues): ``exp(hat(w))``.

    Parameters
    ----------
    w : (..., 3) float
        Axis times angle (any length; angles beyond pi wrap around).

    Returns
    -------
    R : (..., 3, 3) float64
        Rotation matrices.
    """
    w = np.asarray(w, dtype=np.float64)
    if w.shape[-1:] != (3,):
        raise ValueError(f"w must have shape (..., 3), got {w.shape}")
    shape = w.shape[:-1]
    return from_soa(_exp_soa(np.ascontiguousarray(w.reshape(-1, 3).T))).reshape(shape + (3, 3))


def _exp_soa(w: np.ndarray) -> np.ndarray:
    """:func:`so3_exp` on structure-of-arrays: ``w`` (3, m) -> ``r`` (9, m)."""
    x, y, z = w
    th2 = x * x + y * y + z * z
    th = np.sqrt(th2)
    small = th < tol.SO3_SMALL_ANGLE
    ths = np.where(small, 1.0, th)
    A = np.where(small, 1.0 - th2 / 6.0 + th2**2 / 120.0, np.sin(ths) / ths)
    B = np.where(small, 0.5 - th2 / 24.0 + th2**2 / 720.0, (1.0 - np.cos(ths)) / ths**2)
    # R = I + A hat(w) + B (w w^T - |w|^2 I)
    r = np.empty((9, w.shape[1]))
    diag = 1.0 - B * th2
    Bx, By = B * x, B * y
    r[0] = diag + Bx * x
    r[4] = diag + By * y
    r[8] = diag + B * z * z
    Ax, Ay, Az = A * x, A * y, A * z
    xy, xz, yz = Bx * y, Bx * z, By * z
    r[1] = xy - Az
    r[3] = xy + Az
    r[2] = xz + Ay
    r[6] = xz - Ay
    r[5] = yz - Ax
    r[7] = yz + Ax
    return r


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


def _quat_from_soa(r: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(4, m)`` (w, x, y, z) of rotations ``(9, m)``, Shepperd's method.

    Each column uses the largest of ``(w, x, y, z)`` as pivot, so the result is accurate to
    rounding for every angle (including pi); the sign is arbitrary.
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22 = r
    tr = r00 + r11 + r22
    cand = np.stack([tr, r00, r11, r22])  # 4 |w|^2 - 1 etc. up to affine maps: pick the largest
    k = np.argmax(cand, axis=0)
    q = np.empty((4, r.shape[1]))
    # pivot w
    s = np.sqrt(np.maximum(1.0 + tr, 0.0)) * 2.0  # 4 w
    sel = k == 0
    if sel.any():
        ss = s[sel]
        q[0, sel] = 0.25 * ss
        q[1, sel] = (r21[sel] - r12[sel]) / ss
        q[2, sel] = (r02[sel] - r20[sel]) / ss
        q[3, sel] = (r10[sel] - r01[sel]) / ss
    for axis, (a, b, c) in enumerate(((0, 1, 2), (1, 2, 0), (2, 0, 1)), start=1):
        sel = k == axis
        if not sel.any():
            continue
        raa, rbb, rcc = r[4 * a][sel], r[4 * b][sel], r[4 * c][sel]
        ss = np.sqrt(np.maximum(1.0 + raa - rbb - rcc, 0.0)) * 2.0  # 4 q_a
        q[1 + a, sel] = 0.25 * ss
        q[0, sel] = (r[3 * c + b][sel] - r[3 * b + c][sel]) / ss
        q[1 + b, sel] = (r[3 * a + b][sel] + r[3 * b + a][sel]) / ss
        q[1 + c, sel] = (r[3 * a + c][sel] + r[3 * c + a][sel]) / ss
    return q


def _relative_log_quat(qi: np.ndarray, qj: np.ndarray) -> np.ndarray:
    """``log(R_i^T R_j)`` as rotation vectors ``(3, m)`` from unit quaternions ``(4, m)``.

    ``conj(q_i) q_j`` is the quaternion of ``R_i^T R_j``; its log is
    ``2 atan2(|v|, |w|) sign(w) v / |v|``, accurate at every angle (at exactly pi the sign is
    arbitrary, as for :func:`so3_log`).
    """
    aw, ax, ay, az = qi
    bw, bx, by, bz = qj
    w = aw * bw + ax * bx + ay * by + az * bz
    x = aw * bx - ax * bw - (ay * bz - az * by)
    y = aw * by - ay * bw - (az * bx - ax * bz)
    z = aw * bz - az * bw - (ax * by - ay * bx)
    nv = np.sqrt(x * x + y * y + z * z)
    sign = np.where(w < 0, -1.0, 1.0)
    theta = 2.0 * np.arctan2(nv, np.abs(w))
    small = nv < 1e-300
    # theta / |v| -> 2 / |w| as |v| -> 0 (series: 2 (1 - |v|^2 / (3 w^2)) / |w| is exact enough)
    factor = np.where(small, 2.0, theta / np.where(small, 1.0, nv)) * sign
    return np.stack([factor * x, factor * y, factor * z])
