"""How well a mesh VAE reconstructs meshes: the per-vertex position error of the paper's Tables 1-3.

The error of a reconstructed mesh is the mean Euclidean distance between its vertices and the true
ones, after rigidly aligning the reconstruction to the truth (the RIMD feature carries no global
pose, so a RIMD reconstruction sits wherever the reference mesh does; the same alignment is applied
to the coordinate baselines so that all three are measured alike). The error is in the mesh's own
units; :func:`evaluate_model` also reports it relative to the bounding-box diagonal.
"""

from __future__ import annotations

import time

import numpy as np

from meshvae_lib.geometry.alignment import bounding_box_diagonal, rigid_align
from meshvae_lib.model.inference import make_inference
from meshvae_lib.tolerances import PCA_RANK_RTOL
from meshvae_lib.validation import check_is_fitted, check_vertices

__all__ = ["per_vertex_error", "evaluate_model", "training_split_of", "CoordinatePCA", "pca_baseline", "regional_pca_baseline"]


def per_vertex_error(V_pred, V_true, align: bool = True) -> np.ndarray:
    """Mean vertex distance per mesh.

    V_pred, V_true : (N, n, 3) or (n, 3) float. align : first move V_pred rigidly onto V_true.
    Returns (N,) float64 (or a float for single meshes): mean_k |V_pred[k] - V_true[k]|.
    """
    P, T = check_vertices(V_pred, "V_pred"), check_vertices(V_true, "V_true")
    if P.shape != T.shape:
        raise ValueError(f"V_pred and V_true must have one shape, got {P.shape} and {T.shape}")
    if align:
        P = rigid_align(P, T)
    err = np.linalg.norm(P - T, axis=-1).mean(axis=-1)
    return float(err) if P.ndim == 2 else err


def evaluate_model(model, collection, indices=None, held_out_only: bool = False, fit_iterations: int = 0,
                   inference=None, progress: bool = False) -> dict:
    """Reconstruct meshes of ``collection`` (encode, decode) and measure them: the one way to the
    reconstruction error of a model, held-out (``held_out_only``) or not.

    model : :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`.
    collection : MeshCollection-like with ``vertices (N, n, 3)``, ``faces``, ``labels``, ``names``.
    indices : which meshes (default: all); ``held_out_only`` uses the model's held-out meshes,
        found by their identity (:func:`training_split_of`): the collection must hold all of them,
        in any order, and no mesh that was not in the training collection.
    inference : None (the model's own inference: by default "gauss-newton", the encoder's mean
        refined on the vertex error), a name of :data:`~meshvae_lib.model.inference.METHODS`
        ("encoder": the paper's feed-forward encoder) or a strategy object.
    fit_iterations : k > 0 fits the codes by finite differences with k steps (the
        "finite-difference" strategy; ``meshvae evaluate --fit-latent``).
    progress : a progress bar over the meshes while codes are fitted (seconds per mesh at 10k
        vertices).

    Returns a dict: ``mean_vertex_error`` (float, mesh units), ``relative_error`` (mean error /
    bounding-box diagonal of each true mesh, averaged), ``n_meshes``, ``per_mesh`` (list of float),
    ``names``, ``indices``, ``features`` (the model's feature kind), ``inference`` (the strategy's
    name), ``fit_iterations`` (the finite-difference steps; 0 for the other strategies) and
    ``seconds_per_mesh`` (encoding and decoding).
    """
    model.check_compatible(collection)
    V = np.asarray(collection.vertices, dtype=np.float64)
    idx = _evaluated(model, len(V), indices, held_out_only, V)
    labels = {k: np.asarray(v)[idx] for k, v in (getattr(collection, "labels", {}) or {}).items()}
    sub = V[idx]
    if fit_iterations:
        if inference not in (None, "finite-difference"):
            raise ValueError(f"fit_iterations is the finite-difference fit; inference {inference!r} was asked for")
        strategy = make_inference("finite-difference", iterations=fit_iterations)
    else:
        strategy = make_inference(model.inference if inference is None else inference)
    start = time.perf_counter()
    rec = model.reconstruct(sub, labels=labels if model.is_conditional else None, inference=strategy,
                            **({"progress": True} if progress else {}))
    seconds = time.perf_counter() - start
    err = per_vertex_error(rec, sub)
    diag = np.atleast_1d(bounding_box_diagonal(sub))
    names = list(getattr(collection, "names", []) or [])
    return {
        "mean_vertex_error": float(np.mean(err)),
        "relative_error": float(np.mean(err / diag)),
        "n_meshes": int(idx.size),
        "per_mesh": [float(e) for e in err],
        "names": [names[i] for i in idx] if names else [str(i) for i in idx],
        "indices": [int(i) for i in idx],
        "features": model.feature_kind.name,
        "fit_iterations": int(strategy.iterations) if strategy.name == "finite-difference" else 0,
        "inference": strategy.name,
        "inference_description": strategy.describe(),
        "seconds_per_mesh": seconds / idx.size,
    }


