"""Self-intersections of a triangle mesh: how many pairs of non-adjacent triangles cross each other.

A number to put beside the pictures of an interpolation (paper Fig. 4; used by
:func:`meshvae_lib.applications.interpolation.implausibility`). Candidate pairs come from a uniform
grid over the triangles' bounding boxes (:func:`candidate_triangle_pairs`, broad phase); each
candidate is decided by a vectorised separating-axis test (:func:`triangle_pairs_intersect`, 11
axes: both normals and the 9 edge-edge cross products). Pairs that share a vertex are never
counted. Triangles that only touch (overlap below ``SELF_INTERSECTION_RTOL`` times the mean edge
length along some axis) do not count; coplanar triangles, whose overlap along their common normal
is zero, count as touching too (a contact of no thickness, not a crossing).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.topology import edge_lengths
from meshvae_lib.validation import check_mesh

__all__ = ["self_intersections", "triangle_pairs_intersect", "candidate_triangle_pairs"]




def _pairs_within_groups(order: np.ndarray, starts: np.ndarray, sizes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All pairs (i < j in position) inside each group of a sorted array, vectorised."""
    sizes = sizes.astype(np.int64)
    pos = np.arange(order.size, dtype=np.int64)
    group_end = np.repeat(starts + sizes, sizes)  # exclusive end of each element's group
    n_after = group_end - pos - 1
    total = int(n_after.sum())
    if total == 0:
        return np.empty(0, np.int64), np.empty(0, np.int64)
    first = np.repeat(pos, n_after)
    run_start = np.repeat(np.cumsum(n_after) - n_after, n_after)
    second = first + 1 + (np.arange(total, dtype=np.int64) - run_start)
    return order[first], order[second]


