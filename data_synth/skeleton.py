"""Skeletons: joints in a tree, rotations about axes, forward kinematics.

A pose gives every joint a *local rotation*, expressed in the rest pose's world axes (x: the
character's left, y: up, z: forward), applied about the joint. Forward kinematics composes them
down the tree: ``R_j = R_parent(j) @ L_j`` and ``p_j = p_parent + R_parent (r_j - r_parent)``,
with ``r`` the rest positions. A point ``x`` bound to joint ``j`` moves to ``R_j (x - r_j) + p_j``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Skeleton", "axis_rotation", "forward_kinematics"]


def axis_rotation(axis, angle) -> np.ndarray:
    """Rotation matrices about a fixed axis (Rodrigues).

    Parameters
    ----------
    axis : (3,) float, need not be unit length.
    angle : float or (n,) float64, radians.

    Returns
    -------
    R : (3, 3) or (n, 3, 3) float64.
    """
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    angle = np.asarray(angle, dtype=np.float64)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s = np.sin(angle)[..., None, None]
    c = np.cos(angle)[..., None, None]
    return np.eye(3) + s * K + (1.0 - c) * (K @ K)


@dataclass(frozen=True)
class Skeleton:
    """Joint tree.

    Attributes
    ----------
    names : tuple of str, one per joint; joint 0 is the root.
    parents : (n_joints,) int64, ``parents[0] == -1`` and ``parents[j] < j``.
    rest : (n_joints, 3) float64, rest positions.
    """

    names: tuple
    parents: np.ndarray
    rest: np.ndarray

    def __post_init__(self):
        parents = np.asarray(self.parents)
        if parents[0] != -1 or np.any(parents[1:] >= np.arange(1, len(parents))):
            raise ValueError(f"parents must list every parent before its child, got {parents}")

    @property
    def n_joints(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        try:
            return self.names.index(name)
        except ValueError:
            raise ValueError(f"no joint named {name!r}; joints are {list(self.names)}") from None

    def relatives(self, depth: int = 1) -> list[set]:
        """For each joint: itself, its ancestors and descendants up to ``depth`` generations.

        Siblings (say the two thighs) are never relatives, so their weights never mix.
        """
        out = [{j} for j in range(self.n_joints)]
        for j in range(self.n_joints):
            a = j
            for _ in range(depth):
                a = int(self.parents[a])
                if a < 0:
                    break
                out[j].add(a)
                out[a].add(j)
        return out


def forward_kinematics(skeleton: Skeleton, local: np.ndarray, root_translation: np.ndarray,
                       rest: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Global joint rotations and positions of a batch of poses.

    Parameters
    ----------
    skeleton : Skeleton
    local : (n_frames, n_joints, 3, 3) float64, local rotations.
    root_translation : (n_frames, 3) float64, displacement of the root from its rest position.
    rest : (n_joints, 3) float64, rest joint positions (default ``skeleton.rest``; a body shape
        passes its own).

    Returns
    -------
    R : (n_frames, n_joints, 3, 3) float64
    p : (n_frames, n_joints, 3) float64
    """
    rest = skeleton.rest if rest is None else np.asarray(rest, dtype=np.float64)
    n = local.shape[0]
    R = np.empty_like(local)
    p = np.empty((n, skeleton.n_joints, 3))
    R[:, 0] = local[:, 0]
    p[:, 0] = rest[0] + root_translation
    for j in range(1, skeleton.n_joints):  # loop over joints (about 20), vectorised over frames
        q = skeleton.parents[j]
        R[:, j] = R[:, q] @ local[:, j]
        p[:, j] = p[:, q] + np.einsum("nab,b->na", R[:, q], rest[j] - rest[q])
    return R, p