def training_split_of(model, vertices) -> tuple[np.ndarray, np.ndarray]:
    """Where the model's training and held-out meshes are in a collection, found by identity.

    model : a fitted MeshVAEModel (``holdout_mask_``, ``mesh_fingerprints_``).
    vertices : (N, n, 3) float, the collection's meshes.

    Returns ``(train, held)``: (k,) and (m,) int64 indices into ``vertices`` of the model's training
    meshes found there and of all its held-out meshes, in the order the model was trained on them.
    Each mesh is recognised by :func:`~meshvae_lib.geometry.collection.mesh_fingerprints` of its
    vertices (equal up to round-off), so the collection may list them in any order and may leave training meshes out. A
    model without fingerprints (read from a checkpoint of format 3 or older) takes them by position,
    and the collection must then have as many meshes as it was trained on.

    Raises ValueError when the model held out no meshes, when a held-out mesh is not in the
    collection, or when the collection holds meshes that were not in the training collection.
    """
    from meshvae_lib.geometry.collection import find_meshes

    mask = np.asarray(model.holdout_mask_, dtype=bool)
    V = np.asarray(vertices)
    prints = model.mesh_fingerprints_
    if prints is None and len(mask) != len(V):
        raise ValueError(f"the model was trained on {len(mask)} meshes, this collection has {len(V)}:"
                         " held-out meshes cannot be identified")
    if not mask.any():
        raise ValueError("the model was trained without held-out meshes (meshvae train --holdout-every K)")
    if prints is None:
        return np.flatnonzero(~mask), np.flatnonzero(mask)
    order = np.concatenate([np.flatnonzero(mask), np.flatnonzero(~mask)])
    found, missing = find_meshes(np.asarray(prints)[order], V)
    held_missing = int((missing < mask.sum()).sum())
    if held_missing:
        raise ValueError(f"{held_missing} of the model's {int(mask.sum())} held-out meshes are not in this collection"
                         " (a mesh is recognised by its vertex positions: give the training collection, in any order)")
    other = np.setdiff1d(np.arange(len(V)), found)
    if other.size:
        raise ValueError(f"{other.size} of this collection's {len(V)} meshes were not in the model's training"
                         f" collection (first: index {int(other[0])}): held-out meshes are measured only on the"
                         " training collection")
    n_held = int(mask.sum())
    return found[n_held:], found[:n_held]


def _evaluated(model, n: int, indices, held_out_only: bool, vertices=None) -> np.ndarray:
    """The indices of the meshes :func:`evaluate_model` measures, checked."""
    if held_out_only:
        idx = training_split_of(model, vertices)[1]
    else:
        idx = np.arange(n) if indices is None else np.asarray(indices, dtype=np.int64).ravel()
    if idx.size == 0:
        raise ValueError("no meshes to evaluate")
    if idx.min() < -n or idx.max() >= n:
        raise ValueError(f"indices must lie in 0..{n - 1}, got {idx.min()}..{idx.max()}")
    return idx


