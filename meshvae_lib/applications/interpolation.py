"""Mesh interpolation (paper Sec. 4.5 and 5.3, Fig. 4) and numbers that tell plausible from implausible.

Three ways to go from mesh A to mesh B in ``n_steps`` steps:

- **latent** (the paper's): encode both with the encoder means, step linearly between the two
  latent vectors, decode every step (``interpolate_latent``; ``interpolate_generated`` starts from
  two latent vectors, e.g. two generated shapes);
- **RIMD**: step linearly between the two RIMD feature vectors and reconstruct every step
  (``interpolate_features``; the paper's first row of Fig. 4, which shows self-intersections);
- **coordinates**: step linearly between the vertex positions (``interpolate_coordinates``; B is
  first rigidly aligned to A, otherwise a turn would shrink the body through its middle).

Implausibility, to put numbers beside the pictures:

- ``self_intersections(V, F)``: how many pairs of non-adjacent triangles cross each other. Candidate
  pairs come from a uniform grid over the triangles' bounding boxes; each candidate is decided by a
  vectorised separating-axis test (11 axes: both normals and the 9 edge-edge cross products).
  Pairs that share a vertex are never counted. Triangles that only touch (overlap below
  ``SELF_INTERSECTION_RTOL`` times the mean edge length along some axis) do not count; coplanar
  triangles, whose overlap along their common normal is zero, count as touching too (a contact of
  no thickness, not a crossing).
- ``edge_length_distortion(V, F, dataset)``: the mean relative edge-length change against the
  data-set mesh that is nearest by this same measure (it is rigid-motion invariant). An
  interpolation that stays on the shape space keeps edges close to those of some real mesh.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.alignment import rigid_align

__all__ = [
    "linear_steps",
    "interpolate_coordinates",
    "interpolate_features",
    "interpolate_latent",
    "LatentPath",
    "interpolate_generated",
    "edge_lengths",
    "edge_length_distortion",
    "self_intersections",
    "triangle_pairs_intersect",
    "candidate_triangle_pairs",
    "implausibility",
    "ImplausibilityTable",
]


# --------------------------------------------------------------------------------------------
# interpolation paths
# --------------------------------------------------------------------------------------------


def linear_steps(a, b, n_steps: int) -> np.ndarray:
    """``n_steps`` evenly spaced points from ``a`` to ``b`` (both ends included).

    Parameters
    ----------
    a, b : arrays of the same shape ``S``, float
    n_steps : int >= 2

    Returns
    -------
    path : (n_steps, *S) float64, ``path[0] == a``, ``path[-1] == b``.
    """
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"a and b must have the same shape, got {a.shape} and {b.shape}")
    if int(n_steps) < 2:
        raise ValueError(f"n_steps must be at least 2, got {n_steps}")
    t = np.linspace(0.0, 1.0, int(n_steps)).reshape((-1,) + (1,) * a.ndim)
    return (1.0 - t) * a[None] + t * b[None]


def interpolate_coordinates(V_a, V_b, n_steps: int, align: bool = True) -> np.ndarray:
    """Direct linear interpolation of vertex coordinates.

    Parameters
    ----------
    V_a, V_b : (n_vertices, 3) float
    align : bool
        Rigidly align ``V_b`` to ``V_a`` first (default).

    Returns
    -------
    (n_steps, n_vertices, 3) float64
    """
    V_a = np.asarray(V_a, dtype=np.float64)
    V_b = np.asarray(V_b, dtype=np.float64)
    if V_a.ndim != 2 or V_a.shape[1] != 3 or V_a.shape != V_b.shape:
        raise ValueError(f"V_a and V_b must both be (n_vertices, 3), got {V_a.shape} and {V_b.shape}")
    if align:
        V_b = rigid_align(V_b, V_a)
    return linear_steps(V_a, V_b, n_steps)


def interpolate_features(f_a, f_b, n_steps: int, reconstruct: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
    """Direct linear interpolation of RIMD features (the paper's Fig. 4, first row).

    Parameters
    ----------
    f_a, f_b : (K,) float
        RIMD features of the two end meshes.
    reconstruct : callable
        ``(n_steps, K) -> (n_steps, n_vertices, 3)``, e.g. ``RIMDReconstructor(V0, F).reconstruct``.

    Returns
    -------
    (n_steps, n_vertices, 3) float64
    """
    f_a = np.asarray(f_a, dtype=np.float64)
    if f_a.ndim != 1:
        raise ValueError(f"f_a must be a (K,) feature vector, got {f_a.shape}")
    return np.asarray(reconstruct(linear_steps(f_a, f_b, n_steps)), dtype=np.float64)


def _to_numpy(x) -> np.ndarray:
    if isinstance(x, tuple):
        x = x[0]
    if hasattr(x, "detach"):
        x = x.detach().cpu().numpy()
    return np.asarray(x, dtype=np.float64)


def interpolate_latent(
    encode: Callable, decode: Callable, x_a, x_b, n_steps: int
) -> tuple[np.ndarray, np.ndarray]:
    """Interpolation in the latent space with the encoder means (paper Sec. 5.3).

    Parameters
    ----------
    encode : callable
        Inputs of two meshes stacked on a first axis of length 2 -> encoder means ``(2, latent)``
        (a ``(mu, sigma)`` tuple is accepted).
    decode : callable
        ``(n_steps, latent) -> (n_steps, n_vertices, 3)`` meshes.
    x_a, x_b : whatever ``encode`` takes for one mesh (e.g. ``(n_vertices, 3)`` or ``(K,)``).

    Returns
    -------
    z : (n_steps, latent) float64, the latent path
    V : (n_steps, n_vertices, 3) float64, the decoded meshes
    """
    mu = _to_numpy(encode(np.stack([np.asarray(x_a), np.asarray(x_b)])))
    if mu.ndim != 2 or mu.shape[0] != 2:
        raise ValueError(f"encode must return (2, latent_dim) for two inputs, got {mu.shape}")
    return interpolate_generated(decode, mu[0], mu[1], n_steps)


def interpolate_generated(decode: Callable, z_a, z_b, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
    """Interpolation between two latent vectors (e.g. two generated shapes, paper Fig. 6a).

    Returns
    -------
    z : (n_steps, latent) float64
    V : (n_steps, n_vertices, 3) float64
    """
    z = linear_steps(z_a, z_b, n_steps)
    if z.ndim != 2:
        raise ValueError(f"z_a and z_b must be (latent_dim,) vectors, got {np.shape(z_a)}")
    return z, _to_numpy(decode(z))


class LatentPath:
    """The straight latent path between two codes, decoded on demand: ``path(t)`` is the mesh at
    ``z(t) = (1 - t) z_a + t z_b`` (for a slider, e.g. ``InterpolationSlider(..., interpolate=path)``).

    decode : callable ``(latent,) -> (n_vertices, 3)`` (e.g. ``MeshVAEModel.decode_latent``);
    z_a, z_b : (latent,) float, the two ends (t = 0 and t = 1).
    """

    def __init__(self, decode: Callable, z_a, z_b):
        if not callable(decode):
            raise ValueError(f"decode must be callable, got {type(decode).__name__}")
        self.z_a, self.z_b = _to_numpy(z_a), _to_numpy(z_b)
        if self.z_a.ndim != 1 or self.z_a.shape != self.z_b.shape:
            raise ValueError(f"z_a and z_b must be (latent_dim,) vectors of one size, got {self.z_a.shape}, {self.z_b.shape}")
        self.decode = decode

    def latent(self, t: float) -> np.ndarray:
        """z(t), (latent,) float64."""
        return (1.0 - float(t)) * self.z_a + float(t) * self.z_b

    def __call__(self, t: float) -> np.ndarray:
        """The decoded mesh at t, (n_vertices, 3)."""
        return _to_numpy(self.decode(self.latent(t)))


# --------------------------------------------------------------------------------------------
# edge-length distortion
# --------------------------------------------------------------------------------------------


def _mesh_edges(F: np.ndarray) -> np.ndarray:
    from meshvae_lib.geometry.topology import edges

    return edges(F)


def edge_lengths(V, F) -> np.ndarray:
    """Lengths of the undirected edges ``topology.edges(F)``.

    Parameters
    ----------
    V : (n_vertices, 3) or (N, n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    (n_edges,) or (N, n_edges) float64
    """
    V = np.asarray(V, dtype=np.float64)
    if V.ndim not in (2, 3) or V.shape[-1] != 3:
        raise ValueError(f"V must be (n_vertices, 3) or (N, n_vertices, 3), got {V.shape}")
    E = _mesh_edges(np.asarray(F, dtype=np.int64))
    return np.linalg.norm(V[..., E[:, 1], :] - V[..., E[:, 0], :], axis=-1)


def edge_length_distortion(V, F, dataset, chunk: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Mean relative edge-length change against the nearest data-set mesh.

    ``d(V, D) = mean_e |l_e(V) - l_e(D)| / l_e(D)``; the distortion of ``V`` is ``min_D d(V, D)``
    over the data-set meshes ``D``, and the nearest mesh is the minimiser. Zero for any rigid
    motion of a data-set mesh.

    Parameters
    ----------
    V : (n_vertices, 3) or (N, n_vertices, 3) float
    F : (n_faces, 3) int
    dataset : (M, n_vertices, 3) float

    Returns
    -------
    distortion : (N,) float64 (or a float for one mesh)
    nearest : (N,) int64 (or an int), index into ``dataset``
    """
    V = np.asarray(V, dtype=np.float64)
    single = V.ndim == 2
    Vb = V[None] if single else V
    D = np.asarray(dataset, dtype=np.float64)
    if D.ndim != 3 or D.shape[1:] != Vb.shape[1:]:
        raise ValueError(
            f"dataset must be (M, {Vb.shape[1]}, 3) to match V {V.shape}, got {D.shape}"
        )
    L = edge_lengths(Vb, F)  # (N, E)
    Ld = edge_lengths(D, F)  # (M, E)
    inv = 1.0 / np.maximum(Ld, np.finfo(float).tiny)
    dist = np.empty((L.shape[0], Ld.shape[0]))
    for s in range(0, L.shape[0], chunk):
        dist[s : s + chunk] = np.abs(L[s : s + chunk, None, :] - Ld[None]).__imul__(inv[None]).mean(axis=2)
    nearest = np.argmin(dist, axis=1)
    best = dist[np.arange(dist.shape[0]), nearest]
    if single:
        return float(best[0]), int(nearest[0])
    return best, nearest.astype(np.int64)


# --------------------------------------------------------------------------------------------
# self-intersections
# --------------------------------------------------------------------------------------------


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
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
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
        if count.sum() <= 27 * m or h > 1e6 * cell_size:
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
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim == 3:
        res = [self_intersections(v, F, return_pairs=True, chunk=chunk) for v in V]
        counts = np.array([r[0] for r in res], dtype=np.int64)
        return (counts, [r[1] for r in res]) if return_pairs else counts
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"V must be (n_vertices, 3) or (N, n_vertices, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3 or (F.size and (F.min() < 0 or F.max() >= V.shape[0])):
        raise ValueError(f"F must be (n_faces, 3) indices into {V.shape[0]} vertices, got {F.shape}")
    pairs = candidate_triangle_pairs(V, F)
    E = _mesh_edges(F)
    mean_edge = float(np.linalg.norm(V[E[:, 1]] - V[E[:, 0]], axis=1).mean()) if E.size else 1.0
    eps = tol.SELF_INTERSECTION_RTOL * mean_edge
    hit = np.zeros(pairs.shape[0], dtype=bool)
    for s in range(0, pairs.shape[0], chunk):
        p = pairs[s : s + chunk]
        hit[s : s + chunk] = triangle_pairs_intersect(V[F[p[:, 0]]], V[F[p[:, 1]]], eps)
    crossing = pairs[hit]
    return (int(crossing.shape[0]), crossing) if return_pairs else int(crossing.shape[0])


# --------------------------------------------------------------------------------------------
# a small table for notebooks
# --------------------------------------------------------------------------------------------


@dataclass
class ImplausibilityTable:
    """Per-step implausibility of several interpolation sequences.

    Attributes
    ----------
    methods : list of str
    self_intersections : dict method -> (n_steps,) int64
    edge_distortion : dict method -> (n_steps,) float64
    nearest : dict method -> (n_steps,) int64 (index of the nearest data-set mesh)
    """

    methods: list = field(default_factory=list)
    self_intersections: dict = field(default_factory=dict)
    edge_distortion: dict = field(default_factory=dict)
    nearest: dict = field(default_factory=dict)

    def rows(self) -> list[dict]:
        """One summary row per method: max/mean over the steps."""
        return [
            {
                "method": m,
                "max self-intersections": int(self.self_intersections[m].max()),
                "mean self-intersections": float(self.self_intersections[m].mean()),
                "max edge distortion": float(self.edge_distortion[m].max()),
                "mean edge distortion": float(self.edge_distortion[m].mean()),
            }
            for m in self.methods
        ]

    def to_markdown(self) -> str:
        """The summary rows as a markdown table."""
        lines = [
            "| method | self-intersections (max / mean over steps) | edge-length distortion (max / mean) |",
            "| --- | --- | --- |",
        ]
        for r in self.rows():
            lines.append(
                f"| {r['method']} | {r['max self-intersections']} / {r['mean self-intersections']:.1f} "
                f"| {r['max edge distortion']:.4f} / {r['mean edge distortion']:.4f} |"
            )
        return "\n".join(lines)


def implausibility(sequences: dict, F, dataset) -> ImplausibilityTable:
    """Self-intersections and edge-length distortion of every step of every sequence.

    Parameters
    ----------
    sequences : dict name -> (n_steps, n_vertices, 3) float
    F : (n_faces, 3) int
    dataset : (M, n_vertices, 3) float, the training meshes

    Returns
    -------
    ImplausibilityTable
    """
    out = ImplausibilityTable()
    for name, seq in sequences.items():
        seq = np.asarray(seq, dtype=np.float64)
        if seq.ndim != 3:
            raise ValueError(f"sequence {name!r} must be (n_steps, n_vertices, 3), got {seq.shape}")
        out.methods.append(name)
        out.self_intersections[name] = self_intersections(seq, F)
        d, nn = edge_length_distortion(seq, F, dataset)
        out.edge_distortion[name] = d
        out.nearest[name] = nn
    return out
