"""Embeddings (NPE ours, PCA, t-SNE wrappers) and retrieval precision-recall (paper Sec. 5.4)."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.applications import embedding as emb
from meshvae_lib.applications import retrieval as ret

# ---------------------------------------------------------------------------------------------
# NPE
# ---------------------------------------------------------------------------------------------


def test_local_weights_hand_computed_on_a_line():
    # points 0,1,2,3,4 on a line; k = 2. Interior point i = average of i-1, i+1 -> (0.5, 0.5);
    # point 0 from 1, 2: x0 = 2 x1 - x2 -> (2, -1) (the only affine combination that is exact).
    X = np.arange(5.0)[:, None] * np.array([[1.0, 2.0, -0.5]])
    nb = np.array([[1, 2], [0, 2], [1, 3], [2, 4], [3, 2]])
    W = emb.locally_linear_weights(X, nb, reg=1e-9)
    np.testing.assert_allclose(W[0], [2.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(W[1:4], 0.5, atol=1e-6)
    np.testing.assert_allclose(W[4], [2.0, -1.0], atol=1e-6)
    np.testing.assert_allclose(W.sum(axis=1), 1.0, atol=1e-12)


def test_knn_against_brute_force(rng):
    X = rng.normal(size=(30, 4))
    nb = emb._knn_indices(X, 5)
    for i in range(30):
        d = np.linalg.norm(X - X[i], axis=1)
        d[i] = np.inf
        np.testing.assert_array_equal(nb[i], np.argsort(d)[:5])


def _rayleigh_brute_force(X, W_dense, thetas):
    """NPE's objective a^T X^T M X a / a^T X^T X a for unit directions a(theta) in 2D."""
    Xc = X - X.mean(axis=0)
    R = Xc - W_dense @ Xc
    A = R.T @ R
    B = Xc.T @ Xc
    a = np.stack([np.cos(thetas), np.sin(thetas)], axis=1)
    return np.einsum("ti,ij,tj->t", a, A, a) / np.einsum("ti,ij,tj->t", a, B, a)


def test_npe_direction_matches_brute_force_scan(rng):
    # A hand-made 2D case: a smooth chain along u (locally linear) plus large jitter along v.
    # PCA picks v (largest variance); NPE must pick the direction of smallest reconstruction
    # cost, found here by scanning all directions.
    n = 60
    t = np.linspace(0, 1, n)
    u = np.array([np.cos(0.3), np.sin(0.3)])
    v = np.array([-u[1], u[0]])
    X = 3.0 * t[:, None] * u + 0.05 * rng.normal(size=n)[:, None] * v
    X = X + np.array([5.0, -2.0])
    npe = emb.NeighborhoodPreservingEmbedding(n_components=1, n_neighbors=4, reg=1e-3, reg_eig=0.0)
    npe.fit(X)
    W = np.zeros((n, n))
    np.put_along_axis(W, npe.neighbors_, npe.weights_, axis=1)
    thetas = np.linspace(0, np.pi, 20001)
    cost = _rayleigh_brute_force(X, W, thetas)
    best = thetas[np.argmin(cost)]
    a = npe.components_[:, 0] / np.linalg.norm(npe.components_[:, 0])
    got = np.arctan2(a[1], a[0]) % np.pi
    assert abs(np.angle(np.exp(2j * (got - best)))) / 2 < 2e-4
    assert npe.eigenvalues_[0] == pytest.approx(cost.min(), rel=1e-6)


def test_npe_recovers_a_plane_in_high_dimension(rng):
    # 2D data linearly embedded in 40D with more features than samples: the embedding must be an
    # affine image of the plane coordinates (rank 2, exact linear fit).
    n = 35
    P = rng.uniform(-1, 1, size=(n, 2))
    A = rng.normal(size=(2, 40))
    X = P @ A + 0.3
    Y = emb.NeighborhoodPreservingEmbedding(2, n_neighbors=8).fit_transform(X)
    assert Y.shape == (n, 2) and Y.dtype == np.float64
    design = np.column_stack([P, np.ones(n)])
    coef, *_ = np.linalg.lstsq(design, Y, rcond=None)
    assert np.abs(design @ coef - Y).max() < 1e-8 * np.abs(Y).max()
    assert np.linalg.matrix_rank(coef[:2], tol=1e-8) == 2


def test_npe_deterministic_and_transform_consistent(rng):
    X = rng.normal(size=(40, 6))
    a = emb.NeighborhoodPreservingEmbedding(2, 10).fit(X)
    b = emb.NeighborhoodPreservingEmbedding(2, 10).fit(X)
    np.testing.assert_array_equal(a.transform(X), b.transform(X))
    np.testing.assert_allclose(a.transform(X[:5]), a.fit_transform(X)[:5], atol=1e-12)


def test_npe_validates():
    with pytest.raises(ValueError, match=r"\(n_samples, n_features\)"):
        emb.NeighborhoodPreservingEmbedding().fit(np.zeros(5))
    with pytest.raises(ValueError, match="n_neighbors"):
        emb.NeighborhoodPreservingEmbedding(n_neighbors=25).fit(np.random.default_rng(0).normal(size=(10, 3)))
    with pytest.raises(ValueError, match="shape"):
        emb.NeighborhoodPreservingEmbedding(2, 3).fit(np.eye(8)).transform(np.zeros((2, 3)))


# ---------------------------------------------------------------------------------------------
# PCA / t-SNE wrappers and the sigma_object prior
# ---------------------------------------------------------------------------------------------