class CoordinatePCA:
    """Linear PCA on vertex coordinates: the linear floor every learned model is compared with.

    Each mesh is flattened to a row of 3n coordinates (optionally after rigidly aligning it to the
    reference mesh, ``aligned=True``); the rows of the training meshes are centred on their mean
    and the ``n_components`` leading right singular vectors span the model. A mesh is reconstructed
    by projecting its centred row orthogonally onto that span and adding the mean back. With
    ``n_components = N - 1`` (the default, all directions a training set of N meshes spans) the
    training meshes are reproduced exactly.

    Parameters
    ----------
    n_components : int or None
        number of principal directions kept (None: all that the training meshes span, N - 1 for
        N meshes in general position).
    aligned : bool
        fit and reconstruct rigidly aligned coordinates (the paper's "aligned coordinates").

    Attributes (after :meth:`fit`)
    ------------------------------
    mean_ : (3n,) float64, the training meshes' mean row.
    components_ : (k, 3n) float64, orthonormal principal directions, largest variance first.
    singular_values_ : (k,) float64.
    reference_ : (n, 3) float64, the mesh others are aligned to (the first training mesh).
    """

    def __init__(self, n_components: int | None = None, aligned: bool = False):
        self.n_components = n_components
        self.aligned = aligned

    def _rows(self, V) -> np.ndarray:
        V = check_vertices(V, "meshes")
        V = V[None] if V.ndim == 2 else V
        if hasattr(self, "reference_") and V.shape[1] != len(self.reference_):
            raise ValueError(f"the PCA was fitted on meshes of {len(self.reference_)} vertices, got {V.shape[1]}")
        if self.aligned:
            V = rigid_align(V, self.reference_)
        return V.reshape(len(V), -1)

    def fit(self, V_train) -> "CoordinatePCA":
        """V_train : (N, n, 3) float training meshes, N >= 2. Returns ``self``."""
        V = check_vertices(V_train, "V_train", batch=True)
        if len(V) < 2:
            raise ValueError(f"need (N >= 2, n_vertices, 3) training meshes, got {V.shape}")
        self.reference_ = V[0].copy()
        X = self._rows(V)
        self.mean_ = X.mean(axis=0)
        _, s, Vt = np.linalg.svd(X - self.mean_, full_matrices=False)
        rank = int(np.sum(s > s[0] * PCA_RANK_RTOL)) if s.size and s[0] > 0 else 0
        k = rank if self.n_components is None else int(self.n_components)
        if not 0 <= k <= min(rank, len(V) - 1) and self.n_components is not None:
            raise ValueError(f"n_components must lie in 0..{min(rank, len(V) - 1)} for these {len(V)} meshes, got {k}")
        self.components_ = Vt[:k]
        self.singular_values_ = s[:k]
        return self

    def transform(self, V) -> np.ndarray:
        """Meshes (N, n, 3) -> principal coefficients (N, k) float64."""
        check_is_fitted(self, "components_", "call fit(V_train) first")
        return (self._rows(V) - self.mean_) @ self.components_.T

    def inverse_transform(self, Z) -> np.ndarray:
        """Coefficients (N, k) -> meshes (N, n, 3) float64 (in the aligned frame when ``aligned``)."""
        check_is_fitted(self, "components_", "call fit(V_train) first")
        Z = np.atleast_2d(np.asarray(Z, dtype=np.float64))
        return (Z @ self.components_ + self.mean_).reshape(len(Z), -1, 3)

    def reconstruct(self, V) -> np.ndarray:
        """Project meshes (N, n, 3) onto the model and back: (N, n, 3) float64."""
        return self.inverse_transform(self.transform(V))



