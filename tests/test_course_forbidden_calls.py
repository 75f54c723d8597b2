"""forbidden_calls: every path to a forbidden function or class raises inside the block, nothing after it."""

import numpy as np
import pytest

from meshvae_lib.course import LIBRARY_PCA, column_reconstructions, forbidden_calls
from meshvae_lib.model import evaluation
from meshvae_lib.model.evaluation import pca_baseline


def _meshes(n=6, v=5, seed=0):
    return np.random.default_rng(seed).normal(size=(n, v, 3))


def test_every_alias_of_a_function_raises_and_is_restored():
    V = _meshes()
    before = pca_baseline(V[:4], V[4:], n_components=2)["per_mesh"]
    namespace = {"pca_baseline": pca_baseline, "floor_fn": evaluation.pca_baseline, "other": np.mean}
    with forbidden_calls(["meshvae_lib.model.evaluation.pca_baseline"], "no PCA", namespace) as blocked:
        assert set(blocked) == {"pca_baseline", "floor_fn"}
        with pytest.raises(AssertionError, match="no PCA"):
            evaluation.pca_baseline(V[:4], V[4:])
        from meshvae_lib.model import pca_baseline as again   # the package's lazy export, imported anew
        with pytest.raises(AssertionError, match="no PCA"):
            again(V[:4], V[4:])
        with pytest.raises(AssertionError, match="no PCA"):
            blocked["floor_fn"](V[:4], V[4:])
    assert evaluation.pca_baseline is pca_baseline
    assert pca_baseline(V[:4], V[4:], n_components=2)["per_mesh"] == before


def test_a_class_raises_through_a_helper_that_imported_it():
    V = _meshes()
    expected = column_reconstructions(V[5], V[:5], 2)
    with forbidden_calls(LIBRARY_PCA, "no PCA"):
        with pytest.raises(AssertionError, match="no PCA"):
            column_reconstructions(V[5], V[:5], 2)   # table_row's own CoordinatePCA
        with pytest.raises(AssertionError, match="no PCA"):
            evaluation.regional_pca_baseline(V[:5], V[5:], np.zeros(5, int), 2)
        with pytest.raises(AssertionError, match="no PCA"):
            from sklearn.decomposition import PCA
            PCA(2).fit(V[:5].reshape(5, -1))
        from sklearn.decomposition import IncrementalPCA, KernelPCA, TruncatedSVD
        from sklearn.utils.extmath import randomized_svd
        X = V[:5].reshape(5, -1)
        for make in (lambda: IncrementalPCA(2).fit(X), lambda: TruncatedSVD(2).fit(X - X.mean(axis=0)),
                     lambda: KernelPCA(2).fit(X), lambda: randomized_svd(X, 2)):
            with pytest.raises(AssertionError, match="no PCA"):   # every scikit-learn route to principal directions
                make()
        np.linalg.svd(V[0])   # numpy itself stays allowed
    after = column_reconstructions(V[5], V[:5], 2)
    assert all(np.array_equal(after[k], expected[k]) for k in expected)


def test_a_path_that_cannot_be_imported_is_skipped():
    with forbidden_calls(["no_such_package.thing", "meshvae_lib.model.evaluation.no_such_name"], "x", {"a": 1}) as b:
        assert b == {}