def test_pca_and_tsne_shapes_and_seed(rng):
    X = rng.normal(size=(40, 8))
    P = emb.pca_embedding(X)
    assert P.shape == (40, 2) and P.dtype == np.float64
    # PCA: first coordinate has the largest variance, coordinates uncorrelated
    assert P[:, 0].var() >= P[:, 1].var()
    assert abs(np.corrcoef(P.T)[0, 1]) < 1e-8
    T1 = emb.tsne_embedding(X, seed=3)
    T2 = emb.tsne_embedding(X, seed=3)
    assert T1.shape == (40, 2)
    np.testing.assert_array_equal(T1, T2)


def test_embedding_sigma_object_is_the_default_padded():
    from meshvae_lib.defaults import EMBEDDING_SIGMA_OBJECT
    from meshvae_lib.model.train_config import pad_sigma_object

    np.testing.assert_array_equal(pad_sigma_object(EMBEDDING_SIGMA_OBJECT, 6), [0.1, 0.1, 1, 1, 1, 1])
    with pytest.raises(ValueError):
        pad_sigma_object(EMBEDDING_SIGMA_OBJECT, 1)


# ---------------------------------------------------------------------------------------------
# retrieval precision-recall
# ---------------------------------------------------------------------------------------------


def test_average_precision_hand_computed():
    # 1D embedding, positions 0, 1, 3, 7; labels a, b, a, a.
    Y = np.array([[0.0], [1.0], [3.0], [7.0]])
    lab = np.array(["a", "b", "a", "a"])
    ap = ret.average_precision(Y, lab)
    # query 0: ranking 1(b), 2(a), 3(a) -> hits at ranks 2, 3: AP = (1/2 + 2/3) / 2 = 7/12
    # query 1: no other b -> NaN
    # query 2: distances 3, 2, 4 -> ranking 1(b), 0(a), 3(a): AP = (1/2 + 2/3) / 2 = 7/12
    # query 3: distances 7, 6, 4 -> ranking 2(a), 1(b), 0(a): AP = (1 + 2/3) / 2 = 5/6
    np.testing.assert_allclose(ap[[0, 2, 3]], [7 / 12, 7 / 12, 5 / 6], atol=1e-12)
    assert np.isnan(ap[1])
    res = ret.precision_recall_curve(Y, lab, n_points=4)
    assert res.auc["label"] == pytest.approx((7 / 12 + 7 / 12 + 5 / 6) / 3, abs=1e-12)
    # curve at recall 0.25, 0.5 -> first hit; 0.75, 1.0 -> second hit. Mean over queries 0, 2, 3.
    np.testing.assert_allclose(
        res.precision["label"], [(0.5 + 0.5 + 1) / 3] * 2 + [2 / 3] * 2, atol=1e-12
    )


def test_auc_against_sklearn_average_precision(rng):
    from sklearn.metrics import average_precision_score

    Y = rng.normal(size=(50, 2))
    lab = rng.integers(0, 4, size=50)
    ours = ret.average_precision(Y, lab)
    ref = []
    for q in range(50):
        others = np.delete(np.arange(50), q)
        score = -np.linalg.norm(Y[others] - Y[q], axis=1)
        ref.append(average_precision_score(lab[others] == lab[q], score))
    np.testing.assert_allclose(ours, ref, atol=1e-12)


def test_curve_area_converges_to_auc(rng):
    Y = rng.normal(size=(60, 2))
    labels = {"shape": rng.integers(0, 3, 60), "motion": rng.integers(0, 5, 60)}
    res = ret.precision_recall_curve(Y, labels, n_points=20000)
    for k in ("shape", "motion", "mean"):
        assert res.precision[k].mean() == pytest.approx(res.auc[k], abs=2e-3)
    assert res.auc["mean"] == pytest.approx((res.auc["shape"] + res.auc["motion"]) / 2, abs=1e-12)
    assert ret.retrieval_auc(Y, labels) == pytest.approx(res.auc["mean"], abs=1e-12)


def test_auc_extremes_and_joint_relevance():
    # perfectly clustered labels -> AUC 1; joint relevance needs both labels equal
    shape = np.repeat([0, 1, 2], 6)
    motion = np.tile(np.repeat([0, 1], 3), 3)
    Y = np.column_stack([shape * 100.0 + motion * 10.0, np.arange(18) * 0.01])
    assert ret.retrieval_auc(Y, shape) == pytest.approx(1.0)
    assert ret.retrieval_auc(Y, {"shape": shape, "motion": motion}, relevance="joint") == pytest.approx(1.0)
    # motion is not clustered at the top level: below 1 when scored separately
    assert ret.retrieval_auc(Y, motion) < 0.9
    with pytest.raises(ValueError, match="relevance"):
        ret.precision_recall_curve(Y, shape, relevance="both")
    with pytest.raises(ValueError, match=r"\(18,\)"):
        ret.precision_recall_curve(Y, shape[:5])


def test_label_variance_share_separates_group_means_from_noise(rng):
    label = np.repeat(np.arange(4), 50)
    by_label = label.astype(float) * 3.0                       # constant within every group
    noise = rng.normal(size=200)
    noise_centred = noise - np.array([noise[label == g].mean() for g in range(4)])[label]   # every group mean 0
    share = emb.label_variance_share(np.c_[by_label, noise_centred, by_label + noise, np.ones(200)], label)
    assert share.shape == (4,) and share.dtype == np.float64
    assert share[0] == pytest.approx(1.0) and share[1] == pytest.approx(0.0, abs=1e-12) and share[3] == 0.0
    # between-group sum of squares over the total, computed by hand
    col = by_label + noise
    means = np.array([col[label == g].mean() for g in range(4)])
    between = (50 * (means - col.mean()) ** 2).sum()
    assert share[2] == pytest.approx(between / ((col - col.mean()) ** 2).sum())
    with pytest.raises(ValueError, match="one value per row"):
        emb.label_variance_share(np.zeros((5, 2)), np.arange(4))