def candidate_triangle_pairs(V, F, cell_size: float | None = None) -> np.ndarray:
    """Pairs of triangles whose bounding boxes overlap, from a uniform grid (broad phase).

    Every triangle is entered in each grid cell its bounding box touches; pairs sharing a cell are
    kept when their boxes overlap and they share no vertex.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int
    cell_size : float, optional
        Default: the mean of the triangles' largest box extent.

    Returns
    -------
    pairs : (P, 2) int64, ``pairs[:, 0] < pairs[:, 1]``, unique, sorted.
    """
    V, F = check_mesh(V, F, batch=False, name="V")
    tri = V[F]
    lo = tri.min(axis=1)
    hi = tri.max(axis=1)
    m = F.shape[0]
    if m < 2:
        return np.empty((0, 2), np.int64)
    if cell_size is None:
        cell_size = float(np.mean((hi - lo).max(axis=1)))
    h = cell_size if cell_size > 0 else 1.0
    origin = lo.min(axis=0)
    # keep the number of entries bounded: grow the cell while the average entry count is large
    while True:
        ilo = np.floor((lo - origin) / h).astype(np.int64)
        ihi = np.floor((hi - origin) / h).astype(np.int64)
        span = ihi - ilo + 1
        count = span.prod(axis=1)
        if (count.sum() <= tol.SELF_INTERSECTION_CELLS_PER_TRIANGLE * m
                or h > tol.SELF_INTERSECTION_MAX_CELL_GROWTH * cell_size):
            break
        h *= 2.0
    tri_id = np.repeat(np.arange(m, dtype=np.int64), count)
    local = np.arange(count.sum(), dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    sx, sy = span[tri_id, 0], span[tri_id, 1]
    cx = ilo[tri_id, 0] + local % sx
    cy = ilo[tri_id, 1] + (local // sx) % sy
    cz = ilo[tri_id, 2] + local // (sx * sy)
    dims = ihi.max(axis=0) + 1
    key = (cx * dims[1] + cy) * dims[2] + cz
    order = np.argsort(key, kind="stable")
    skey = key[order]
    starts = np.flatnonzero(np.r_[True, skey[1:] != skey[:-1]])
    sizes = np.diff(np.r_[starts, skey.size])
    a, b = _pairs_within_groups(tri_id[order], starts, sizes)
    lo_ab, hi_ab = np.minimum(a, b), np.maximum(a, b)
    keys = np.unique(lo_ab * m + hi_ab)
    a, b = keys // m, keys % m
    a, b = a[a != b], b[a != b]
    overlap = np.all((lo[a] <= hi[b]) & (lo[b] <= hi[a]), axis=1)
    a, b = a[overlap], b[overlap]
    share = (F[a][:, :, None] == F[b][:, None, :]).any(axis=(1, 2))
    return np.column_stack([a[~share], b[~share]]).astype(np.int64)


def triangle_pairs_intersect(A, B, eps: float = 0.0) -> np.ndarray:
    """Separating-axis test for many triangle pairs at once (narrow phase).

    Two non-coplanar triangles are disjoint exactly when their projections on one of 11 axes are
    separated (both normals and the 9 cross products of their edges). Overlap along an axis of
    less than ``eps`` counts as separated, so triangles that merely touch are not counted, and
    neither are coplanar ones (their overlap along the common normal is zero).

    Parameters
    ----------
    A, B : (P, 3, 3) float, the corners of the P pairs
    eps : float, a length

    Returns
    -------
    (P,) bool, True where the triangles intersect (overlap by more than ``eps``).
    """
    A = np.asarray(A, dtype=np.float64)
    B = np.asarray(B, dtype=np.float64)
    if A.ndim != 3 or A.shape[1:] != (3, 3) or A.shape != B.shape:
        raise ValueError(f"A and B must both be (P, 3, 3), got {A.shape} and {B.shape}")
    eA = np.roll(A, -1, axis=1) - A  # (P, 3, 3) edges
    eB = np.roll(B, -1, axis=1) - B
    lA = np.linalg.norm(eA, axis=2)  # (P, 3)
    lB = np.linalg.norm(eB, axis=2)
    nA = np.cross(eA[:, 0], eA[:, 1])
    nB = np.cross(eB[:, 0], eB[:, 1])
    axes = np.concatenate(
        [
            nA[:, None],
            nB[:, None],
            np.cross(eA[:, :, None, :], eB[:, None, :, :]).reshape(-1, 9, 3),
        ],
        axis=1,
    )  # (P, 11, 3)
    # |a x b| / (|a| |b|) = sin of the angle between the crossed vectors: tiny means no axis
    factor = np.concatenate(
        [
            (lA[:, 0] * lA[:, 1])[:, None],
            (lB[:, 0] * lB[:, 1])[:, None],
            (lA[:, :, None] * lB[:, None, :]).reshape(-1, 9),
        ],
        axis=1,
    )
    norm = np.linalg.norm(axes, axis=2)
    degenerate = norm <= tol.SAT_PARALLEL_RTOL * factor
    axes = axes / np.where(degenerate, 1.0, norm)[..., None]
    pa = axes @ np.swapaxes(A, 1, 2)  # (P, 11, 3): projections of the corners on unit axes
    pb = axes @ np.swapaxes(B, 1, 2)
    gap = np.maximum(pb.min(axis=2) - pa.max(axis=2), pa.min(axis=2) - pb.max(axis=2))
    separated = (gap >= -eps) & ~degenerate
    return ~separated.any(axis=1)


def self_intersections(V, F, return_pairs: bool = False, chunk: int = 100_000):
    """Number of crossing pairs of non-adjacent triangles of a mesh (or of each mesh of a batch).

    Parameters
    ----------
    V : (n_vertices, 3) or (N, n_vertices, 3) float
    F : (n_faces, 3) int
    return_pairs : bool
        Also return the crossing pairs (for one mesh: a (P, 2) int64 array; for a batch: a list).

    Returns
    -------
    count : int, or (N,) int64 for a batch; ``(count, pairs)`` with ``return_pairs``.
    """
    V, F = check_mesh(V, F, name="V")
    if V.ndim == 3:
        res = [self_intersections(v, F, return_pairs=True, chunk=chunk) for v in V]
        counts = np.array([r[0] for r in res], dtype=np.int64)
        return (counts, [r[1] for r in res]) if return_pairs else counts
    pairs = candidate_triangle_pairs(V, F)
    lengths = edge_lengths(V, F)
    mean_edge = float(lengths.mean()) if lengths.size else 1.0
    eps = tol.SELF_INTERSECTION_RTOL * mean_edge
    hit = np.zeros(pairs.shape[0], dtype=bool)
    for s in range(0, pairs.shape[0], chunk):
        p = pairs[s : s + chunk]
        hit[s : s + chunk] = triangle_pairs_intersect(V[F[p[:, 0]]], V[F[p[:, 1]]], eps)
    crossing = pairs[hit]
    return (int(crossing.shape[0]), crossing) if return_pairs else int(crossing.shape[0])
