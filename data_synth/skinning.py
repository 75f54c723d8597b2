"""Skinning: smooth per-vertex bone weights, linear blend and dual-quaternion skinning.

Weights start from each vertex's *part* (the bone of the implicit primitive that made the surface
there), are diffused over the mesh (so they blend smoothly across joints, over a width given in
metres, and never jump across a gap between two parts as distance-based weights do) and can
then be restricted to the part's relatives (ancestors and descendants up to two generations,
never siblings) or by a mask. Posing uses dual-quaternion skinning (Kavan et al. 2007), which does not
collapse a twisting wrist or a raised shoulder the way linear blend skinning does ("candy
wrapper"); :func:`linear_blend` is kept for affine maps (body-shape changes) and for comparison.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from data_synth.meshing import vertex_adjacency
from data_synth.skeleton import Skeleton

__all__ = ["skinning_weights", "linear_blend", "dual_quaternion_blend"]


def skinning_weights(V: np.ndarray, F: np.ndarray, parts: np.ndarray, skeleton: Skeleton,
                     blend_width: float, max_influences: int = 4,
                     relatives_depth: int | None = 2, mask: np.ndarray | None = None) -> np.ndarray:
    """Smooth skinning weights.

    Parameters
    ----------
    V : (n_vertices, 3) float64, the rest template.
    F : (n_faces, 3) int64
    parts : (n_vertices,) int64, the joint each vertex belongs to before blending.
    skeleton : Skeleton
    blend_width : float, distance over which weights blend across a joint (same unit as V).
    max_influences : int, bones kept per vertex.
    relatives_depth : int or None, keep only bones within this many generations of the vertex's
        part (None: no restriction; the diffusion over the surface already keeps weights local).
    mask : (n_vertices, n_joints) float64 in [0, 1], optional, multiplies the diffused weights
        (the body uses it to keep each thigh's weight on its own side of the crotch).

    Returns
    -------
    W : (n_vertices, n_joints) float64, rows non-negative and summing to 1.
    """
    n, J = len(V), skeleton.n_joints
    W = np.zeros((n, J))
    W[np.arange(n), parts] = 1.0
    A = vertex_adjacency(F, n)
    deg = np.asarray(A.sum(axis=1)).ravel()
    E = np.vstack([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    mean_edge = np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean()
    iterations = int(np.clip(np.ceil(2.0 * (blend_width / mean_edge) ** 2), 1, 400))
    for _ in range(iterations):
        W = 0.5 * W + 0.5 * (A @ W) / deg[:, None]
    if relatives_depth is not None:
        allowed = np.zeros((J, J), dtype=bool)
        for j, nb in enumerate(skeleton.relatives(depth=relatives_depth)):
            allowed[j, list(nb)] = True
        W *= allowed[parts]
    if mask is not None:
        W *= mask
    W[np.arange(n), parts] += 1e-12  # never an empty row
    if max_influences < J:
        cutoff = -np.sort(-W, axis=1)[:, max_influences - 1 : max_influences]
        W[W < cutoff] = 0.0
    W /= W.sum(axis=1, keepdims=True)
    return W


def linear_blend(V: np.ndarray, W: np.ndarray, M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Linear blend of per-bone affine maps ``x -> M_j x + b_j``.

    Parameters
    ----------
    V : (n_vertices, 3) float64
    W : (n_vertices, n_joints) float64
    M : (n_joints, 3, 3) or (n_frames, n_joints, 3, 3) float64
    b : (n_joints, 3) or (n_frames, n_joints, 3) float64

    Returns
    -------
    (n_vertices, 3) or (n_frames, n_vertices, 3) float64
    """
    moved = np.einsum("...jab,vb->...vja", M, V) + b[..., None, :, :]
    return np.einsum("vj,...vja->...va", W, moved)


def _quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of scalar-last quaternions ``(..., 4)``."""
    av, aw = a[..., :3], a[..., 3:]
    bv, bw = b[..., :3], b[..., 3:]
    v = aw * bv + bw * av + np.cross(av, bv)
    w = aw * bw - np.sum(av * bv, axis=-1, keepdims=True)
    return np.concatenate([v, w], axis=-1)


def dual_quaternion_blend(V: np.ndarray, W: np.ndarray, R: np.ndarray, t: np.ndarray,
                          parents: np.ndarray | None = None) -> np.ndarray:
    """Dual-quaternion skinning of rigid bone transforms ``x -> R_j x + t_j``.

    Parameters
    ----------
    V : (n_vertices, 3) float64, rest positions.
    W : (n_vertices, n_joints) float64, skinning weights.
    R : (n_frames, n_joints, 3, 3) float64, rotations.
    t : (n_frames, n_joints, 3) float64, translations.
    parents : (n_joints,) int64, optional. A quaternion and its negative are the same rotation;
        blending needs them on one side. With ``parents`` every bone's quaternion is put on its
        parent's side (one choice for the whole mesh, so the result is continuous across it);
        without, each vertex aligns the signs with its main bone.

    Returns
    -------
    (n_frames, n_vertices, 3) float64
    """
    n_frames, J = R.shape[:2]
    qr = Rotation.from_matrix(R.reshape(-1, 3, 3)).as_quat().reshape(n_frames, J, 4)
    tq = np.concatenate([t, np.zeros((n_frames, J, 1))], axis=-1)
    if parents is not None:
        for j in range(1, J):  # about 20 bones, vectorised over frames
            flip = np.sum(qr[:, j] * qr[:, parents[j]], axis=-1) < 0
            qr[flip, j] *= -1.0
    qd = 0.5 * _quat_mul(tq, qr)
    pivot = np.argmax(W, axis=1)
    out = np.empty((n_frames, len(V), 3))
    for f in range(n_frames):  # loop over frames, vectorised over vertices and bones
        if parents is None:
            sign = np.sign(qr[f, pivot] @ qr[f].T)  # (n_vertices, J)
            sign[sign == 0] = 1.0
            Ws = W * sign
        else:
            Ws = W
        br = Ws @ qr[f]
        bd = Ws @ qd[f]
        norm = np.linalg.norm(br, axis=1, keepdims=True)
        br, bd = br / norm, bd / norm
        conj = br * np.array([-1.0, -1.0, -1.0, 1.0])
        trans = 2.0 * _quat_mul(bd, conj)[:, :3]
        v, w = br[:, :3], br[:, 3:]
        cx = np.cross(v, V)
        out[f] = V + 2.0 * w * cx + 2.0 * np.cross(v, cx) + trans
    return out
