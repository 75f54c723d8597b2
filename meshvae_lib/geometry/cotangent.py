"""Cotangent edge weights, made robust as in the RIMD reference implementation.

The paper (Sec. 3, Eq. 1) weights edge ``(i, j)`` by ``c_ij = cot(alpha_ij) + cot(beta_ij)``, the
cotangents of the two angles opposite the edge. This module returns exactly that sum.

The ``1/2`` factor: the reference implementation uses ``w_ij = (cot alpha + cot beta) / 2``. A
common factor of all weights does not change the least-squares fit of ``T_i`` (Eq. 1), so the
feature does not depend on it; it only sets the scale of the weights relative to the extra normal
term of the deformation gradient (``NORMAL_EDGE_WEIGHT``, expressed in units of ``c_ij``).

Robustness (``clamp=True``, the default, with the reference's thresholds from
:mod:`meshvae_lib.tolerances`):

- obtuse triangles make ``c_ij`` negative (when the two opposite angles sum past pi) and sliver triangles make it
  huge; values below ``COT_WEIGHT_MIN`` are raised to it, and NaN or values above
  ``COT_WEIGHT_MAX`` are replaced by ``COT_WEIGHT_FALLBACK``;
- a boundary edge has one opposite angle only: ``c_ij = cot(alpha_ij)``;
- a zero-area face has infinite cotangents: its edges get the fallback weight.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.topology import MeshTopology
from meshvae_lib.validation import check_mesh, check_vertices

__all__ = ["corner_cotangents", "cotangent_weights"]


def corner_cotangents(V, F) -> np.ndarray:
    """Cotangent of every corner angle.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    cot : (n_faces, 3) float64
        ``cot[f, k]`` is the cotangent of the angle of face ``f`` at corner ``F[f, k]``; ``inf`` or
        NaN for a zero-area face.
    """
    V, F = check_mesh(V, F, batch=False, name="V")
    return _corner_cotangents(V, F)


def _corner_cotangents(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    P = V[F]  # (m, 3, 3)
    a = np.roll(P, -1, axis=1) - P  # corner k -> k+1
    b = np.roll(P, -2, axis=1) - P  # corner k -> k+2
    dot = np.einsum("mkd,mkd->mk", a, b)
    cross = np.linalg.norm(np.cross(a, b), axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return dot / cross


def cotangent_weights(V, F, clamp: bool = True, topology: MeshTopology | None = None) -> np.ndarray:
    """Cotangent weights ``c_ij = cot alpha_ij + cot beta_ij`` of every edge (paper Eq. 1).

    Parameters
    ----------
    V : (n_vertices, 3) float
        Reference positions.
    F : (n_faces, 3) int
    clamp : bool
        Apply the reference implementation's safeguards (see the module docstring). With
        ``clamp=False`` the raw sums are returned (negative where the opposite angles sum past pi, ``inf``/NaN next to
        zero-area faces).

    Returns
    -------
    c : (n_edges,) float64
        Aligned with :func:`meshvae_lib.geometry.topology.edges`. Boundary edges have one term only.
    topology : MeshTopology of ``F``, optional
        Precomputed (then ``F`` is not checked again).
    """
    if topology is None:
        V, F = check_mesh(V, F, batch=False, name="V")
        topology = MeshTopology(F, len(V))
    else:
        V = check_vertices(V, "V", batch=False, n_vertices=topology.n_vertices)
    cot = _corner_cotangents(V, topology.faces)
    FE = topology.face_edges  # edge opposite each corner
    c = np.bincount(FE.reshape(-1), weights=cot.reshape(-1), minlength=len(topology.edges))
    # bincount turns inf into nan when +inf and -inf meet; keep inf where it arose
    if clamp:
        c = np.where(np.isnan(c) | (c > tol.COT_WEIGHT_MAX), tol.COT_WEIGHT_FALLBACK, c)
        c = np.maximum(c, tol.COT_WEIGHT_MIN)
    return c
