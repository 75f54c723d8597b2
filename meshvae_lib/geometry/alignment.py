"""Rigid alignment (Kabsch / orthogonal Procrustes without scale) and mesh size.

The RIMD feature carries no global pose, so every reconstruction is brought back onto the reference
mesh by the rotation and translation that minimise the summed squared vertex distances.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.validation import check_vertices

__all__ = ["rigid_transform", "rigid_align", "bounding_box_diagonal"]


def rigid_transform(source, target) -> tuple[np.ndarray, np.ndarray]:
    """Best rotation and translation taking ``source`` onto ``target`` (Kabsch, no scale).

    Minimises ``sum_k |R source_k + t - target_k|^2`` over rotations ``R`` (det +1: a reflection is
    never returned, even when the best orthogonal map would be one) and translations ``t``.

    Parameters
    ----------
    source : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    target : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        Broadcast against each other over the mesh axis.

    Returns
    -------
    R : (3, 3) or (n_meshes, 3, 3) float64
        Rotation, applied as ``source @ R.T``.
    t : (3,) or (n_meshes, 3) float64
    """
    P = check_vertices(source, "source")
    Q = check_vertices(target, "target")
    if P.shape[-2] != Q.shape[-2]:
        raise ValueError(
            f"source and target must have the same number of vertices, got {P.shape} and {Q.shape}"
        )
    cp = P.mean(axis=-2, keepdims=True)
    cq = Q.mean(axis=-2, keepdims=True)
    H = np.swapaxes(Q - cq, -1, -2) @ (P - cp)  # (..., 3, 3): sum q p^T
    U, _, Vt = np.linalg.svd(H)
    d = np.sign(np.linalg.det(U @ Vt))
    d = np.where(d == 0, 1.0, d)
    D = np.ones(H.shape[:-2] + (3,))
    D[..., 2] = d
    R = (U * D[..., None, :]) @ Vt
    t = cq[..., 0, :] - (cp @ np.swapaxes(R, -1, -2))[..., 0, :]
    return R, t


def rigid_align(source, target) -> np.ndarray:
    """``source`` moved rigidly (rotation + translation, no scale) to best fit ``target``.

    Parameters
    ----------
    source : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    target : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        One target for all meshes, or one per mesh.

    Returns
    -------
    aligned : float64 array of the broadcast shape of ``source`` and ``target``.
    """
    R, t = rigid_transform(source, target)
    P = np.asarray(source, dtype=np.float64)
    return P @ np.swapaxes(R, -1, -2) + t[..., None, :]


def bounding_box_diagonal(V) -> np.ndarray | float:
    """Length of the axis-aligned bounding-box diagonal, the unit of every reported error.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float

    Returns
    -------
    d : float, or (n_meshes,) float64
    """
    V = check_vertices(V, "V")
    d = np.linalg.norm(V.max(axis=-2) - V.min(axis=-2), axis=-1)
    return float(d) if V.ndim == 2 else d
