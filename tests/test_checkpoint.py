"""MeshVAEModel and its checkpoint: round trip, foreign/corrupted files, conditioning."""

import pickle

from dataclasses import replace

import numpy as np
import pytest
import torch

from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.model.checkpoint import CHECKPOINT_VERSION, _checksum
from meshvae_lib.model.inference import make_inference
from meshvae_lib.model.inference.vertex_fit import VertexFit
from meshvae_lib.model.meshvae_model import FITTED_ATTRIBUTES, MeshVAEModel, load_model
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.validation import NotFittedError

torch.set_num_threads(1)  # tiny models: one thread is faster on the shared 2-core machine


def strip_collection(n=32, seed=0, nx=10, ny=3):
    """Strips bent into an arc (label ``mode`` = "arc") or an S ("s") by an angle (``amount``)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0, 3, nx)
    F = []
    for i in range(nx - 1):
        for j in range(ny - 1):
            a = i * ny + j
            F += [[a, a + ny, a + 1], [a + ny, a + ny + 1, a + 1]]
    Vs, mode, amount = [], [], []
    for k in range(n):
        t = rng.uniform(0.5, 2.0)
        arc = k % 2 == 0
        kappa = np.full(nx, t / 3) if arc else np.where(s < 1.5, 2 * t / 3, -2 * t / 3)
        theta = np.concatenate([[0.0], np.cumsum(0.5 * (kappa[1:] + kappa[:-1]) * np.diff(s))])
        ds = np.diff(s)
        x = np.concatenate([[0.0], np.cumsum(ds * np.cos(0.5 * (theta[1:] + theta[:-1])))])
        z = np.concatenate([[0.0], np.cumsum(ds * np.sin(0.5 * (theta[1:] + theta[:-1])))])
        V = np.array([[x[i], w, z[i]] for i in range(nx) for w in np.linspace(0, 0.6, ny)])
        Vs.append(V)
        mode.append("arc" if arc else "s")
        amount.append(t)
    return MeshCollection(np.array(Vs), np.array(F), labels={"mode": np.array(mode), "amount": np.array(amount)})


@pytest.fixture(scope="module")
def collection():
    return strip_collection()


@pytest.fixture(scope="module")
def model(collection):
    cfg = TrainConfig(epochs=20, latent_dim=6, batch_size=8, progress=False, sigma_object=(0.5,))
    return MeshVAEModel("rimd", cfg, holdout_every=4).fit(collection)


def test_checkpoint_round_trip_decodes_identically(model, collection, tmp_path):
    path = model.save(tmp_path / "m.pt")
    loaded = load_model(path, collection)
    z = model.sample_latent(5, seed=2)
    np.testing.assert_array_equal(loaded.decode_latent(z), model.decode_latent(z))
    np.testing.assert_array_equal(loaded.encode_meshes(collection), model.encode_meshes(collection))
    np.testing.assert_array_equal(loaded.generate(3, seed=1), model.generate(3, seed=1))
    np.testing.assert_array_equal(loaded.holdout_mask_, model.holdout_mask_)
    np.testing.assert_array_equal(loaded.sigma_object_, [0.5] + [1.0] * 5)
    np.testing.assert_array_equal(loaded.normalizer_.min_, model.normalizer_.min_)
    assert loaded.history_ == model.history_
    assert loaded.feature_kind.name == "rimd" and loaded.network.config() == model.network.config()
    assert not [p for p in tmp_path.iterdir() if p.name != "m.pt"]  # no temporary file left behind


def test_sibling_form_round_trips_and_samples_the_unit_prior(collection, tmp_path):
    cfg = TrainConfig(epochs=3, latent_dim=4, batch_size=8, progress=False, sigma_object=(0.1, 0.1),
                      prior_form="sibling")
    m = MeshVAEModel("rimd", cfg).fit(collection)
    # the sibling formula keeps the means' unit spread: generation draws from N(0, I)
    np.testing.assert_array_equal(m.sigma_object_, np.ones(4))
    np.testing.assert_array_equal(m.sample_latent(3, seed=5), np.random.default_rng(5).standard_normal((3, 4)))
    loaded = load_model(m.save(tmp_path / "s.pt"), collection)
    assert loaded.config.prior_form == "sibling" and loaded.config.sigma_object == (0.1, 0.1)
    np.testing.assert_array_equal(loaded.sigma_object_, np.ones(4))


def test_bundle_shapes_and_reconstruction(model, collection):
    n, nv = len(collection), collection.n_vertices
    z, s = model.encode_meshes(collection.vertices, return_sigma=True)
    assert z.shape == (n, 6) and s.shape == (n, 6) and z.dtype == np.float64
    assert model.decode_latent(z).shape == (n, nv, 3)
    assert model.decode_latent(z[0]).shape == (nv, 3)
    assert model.reconstruct(collection.vertices[:2]).shape == (2, nv, 3)
    with pytest.raises(ValueError, match=r"\(n_meshes, 6\)"):
        model.decode_latent(np.zeros((2, 5)))
    assert "rimd" in repr(model)


def test_model_for_another_mesh_is_refused(model, tmp_path):
    path = model.save(tmp_path / "m.pt")
    other = strip_collection(n=4, nx=8)
    with pytest.raises(ValueError, match="30 vertices, got 24"):
        load_model(path, other)
    same_size = strip_collection(n=4)
    same_size.faces = same_size.faces[:, [0, 2, 1]]
    with pytest.raises(ValueError, match="connectivity"):
        load_model(path, same_size)


def test_corrupted_truncated_and_foreign_files_give_clear_errors(model, tmp_path):
    good = model.save(tmp_path / "m.pt").read_bytes()
    (tmp_path / "trunc.pt").write_bytes(good[: len(good) // 2])
    (tmp_path / "noise.pt").write_bytes(np.random.default_rng(0).bytes(2000))
    (tmp_path / "text.pt").write_text("hello")
    torch.save({"weights": torch.zeros(3)}, tmp_path / "other.pt")
    with open(tmp_path / "pickle.pt", "wb") as fh:
        pickle.dump(np.zeros(3), fh, protocol=2)
    (tmp_path / "zeros.pt").write_bytes(bytes(len(good)))
    for name in ("trunc.pt", "noise.pt", "text.pt", "other.pt", "pickle.pt", "zeros.pt"):
        with pytest.raises(ValueError, match="checkpoint") as info:
            load_model(tmp_path / name)
        assert "weights_only" not in str(info.value), name  # never advise unsafe loading
    with pytest.raises(ValueError, match="damaged"):
        load_model(tmp_path / "zeros.pt")
    # flip bytes inside the stored weights: the checksum catches what the zip reader does not
    payload = torch.load(tmp_path / "m.pt", weights_only=True)
    key = next(iter(payload["network_state"]))
    payload["network_state"][key] = payload["network_state"][key] + 1e-3
    torch.save(payload, tmp_path / "tampered.pt")
    with pytest.raises(ValueError, match="corrupted"):
        load_model(tmp_path / "tampered.pt")
    with pytest.raises(FileNotFoundError):
        load_model(tmp_path / "missing.pt")


def test_unfitted_model_and_missing_labels(collection):
    with pytest.raises(NotFittedError, match="MeshVAEModel is not fitted yet: call fit"):
        MeshVAEModel().decode_latent(np.zeros((1, 4)))
    with pytest.raises(ValueError, match="no label column"):
        MeshVAEModel("aligned", TrainConfig(epochs=1, progress=False), labels=["colour"]).fit(collection)


def test_conditioning_changes_what_is_generated(collection, tmp_path):
    # a small alpha and latent space make the KL term push the class information into the condition
    cfg = TrainConfig(epochs=300, latent_dim=2, batch_size=32, lr=1e-2, progress=False, alpha=100.0, seed=0)
    model = MeshVAEModel("aligned", cfg, labels=["mode"]).fit(collection)
    assert model.is_conditional and model.n_conditions == 2
    arc = model.generate(6, seed=5, condition={"mode": "arc"})
    s_shape = model.generate(6, seed=5, condition={"mode": "s"})
    V = collection.vertices
    is_arc = collection.labels["mode"] == "arc"

    def nearest_is_arc(G):
        d = np.linalg.norm((G[:, None] - V[None]).reshape(len(G), len(V), -1), axis=-1)
        return is_arc[np.argmin(d, axis=1)]

    # same latent samples, different condition: different meshes, each like its own class
    assert np.mean(np.linalg.norm(arc - s_shape, axis=-1)) > 0.1
    assert nearest_is_arc(arc).mean() >= 5 / 6
    assert nearest_is_arc(s_shape).mean() <= 1 / 6
    # conditions survive the checkpoint; bad values are refused
    loaded = load_model(model.save(tmp_path / "c.pt"), collection)
    np.testing.assert_array_equal(loaded.generate(2, seed=1, condition={"mode": "s"}),
                                  model.generate(2, seed=1, condition={"mode": "s"}))
    with pytest.raises(ValueError, match="known values"):
        model.generate(2, condition={"mode": "jump"})
    with pytest.raises(ValueError, match="unknown condition columns"):
        model.generate(2, condition={"colour": "red"})
    with pytest.raises(ValueError, match="conditional"):
        model.encode_meshes(collection.vertices)


def test_pca_started_model_round_trips_and_is_at_least_as_good_as_its_pca_start(collection, tmp_path):
    from meshvae_lib.model.evaluation import evaluate_model, pca_baseline

    model = MeshVAEModel("aligned", TrainConfig(progress=False, epochs=40, init="pca")).fit(collection)
    assert model.network.input_rank > 0 and model.normalizer_.a == 0.3 and model.normalizer_.scale == "shared"
    loaded = load_model(model.save(tmp_path / "d.pt"), collection)
    assert loaded.network.input_rank == model.network.input_rank
    np.testing.assert_array_equal(loaded.encode_meshes(collection), model.encode_meshes(collection))
    np.testing.assert_array_equal(loaded.reconstruct(collection.vertices[:3]), model.reconstruct(collection.vertices[:3]))
    # held-out: close to linear PCA on aligned coordinates (the model starts there)
    m = MeshVAEModel("aligned", TrainConfig(progress=False, epochs=40, init="pca"), holdout_every=4).fit(collection)
    mask = m.holdout_mask_
    err = evaluate_model(m, collection, held_out_only=True)["mean_vertex_error"]
    floor = pca_baseline(collection.vertices[~mask], collection.vertices[mask], aligned=True)["mean_vertex_error"]
    assert err < 1.5 * floor + 1e-3


def test_fitting_the_codes_to_the_vertices_never_raises_the_error(collection):
    from meshvae_lib.model.evaluation import evaluate_model, per_vertex_error

    model = MeshVAEModel("rimd", TrainConfig(progress=False, epochs=20, latent_dim=8), holdout_every=4).fit(collection)
    held = np.flatnonzero(model.holdout_mask_)
    V = collection.vertices[held]
    z_enc = model.encode_meshes(V, inference="encoder")
    z_fit = model.encode_meshes(V, inference=make_inference("finite-difference", iterations=2))
    assert z_fit.shape == z_enc.shape
    e_enc = per_vertex_error(model.decode_latent(z_enc), V)
    e_fit = per_vertex_error(model.decode_latent(z_fit), V)
    assert np.all(e_fit <= e_enc + 1e-12) and np.mean(e_fit) < np.mean(e_enc)
    # only the latent dimensions the decoder uses move
    used = model.network.decoder_head.weight.detach().abs().sum(0).numpy() > 0
    np.testing.assert_array_equal(model.used_latent_dims, np.flatnonzero(used))
    np.testing.assert_array_equal(z_fit[:, ~used], z_enc[:, ~used])
    res = evaluate_model(model, collection, held_out_only=True, inference=make_inference("finite-difference", iterations=2))
    assert res["fit_iterations"] == 2 and res["mean_vertex_error"] == pytest.approx(np.mean(e_fit), rel=1e-9)
    with pytest.raises(ValueError, match="iterations"):
        make_inference("finite-difference", iterations=0)
    # the same strategy given to the model by name: encode_meshes and reconstruct use it
    fitting = MeshVAEModel("rimd", TrainConfig(progress=False, epochs=20, latent_dim=8), holdout_every=4,
                           inference="finite-difference").fit(collection)
    np.testing.assert_array_equal(fitting.encode_meshes(V), fitting.encode_meshes(V, inference=VertexFit()))
    with pytest.raises(ValueError, match="inference must be one of"):
        MeshVAEModel(inference="telepathy").fit(collection)


def test_fit_leaves_its_constructor_arguments_and_exposes_the_mesh(collection):
    model = MeshVAEModel("coords", None, holdout_every=4)
    model.fit(collection)
    # defaults used, argument kept; the configuration resolved once (few meshes: the paper's 128; the PCA
    # start's a = 0.3 and the coordinates' shared half-width), and that is what the checkpoint records
    assert model.config is None
    assert model.train_config_ == replace(TrainConfig(), latent_dim=128, a=0.3, feature_scale="shared")
    assert TrainConfig().latent_dim is None and model.latent_dim == 128
    np.testing.assert_array_equal(model.reference_vertices, collection.vertices[0])
    np.testing.assert_array_equal(model.faces, collection.faces)
    for arr in (model.reference_vertices, model.faces):
        with pytest.raises(ValueError, match="read-only"):
            arr[0, 0] = 1
    with pytest.raises(NotFittedError, match="not fitted yet"):
        MeshVAEModel().faces


def test_generate_returns_the_draws_behind_its_meshes(model):
    V, z, c = model.generate(3, seed=7, return_latents=True)
    np.testing.assert_array_equal(z, model.sample_latent(3, seed=7))
    np.testing.assert_allclose(V, model.decode_latent(z), atol=0)
    assert c is None and np.array_equal(model.generate(3, seed=7), V)
    with pytest.raises(ValueError, match="unconditional"):
        model.generate(2, condition={"mode": "arc"})


def test_network_options_round_trip_through_the_checkpoint(collection, tmp_path):
    """A floored deviation and a sigmoid output (the cross-entropy model) are the network's own
    options: load_model rebuilds the same network, and a file of format 1 (without them) loads
    with the defaults."""
    cfg = TrainConfig(epochs=4, latent_dim=4, batch_size=8, progress=False, init="random", sigma_floor=1e-4,
                      output="sigmoid", loss="bce")
    model = MeshVAEModel("rimd", cfg, holdout_every=4).fit(collection)
    assert model.network.sigma_floor == 1e-4 and model.network.output == "sigmoid"
    loaded = load_model(model.save(tmp_path / "bce.pt"), collection)
    assert loaded.network.config() == model.network.config()
    assert loaded.train_config_.loss == "bce" and loaded.train_config_.output == "sigmoid"
    z = model.sample_latent(5, seed=2)
    np.testing.assert_array_equal(loaded.decode_latent(z), model.decode_latent(z))
    np.testing.assert_array_equal(loaded.encode_meshes(collection, return_sigma=True)[1],
                                  model.encode_meshes(collection, return_sigma=True)[1])
    # decoded meshes are in the data's units: the sigmoid's range is mapped back to Eq. 3's
    spread = np.abs(collection.vertices).max()
    assert np.all(np.abs(model.reconstruct(collection.vertices[:3])) < 3 * spread)
    old = _old_format(torch.load(tmp_path / "bce.pt", weights_only=True), version=1)
    for key in ("sigma_floor", "output"):
        del old["network_config"][key]
    torch.save(old, tmp_path / "v1.pt")
    v1 = load_model(tmp_path / "v1.pt")
    assert v1.network.sigma_floor == 0.0 and v1.network.output == "tanh"


def _format_3(payload: dict) -> dict:
    """A format-4 payload written back as format 3: no mesh fingerprints, and a checksum of the weights,
    the reference mesh and the faces instead of the digest of everything."""
    old = {k: v for k, v in payload.items() if k not in ("digest", "mesh_fingerprints")}
    kind = payload["kind"]
    return dict(old, version=3, checksum=_checksum(payload["network_state"], kind["reference"].numpy(),
                                                   kind["faces"].numpy()))


def _old_format(payload: dict, version: int) -> dict:
    """A format-4 payload written back in the layout of format 1 or 2 (the feature extractor's state,
    no architecture, epochs or selection, ``feature_range`` for a)."""
    old = dict(_format_3(payload), version=version)
    kind = old.pop("kind")
    old["extractor"] = {"kind": kind["kind"], "layout": kind["options"].get("layout", "paper"),
                        "reference_index": old["estimator"]["reference_index"], "reference": kind["reference"],
                        "faces": kind["faces"], "n_features": kind["n_features"]}
    for key in ("architecture", "train_epochs", "selection"):
        del old[key]
    old["train_config"] = dict(old["train_config"])
    old["train_config"]["feature_range"] = old["train_config"].pop("a")
    del old["train_config"]["architecture"]
    old["estimator"] = {k: v for k, v in old["estimator"].items() if k != "inference"}
    return old


def test_a_loaded_model_has_exactly_the_fitted_attributes_of_a_fitted_one(model, collection, tmp_path):
    assert set(FITTED_ATTRIBUTES) <= set(vars(model))
    loaded = load_model(model.save(tmp_path / "m.pt"), collection)
    # last_inference_ is the report of the latest Gauss-Newton encoding (other tests encoded with
    # this model), not something fit learns: a loaded model gets one when it encodes
    assert set(vars(loaded)) == set(vars(model)) - {"last_inference_"}
    loaded.encode_meshes(collection.vertices[:1])
    assert set(vars(loaded)) == set(vars(model)) | {"last_inference_"}
    assert loaded.train_epochs_ == model.train_epochs_ and loaded.selection_ == model.selection_
    payload = torch.load(tmp_path / "m.pt", weights_only=True)
    assert payload["version"] == CHECKPOINT_VERSION == 4 and payload["architecture"] == "mesh-vae"


def test_files_of_format_2_still_load(model, collection, tmp_path):
    old = _old_format(torch.load(model.save(tmp_path / "m.pt"), weights_only=True), version=2)
    torch.save(old, tmp_path / "v2.pt")
    v2 = load_model(tmp_path / "v2.pt", collection)
    assert set(vars(v2)) == set(vars(model)) - {"last_inference_"} and v2.selection_ is None
    assert v2.train_epochs_ == model.history_[-1]["epoch"]
    z = model.sample_latent(3, seed=4)
    np.testing.assert_array_equal(v2.decode_latent(z), model.decode_latent(z))
    np.testing.assert_array_equal(v2.encode_meshes(collection), model.encode_meshes(collection))


def test_any_edit_of_a_checkpoint_is_refused(model, collection, tmp_path):
    """The digest covers everything a checkpoint holds: the normaliser scaled by 1.5 and saved again,
    one bit flipped inside its stored bytes (which torch's zip reader does not check), an edited
    number of the configuration, a held-out mesh's digest -- each is refused, naming the file."""
    path = model.save(tmp_path / "m.pt")
    good = load_model(path)
    np.testing.assert_array_equal(good.normalizer_.max_, model.normalizer_.max_)
    edits = {
        "normaliser": lambda p: p["normalizer"].update(max=p["normalizer"]["max"] * 1.5),
        "config": lambda p: p["train_config"].update(lr=p["train_config"]["lr"] * 2),
        "held-out": lambda p: p["holdout_mask"].logical_not_(),
        "fingerprints": lambda p: p.update(mesh_fingerprints=p["mesh_fingerprints"].flip(0).clone()),
        "version": lambda p: p.update(version=3),
    }
    for name, edit in edits.items():
        payload = torch.load(path, weights_only=True)
        edit(payload)
        torch.save(payload, tmp_path / f"{name}.pt")
        with pytest.raises(ValueError, match=rf"{name}\.pt is corrupted or was edited"
                           if name != "version" else rf"{name}\.pt is an incomplete"):
            load_model(tmp_path / f"{name}.pt")
    data = bytearray(path.read_bytes())
    stored = torch.load(path, weights_only=True)["normalizer"]["max"].numpy().tobytes()
    at = bytes(data).find(stored)
    assert at > 0 and bytes(data).find(stored, at + 1) < 0  # the normaliser's bytes, stored once
    data[at + len(stored) // 2] ^= 0x10
    (tmp_path / "flipped.pt").write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"flipped\.pt is corrupted or was edited"):
        load_model(tmp_path / "flipped.pt")


def test_held_out_meshes_are_found_by_identity_in_any_order(model, collection, tmp_path):
    from meshvae_lib.model.evaluation import evaluate_model, training_split_of

    loaded = load_model(model.save(tmp_path / "m.pt"))
    held = np.flatnonzero(model.holdout_mask_)
    base = evaluate_model(loaded, collection, held_out_only=True, inference="encoder")
    assert base["indices"] == held.tolist()
    order = np.random.default_rng(3).permutation(len(collection))
    shuffled = collection.subset(order)
    res = evaluate_model(loaded, shuffled, held_out_only=True, inference="encoder")
    assert sorted(order[res["indices"]].tolist()) == held.tolist()
    assert res["mean_vertex_error"] == pytest.approx(base["mean_vertex_error"], rel=1e-12)
    train, found = training_split_of(loaded, shuffled.vertices)
    np.testing.assert_array_equal(np.sort(order[train]), np.flatnonzero(~model.holdout_mask_))
    np.testing.assert_array_equal(order[found], held)
    # the held-out meshes alone are enough; other meshes of the same connectivity are refused
    only_held = collection.subset(held[::-1])
    assert training_split_of(loaded, only_held.vertices)[0].size == 0
    other = replace(collection, vertices=collection.vertices * 1.01)
    with pytest.raises(ValueError, match=f"{held.size} of the model's {held.size} held-out meshes are not"):
        evaluate_model(loaded, other, held_out_only=True)
    plus = MeshCollection(np.concatenate([collection.vertices, other.vertices[:1]]), collection.faces)
    with pytest.raises(ValueError, match=f"1 of this collection's {len(plus)} meshes were not in the model's training"):
        training_split_of(loaded, plus.vertices)
    # a file of format 3 has no fingerprints: its held-out meshes are taken by position, as before
    torch.save(_format_3(torch.load(tmp_path / "m.pt", weights_only=True)), tmp_path / "v3.pt")
    v3 = load_model(tmp_path / "v3.pt", collection)
    assert v3.mesh_fingerprints_ is None
    assert evaluate_model(v3, collection, held_out_only=True, inference="encoder")["indices"] == held.tolist()
