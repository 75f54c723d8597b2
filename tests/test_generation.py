"""Generation from the (conditional) prior and the nearest-neighbour test (paper Sec. 5.2)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pytest

from meshvae_lib.applications import generation as gen


@dataclass
class _Collection:
    vertices: np.ndarray
    faces: np.ndarray
    labels: dict = field(default_factory=dict)
    names: list = field(default_factory=list)


def _tiny_collection(n=12, seed=0):
    """A bent strip of 10 vertices, n meshes, two 'shape' labels (scale) x bend angles."""
    rng = np.random.default_rng(seed)
    x = np.linspace(0, 1, 5)
    base = np.concatenate([np.column_stack([x, np.zeros(5), np.zeros(5)]),
                           np.column_stack([x, np.full(5, 0.2), np.zeros(5)])])
    F = np.array([[i, i + 1, i + 6] for i in range(4)] + [[i, i + 6, i + 5] for i in range(4)])
    V, shape = [], []
    for j in range(n):
        ang = 0.8 * j / n
        s = 1.0 if j % 2 == 0 else 1.3
        P = base * s
        P[:, 2] = np.sin(ang) * P[:, 0] ** 2
        V.append(P + 0.001 * rng.normal(size=P.shape))
        shape.append("small" if s == 1.0 else "large")
    return _Collection(np.array(V), F, {"shape": np.array(shape)}, [str(i) for i in range(n)])


def _tiny_model(coll, labels=(), seed=0):
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.train_config import TrainConfig

    cfg = TrainConfig(epochs=5, batch_size=4, latent_dim=3, seed=seed, device="cpu", progress=False)
    return MeshVAEModel(features="coords", config=cfg, labels=labels).fit(coll)


def test_prior_draws_shape_seed_and_scale():
    """MeshVAEModel.sample_latent draws N(0, diag(sigma_object^2)) with the exact prior form."""
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.train_config import TrainConfig

    cfg = TrainConfig(epochs=2, batch_size=4, latent_dim=3, seed=0, device="cpu", progress=False,
                      sigma_object=(0.1, 0.5, 1.0), prior_form="exact", init="random")
    model = MeshVAEModel(features="coords", config=cfg).fit(_tiny_collection())
    z = model.sample_latent(20000, seed=4)
    assert z.shape == (20000, 3) and z.dtype == np.float64
    np.testing.assert_allclose(z.std(axis=0), [0.1, 0.5, 1.0], rtol=0.03)
    np.testing.assert_allclose(z.mean(axis=0), 0.0, atol=0.03)
    np.testing.assert_array_equal(model.sample_latent(5, seed=1), model.sample_latent(5, seed=1))
    assert not np.array_equal(model.sample_latent(5, seed=1), model.sample_latent(5, seed=2))
    with pytest.raises(ValueError, match="n must be an integer >= 1, got 0"):
        model.sample_latent(0)


def test_a_temperature_scales_the_prior_draws_and_brings_samples_nearer_the_mean():
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.train_config import TrainConfig

    cfg = TrainConfig(epochs=2, batch_size=4, latent_dim=3, seed=0, device="cpu", progress=False,
                      sigma_object=(0.1, 0.5, 1.0), prior_form="exact", init="random")
    model = MeshVAEModel(features="coords", config=cfg).fit(_tiny_collection())
    z1 = model.sample_latent(50, seed=3)
    np.testing.assert_array_equal(model.sample_latent(50, seed=3, temperature=0.5), 0.5 * z1)
    np.testing.assert_array_equal(model.sample_latent(50, seed=3, temperature=1), z1)   # the paper's prior
    V, z, _ = model.generate(50, seed=3, temperature=0.25, return_latents=True)
    np.testing.assert_array_equal(z, 0.25 * z1)
    np.testing.assert_array_equal(V, model.decode_latent(z))
    # decoded samples move towards the mesh of the prior's mean as the temperature falls
    centre = model.decode_latent(np.zeros(3))
    spread = {t: float(np.linalg.norm(model.generate(50, seed=3, temperature=t) - centre, axis=-1).mean())
              for t in (1.0, 0.5, 0.25)}
    assert spread[0.25] < spread[0.5] < spread[1.0], spread
    for bad in (0, -1.0, float("nan"), float("inf"), "warm"):
        with pytest.raises(ValueError, match="temperature must be a finite number > 0"):
            model.sample_latent(3, temperature=bad)


def test_nearest_neighbors_against_brute_force(rng):
    Q = rng.normal(size=(37, 6))
    D = rng.normal(size=(23, 6))
    idx, dist = gen.nearest_neighbors(Q, D, chunk=5)  # several chunks, one partial
    for i in range(37):
        d = [np.sqrt(np.sum((Q[i] - D[m]) ** 2)) for m in range(23)]
        assert idx[i] == int(np.argmin(d))
        assert dist[i] == pytest.approx(min(d), rel=1e-13)
    # a query equal to a dataset row finds it at distance 0; leave-one-out does not
    idx, dist = gen.nearest_neighbors(D[[4]], D)
    assert idx[0] == 4 and dist[0] == 0.0
    idx, dist = gen.nearest_neighbors(D, D, chunk=7, exclude_self=True)
    for i in range(23):
        d = np.linalg.norm(D - D[i], axis=1)
        d[i] = np.inf
        assert idx[i] == int(np.argmin(d)) and dist[i] == pytest.approx(d.min(), rel=1e-13)
    with pytest.raises(ValueError, match=r"\(37, 6\) and \(23, 5\)"):
        gen.nearest_neighbors(Q, D[:, :5])


def test_nearest_training_meshes_shapes_determinism_and_neighbours():
    coll = _tiny_collection()
    model = _tiny_model(coll)
    a = gen.nearest_training_meshes(model, 4, coll, seed=7, feature_space="model")
    b = gen.nearest_training_meshes(model, 4, coll, seed=7, feature_space="model")
    assert a.vertices.shape == (4, 10, 3) and a.vertices.dtype == np.float64
    assert a.latents.shape == (4, 3)
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.nearest, b.nearest)
    # the neighbours are the brute-force nearest meshes in the model's feature space
    X = coll.vertices.reshape(len(coll.vertices), -1)
    for i in range(4):
        d = np.linalg.norm(X - a.vertices[i].ravel(), axis=1)
        assert a.nearest[i] == int(np.argmin(d)) and a.distance[i] == pytest.approx(d.min(), rel=1e-9)
    assert a.dataset_nn_distance.shape == (12,) and np.all(a.dataset_nn_distance > 0)
    assert a.novelty_ratio().shape == (4,)
    np.testing.assert_array_equal(a.nearest_labels["shape"], coll.labels["shape"][a.nearest])
    np.testing.assert_array_equal(a.vertices, model.generate(4, seed=7))  # the model's own generation
    assert not np.array_equal(model.generate(4, seed=8), a.vertices)
    assert "| sample |" in a.to_markdown()
    with pytest.raises(ValueError, match="unconditional"):
        gen.nearest_training_meshes(model, 2, coll, condition={"shape": "small"})
    with pytest.raises(ValueError, match="feature_space"):
        gen.nearest_training_meshes(model, 2, coll, feature_space="xyz")


@pytest.mark.parametrize("space", ["rimd", "model"])
def test_nearest_training_meshes_with_precomputed_dataset_features_matches(space):
    coll = _tiny_collection()
    model = _tiny_model(coll)
    X = gen.dataset_feature_rows(model, coll, feature_space=space)
    assert X.shape[0] == 12 and X.dtype == np.float64
    a = gen.nearest_training_meshes(model, 5, coll, seed=3, feature_space=space)
    b = gen.nearest_training_meshes(model, 5, coll, seed=3, feature_space=space, dataset_features=X)
    np.testing.assert_array_equal(a.nearest, b.nearest)
    np.testing.assert_array_equal(a.distance, b.distance)
    np.testing.assert_array_equal(a.dataset_nn_distance, b.dataset_nn_distance)
    with pytest.raises(ValueError, match=r"dataset_features must be \(12, "):
        gen.nearest_training_meshes(model, 2, coll, feature_space=space, dataset_features=X[:5])


def test_nearest_training_meshes_of_a_conditional_model_use_the_condition():
    coll = _tiny_collection()
    model = _tiny_model(coll, labels=("shape",))
    res = gen.nearest_training_meshes(model, 3, coll, seed=1, condition={"shape": "large"})
    assert res.conditions.shape == (3, model.n_conditions)
    want = model.condition_vector({"shape": "large"}, n=3)
    np.testing.assert_array_equal(res.conditions, want)
    other = gen.nearest_training_meshes(model, 3, coll, seed=1, condition={"shape": "small"})
    np.testing.assert_array_equal(res.latents, other.latents)  # same prior draws
    assert not np.allclose(res.vertices, other.vertices)  # the condition changes the decoding


def test_condition_agreement_against_a_loop_and_the_chance_level():
    coll = _tiny_collection()
    model = _tiny_model(coll, labels=("shape",))
    got = gen.condition_agreement(model, coll, "shape", n=5, seed=2)
    want = []
    for v in ("large", "small"):
        res = gen.nearest_training_meshes(model, 5, coll, seed=2, condition={"shape": v})
        want.append(np.mean(res.nearest_labels["shape"] == v))
    np.testing.assert_array_equal(got, want)
    # unconditioned, each mesh's neighbour has exactly one of the values: the shares sum to 1
    plain = gen.condition_agreement(model, coll, "shape", n=5, seed=2, conditioned=False)
    assert plain.sum() == pytest.approx(1.0, abs=1e-12)
    assert gen.condition_agreement(model, coll, "shape", values=["small"], n=5, seed=2) == pytest.approx(got[1:])
    with pytest.raises(ValueError, match="no label column"):
        gen.condition_agreement(model, coll, "motion")
