"""Two-dimensional embeddings of a shape collection (Sec. 5.4): NPE, PCA, t-SNE and the mesh VAE's.

The paper embeds the Dyna collection (many body shapes, each performing several motions) in 2D with
its extended mesh VAE (``sigma_object = (0.1, 0.1, 1, ..., 1)``, Sec. 4.4) and compares it with PCA,
NPE (Neighborhood Preserving Embedding, k = 25) and t-SNE (perplexity 30). Their quality is measured by
retrieval (:mod:`~meshvae_lib.applications.retrieval`); the paper reports the area under the
precision-recall curve: ours 0.5168 > t-SNE 0.4961 > PCA 0.2272 > NPE 0.1391.

Public names
------------
``NeighborhoodPreservingEmbedding`` (our implementation; no maintained Python package has it),
``pca_embedding``, ``tsne_embedding``, ``label_variance_share`` (what share of each embedding
direction's variance lies between the groups of a label: what a direction encodes). The mesh VAE's embedding is the first encoder means of the
sigma_object model (``model.encode_meshes(coll)[:, :2]``; its prior: ``defaults.EMBEDDING_SIGMA_OBJECT``
padded by ``train_config.pad_sigma_object``). Their retrieval scores:
:mod:`~meshvae_lib.applications.retrieval`.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg

from meshvae_lib import defaults as hp
from meshvae_lib import tolerances as tol
from meshvae_lib.validation import check_is_fitted, check_rows, check_samples

__all__ = [
    "NeighborhoodPreservingEmbedding",
    "label_variance_share",
    "pca_embedding",
    "tsne_embedding",
]


def _knn_indices(X: np.ndarray, k: int) -> np.ndarray:
    """Indices of the ``k`` nearest other samples of every sample, (n, k) int64, nearest first."""
    sq = np.einsum("ij,ij->i", X, X)
    D2 = sq[:, None] + sq[None, :] - 2.0 * (X @ X.T)
    np.fill_diagonal(D2, np.inf)
    idx = np.argpartition(D2, k - 1, axis=1)[:, :k]
    order = np.argsort(np.take_along_axis(D2, idx, axis=1), axis=1, kind="stable")
    return np.take_along_axis(idx, order, axis=1).astype(np.int64)


def locally_linear_weights(X, neighbors, reg: float = tol.NPE_REG) -> np.ndarray:
    """Reconstruction weights of every sample from its neighbours (the first step of LLE and NPE).

    For each sample ``x_i`` with neighbours ``N(i)``, the weights minimise
    ``|x_i - sum_j w_ij x_j|^2`` subject to ``sum_j w_ij = 1``. The local Gram matrix
    ``C_jk = (x_i - x_j) . (x_i - x_k)`` is regularised by ``reg * trace(C)`` on its diagonal, so
    that neighbourhoods spanning fewer dimensions than ``k`` still have a unique solution.

    Parameters
    ----------
    X : (n_samples, n_features) float64
    neighbors : (n_samples, k) int
    reg : float

    Returns
    -------
    W : (n_samples, k) float64, rows sum to 1; ``W[i, m]`` belongs to ``neighbors[i, m]``.
    """
    X = np.asarray(X, dtype=np.float64)
    nb = np.asarray(neighbors, dtype=np.int64)
    Z = X[nb] - X[:, None, :]  # (n, k, d)
    C = Z @ np.swapaxes(Z, 1, 2)  # (n, k, k)
    k = nb.shape[1]
    tr = np.trace(C, axis1=1, axis2=2)
    tr = np.where(tr > 0, tr, 1.0)
    C = C + (reg * tr)[:, None, None] * np.eye(k)[None]
    w = np.linalg.solve(C, np.ones((nb.shape[0], k, 1)))[..., 0]
    return w / w.sum(axis=1, keepdims=True)


class NeighborhoodPreservingEmbedding:
    """Neighborhood Preserving Embedding (He, Cai, Yan, Zhang, ICCV 2005), used by the paper's Sec. 5.4.

    NPE is the linear approximation of LLE: it finds the projection ``y = (x - mean) @ A`` whose
    columns keep the locally linear reconstruction weights ``W`` of the data:
    minimise ``sum_i |y_i - sum_j W_ij y_j|^2`` subject to ``sum_i |y_i|^2`` fixed, i.e. the
    generalised eigenproblem ``X^T M X a = lambda X^T X a`` with ``M = (I - W)^T (I - W)``, smallest
    eigenvalues first. As in the original paper, the data are first projected on their principal
    components (all with non-negligible variance, at most ``n_samples - 1``), so that ``X^T X`` is
    not singular when there are more features than samples; a ridge of ``reg_eig`` times the mean
    eigenvalue keeps the problem well posed.

    Parameters
    ----------
    n_components : int
    n_neighbors : int
        The paper's k = 25.
    reg : float
        Regulariser of the local weights (see ``locally_linear_weights``).
    reg_eig : float
        Relative ridge on ``X^T X``.

    Attributes
    ----------
    mean_ : (n_features,) float64
    components_ : (n_features, n_components) float64
        Projection directions in the input space, ``transform(X) = (X - mean_) @ components_``.
    eigenvalues_ : (n_components,) float64
        Generalised eigenvalues (the neighbourhood reconstruction cost), ascending.
    weights_ : (n_samples, n_neighbors) float64, neighbors_ : (n_samples, n_neighbors) int64
    """

    def __init__(
        self,
        n_components: int = 2,
        n_neighbors: int = hp.NPE_N_NEIGHBORS,
        reg: float = tol.NPE_REG,
        reg_eig: float = tol.NPE_REG_EIG,
    ):
        self.n_components = n_components
        self.n_neighbors = n_neighbors
        self.reg = reg
        self.reg_eig = reg_eig

    def fit(self, X) -> "NeighborhoodPreservingEmbedding":
        """Learn the projection from ``X : (n_samples, n_features)``; returns ``self``."""
        X = check_samples(X)
        n, d = X.shape
        k = int(self.n_neighbors)
        if not 1 <= k < n:
            raise ValueError(f"n_neighbors must be in [1, n_samples - 1] = [1, {n - 1}], got {k}")
        self.mean_ = X.mean(axis=0)
        Xc = X - self.mean_
        # PCA step: an orthonormal basis P of the data's span.
        U, s, Vt = np.linalg.svd(Xc, full_matrices=False)
        keep = s > tol.NPE_PCA_RTOL * (s[0] if s.size and s[0] > 0 else 1.0)
        P = Vt[keep].T  # (d, r)
        r = P.shape[1]
        if r < int(self.n_components):
            raise ValueError(
                f"the data span only {r} dimensions, fewer than n_components={self.n_components}"
            )
        Y = Xc @ P  # (n, r)
        self.neighbors_ = _knn_indices(Y, k)
        self.weights_ = locally_linear_weights(Y, self.neighbors_, self.reg)
        # (I - W) Y, without forming the n x n matrix W densely more than needed.
        Wd = np.zeros((n, n))
        np.put_along_axis(Wd, self.neighbors_, self.weights_, axis=1)
        R = Y - Wd @ Y
        A = R.T @ R
        B = Y.T @ Y
        B = B + self.reg_eig * (np.trace(B) / r) * np.eye(r)
        A = 0.5 * (A + A.T)
        evals, evecs = scipy.linalg.eigh(A, B, subset_by_index=[0, int(self.n_components) - 1])
        # fix the sign of each direction so results are reproducible: largest |entry| positive.
        big = np.argmax(np.abs(evecs), axis=0)
        evecs = evecs * np.sign(evecs[big, np.arange(evecs.shape[1])])
        self.eigenvalues_ = evals
        self.components_ = P @ evecs
        return self

    def transform(self, X) -> np.ndarray:
        """Project ``X : (n_samples, n_features)`` to ``(n_samples, n_components)`` float64."""
        check_is_fitted(self, "components_", "call fit(X) first")
        X = check_rows(X, "X", self.mean_.shape[0], single=False)
        return (X - self.mean_) @ self.components_

    def fit_transform(self, X) -> np.ndarray:
        """``fit(X).transform(X)``."""
        return self.fit(X).transform(X)


def pca_embedding(X, n_components: int = 2, seed: int = 0) -> np.ndarray:
    """PCA embedding via scikit-learn, ``X : (n, d)`` -> ``(n, n_components)`` float64.

    ``seed`` feeds the randomized SVD scikit-learn may choose for large inputs.
    """
    from sklearn.decomposition import PCA

    X = check_samples(X)
    return PCA(n_components=n_components, random_state=seed).fit_transform(X).astype(np.float64)


def tsne_embedding(
    X,
    n_components: int = 2,
    perplexity: float = hp.TSNE_PERPLEXITY,
    seed: int = 0,
    pca_dims: int | None = hp.TSNE_PCA_DIMS,
) -> np.ndarray:
    """t-SNE embedding via scikit-learn (Sec. 5.4: perplexity 30), ``(n, d)`` -> ``(n, n_components)``.

    As is usual for very high-dimensional inputs, the data are first reduced to ``pca_dims``
    principal components (``None``: no reduction). Perplexity is capped at ``(n - 1) / 3`` so tiny
    collections still run. Initialisation is by PCA, so results depend only on ``seed``.
    """
    from sklearn.decomposition import PCA
    from sklearn.manifold import TSNE

    X = check_samples(X)
    n = X.shape[0]
    if pca_dims is not None and X.shape[1] > pca_dims and n > pca_dims:
        X = PCA(n_components=pca_dims, random_state=seed).fit_transform(X)
    perp = float(min(perplexity, max(1.0, (n - 1) / 3.0)))
    ts = TSNE(n_components=n_components, perplexity=perp, init="pca", random_state=seed)
    return ts.fit_transform(X).astype(np.float64)


def label_variance_share(Y, label) -> np.ndarray:
    """The share of each column's variance that lies between the groups of ``label`` (eta squared).

    Y : (n, m) float, one row per sample (an embedding, or principal components); label : (n,) any
    hashable values. Returns (m,) float64 in [0, 1]: 1 - (within-group sum of squares) / (total sum
    of squares) per column; 1 where a column is constant within every group, 0 where every group has
    the column's overall mean. A constant column gets 0.
    """
    Y = check_samples(Y)
    label = np.asarray(label)
    if label.shape != (len(Y),):
        raise ValueError(f"label: one value per row of Y ({len(Y)}), got shape {label.shape}")
    centred = Y - Y.mean(axis=0)
    total = (centred ** 2).sum(axis=0)
    _, group = np.unique(label, return_inverse=True)
    within = np.zeros(Y.shape[1])
    for g in range(group.max() + 1):
        rows = Y[group == g]
        within += ((rows - rows.mean(axis=0)) ** 2).sum(axis=0)
    share = np.where(total > 0, 1.0 - within / np.where(total > 0, total, 1.0), 0.0)
    return np.clip(share, 0.0, 1.0)
