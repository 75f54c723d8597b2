"""Boundaries of a triangle mesh: the edges of one face only, their vertices and their loops.

A closed mesh has none; an open one (a flag, a tube) has one ordered loop per hole.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.validation import check_faces

__all__ = ["boundary_edges", "boundary_vertices", "boundary_loops"]


def boundary_edges(F) -> np.ndarray:
    """Boundary half-edges, oriented as in their only face.

    Parameters
    ----------
    F : (n_faces, 3) int

    Returns
    -------
    B : (n_boundary_edges, 2) int64
        Directed edges ``(i, j)`` that belong to exactly one face, in the direction that face
        traverses them (so a boundary loop is followed by chaining ``j`` to the next ``i``).
    """
    F = check_faces(F)
    he = np.stack([F, np.roll(F, -1, axis=1)], axis=2).reshape(-1, 2)  # half-edges, face order
    key = np.sort(he, axis=1)
    _, inv, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return he[counts[inv.reshape(-1)] == 1]


def boundary_vertices(F) -> np.ndarray:
    """Vertices on the mesh boundary.

    Parameters
    ----------
    F : (n_faces, 3) int

    Returns
    -------
    b : (n_boundary_vertices,) int64
        Sorted ids of vertices incident to an edge that has only one face. Empty for a closed mesh.
    """
    return np.unique(boundary_edges(F).reshape(-1))


def boundary_loops(F) -> list[np.ndarray]:
    """Boundary loops as ordered vertex cycles.

    Parameters
    ----------
    F : (n_faces, 3) int

    Returns
    -------
    loops : list of (loop_length,) int64
        Each loop lists its vertices in the order the adjacent faces traverse the boundary, starting
        at its smallest vertex id; loops are sorted by that start vertex. Empty for a closed mesh.

    Raises
    ------
    ValueError
        If a boundary vertex has more than one outgoing boundary edge (non-manifold boundary).
    """
    B = boundary_edges(F)
    if len(B) == 0:
        return []
    src, dst = B[:, 0], B[:, 1]
    if len(np.unique(src)) != len(src):
        vals, c = np.unique(src, return_counts=True)
        raise ValueError(f"non-manifold boundary at vertex {vals[c > 1][0]}")
    nxt = dict(zip(src.tolist(), dst.tolist()))
    loops = []
    remaining = set(nxt)
    while remaining:
        start = min(remaining)
        loop = [start]
        remaining.discard(start)
        v = nxt[start]
        while v != start:
            if v not in remaining:
                raise ValueError(f"boundary does not close into a loop at vertex {v}")
            loop.append(v)
            remaining.discard(v)
            v = nxt[v]
        loops.append(np.asarray(loop, dtype=np.int64))
    return loops
