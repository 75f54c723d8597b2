"""Generation of novel meshes and the nearest-neighbour test against memorisation (paper Sec. 5.2).

A trained mesh VAE generates new meshes by decoding latent vectors drawn from its prior
``N(0, diag(sigma_object^2))`` (``N(0, I)`` for the standard model). The conditional mesh VAE
(Sec. 4.3) draws z from the same prior -- its prior does not depend on the condition -- and decodes
it together with a chosen condition (a body shape, a motion).

To show that the network does not merely memorise its training set, the paper finds for every
generated mesh its nearest neighbour in the training set by Euclidean distance in RIMD feature
space (Sec. 5.2, following Gao et al. 2016) and shows the two side by side.
``nearest_training_meshes`` does the same and, so that "near" has a scale, also reports the
typical distance between a training mesh and its nearest *other* training mesh
(``dataset_nn_distance``): a generated mesh much closer to a training mesh than that would be a
copy.

A decoder of local parts (:class:`~meshvae_lib.model.local_parts.LocalPartsVAE`) also generates by
mixing parts (``mix_parts``): each region's latent dimensions taken from the code of a training
mesh drawn for that region, so the new mesh has this pose's arm and that pose's legs (the paper's
reading of its Fig. 2); ``parts_code`` builds such a code from sources chosen by hand.

Public names: ``nearest_training_meshes``, ``GenerationResult``, ``nearest_neighbors``,
``dataset_feature_rows``, ``condition_agreement``, ``mix_parts``, ``parts_code``. (Meshes alone, without the comparison:
``MeshVAEModel.generate``; prior draws: ``MeshVAEModel.sample_latent``.)
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshvae_lib.defaults import DEFAULT_LAYOUT
from meshvae_lib.tolerances import DUPLICATE_DISTANCE_RTOL
from meshvae_lib.validation import check_choice, check_count, check_vertices

__all__ = ["nearest_neighbors", "dataset_feature_rows", "nearest_training_meshes", "GenerationResult",
           "condition_agreement", "mix_parts", "parts_code", "FEATURE_SPACES"]

#: the spaces nearest neighbours are searched in: RIMD features in the paper's layout (Sec. 5.2's
#: distance, whatever the model's own features and layout), or the model's own feature rows.
FEATURE_SPACES = ("rimd", "model")


def nearest_neighbors(queries, dataset, chunk: int = 256, exclude_self: bool = False):
    """Nearest row of ``dataset`` to every row of ``queries`` by Euclidean distance.

    Squared distances are computed as ``|q|^2 + |d|^2 - 2 q.d`` in chunks (one matrix product per
    chunk); the distance to the chosen row is then recomputed directly, so it is exact.

    Parameters
    ----------
    queries : (n, K) float
    dataset : (M, K) float
    exclude_self : bool
        ``queries`` is ``dataset`` itself: row i may not pick itself (leave-one-out).

    Returns
    -------
    index : (n,) int64
    distance : (n,) float64
    """
    Q = np.asarray(queries, dtype=np.float64)
    D = np.asarray(dataset, dtype=np.float64)
    if Q.ndim != 2 or D.ndim != 2 or Q.shape[1] != D.shape[1]:
        raise ValueError(f"queries and dataset must be (n, K) and (M, K), got {Q.shape} and {D.shape}")
    if D.shape[0] < (2 if exclude_self else 1):
        raise ValueError(f"dataset has too few rows: {D.shape[0]}")
    if exclude_self and Q.shape != D.shape:
        raise ValueError(f"exclude_self needs queries to be the dataset, got {Q.shape} and {D.shape}")
    dn = np.einsum("ij,ij->i", D, D)
    index = np.empty(Q.shape[0], dtype=np.int64)
    for s in range(0, Q.shape[0], chunk):
        q = Q[s : s + chunk]
        d2 = np.einsum("ij,ij->i", q, q)[:, None] + dn[None, :] - 2.0 * (q @ D.T)
        if exclude_self:
            d2[np.arange(q.shape[0]), np.arange(s, s + q.shape[0])] = np.inf
        index[s : s + chunk] = np.argmin(d2, axis=1)
    distance = np.linalg.norm(Q - D[index], axis=1)
    return index, distance


@dataclass
class GenerationResult:
    """New meshes and their nearest training meshes (paper Fig. 2 and 3).

    Attributes
    ----------
    latents : (n, D) float64, the prior draws
    vertices : (n, n_vertices, 3) float64, the decoded meshes
    conditions : (n, C) float32 or None
    nearest : (n,) int64, index of the nearest training mesh in RIMD feature space (or None)
    distance : (n,) float64, its RIMD feature distance (or None)
    dataset_nn_distance : (M,) float64, each training mesh's distance to its nearest other one
    nearest_labels : dict column -> (n,) labels of the nearest training meshes
    """

    latents: np.ndarray
    vertices: np.ndarray
    conditions: np.ndarray | None = None
    nearest: np.ndarray | None = None
    distance: np.ndarray | None = None
    dataset_nn_distance: np.ndarray | None = None
    nearest_labels: dict = field(default_factory=dict)

    def novelty_ratio(self) -> np.ndarray:
        """(n,) float64: each generated mesh's nearest distance over the median training-set
        nearest-neighbour distance (exact duplicates in the training set left out) (about 1: as new as a training mesh is to the others; near 0: a
        copy)."""
        if self.distance is None or self.dataset_nn_distance is None:
            raise ValueError("no nearest neighbours were computed")
        d = self.dataset_nn_distance
        d = d[d > DUPLICATE_DISTANCE_RTOL * max(float(d.max()), 1e-300)]  # exact duplicates (shared rest frames) say nothing
        return self.distance / (np.median(d) if d.size else np.nan)

    def rows(self) -> list[dict]:
        out = []
        for i in range(self.latents.shape[0]):
            row = {"sample": i}
            if self.nearest is not None:
                row.update(nearest=int(self.nearest[i]), distance=float(self.distance[i]),
                           novelty=float(self.novelty_ratio()[i]))
            for k, v in self.nearest_labels.items():
                row[f"nearest {k}"] = v[i]
            out.append(row)
        return out

    def to_markdown(self) -> str:
        rows = self.rows()
        if not rows:
            return ""
        keys = list(rows[0])
        lines = ["| " + " | ".join(keys) + " |", "| " + " | ".join("---" for _ in keys) + " |"]
        for r in rows:
            lines.append("| " + " | ".join(f"{r[k]:.4g}" if isinstance(r[k], float) else str(r[k]) for k in keys) + " |")
        return "\n".join(lines)


def _feature_rows(model, V: np.ndarray, feature_space: str) -> np.ndarray:
    if feature_space == "rimd":  # the paper's distance: its layout, whatever the model's (DEFAULT_LAYOUT)
        from meshvae_lib.geometry.rimd import rimd_features

        rows = rimd_features(model.reference_vertices, V, model.faces, layout=DEFAULT_LAYOUT)
        return np.asarray(rows, dtype=np.float64).reshape(len(V), -1)
    return model.feature_kind.encode(V)


def dataset_feature_rows(model, dataset, feature_space: str = "rimd") -> np.ndarray:
    """The feature rows ``generate`` compares against, computed once for repeated calls.

    Parameters
    ----------
    model : a trained ``MeshVAEModel``
    dataset : a collection (``vertices (M, n_vertices, 3)``) or its vertices
    feature_space : one of :data:`FEATURE_SPACES`, as in :func:`nearest_training_meshes`

    Returns
    -------
    X : (M, K) float64, to pass to ``nearest_training_meshes(..., dataset_features=X)``
    """
    check_choice(feature_space, FEATURE_SPACES, "feature_space")
    D = check_vertices(getattr(dataset, "vertices", dataset), "dataset", batch=True)
    return _feature_rows(model, D, feature_space)


def nearest_training_meshes(
    model, n: int, dataset, seed: int = 0, condition: dict | None = None, feature_space: str = "rimd",
    dataset_features=None,
) -> GenerationResult:
    """Generate ``n`` meshes from the prior (``model.generate``) and find their nearest training
    meshes (Sec. 5.2).

    Parameters
    ----------
    model : a trained ``MeshVAEModel`` (any feature kind)
    n : int >= 1
    seed : int, seeds the prior draws (and the unset condition columns)
    condition : dict column -> value, for a conditional model (Sec. 4.3), e.g. ``{"shape": "s3"}``;
        columns left out take the values of random training meshes
    dataset : the training collection (``vertices (M, n_vertices, 3)``, optional ``labels``) or
        its (M, n_vertices, 3) vertices
    feature_space : "rimd" (the paper's: RIMD features in the paper's layout relative to the
        model's reference mesh, whatever features and layout the model itself uses) or "model" (the
        model's own, unnormalised feature rows, e.g. aligned coordinates)
    dataset_features : (M, K) float64 or None, the dataset's rows from
        :func:`dataset_feature_rows` (same ``feature_space``); saves recomputing them on every call

    Returns
    -------
    GenerationResult
    """
    n = check_count(n, "n", minimum=1)
    check_choice(feature_space, FEATURE_SPACES, "feature_space")
    D = check_vertices(getattr(dataset, "vertices", dataset), "dataset", batch=True,
                       n_vertices=len(model.reference_vertices))
    V, z, cond = model.generate(n, seed=seed, condition=condition, return_latents=True)
    result = GenerationResult(latents=z, vertices=V, conditions=cond)
    Xg = _feature_rows(model, V, feature_space)
    if dataset_features is None:
        Xd = _feature_rows(model, D, feature_space)
    else:
        Xd = np.asarray(dataset_features, dtype=np.float64)
        if Xd.shape != (len(D), Xg.shape[1]):
            raise ValueError(f"dataset_features must be ({len(D)}, {Xg.shape[1]}) for this dataset and "
                             f"feature_space={feature_space!r}, got {Xd.shape}")
    result.nearest, result.distance = nearest_neighbors(Xg, Xd)
    if len(D) >= 2:
        result.dataset_nn_distance = nearest_neighbors(Xd, Xd, exclude_self=True)[1]
    labels = getattr(dataset, "labels", None) or {}
    result.nearest_labels = {k: np.asarray(v)[result.nearest] for k, v in labels.items()}
    return result


def condition_agreement(model, dataset, column: str, values=None, n: int = 10, seed: int = 0,
                        conditioned: bool = True, dataset_features=None) -> np.ndarray:
    """Does a conditional model generate what it is asked for? (Sec. 4.3, 5.2)

    For every value ``v`` of label ``column``, generate ``n`` meshes (asked for ``{column: v}``
    when ``conditioned``, else unconditioned: the chance level of a plain model) and classify each
    by the label of its nearest mesh of ``dataset`` in RIMD feature space (a 1-nearest-neighbour
    classifier fitted on the data set). Returns the share of the ``n`` meshes classified as ``v``.

    Parameters
    ----------
    model : a trained ``MeshVAEModel``; conditional on ``column`` when ``conditioned``
    dataset : collection with ``vertices`` and ``labels[column]``
    column : the label to check; values : its values to ask for (default: all, sorted)
    n, seed : meshes per value and the seed of their prior draws (the same draws for every value)
    dataset_features : (M, K) float64, the dataset's rows from :func:`dataset_feature_rows`, optional

    Returns
    -------
    (n_values,) float64 in [0, 1], in the order of ``values``.
    """
    labels = getattr(dataset, "labels", None) or {}
    if column not in labels:
        raise ValueError(f"the data set has no label column {column!r}; it has {sorted(labels)}")
    values = np.unique(np.asarray(labels[column])) if values is None else list(values)
    X = dataset_feature_rows(model, dataset) if dataset_features is None else dataset_features
    hits = []
    for v in values:
        res = nearest_training_meshes(model, n, dataset, seed=seed, condition={column: v} if conditioned else None,
                                      dataset_features=X)
        hits.append(float(np.mean(res.nearest_labels[column] == v)))
    return np.asarray(hits)


def mix_parts(codes, latent_region, n: int, seed: int = 0, neighbours: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """New codes that mix the parts of given ones: region by region, the dimensions of a code drawn at random.

    codes : (M, D) float, e.g. the training meshes' codes; latent_region : (D,) int, the region of
    each latent dimension (a local-parts network's ``latent_region``); n : codes to make; seed : the
    draws' seed; neighbours : None (default) draws every region's source among all M codes; k draws
    a base code, then every region's source among the base's k nearest codes (Euclidean, the base
    included): parts of similar poses, as a new pose of the same motion combines them.

    Returns ``(z (n, D) float64, sources (n, R) int64)``: ``z[i]``'s dimensions of the r-th region
    (in increasing region number) are those of ``codes[sources[i, r]]``.
    """
    Z = np.asarray(codes, dtype=np.float64)
    labels = np.asarray(latent_region)
    if Z.ndim != 2 or labels.shape != (Z.shape[1],) or len(Z) < 1:
        raise ValueError(f"codes must be (M >= 1, D) and latent_region (D,), got {Z.shape} and {labels.shape}")
    n = check_count(n, "n", minimum=1)
    regions = np.unique(labels)
    rng = np.random.default_rng(seed)
    if neighbours is None:
        sources = rng.integers(0, len(Z), size=(n, len(regions)))
    else:
        k = check_count(neighbours, "neighbours", minimum=1)
        if k > len(Z):
            raise ValueError(f"neighbours must be at most the {len(Z)} codes, got {k}")
        base = rng.integers(0, len(Z), size=n)
        d2 = np.sum((Z[base][:, None, :] - Z[None, :, :]) ** 2, axis=-1)  # (n, M)
        near = np.argsort(d2, axis=1, kind="stable")[:, :k]
        sources = np.take_along_axis(near, rng.integers(0, k, size=(n, len(regions))), axis=1)
    return parts_code(Z, labels, sources), sources


def parts_code(codes, latent_region, sources) -> np.ndarray:
    """Codes whose every region's dimensions are those of a chosen code: the mix of parts by hand.

    codes : (M, D) float; latent_region : (D,) int, the region of each latent dimension (a
    local-parts network's ``latent_region``); sources : (n, R) int, for each new code and each
    region (in increasing region number) the index of the code its dimensions come from.

    Returns ``z (n, D) float64``: ``z[i]``'s dimensions of the r-th region are those of
    ``codes[sources[i, r]]`` (what :func:`mix_parts` returns for the sources it draws).
    """
    Z = np.asarray(codes, dtype=np.float64)
    labels = np.asarray(latent_region)
    if Z.ndim != 2 or labels.shape != (Z.shape[1],) or len(Z) < 1:
        raise ValueError(f"codes must be (M >= 1, D) and latent_region (D,), got {Z.shape} and {labels.shape}")
    regions = np.unique(labels)
    src = np.asarray(sources)
    if src.ndim != 2 or src.shape[1] != len(regions) or not np.issubdtype(src.dtype, np.integer):
        raise ValueError(f"sources must be (n, {len(regions)}) integers (one code index per region), got "
                         f"{src.shape} {src.dtype}")
    if src.size and (src.min() < 0 or src.max() >= len(Z)):
        raise ValueError(f"sources must index the {len(Z)} codes, got values from {src.min()} to {src.max()}")
    z = np.empty((len(src), Z.shape[1]))
    for r, g in enumerate(regions):  # a loop over the regions (a handful)
        cols = np.flatnonzero(labels == g)
        z[:, cols] = Z[src[:, r]][:, cols]
    return z
