"""Regions of a mesh found without labels: the parts of the local-parts decoder
(:class:`~meshvae_lib.model.local_parts.LocalPartsVAE`).

Two rules, both deterministic (no random start); the local-parts network's default is
``defaults.LOCAL_PARTS_METHOD``:

- ``"kmeans"``: Lloyd's k-means on the reference mesh's vertex positions, started at farthest
  points (the first centre is the vertex nearest the centroid, each next one the vertex farthest
  from the centres so far). Regions are compact in space; two parts that touch in the reference
  pose (an arm against the body) may share one.
- ``"spectral"``: the same k-means on the vertices' coordinates in the first ``n_regions``
  eigenvectors of the mesh's normalised graph Laplacian, the constant one dropped (spectral clustering, Shi and Malik
  2000; Ng, Jordan and Weiss 2002): regions follow the surface, not the space around it, so limbs
  that touch are told apart.

Everything is vectorised over vertices; the loops run over k-means iterations and centres.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from meshvae_lib.defaults import REGION_METHODS
from meshvae_lib.geometry.topology import MeshTopology
from meshvae_lib.validation import check_choice, check_count, check_mesh

__all__ = ["REGION_METHODS", "kmeans_labels", "mesh_regions"]

_MAX_ITERATIONS = 100


def kmeans_labels(P, k: int) -> np.ndarray:
    """Lloyd's k-means of points ``P (n, d)`` float into ``k`` clusters from farthest-point centres.

    Returns labels ``(n,)`` int64 in ``0..k-1``, every cluster non-empty, numbered by their first
    point (the cluster of point 0 is 0, the next new cluster met in point order 1, ...), so equal
    partitions get equal labels. Deterministic: the first centre is the point nearest the mean.
    """
    P = np.asarray(P, dtype=np.float64)
    if P.ndim != 2 or not np.all(np.isfinite(P)):
        raise ValueError(f"points must be a finite (n, d) array, got shape {P.shape}")
    k = check_count(k, "k", minimum=1)
    if k > len(P):
        raise ValueError(f"cannot make {k} clusters of {len(P)} points")
    first = int(np.argmin(np.sum((P - P.mean(0)) ** 2, axis=1)))
    centres = [first]
    d2 = np.sum((P - P[first]) ** 2, axis=1)
    for _ in range(k - 1):
        nxt = int(np.argmax(d2))
        centres.append(nxt)
        d2 = np.minimum(d2, np.sum((P - P[nxt]) ** 2, axis=1))
    C = P[centres].copy()
    labels = np.full(len(P), -1, np.int64)
    for _ in range(_MAX_ITERATIONS):
        dist = np.sum(P * P, axis=1)[:, None] - 2.0 * P @ C.T + np.sum(C * C, axis=1)[None, :]
        new = np.argmin(dist, axis=1)
        counts = np.bincount(new, minlength=k)
        if np.any(counts == 0):  # an emptied cluster restarts at the point farthest from its centre
            worst = np.argsort(-dist[np.arange(len(P)), new])
            for c, p in zip(np.flatnonzero(counts == 0), worst):
                new[p] = c
        if np.array_equal(new, labels):
            break
        labels = new
        C = np.stack([P[labels == c].mean(0) for c in range(k)])
    _, first_seen = np.unique(labels, return_index=True)
    renumber = np.empty(k, np.int64)
    renumber[np.argsort(first_seen)] = np.arange(k)
    return renumber[labels]


def _spectral_coordinates(n: int, F: np.ndarray, k: int) -> np.ndarray:
    """The first ``k`` eigenvectors of the graph Laplacian of the faces' edges (normalised by the
    degrees, ``L = I - D^-1/2 A D^-1/2``) but the constant one: ``(n, k - 1)``, rows scaled to unit
    length (Ng, Jordan and Weiss)."""
    E = MeshTopology(F, n).edges
    A = sp.coo_matrix((np.ones(len(E)), (E[:, 0], E[:, 1])), shape=(n, n))
    A = (A + A.T).tocsr()
    d = np.asarray(A.sum(axis=1)).ravel()
    s = 1.0 / np.sqrt(np.maximum(d, 1.0))
    # the smallest eigenvalues of L are the largest of 2I - L = I + D^-1/2 A D^-1/2 (no factorisation)
    M = sp.identity(n, format="csr") + sp.diags(s) @ A @ sp.diags(s)
    m = min(k, n - 2)
    v0 = np.sqrt(np.maximum(d, 1.0))  # a fixed start vector: the same eigenvectors every run
    vals, vecs = spla.eigsh(M, k=m, which="LA", v0=v0 / np.linalg.norm(v0), tol=1e-8)
    order = np.argsort(-vals)
    Y = (vecs[:, order] * s[:, None])[:, 1:]  # D^-1/2 u: drop the constant one
    Y *= np.sign(Y[np.argmax(np.abs(Y), axis=0), np.arange(Y.shape[1])])  # a fixed sign per vector
    return Y / np.maximum(np.linalg.norm(Y, axis=1, keepdims=True), 1e-300)


def mesh_regions(V, F, n_regions: int, method: str = "kmeans") -> np.ndarray:
    """The vertices of mesh ``(V (n, 3) float, F (n_faces, 3) int)`` split into ``n_regions`` regions.

    method : one of :data:`REGION_METHODS` (see the module docstring).
    Returns labels ``(n,)`` int64 in ``0..n_regions-1`` (numbered as :func:`kmeans_labels`).
    """
    V, F = check_mesh(V, F, batch=False)
    check_choice(method, REGION_METHODS, "method")
    n_regions = check_count(n_regions, "n_regions", minimum=1)
    if n_regions > len(V):
        raise ValueError(f"cannot split a mesh of {len(V)} vertices into {n_regions} regions")
    if method == "kmeans" or n_regions == 1:
        return kmeans_labels(V, n_regions)
    return kmeans_labels(_spectral_coordinates(len(V), np.asarray(F, np.int64), n_regions), n_regions)
