"""The decoder of local parts (issue 40): regions found without labels, where feature components lie,
the regional PCA start, the network's block structure through training and checkpoints, mixing parts,
and the gain it is for: a held-out mesh that combines parts of different training meshes."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from geometry_fixtures import icosphere, strip, tube
from meshvae_lib.applications.generation import mix_parts, parts_code
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.geometry.regions import kmeans_labels, mesh_regions
from meshvae_lib.model.evaluation import evaluate_model, pca_baseline, regional_pca_baseline
from meshvae_lib.model.feature_kinds import make_kind
from meshvae_lib.model.local_parts import LocalPartsVAE
from meshvae_lib.model.meshvae_model import MeshVAEModel, load_model
from meshvae_lib.model.pca_start import pca_start, regional_pca_start
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import holdout_mask

torch.set_num_threads(1)


# -- regions --------------------------------------------------------------------------------------
def test_kmeans_finds_separated_blobs_and_numbers_clusters_by_first_point(rng):
    P = np.concatenate([rng.normal(c, 0.1, size=(30, 3)) for c in ([5, 0, 0], [0, 0, 0], [0, 5, 0])])
    labels = kmeans_labels(P, 3)
    assert labels.dtype == np.int64
    np.testing.assert_array_equal(labels, np.repeat([0, 1, 2], 30))
    np.testing.assert_array_equal(kmeans_labels(P[::-1], 3), np.repeat([0, 1, 2], 30))  # numbered by order met
    np.testing.assert_array_equal(kmeans_labels(P, 1), np.zeros(90, np.int64))
    with pytest.raises(ValueError, match="cannot make 91 clusters of 90 points"):
        kmeans_labels(P, 91)


@pytest.mark.parametrize("method", ["kmeans", "spectral"])
def test_regions_of_a_strip_are_contiguous_bands_along_it(method):
    V, F = strip(41, 5, 4.0, 0.4)
    labels = mesh_regions(V, F, 4, method)
    assert len(np.unique(labels)) == 4
    # along every line of the strip the label changes exactly three times, always upwards: four bands
    along = labels.reshape(41, 5)
    steps = np.diff(along, axis=0)
    assert np.all(steps >= 0) and np.all(np.count_nonzero(steps, axis=0) == 3)
    assert np.bincount(labels).min() >= 5 * 41 // 8  # no sliver


def test_spectral_regions_follow_the_surface_where_kmeans_follows_space():
    # a tube folded so its two ends touch: k-means puts both ends in one region, the spectral rule does not
    V, F = tube(12, 40, radius=0.2, height=4.0, capped=False)
    s = V[:, 2] / 4.0
    folded = np.stack([V[:, 0] + np.where(s > 0.5, 0.6, 0.0), V[:, 1], np.where(s > 0.5, 4.0 - V[:, 2], V[:, 2])], 1)
    ends = (s < 0.1) | (s > 0.9)
    bottom, top = s < 0.1, s > 0.9
    km, sp = mesh_regions(folded, F, 2, "kmeans"), mesh_regions(folded, F, 2, "spectral")
    assert set(km[bottom]) & set(km[top])  # the touching ends share a k-means region
    assert not set(sp[bottom]) & set(sp[top]) and ends.any()


def test_region_arguments_are_checked():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="method"):
        mesh_regions(V, F, 2, "geodesic")
    with pytest.raises(ValueError, match="cannot split a mesh of 42 vertices into 43 regions"):
        mesh_regions(V, F, 43)


# -- where features lie ----------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["rimd", "coords", "aligned"])
def test_feature_vertices_name_the_vertices_whose_motion_changes_the_feature(kind):
    """Moving one vertex changes only components that belong to it or to its neighbours (RIMD's
    rotations and scalings are per one-ring)."""
    V, F = icosphere(2)
    k = make_kind(kind, V, F)
    where = k.feature_vertices()
    assert where.shape == (k.n_features,) and where.dtype == np.int64
    assert where.min() == 0 and where.max() == len(V) - 1
    moved = V.copy()
    moved[7] += 0.05
    changed = np.abs(k.encode(moved[None])[0] - k.encode(V[None])[0]) > 1e-12
    near = {7} | set(F[np.any(F == 7, axis=1)].ravel().tolist())
    if kind == "rimd":  # a one-ring's rotation moves with the triangles around it: two rings
        near |= set(F[np.isin(F, list(near)).any(axis=1)].ravel().tolist())
    if kind != "aligned":  # aligned coordinates move everywhere (the rigid alignment is global)
        assert changed.any() and set(where[changed].tolist()) <= near


# -- the regional start ------------------------------------------------------------------------------
def test_the_regional_start_is_block_structured_and_one_region_is_the_global_start(rng):
    X = np.tanh(rng.normal(0, 0.2, size=(12, 30)))
    regions = np.repeat([0, 1, 2], 10)
    start, latent_region = regional_pca_start(X, regions, 3, 4, alpha=1e6)
    np.testing.assert_array_equal(latent_region, np.repeat([0, 1, 2], 4))
    outside = regions[None, :] != latent_region[:, None]
    assert np.all(start.basis[outside] == 0) and np.all(start.decoder_weight[outside.T] == 0)
    assert np.abs(start.basis[~outside]).max() > 0
    one, _ = regional_pca_start(X, np.zeros(30, np.int64), 1, 11, alpha=1e6)
    ref = pca_start(X, 11, alpha=1e6)
    # the same directions and fit (K = 30 in both: the deviations use the whole row's length)
    np.testing.assert_allclose(np.abs(one.basis), np.abs(ref.basis), atol=1e-9)
    np.testing.assert_allclose(one.sigma, ref.sigma, rtol=1e-12)
    np.testing.assert_allclose(one.decoder_weight @ (one.basis @ (X - X.mean(0)).T),
                               ref.decoder_weight @ (ref.basis @ (X - X.mean(0)).T), atol=1e-9)
    with pytest.raises(ValueError, match="feature_region"):
        regional_pca_start(X, np.repeat([0, 1, 5], 10), 3, 4, alpha=1e6)


# -- the network -------------------------------------------------------------------------------------
def _bend_ends(V, a, b):
    """The strip of ``strip(.., length=3)`` with its end x < 1 bent up by angle a and its end x > 2
    by angle b (arcs tangent to the flat middle)."""
    V = V.copy()
    x = V[:, 0].copy()
    for angle, zone, sign, joint in ((a, x < 1, -1.0, 1.0), (b, x > 2, 1.0, 2.0)):
        s, R = np.abs(x[zone] - joint), 1.0 / angle
        V[zone, 0] = joint + sign * R * np.sin(angle * s)
        V[zone, 2] = R * (1.0 - np.cos(angle * s))
    return V


@pytest.fixture(scope="module")
def two_ends():
    """40 strips whose two ends bend; the training meshes bend both ends alike, the held-out ones
    (every 5th, ``holdout_mask``) each end by its own angle: a new combination of parts."""
    V0, F = strip(31, 5, 3.0, 0.6)
    angles = np.random.default_rng(0).uniform(0.3, 2.5, size=(40, 2))
    held = holdout_mask(40, 5)
    angles[~held, 1] = angles[~held, 0]
    coll = MeshCollection(np.stack([_bend_ends(V0, a, b) for a, b in angles]), F)
    cfg = TrainConfig(architecture="local-parts", latent_dim=2, network_options={"n_regions": 2}, progress=False,
                      device="cpu")
    return coll, MeshVAEModel("rimd", cfg, holdout_every=5).fit(coll)


def test_a_new_combination_of_parts_is_reconstructed_where_global_models_cannot(two_ends):
    coll, model = two_ends
    V = np.asarray(coll.vertices)
    mask = model.holdout_mask_
    idx = np.flatnonzero(mask)
    local = evaluate_model(model, coll, indices=idx, inference="gauss-newton")["mean_vertex_error"]
    default = MeshVAEModel("rimd", TrainConfig(progress=False, device="cpu"), holdout_every=5).fit(coll)
    glob = evaluate_model(default, coll, indices=idx, inference="gauss-newton")["mean_vertex_error"]
    regional = regional_pca_baseline(V[~mask], V[mask], model.network.vertex_region.numpy(), 1)["mean_vertex_error"]
    floor = pca_baseline(V[~mask], V[mask], n_components=2)["mean_vertex_error"]
    # measured: local 1.8e-4; the global default (every direction of the training meshes) 3.6e-2, global
    # coordinate PCA with 2 directions 3.6e-2, coordinate PCA with the same regions and directions 1.4e-2
    assert local < 0.02 * glob and local < 0.02 * floor
    assert local < 0.1 * regional
    assert model.selection_["skipped"] == LocalPartsVAE.linear_optimum


def test_each_region_is_decoded_from_its_own_dimensions_only(two_ends):
    _, model = two_ends
    net = model.network
    assert isinstance(net, LocalPartsVAE) and net.latent_dim == 2 and net.n_regions == 2
    z = torch.zeros(2, 2)
    z[1, 0] = 1.5  # region 0's dimension
    rows = net.decode(z).detach().numpy()
    changed = np.abs(rows[1] - rows[0]) > 0
    feature_region = net.feature_region.numpy()
    assert changed.any() and np.all(feature_region[changed] == net.latent_region[0].item())
    W, _ = net.linear_decoder()
    outside = feature_region[:, None] != net.latent_region.numpy()[None, :]
    assert torch.all(W[torch.from_numpy(outside)] == 0)


def test_training_keeps_the_blocks_and_the_checkpoint_keeps_the_regions(two_ends, tmp_path):
    coll, model = two_ends
    cfg = TrainConfig(architecture="local-parts", latent_dim=2, network_options={"n_regions": 2}, epochs=5,
                      early_stopping=False, progress=False, device="cpu")
    trained = MeshVAEModel("rimd", cfg, holdout_every=5).fit(coll)
    net = trained.network
    W, _ = net.linear_decoder()
    start_W, _ = model.network.linear_decoder()
    outside = torch.from_numpy(net.feature_region.numpy()[:, None] != net.latent_region.numpy()[None, :])
    assert not torch.equal(W, start_W)  # it trained ...
    assert torch.all(W[outside] == 0)  # ... inside the blocks only
    back = load_model(trained.save(tmp_path / "local.pt"), coll)
    assert isinstance(back.network, LocalPartsVAE)
    for name in ("vertex_region", "feature_region", "latent_region"):
        assert torch.equal(getattr(back.network, name), getattr(net, name))
    z = np.array([[0.3, -0.7]])
    np.testing.assert_array_equal(back.decode_latent(z), trained.decode_latent(z))


def test_the_latent_size_must_be_a_multiple_of_the_regions(two_ends):
    coll, _ = two_ends
    with pytest.raises(ValueError, match="latent_dim 3 is not a multiple of n_regions 2"):     # when the config is made
        TrainConfig(architecture="local-parts", latent_dim=3, network_options={"n_regions": 2})
    with pytest.raises(ValueError, match="latent_dim 128 is not a multiple of n_regions 3"):   # the default latent size
        TrainConfig(architecture="local-parts", network_options={"n_regions": 3})
    with pytest.raises(ValueError, match="latent_dim 3 is not a multiple of n_regions 2"):     # and the network itself
        LocalPartsVAE(10, latent_dim=3, n_regions=2)
    with pytest.raises(ValueError, match="n_regions"):
        TrainConfig(architecture="local-parts", network_options={"regions": 2})


# -- mixing parts --------------------------------------------------------------------------------------
def test_mix_parts_takes_each_regions_dimensions_from_its_source(rng):
    codes = rng.normal(size=(6, 6))
    latent_region = np.array([0, 0, 1, 1, 2, 2])
    z, sources = mix_parts(codes, latent_region, 5, seed=3)
    assert z.shape == (5, 6) and sources.shape == (5, 3) and sources.dtype == np.int64
    for i in range(5):
        for r in range(3):
            np.testing.assert_array_equal(z[i, 2 * r: 2 * r + 2], codes[sources[i, r], 2 * r: 2 * r + 2])
    z2, s2 = mix_parts(codes, latent_region, 5, seed=3)
    np.testing.assert_array_equal(z2, z)
    with pytest.raises(ValueError, match="latent_region"):
        mix_parts(codes, latent_region[:4], 2)


def test_parts_code_takes_each_regions_dimensions_from_the_chosen_code(rng):
    codes = rng.normal(size=(6, 6))
    latent_region = np.array([1, 1, 0, 0, 2, 2])      # regions in increasing number: 0, 1, 2
    z = parts_code(codes, latent_region, [[4, 2, 5], [0, 0, 0]])
    np.testing.assert_array_equal(z[0], [codes[2, 0], codes[2, 1], codes[4, 2], codes[4, 3], codes[5, 4], codes[5, 5]])
    np.testing.assert_array_equal(z[1], codes[0])
    zm, sources = mix_parts(codes, latent_region, 5, seed=3)
    np.testing.assert_array_equal(parts_code(codes, latent_region, sources), zm)
    with pytest.raises(ValueError, match="sources must be"):
        parts_code(codes, latent_region, [[0, 1]])
    with pytest.raises(ValueError, match="sources must be"):
        parts_code(codes, latent_region, [[0.0, 1.0, 2.0]])
    with pytest.raises(ValueError, match="index the 6 codes"):
        parts_code(codes, latent_region, [[0, 1, 6]])


def test_mixed_parts_of_the_two_ends_are_new_combinations(two_ends):
    coll, model = two_ends
    V = np.asarray(coll.vertices)
    train = V[~model.holdout_mask_]
    codes = model.encode_meshes(train, inference="encoder")
    z, sources = mix_parts(codes, model.network.latent_region.numpy(), 4, seed=1)
    M = model.decode_latent(z)
    region = model.network.vertex_region.numpy()
    for m, src in zip(M, sources):  # each end is its source's end, up to a rigid motion
        for r, s in enumerate(src):
            part = region == r
            assert np.abs(rigid_align(m[part], train[s][part]) - train[s][part]).max() < 0.02
    assert len({tuple(s) for s in sources}) > 1 and any(s[0] != s[1] for s in sources)
