"""The shared argument checks: what they accept, what they return, what their errors show."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.validation import (
    check_choice, check_count, check_faces, check_finite, check_matrices, check_mesh, check_positive, check_rows,
    check_vectors, check_vertices)


def test_check_faces_converts_and_refuses():
    F = np.array([[0, 1, 2]], dtype=np.int64)
    assert check_faces(F) is F  # int64 input is not copied
    out = check_faces([[0.0, 1.0, 2.0]])
    assert out.dtype == np.int64 and out.tolist() == [[0, 1, 2]]
    with pytest.raises(ValueError, match=r"faces must have shape \(n_faces, 3\), got \(2,\)"):
        check_faces([0, 1])
    with pytest.raises(ValueError, match=r"integer vertex indices, got dtype float64"):
        check_faces([[0, 1, 2.5]])
    with pytest.raises(ValueError, match="F: negative vertex index -1"):
        check_faces([[0, 1, -1]], name="F")
    with pytest.raises(ValueError, match="vertex index 3 is out of range, there are 3 vertices"):
        check_faces([[0, 1, 3]], n_vertices=3)
    assert check_faces(np.zeros((0, 3))).shape == (0, 3)


def test_check_vertices_shapes_counts_and_finiteness():
    V = check_vertices(np.zeros((4, 3), np.float32))
    assert V.dtype == np.float64 and V.shape == (4, 3)
    assert check_vertices(np.zeros((2, 4, 3))).shape == (2, 4, 3)
    with pytest.raises(ValueError, match=r"V0 must have shape \(n_vertices, 3\), got \(2, 4, 3\)"):
        check_vertices(np.zeros((2, 4, 3)), "V0", batch=False)
    with pytest.raises(ValueError, match=r"\(n_meshes, n_vertices, 3\), got \(4, 3\)"):
        check_vertices(np.zeros((4, 3)), batch=True)
    with pytest.raises(ValueError, match=r"\(5, 3\) or \(n_meshes, 5, 3\), got \(4, 3\)"):
        check_vertices(np.zeros((4, 3)), n_vertices=5)
    with pytest.raises(ValueError, match=r"got \(\)"):
        check_vertices(1.0)
    bad = np.zeros((2, 4, 3))
    bad[1, 2, 0] = np.inf
    check_vertices(bad)  # finiteness only on request
    with pytest.raises(ValueError, match=r"V: 1 of 24 coordinates are NaN or infinite \(first at index \(1, 2, 0\)\)"):
        check_vertices(bad, "V", finite=True)


def test_check_mesh_ties_faces_to_vertices():
    V, F = check_mesh(np.zeros((3, 3)), [[0, 1, 2]])
    assert V.dtype == np.float64 and F.dtype == np.int64
    with pytest.raises(ValueError, match="there are 3 vertices"):
        check_mesh(np.zeros((3, 3)), [[0, 1, 3]])
    with pytest.raises(ValueError, match=r"vertices must have shape"):
        check_mesh(np.zeros((3, 2)), [[0, 1, 2]])


def test_matrices_vectors_rows():
    assert check_matrices(np.eye(3), "T").shape == (3, 3)
    with pytest.raises(ValueError, match=r"T must have shape \(\.\.\., 3, 3\), got \(4, 2, 3\)"):
        check_matrices(np.zeros((4, 2, 3)), "T")
    with pytest.raises(ValueError, match=r"w must have shape \(\.\.\., 3\), got \(2, 4\)"):
        check_vectors(np.zeros((2, 4)), "w")
    assert check_rows(np.zeros(6), "f", 6).shape == (6,)
    with pytest.raises(ValueError, match=r"f must have shape \(6,\) or \(n_meshes, 6\) for this layout, got \(7,\)"):
        check_rows(np.zeros(7), "f", 6, what="for this layout")
    with pytest.raises(ValueError, match=r"f must have shape \(n_meshes, k\), got \(7,\)"):
        check_rows(np.zeros(7), "f", single=False)


def test_finite_choice_count():
    x = np.array([1.0, np.nan])
    with pytest.raises(ValueError, match=r"x: 1 of 2 values are NaN or infinite \(first at index 1\)"):
        check_finite(x, "x")
    assert check_choice("paper", ("paper", "compact"), "layout") == "paper"
    with pytest.raises(ValueError, match=r"layout must be one of \('paper', 'compact'\), got 'dense'"):
        check_choice("dense", ("paper", "compact"), "layout")
    assert check_count(3.0, "n") == 3 and isinstance(check_count(3.0, "n"), int)
    for bad in (-1, 2.5, "x", None):
        with pytest.raises(ValueError, match="n must be a non-negative integer"):
            check_count(bad, "n")
    with pytest.raises(ValueError, match=r"n_steps must be an integer >= 2, got 1"):
        check_count(1, "n_steps", minimum=2)
    assert check_positive(2, "t") == 2.0 and isinstance(check_positive(2, "t"), float)
    assert check_positive(np.float32(1e-30), "t") > 0
    for bad in (0, -0.5, np.nan, np.inf, "x", None):
        with pytest.raises(ValueError, match="t must be a finite number > 0, got"):
            check_positive(bad, "t")


def test_check_is_fitted_raises_one_not_fitted_error():
    from meshvae_lib.applications.embedding import NeighborhoodPreservingEmbedding
    from meshvae_lib.model.conditions import ConditionEncoder
    from meshvae_lib.model.evaluation import CoordinatePCA
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.normalization import FeatureNormalizer
    from meshvae_lib.validation import NotFittedError, check_is_fitted

    class Thing:
        pass

    t = Thing()
    with pytest.raises(NotFittedError, match=r"this Thing is not fitted yet: call fit\(X\) first"):
        check_is_fitted(t, ("a_", "b_"), "call fit(X) first")
    t.a_ = t.b_ = 1
    check_is_fitted(t, ("a_", "b_"))
    # a ValueError and an AttributeError (as scikit-learn's): hasattr on a fitted-only property is False
    assert issubclass(NotFittedError, ValueError) and issubclass(NotFittedError, AttributeError)
    assert not hasattr(MeshVAEModel(), "latent_dim")
    calls = [lambda: MeshVAEModel().faces, lambda: FeatureNormalizer().transform(np.zeros((1, 2))),
             lambda: ConditionEncoder(["x"]).transform({"x": np.zeros(1)}),
             lambda: CoordinatePCA().transform(np.zeros((1, 3, 3))),
             lambda: NeighborhoodPreservingEmbedding().transform(np.zeros((2, 3)))]
    for call in calls:
        with pytest.raises(NotFittedError, match="is not fitted yet"):
            call()


def test_an_empty_mesh_is_refused():
    with pytest.raises(ValueError, match=r"V must have shape \(n_vertices, 3\), got \(0, 3\)"):
        check_vertices(np.zeros((0, 3)), "V", batch=False)
