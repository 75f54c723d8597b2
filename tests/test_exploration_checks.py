"""Stand-in latent spaces for checking an exploration: the whitened PCA floor, relabelled axes, a grid's spread."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.applications import exploration as ex
from meshvae_lib.applications.exploration_checks import RelabelledLatents, WhitenedPCA, grid_spread
from meshvae_lib.model.evaluation import CoordinatePCA


def _meshes(n_meshes=30, n_vertices=40, seed=0):
    """Random meshes: a base point cloud plus a few smooth, differently strong deformations."""
    rng = np.random.default_rng(seed)
    base = rng.normal(size=(n_vertices, 3))
    modes = rng.normal(size=(4, n_vertices, 3))
    w = rng.normal(size=(n_meshes, 4)) * np.array([3.0, 1.5, 0.7, 0.2])
    return base + np.einsum("mk,kvc->mvc", w, modes) + 0.01 * rng.normal(size=(n_meshes, n_vertices, 3))


def test_whitened_pca_codes_are_unit_variance_and_decode_to_the_pca_reconstruction():
    V = _meshes()
    floor = WhitenedPCA(5).fit(V)
    Z = floor.encode_meshes(V)
    assert floor.latent_dim == 5 and Z.shape == (30, 5)
    np.testing.assert_allclose(Z.std(axis=0), 1.0, rtol=1e-10)
    np.testing.assert_allclose(Z.mean(axis=0), 0.0, atol=1e-10)
    np.testing.assert_allclose(floor.decode_latent(Z), CoordinatePCA(5).fit(V).reconstruct(V), atol=1e-9)
    np.testing.assert_allclose(floor.decode_latent(np.zeros(5)), V.mean(axis=0), atol=1e-12)   # z = 0: the mean mesh
    assert np.all(np.diff(floor.scale_) <= 0), "directions come in the order of their variance"
    with pytest.raises(ValueError):
        floor.decode_latent(np.zeros(4))


def test_whitened_pca_moves_its_leading_directions_farthest_on_ordered_data():
    V = _meshes()
    move = ex.dimension_displacement(WhitenedPCA(4).fit(V), reference_vertices=V)
    assert move[0] > move[1] > move[2] > move[3] > 0


def test_relabelled_latents_decode_the_same_shapes_under_other_coordinates():
    V = _meshes()
    floor = WhitenedPCA(4).fit(V)
    order, signs = np.array([2, 0, 3, 1]), np.array([1.0, -1.0, -1.0, 1.0])
    relab = RelabelledLatents(floor, order, signs)
    z = np.array([0.5, -1.0, 2.0, 0.25])
    w = np.zeros(4)
    w[order] = signs * z
    np.testing.assert_allclose(relab.decode_latent(z), floor.decode_latent(w), atol=1e-12)
    assert relab.decode_latent(np.zeros((3, 4))).shape == (3, 40, 3)
    # the displacement over [-2, 2] is symmetric in the sign: relabelling permutes it
    np.testing.assert_allclose(ex.dimension_displacement(relab), ex.dimension_displacement(floor)[order], rtol=1e-9)
    # encoding is the inverse map: a mesh's code decodes to what the model decodes of its own code
    Z, W = relab.encode_meshes(V[:5]), floor.encode_meshes(V[:5])
    assert Z.shape == (5, 4)
    np.testing.assert_allclose(Z[:, 1], -W[:, 0], atol=1e-12)   # new axis 1 is the model's axis 0, flipped
    np.testing.assert_allclose(relab.model_latents(Z), W, atol=1e-12)
    np.testing.assert_allclose(relab.decode_latent(Z), floor.decode_latent(W), atol=1e-10)
    with pytest.raises(ValueError, match="permutation"):
        RelabelledLatents(floor, [0, 0, 1, 2])
    with pytest.raises(ValueError, match="signs"):
        RelabelledLatents(floor, signs=[1, 2, 1, 1])


def test_grid_spread_is_zero_on_a_constant_grid_and_grows_with_the_step():
    V = _meshes()
    floor = WhitenedPCA(4).fit(V)
    flat = ex.explore(floor, dims=(0, 1), n=3, value_range=(0.0, 0.0))
    assert grid_spread(flat) == pytest.approx(0.0, abs=1e-12)
    narrow = grid_spread(ex.explore(floor, dims=(0, 1), n=3, value_range=(-1, 1)), reference_vertices=V)
    wide = grid_spread(ex.explore(floor, dims=(0, 1), n=3, value_range=(-2, 2)), reference_vertices=V)
    assert 0 < narrow < wide
    assert grid_spread(ex.explore(floor, dims=(0, 1), n=3), reference_vertices=V) == pytest.approx(
        grid_spread(ex.explore(floor, dims=(0, 1), n=3)) / ex.data_spread(V))
    with pytest.raises(ValueError, match="odd"):
        grid_spread(ex.explore(floor, dims=(0, 1), n=4))
