"""Rotations: the SO(3) logarithm and exponential, and the batched 3x3 kernels they run on.

Everything is vectorised over leading axes and written in closed form:

- :func:`so3_log` uses ``theta = atan2(|v| / 2, (tr R - 1) / 2)`` with ``v`` the axial vector of
  ``R - R^T``, a series for small angles, and the symmetric part ``R + R^T`` for the axis near
  ``theta = pi`` (where ``v`` vanishes). Accurate to ~1e-15 everywhere, no NaN at ``pi``.
- :func:`so3_exp` is Rodrigues' formula with series for small angles.
- The polar decomposition ``T = R S`` lives in :mod:`meshvae_lib.geometry.polar`.

Convention: ``so3_exp(w)`` rotates by ``|w|`` radians about ``w / |w|`` (right-hand rule), and
``hat(w) @ x = w x x`` (cross product).

The hot paths of the feature extraction and the reconstruction work on the *structure-of-arrays*
layout: ``m`` matrices as one ``(9, m)`` array of row-major entries (:func:`to_soa`,
:func:`from_soa`, :func:`matmul_soa`), rotation vectors as ``(3, m)`` (:func:`exp_soa`,
:func:`log_soa`) and unit quaternions ``(w, x, y, z)`` as ``(4, m)`` (:func:`quat_from_soa`,
:func:`quat_exp_soa`, :func:`quat_mul_soa`, :func:`relative_log_quat`); component-wise numpy on
long rows is several times faster than ``np.matmul`` or ``np.cross`` on ``(m, 3, 3)``.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.validation import check_matrices, check_vectors

__all__ = [
    "hat",
    "right_jacobian",
    "vee",
    "so3_log",
    "so3_exp",
    "rotation_angle",
    "to_soa",
    "from_soa",
    "matmul_soa",
    "exp_soa",
    "log_soa",
    "quat_from_soa",
    "quat_exp_soa",
    "quat_mul_soa",
    "relative_log_quat",
]


def hat(w) -> np.ndarray:
    """Skew-symmetric matrix of a 3-vector: ``hat(w) @ x == np.cross(w, x)``.

    Parameters
    ----------
    w : (..., 3) float

    Returns
    -------
    W : (..., 3, 3) float64
    """
    w = check_vectors(w, "w")
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
    W = check_matrices(W, "W")
    return 0.5 * np.stack(
        [W[..., 2, 1] - W[..., 1, 2], W[..., 0, 2] - W[..., 2, 0], W[..., 1, 0] - W[..., 0, 1]],
        axis=-1,
    )


def to_soa(M: np.ndarray) -> np.ndarray:
    """``(..., 3, 3)`` matrices (``m`` of them) to structure-of-arrays ``(9, m)`` float64 (row-major
    entries)."""
    return np.ascontiguousarray(M.reshape(-1, 9).T)


def from_soa(x: np.ndarray) -> np.ndarray:
    """Structure-of-arrays ``(9, m)`` back to ``(m, 3, 3)`` float64 (C-contiguous)."""
    return np.ascontiguousarray(x.T).reshape(-1, 3, 3)


def matmul_soa(a: np.ndarray, b: np.ndarray, transpose_a: bool = False,
               transpose_b: bool = False) -> np.ndarray:
    """Batched 3x3 products on structure-of-arrays: ``a @ b`` (optionally transposed factors).

    ``a`` and ``b`` are ``(9, m)`` (or one of them ``(9, 1)``, broadcast); returns ``(9, m)``
    float64. Faster than ``np.matmul`` on ``(m, 3, 3)`` for large ``m``.
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
    R = check_matrices(R, "R")
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
    R = check_matrices(R, "R")
    shape = R.shape[:-2]
    return np.ascontiguousarray(log_soa(to_soa(R)).T).reshape(shape + (3,))


def log_soa(r: np.ndarray) -> np.ndarray:
    """:func:`so3_log` on structure-of-arrays: rotations ``r (9, m)`` -> rotation vectors
    ``w (3, m)`` float64."""
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
        dk = np.take_along_axis(d, k[:, None], axis=-1)
        u = col / np.sqrt(np.maximum(dk, tol.DIVISION_FLOOR))
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
    w = check_vectors(w, "w")
    shape = w.shape[:-1]
    return from_soa(exp_soa(np.ascontiguousarray(w.reshape(-1, 3).T))).reshape(shape + (3, 3))


def exp_soa(w: np.ndarray) -> np.ndarray:
    """:func:`so3_exp` on structure-of-arrays: rotation vectors ``w (3, m)`` -> rotations
    ``r (9, m)`` float64."""
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


def quat_from_soa(r: np.ndarray) -> np.ndarray:
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


def relative_log_quat(qi: np.ndarray, qj: np.ndarray) -> np.ndarray:
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
    small = nv < tol.DIVISION_FLOOR
    # theta / |v| -> 2 / |w| as |v| -> 0 (series: 2 (1 - |v|^2 / (3 w^2)) / |w| is exact enough)
    factor = np.where(small, 2.0, theta / np.where(small, 1.0, nv)) * sign
    return np.stack([factor * x, factor * y, factor * z])


def quat_exp_soa(w: np.ndarray) -> np.ndarray:
    """Unit quaternions ``(4, m)`` float64 of rotation vectors ``(3, m)``:
    ``(cos(t/2), sin(t/2) w / t)``."""
    t = np.sqrt(np.einsum("km,km->m", w, w))
    small = t < tol.SO3_SMALL_ANGLE
    half = 0.5 * t
    s = np.where(small, 0.5 - t * t / 48.0, np.sin(half) / np.where(small, 1.0, t))
    return np.concatenate([np.cos(half)[None], w * s], axis=0)


def quat_mul_soa(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of quaternions ``(4, m)`` (``(w, x, y, z)`` rows), ``(4, m)`` float64."""
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return np.stack([
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    ])


def right_jacobian(w: np.ndarray) -> np.ndarray:
    """Right Jacobians of the SO(3) exponential: ``exp(hat(w + d)) ~ exp(hat(w)) exp(hat(J_r(w) d))``.

    Parameters
    ----------
    w : (m, 3) float64
        Rotation vectors.

    Returns
    -------
    J : (m, 3, 3) float64
        ``J_r(w) = I - (1 - cos t) / t^2 hat(w) + (t - sin t) / t^3 hat(w)^2``, ``t = |w|`` (series
        below ``SO3_SMALL_ANGLE``). The left Jacobian is ``J_r(-w) = J_r(w)^T``.
    """
    w = np.asarray(w, dtype=np.float64)
    t2 = np.einsum("mi,mi->m", w, w)
    t = np.sqrt(t2)
    small = t < tol.SO3_SMALL_ANGLE
    ts = np.where(small, 1.0, t)
    a = np.where(small, 0.5 - t2 / 24.0, (1.0 - np.cos(ts)) / ts ** 2)
    b = np.where(small, 1.0 / 6.0 - t2 / 120.0, (ts - np.sin(ts)) / ts ** 3)
    W = hat(w)
    return np.eye(3) - a[:, None, None] * W + b[:, None, None] * (W @ W)