def pca_baseline(V_train, V_eval, n_components: int | None = None, aligned: bool = False) -> dict:
    """Fit :class:`CoordinatePCA` on training meshes and measure it on others, like :func:`evaluate_model`.

    V_train : (N, n, 3) float training meshes; V_eval : (M, n, 3) float meshes to reconstruct (e.g.
    the held-out ones); n_components, aligned : see :class:`CoordinatePCA`.

    Returns a dict: ``mean_vertex_error`` (mean over the meshes of the mean vertex distance after
    rigid alignment, mesh units: the same number :func:`evaluate_model` reports), ``relative_error``,
    ``train_error`` (the same on ``V_train``), ``n_components``, ``n_meshes``, ``per_mesh`` (list).
    """
    pca = CoordinatePCA(n_components, aligned).fit(V_train)
    Ve = np.asarray(V_eval, dtype=np.float64)
    Vt = np.asarray(V_train, dtype=np.float64)
    err = np.atleast_1d(per_vertex_error(pca.reconstruct(Ve), Ve))
    diag = np.atleast_1d(bounding_box_diagonal(Ve))
    train = np.atleast_1d(per_vertex_error(pca.reconstruct(Vt), Vt))
    return {
        "mean_vertex_error": float(np.mean(err)),
        "relative_error": float(np.mean(err / diag)),
        "train_error": float(np.mean(train)),
        "n_components": int(pca.components_.shape[0]),
        "aligned": bool(aligned),
        "n_meshes": int(len(Ve)),
        "per_mesh": [float(e) for e in err],
    }


def regional_pca_baseline(V_train, V_eval, vertex_region, per_region: int) -> dict:
    """PCA on coordinates region by region: the linear floor of a decoder of local parts at its capacity.

    V_train : (N, n, 3) float training meshes; V_eval : (M, n, 3) float meshes to reconstruct;
    vertex_region : (n,) int, the region of each vertex (e.g. a local-parts network's
    ``vertex_region``); per_region : principal directions kept in each region (fewer where the
    region's training coordinates span fewer). Each region's coordinates are projected onto their
    own directions (regions share no coordinate, so this is the orthogonal projection onto the
    regions' directions together).

    Returns a dict as :func:`pca_baseline`'s (``mean_vertex_error``, ``relative_error``,
    ``n_components``: the directions used in all, ``n_meshes``, ``per_mesh``).
    """
    Vt = check_vertices(V_train, "V_train", batch=True)
    Ve = check_vertices(V_eval, "V_eval", batch=True)
    labels = np.asarray(vertex_region, dtype=np.int64)
    if labels.shape != (Vt.shape[1],) or Ve.shape[1] != Vt.shape[1]:
        raise ValueError(f"vertex_region must be ({Vt.shape[1]},) for meshes of {Vt.shape[1]} vertices, got"
                         f" {labels.shape} and meshes of {Ve.shape[1]}")
    out, used = np.empty_like(Ve), 0
    for g in np.unique(labels):
        idx = np.flatnonzero(labels == g)
        X, Y = Vt[:, idx].reshape(len(Vt), -1), Ve[:, idx].reshape(len(Ve), -1)
        mean = X.mean(axis=0)
        _, s, W = np.linalg.svd(X - mean, full_matrices=False)
        k = min(int(per_region), int(np.sum(s > s[0] * PCA_RANK_RTOL)) if s.size and s[0] > 0 else 0)
        W, used = W[:k], used + k
        out[:, idx] = (mean + (Y - mean) @ W.T @ W).reshape(len(Ve), len(idx), 3)
    err = np.atleast_1d(per_vertex_error(out, Ve))
    diag = np.atleast_1d(bounding_box_diagonal(Ve))
    return {"mean_vertex_error": float(np.mean(err)), "relative_error": float(np.mean(err / diag)),
            "n_components": int(used), "n_meshes": int(len(Ve)), "per_mesh": [float(e) for e in err]}
