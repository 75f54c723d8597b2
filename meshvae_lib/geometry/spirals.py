"""Spiral sequences and a mesh hierarchy for spiral-convolution networks (SpiralNet++, Gong et al.
2019; the down- and up-sampling of CoMA, Ranjan et al. 2018).

A spiral of vertex ``v`` lists ``v``, then its one-ring, then its two-ring, ..., each ring in
counter-clockwise order around ``v``'s normal starting from the ring member with the smallest angle
to a fixed first direction, cut to a fixed length. A spiral convolution is then one linear map of
the concatenated features along each vertex's spiral (:class:`~meshvae_lib.model.spiral_net.SpiralVAE`).

The hierarchy simplifies the reference mesh by quadric error metrics (Garland and Heckbert 1997)
level by level. The simplification itself is ``fast-simplification`` (PyVista's maintained wrapper
of Sven Forstmann's Fast-Quadric-Mesh-Simplification: a manylinux wheel with no dependency but
numpy, deterministic, 25 ms for 10k vertices): it reports which fine vertex went to which coarse
vertex. From that map:

- down-sampling ``D`` (n_coarse, n_fine): each coarse vertex is the mean of the fine vertices
  collapsed into it;
- up-sampling ``U`` (n_fine, n_coarse): each fine vertex is the barycentric interpolation of the
  closest point on the coarse triangles around the coarse vertex it went to (as CoMA's, which
  searches every triangle).

Everything is vectorised over vertices (Python loops run over rings and levels only).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.validation import check_mesh

__all__ = ["spiral_indices", "MeshLevel", "mesh_hierarchy", "closest_point_barycentric"]

#: rings searched for a spiral before it is padded (a spiral shorter than this many rings is
#: padded with its own centre vertex: only at tiny meshes or isolated patches).
_MAX_RINGS = 8


def spiral_indices(V, F, length: int) -> np.ndarray:
    """The spiral sequence of every vertex (SpiralNet++'s spirals, dilation 1).

    Parameters
    ----------
    V : (n, 3) float, the reference positions (they set the ring order: the angle around the normal).
    F : (n_faces, 3) int.
    length : int >= 1, the spiral length (SpiralNet++'s reconstruction setting: 9).

    Returns
    -------
    (n, length) int64: row v = [v, ring 1 counter-clockwise, ring 2 counter-clockwise, ...][:length];
    the start of every ring is the member closest in angle to the direction from v to its
    smallest-index neighbour. A vertex with fewer than ``length - 1`` vertices within ``_MAX_RINGS``
    rings is padded with v itself.
    """
    V, F = check_mesh(V, F)
    if int(length) < 1:
        raise ValueError(f"length must be at least 1, got {length}")
    n = len(V)
    A = sp.coo_matrix((np.ones(3 * len(F)), (F.ravel(), np.roll(F, -1, axis=1).ravel())), shape=(n, n)).tocsr()
    A = ((A + A.T) > 0).astype(np.int32).tocsr()
    # ring distance of every (v, u) pair up to the rings needed: BFS by sparse products
    members, ring = [np.arange(n)], [np.zeros(n, np.int64)]
    centres = [np.arange(n)]
    seen = sp.identity(n, dtype=np.int32, format="csr")
    frontier = seen
    for r in range(1, _MAX_RINGS + 1):
        if min(np.diff(seen.indptr)) >= length:
            break
        reach = ((frontier @ A) > 0).astype(np.int32)
        new = (reach - reach.multiply(seen)).tocoo()
        new.eliminate_zeros()
        centres.append(new.row.astype(np.int64))
        members.append(new.col.astype(np.int64))
        ring.append(np.full(new.nnz, r, np.int64))
        seen = ((seen + new.tocsr()) > 0).astype(np.int32).tocsr()
        frontier = new.tocsr()
    v, u, k = np.concatenate(centres), np.concatenate(members), np.concatenate(ring)
    angle = _ring_angles(V, F, A, v, u)
    order = np.lexsort((u, angle, k, v))  # by centre, then ring, then angle (index breaks ties)
    v, u = v[order], u[order]
    starts = np.searchsorted(v, np.arange(n))
    position = np.arange(len(v)) - starts[v]
    out = np.repeat(np.arange(n)[:, None], length, axis=1)
    keep = position < length
    out[v[keep], position[keep]] = u[keep]
    return out


def _ring_angles(V, F, A, v, u) -> np.ndarray:
    """Angle in [0, 2 pi) of ``u - v`` around v's normal, from the direction to v's smallest-index
    neighbour; 0 for u = v."""
    normal = vertex_normals(V, F)
    first = A.indices[A.indptr[:-1]]  # csr rows are sorted: the smallest neighbour
    x = V[first] - V
    x -= np.sum(x * normal, axis=1, keepdims=True) * normal
    x /= np.maximum(np.linalg.norm(x, axis=1, keepdims=True), np.finfo(float).tiny)
    y = np.cross(normal, x)
    d = V[u] - V[v]
    a = np.arctan2(np.sum(d * y[v], axis=1), np.sum(d * x[v], axis=1))
    a = np.where(u == v, 0.0, np.mod(a, 2 * np.pi))
    return np.round(a, 12)  # ties (identical directions) fall back to the vertex index


@dataclass(frozen=True)
class MeshLevel:
    """One level of a :func:`mesh_hierarchy`.

    vertices : (n_l, 3) float64; faces : (f_l, 3) int64; spirals : (n_l, length) int64
    (:func:`spiral_indices`); down : (n_{l+1}, n_l) csr float64 to the next coarser level (None at
    the coarsest); up : (n_l, n_{l+1}) csr float64 from it (None at the coarsest).
    """

    vertices: np.ndarray
    faces: np.ndarray
    spirals: np.ndarray
    down: sp.csr_matrix | None
    up: sp.csr_matrix | None


def mesh_hierarchy(V, F, factors, spiral_length: int) -> list[MeshLevel]:
    """The reference mesh and its quadric-error simplifications, each ``factors[l]`` times fewer
    vertices than the last (CoMA and SpiralNet++: four levels of 4).

    V : (n, 3) float; F : (n_faces, 3) int; factors : sequence of ints >= 2; spiral_length : int.
    Returns ``len(factors) + 1`` :class:`MeshLevel`, finest first. ValueError when a level would
    have fewer than 4 vertices.
    """
    import fast_simplification

    V, F = check_mesh(V, F)
    factors = [int(f) for f in factors]
    if any(f < 2 for f in factors):
        raise ValueError(f"every down-sampling factor must be at least 2, got {factors}")
    too_few = (f"the mesh has {len(V)} vertices ({len(F)} faces): too few for down-sampling by {factors}"
               " (the coarsest level needs at least 4 faces); give fewer or smaller factors")
    if len(F) / np.prod(factors, dtype=float) < 4:
        raise ValueError(too_few)
    levels, verts, faces = [], V, F
    for factor in factors:
        target = int(np.ceil(len(faces) / factor))
        if target < 4:
            raise ValueError(too_few)
        _, _, collapses = fast_simplification.simplify(verts.astype(np.float32), faces.astype(np.int32),
                                                       target_count=target, return_collapses=True)
        coarse_v, coarse_f, mapping = fast_simplification.replay_simplification(
            verts.astype(np.float32), faces.astype(np.int32), collapses)
        coarse_v, coarse_f, mapping = coarse_v.astype(np.float64), coarse_f.astype(np.int64), mapping.astype(np.int64)
        n_c = len(coarse_v)
        counts = np.bincount(mapping, minlength=n_c).astype(np.float64)
        down = sp.csr_matrix((1.0 / counts[mapping], (mapping, np.arange(len(verts)))), shape=(n_c, len(verts)))
        coarse_v = down @ verts  # the coarse vertex is the mean of its fine vertices
        up = _upsampling(verts, coarse_v, coarse_f, mapping)
        levels.append(MeshLevel(verts, faces, spiral_indices(verts, faces, spiral_length), down, up))
        verts, faces = coarse_v, coarse_f
    levels.append(MeshLevel(verts, faces, spiral_indices(verts, faces, spiral_length), None, None))
    return levels


def _upsampling(fine: np.ndarray, coarse: np.ndarray, faces: np.ndarray, mapping: np.ndarray) -> sp.csr_matrix:
    """(n_fine, n_coarse): barycentric weights of each fine vertex's closest point on the coarse
    triangles incident to ``mapping[i]``."""
    n_f, n_c = len(fine), len(coarse)
    inc = sp.coo_matrix((np.ones(faces.size), (faces.ravel(), np.repeat(np.arange(len(faces)), 3))),
                        shape=(n_c, len(faces))).tocsr()
    deg = np.diff(inc.indptr)
    if np.any(deg[mapping] == 0):
        raise ValueError("a coarse vertex of the simplified mesh has no triangle")
    width = int(deg.max())
    slot = np.arange(width)
    cand = inc.indices[np.minimum(inc.indptr[mapping][:, None] + slot, len(inc.indices) - 1)]  # (n_f, width)
    valid = slot[None, :] < deg[mapping][:, None]
    tri = coarse[faces[cand]]  # (n_f, width, 3 corners, 3)
    bary = closest_point_barycentric(np.broadcast_to(fine[:, None, :], cand.shape + (3,)), tri)
    dist = np.linalg.norm(np.einsum("...k,...kd->...d", bary, tri) - fine[:, None, :], axis=-1)
    best = np.argmin(np.where(valid, dist, np.inf), axis=1)
    rows = np.arange(n_f)
    w, f = bary[rows, best], faces[cand[rows, best]]
    return sp.csr_matrix((w.ravel(), (np.repeat(rows, 3), f.ravel())), shape=(n_f, n_c))


def closest_point_barycentric(p: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """Barycentric coordinates of the point of each triangle closest to ``p``.

    p : (..., 3) float; tri : (..., 3, 3) float (corners a, b, c). Returns (..., 3) float64, each row
    non-negative and summing to 1 (Ericson, *Real-Time Collision Detection*, 5.1.5, vectorised).
    """
    p, tri = np.asarray(p, np.float64), np.asarray(tri, np.float64)
    a, b, c = tri[..., 0, :], tri[..., 1, :], tri[..., 2, :]
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.sum(ab * ap, -1), np.sum(ac * ap, -1)
    bp, cp = p - b, p - c
    d3, d4 = np.sum(ab * bp, -1), np.sum(ac * bp, -1)
    d5, d6 = np.sum(ab * cp, -1), np.sum(ac * cp, -1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    safe = lambda x: np.where(np.abs(x) > 0, x, 1.0)  # noqa: E731
    out = np.empty(p.shape[:-1] + (3,))
    # interior
    den = safe(va + vb + vc)
    v, w = vb / den, vc / den
    out[...] = np.stack([1 - v - w, v, w], -1)
    # edges (later assignments win: vertices override edges)
    t = d1 / safe(d1 - d3)
    m = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    out[m] = np.stack([1 - t, t, 0 * t], -1)[m]
    t = d2 / safe(d2 - d6)
    m = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    out[m] = np.stack([1 - t, 0 * t, t], -1)[m]
    t = (d4 - d3) / safe((d4 - d3) + (d5 - d6))
    m = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
    out[m] = np.stack([0 * t, 1 - t, t], -1)[m]
    for corner, m in enumerate([(d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (d6 >= 0) & (d5 <= d6)]):
        e = np.zeros(3)
        e[corner] = 1.0
        out[m] = e
    return out
