"""Mesh interpolation (paper Sec. 4.5 and 5.3, Fig. 4) and numbers that tell plausible from implausible.

Three ways to go from mesh A to mesh B in ``n_steps`` steps:

- **latent** (the paper's): the straight path between two latent codes (the codes of two meshes,
  ``model.encode_meshes``, or two generated shapes), decoded (:class:`LatentPath`: every step with
  ``path.steps(n_steps)``, any point with ``path(t)``);
- **RIMD**: step linearly between the two RIMD feature vectors and reconstruct every step
  (``interpolate_features``; the paper's first row of Fig. 4, which shows self-intersections);
- **coordinates**: step linearly between the vertex positions (``interpolate_coordinates``; B is
  first rigidly aligned to A, otherwise a turn would shrink the body through its middle).

Implausibility, to put numbers beside the pictures (``implausibility`` tabulates both per step):

- ``self_intersections(V, F)`` (:mod:`meshvae_lib.geometry.intersections`): how many pairs of
  non-adjacent triangles cross each other.
- ``edge_length_distortion(V, F, dataset)``: the mean relative edge-length change against the
  data-set mesh that is nearest by this same measure (it is rigid-motion invariant). An
  interpolation that stays on the shape space keeps edges close to those of some real mesh.
- ``vertex_edge_stretch(V, V_ref, F)``: the same change against one given mesh, per vertex (the
  mean over its edges), to colour a mesh by where it stretches.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.geometry.intersections import self_intersections
from meshvae_lib.geometry.topology import edge_lengths, edges

__all__ = [
    "linear_steps",
    "interpolate_coordinates",
    "interpolate_features",
    "LatentPath",
    "edge_length_distortion",
    "vertex_edge_stretch",
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


class LatentPath:
    """Interpolation in the latent space (paper Sec. 4.5, 5.3, Fig. 6a): the straight path between
    two codes, decoded. ``path(t)`` is the mesh at ``z(t) = (1 - t) z_a + t z_b`` (for a slider,
    e.g. ``InterpolationSlider(..., interpolate=path)``); ``path.steps(n)`` decodes n evenly spaced
    steps, both ends included.

    decode : callable ``(latent,) -> (n_vertices, 3)`` and ``(n, latent) -> (n, n_vertices, 3)``
        (e.g. ``MeshVAEModel.decode_latent``);
    z_a, z_b : (latent,) float, the two ends (t = 0 and t = 1): e.g. the two rows of
        ``model.encode_meshes(np.stack([V_a, V_b]))``, or two prior draws.
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

    def steps(self, n_steps: int) -> tuple[np.ndarray, np.ndarray]:
        """``n_steps`` evenly spaced points of the path, decoded in one call.

        Returns
        -------
        z : (n_steps, latent) float64, ``z[0] == z_a``, ``z[-1] == z_b``
        V : (n_steps, n_vertices, 3) float64
        """
        z = linear_steps(self.z_a, self.z_b, n_steps)
        return z, _to_numpy(self.decode(z))


# --------------------------------------------------------------------------------------------
# edge-length distortion
# --------------------------------------------------------------------------------------------


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


def vertex_edge_stretch(V, V_ref, F) -> np.ndarray:
    """Relative edge-length change against one reference mesh, averaged at each vertex.

    ``s_e = |l_e(V) - l_e(V_ref)| / l_e(V_ref)`` per undirected edge, and per vertex the mean of
    ``s_e`` over the edges that meet there. Zero for a rigid motion of ``V_ref``, ``|c - 1|``
    everywhere for ``c V_ref``; colour a mesh by it to see where it stretches or shrinks.

    Parameters
    ----------
    V : (n_vertices, 3) or (N, n_vertices, 3) float
    V_ref : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    stretch : (n_vertices,) or (N, n_vertices) float64, non-negative
    """
    V = np.asarray(V, dtype=np.float64)
    V_ref = np.asarray(V_ref, dtype=np.float64)
    if V_ref.ndim != 2 or V.shape[-2:] != V_ref.shape:
        raise ValueError(f"V_ref must be one mesh of the same vertex count as V {V.shape}, got {V_ref.shape}")
    E = edges(F)
    s = np.abs(edge_lengths(V, F) / np.maximum(edge_lengths(V_ref, F), np.finfo(float).tiny) - 1.0)
    n, m = V_ref.shape[0], len(E)
    # (n, m) vertex-edge incidence, each row scaled by 1 / the vertex's degree: one sparse product
    degree = np.bincount(E.ravel(), minlength=n)
    A = sp.csr_matrix((np.ones(2 * m), (E.T.ravel(), np.tile(np.arange(m), 2))), shape=(n, m))
    out = (A @ s.reshape(-1, m).T).T / np.maximum(degree, 1)
    return out.reshape(V.shape[:-1])


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
