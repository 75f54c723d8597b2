"""Checks a stand-in collection must pass to behave like a real capture: no repeated meshes.

A collection that holds the same mesh twice lets a "held-out" mesh be a copy of a training one, and
caps every neighbour metric unannounced. :func:`duplicate_pairs` finds them. (Self-intersections are
counted with the library's ``meshvae_lib.geometry.intersections.self_intersections`` by the tests
and ``benchmarks/bench_synth_floor.py``; ``data_synth`` does not depend on ``meshvae_lib``.)
"""

from __future__ import annotations

import numpy as np

from data_synth import constants as C

__all__ = ["duplicate_pairs", "bounding_box_diagonals"]


def bounding_box_diagonals(vertices) -> np.ndarray:
    """Length of each mesh's bounding-box diagonal: (N, V, 3) float -> (N,) float64."""
    V = np.asarray(vertices, dtype=np.float64)
    if V.ndim != 3 or V.shape[2] != 3:
        raise ValueError(f"vertices must be (n_meshes, n_vertices, 3), got {V.shape}")
    return np.linalg.norm(V.max(axis=1) - V.min(axis=1), axis=1)


def duplicate_pairs(vertices, rtol: float = C.DUPLICATE_MESH_RTOL) -> np.ndarray:
    """Pairs of meshes that are the same mesh: every vertex within ``rtol`` x the first mesh's
    bounding-box diagonal of its counterpart (no alignment: a rigidly moved copy is a new mesh).

    vertices : (N, V, 3) float; rtol : float >= 0.

    Returns (P, 2) int64, rows ``(i, j)`` with ``i < j``, sorted. Vectorised over the later meshes
    (one pass per mesh, O(N^2 V) work).
    """
    V = np.asarray(vertices, dtype=np.float64)
    diag = bounding_box_diagonals(V)
    if not np.isfinite(rtol) or rtol < 0:
        raise ValueError(f"rtol must be a finite number >= 0, got {rtol!r}")
    pairs = []
    for i in range(len(V) - 1):
        gap = np.sqrt(((V[i + 1:] - V[i]) ** 2).sum(axis=2)).max(axis=1)
        for j in np.flatnonzero(gap <= rtol * diag[i]):
            pairs.append((i, i + 1 + int(j)))
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)
