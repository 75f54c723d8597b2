"""train_vae: loss goes down, runs repeat exactly, history and held-out parts, sigma_object."""

from dataclasses import replace

import numpy as np
import pytest
import torch

from meshvae_lib.model.normalization import FeatureNormalizer
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.train_config import pad_sigma_object
from meshvae_lib.model.training import holdout_mask, resolve_device, train_vae

torch.set_num_threads(1)  # tiny models: one thread is faster on the shared 2-core machine


def _data(n=48, k=60, seed=0):
    """Normalised rows that lie near a 3-D manifold (so a small latent space can explain them)."""
    rng = np.random.default_rng(seed)
    Z = rng.normal(size=(n, 3))
    X = np.tanh(Z @ rng.normal(size=(3, k)) / 2) + 0.01 * rng.normal(size=(n, k))
    return FeatureNormalizer().fit_transform(X)


def test_tiny_training_run_lowers_the_loss_and_records_history():
    X = _data()
    # the optimisation loop itself: the paper's random start, no early stopping
    res = train_vae(X[:40], config=TrainConfig(epochs=60, latent_dim=6, batch_size=8, progress=False, eval_every=20,
                                               init="random", early_stopping=False),
                    val_features=X[40:])
    h = res.history
    assert len(h) == 60 and [r["epoch"] for r in h] == list(range(1, 61))
    assert h[-1]["total"] < 0.2 * h[0]["total"]
    assert h[-1]["mse"] < 0.3 * h[0]["mse"]
    for r in h:
        assert r["total"] == pytest.approx(r["reconstruction"] + r["kl"], rel=1e-5)
    evaluated = [r["epoch"] for r in h if "val_mse" in r]
    assert evaluated == [20, 40, 60]
    assert h[-1]["val_mse"] < h[0]["mse"]
    assert not res.model.training and res.seconds > 0 and res.device == "cpu"


def test_same_seed_gives_identical_weights_other_seed_does_not():
    X = _data(n=20, k=30)
    cfg = dict(epochs=4, latent_dim=4, hidden=(8,), progress=False)
    a = train_vae(X, config=TrainConfig(seed=3, **cfg)).model.state_dict()
    b = train_vae(X, config=TrainConfig(seed=3, **cfg)).model.state_dict()
    c = train_vae(X, config=TrainConfig(seed=4, **cfg)).model.state_dict()
    assert all(torch.equal(a[k], b[k]) for k in a)
    assert not all(torch.equal(a[k], c[k]) for k in a)


def test_sigma_object_shrinks_the_spread_of_the_chosen_dimensions():
    X = _data(n=40, k=40, seed=1)
    latent = 6

    def spread(sigma_object):
        # a small alpha and a large lr let the KL term act within a few hundred steps
        res = train_vae(X, config=TrainConfig(epochs=100, batch_size=8, alpha=200.0, latent_dim=latent,
                                              sigma_object=sigma_object, lr=1e-2, progress=False, seed=0))
        with torch.no_grad():
            mu, sigma = res.model.encode(torch.from_numpy(X.astype(np.float32)))
        # std of the aggregate posterior per dimension: sqrt(var of means + mean variance)
        return np.sqrt(mu.var(0).numpy() + (sigma**2).mean(0).numpy())

    base = spread(None)
    small = spread((0.1, 0.1))  # padded with 1 to the latent size
    assert np.all(small[:2] < 0.25), small
    assert np.all(small[:2] < 0.35 * base[:2]), (small, base)
    assert np.all(small[2:] > 0.5), small


def test_sibling_prior_form_puts_the_dominant_variation_in_the_chosen_dimensions():
    """The reason the embedding and exploration models use prior_form="sibling" (Sec. 4.4).

    Decode the encoder means with only one pair of latent dimensions kept (the rest zeroed): the
    lower the error, the more of the data that pair carries. With the sibling formula dimensions
    1-2 carry the most; with the exact KL they end up unused (the KL blind to rescaling gives them
    no advantage, and their 100x width cost at the start of training switches them off).
    """
    X = _data(n=40, k=40, seed=1)
    x = torch.from_numpy(X.astype(np.float32))

    def pair_errors(form):
        res = train_vae(X, config=TrainConfig(epochs=100, batch_size=8, alpha=200.0, latent_dim=6, lr=1e-2,
                                              sigma_object=(0.1, 0.1), prior_form=form, progress=False, seed=0))
        with torch.no_grad():
            mu, sigma = res.model.encode(x)

            def keep(dims):
                z = torch.zeros_like(mu)
                z[:, dims] = mu[:, dims]
                return float(((res.model.decode(z) - x) ** 2).mean())

            return [keep([0, 1]), keep([2, 3]), keep([4, 5]), keep([])], mu.std(0).numpy(), sigma.mean(0).numpy()

    (p12, p34, p56, none), spread, width = pair_errors("sibling")
    assert p12 < 0.6 * min(p34, p56) and p12 < 0.4 * none, (p12, p34, p56, none)
    assert np.all(spread[:2] > 0.5) and np.all(width[:2] < 0.2), (spread, width)  # unit-spread means, narrow posteriors
    (p12, p34, p56, none), spread, _ = pair_errors("exact")
    assert p12 > 0.95 * none and min(p34, p56) < 0.8 * none, (p12, p34, p56, none)
    assert np.all(spread[:2] < 0.05), spread
    with pytest.raises(ValueError, match="prior_form"):
        TrainConfig(prior_form="paper")


def test_holdout_mask_and_sigma_object_padding():
    np.testing.assert_array_equal(np.flatnonzero(holdout_mask(10, 3)), [2, 5, 8])
    assert not holdout_mask(5, 0).any()
    with pytest.raises(ValueError, match="got 1"):
        holdout_mask(5, 1)
    np.testing.assert_array_equal(pad_sigma_object([0.1, 0.5], 4), [0.1, 0.5, 1.0, 1.0])
    assert pad_sigma_object(None, 4) is None
    with pytest.raises(ValueError, match="3 entries.*2"):
        pad_sigma_object([1, 1, 1], 2)
    with pytest.raises(ValueError, match="positive"):
        pad_sigma_object([0.0], 2)


def test_conditional_training_and_input_checks():
    X = _data(n=12, k=20)
    C = np.eye(2)[np.arange(12) % 2]
    res = train_vae(X, C, TrainConfig(epochs=2, latent_dim=3, progress=False), X[:4], C[:4])
    assert res.model.n_conditions == 2
    with pytest.raises(ValueError, match="val_conditions"):
        train_vae(X, C, TrainConfig(epochs=1, progress=False), X[:4])
    with pytest.raises(ValueError, match="at least 2"):
        train_vae(X[:1], config=TrainConfig(epochs=1, progress=False))
    with pytest.raises(ValueError, match="conditions has 3 rows"):
        train_vae(X, C[:3], TrainConfig(epochs=1, progress=False))
    with pytest.raises(ValueError, match="epochs"):
        TrainConfig(epochs=0)
    assert resolve_device("cpu").type == "cpu"


def test_progress_bar_is_shown_when_asked(capsys):
    X = _data(n=8, k=10)
    train_vae(X, config=TrainConfig(epochs=2, latent_dim=2, progress=True))
    assert "training mesh VAE" in capsys.readouterr().err


def test_divergence_stops_with_a_clear_error():
    X = _data(n=8, k=10)
    with pytest.raises(ValueError, match=r"diverged at epoch \d+ \(loss nan\); try a smaller learning rate"):
        train_vae(X, config=TrainConfig(epochs=3, latent_dim=2, lr=1e30, alpha=1e30, progress=False))


# --- PCA initialisation and early stopping (issue 12) ---------------------------------------------

from meshvae_lib.model.vae import MeshVAE  # noqa: E402


def _in_range(n=30, k=80, rank=5, seed=1, a=0.3):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, rank)) @ rng.normal(size=(rank, k)) + 0.01 * rng.normal(size=(n, k))
    return FeatureNormalizer(a=a).fit_transform(X)


def test_the_pca_start_is_the_pca_reconstruction():
    X = _in_range()
    x = torch.from_numpy(X.astype(np.float32))
    cfg = TrainConfig(latent_dim=40, progress=False)
    net = MeshVAE.from_pca(x, cfg).eval()
    assert net.input_rank == 29 and net.config()["input_rank"] == 29  # min(D, N - 1)
    with torch.no_grad():
        mu, sigma = net.encode(x)
        rec = net.decode(mu).double().numpy()
    # r = N - 1: every training row comes back (float32 round-off through atanh / tanh)
    np.testing.assert_allclose(rec, X, atol=2e-4)
    # whitened coefficients: unit spread over the training rows, unused dimensions exactly 0
    np.testing.assert_allclose(mu[:, :29].double().std(0, unbiased=True).numpy(), 1.0, atol=1e-3)
    assert torch.all(mu[:, 29:] == 0)
    # deviations: the linear-Gaussian posterior (1 + alpha c^2 / K)^(-1/2), 1 where unused
    np.testing.assert_allclose(sigma[:, 29:].numpy(), 1.0, atol=1e-6)
    c = np.linalg.svd(X - X.mean(0), compute_uv=False)[:29] / np.sqrt(29)
    np.testing.assert_allclose(sigma[0, :29].double().numpy(), 1 / np.sqrt(1 + cfg.alpha * c ** 2 / 80), rtol=1e-3)
    # the encoder ignores what lies outside the training rows' span
    rng = np.random.default_rng(0)
    e = rng.normal(size=80)
    e -= (X - X.mean(0)).T @ np.linalg.lstsq((X - X.mean(0)).T, e, rcond=None)[0]
    shifted = torch.from_numpy((X[:3] + 0.5 * e / np.linalg.norm(e)).astype(np.float32))
    with torch.no_grad():
        np.testing.assert_allclose(net.encode(shifted)[0].numpy(), mu[:3].numpy(), atol=3e-3)  # float32
    with pytest.raises(ValueError, match="internal layers"):
        MeshVAE.from_pca(x, TrainConfig(hidden=(8,)))
    with pytest.raises(ValueError, match="input_rank"):
        MeshVAE(10, 4, input_rank=11)


def test_pca_start_chooses_the_epochs_by_early_stopping_on_training_rows():
    X = _in_range(n=40)
    assert TrainConfig().uses_pca_init() and TrainConfig().resolved_early_stopping()  # the library's default
    paper = TrainConfig(init="random")  # the paper's training: random start, a = 0.9, all epochs
    assert not paper.uses_pca_init() and not paper.resolved_early_stopping() and paper.resolved_a() == 0.9
    cfg = TrainConfig(epochs=50, latent_dim=8, progress=False, eval_every=5, patience=20, init="pca")
    assert cfg.uses_pca_init() and cfg.resolved_early_stopping() and cfg.resolved_a() == 0.3
    res = train_vae(X, config=cfg, val_features=X[:2])
    sel = res.selection
    assert sel["validation_rows"] == [7, 15, 23, 31, 39]  # every 8th training row
    epochs = [h["epoch"] for h in sel["history"]]
    assert epochs[0] == 0 and all(e % 5 == 0 for e in epochs) and epochs[-1] <= 50
    best = min(sel["history"], key=lambda h: h["val_mse"])
    assert res.epochs == sel["epochs"] == best["epoch"]
    # stops once patience epochs bring nothing better
    assert epochs[-1] == 50 or epochs[-1] - res.epochs >= 20
    # the final network was trained on all rows for the chosen number of epochs
    assert res.model.input_rank == 8
    assert len(res.history) == max(res.epochs, 1) and res.history[-1]["epoch"] == res.epochs
    assert "val_mse" in res.history[-1]
    # same seed, same result
    again = train_vae(X, config=cfg, val_features=X[:2])
    assert again.epochs == res.epochs
    assert all(torch.equal(a, b) for a, b in zip(res.model.state_dict().values(), again.model.state_dict().values()))


def test_zero_chosen_epochs_returns_the_initialisation_with_an_epoch_0_record():
    X = _in_range(n=24)
    cfg = TrainConfig(epochs=30, latent_dim=6, progress=False, lr=1.0, eval_every=5, patience=10, init="pca")  # lr 1: ruins it
    res = train_vae(X, config=cfg)
    assert res.epochs == 0 and len(res.history) == 1 and res.history[0]["epoch"] == 0
    init = MeshVAE.from_pca(torch.from_numpy(X.astype(np.float32)), cfg)
    assert all(torch.equal(a, b) for a, b in zip(res.model.state_dict().values(), init.state_dict().values()))
    assert res.history[0]["total"] == pytest.approx(res.history[0]["reconstruction"] + res.history[0]["kl"], rel=1e-6)


def test_which_networks_get_the_pca_start_and_new_config_checks():
    assert not TrainConfig(hidden=(8,)).uses_pca_init()
    assert not TrainConfig(sigma_object=(0.1,)).uses_pca_init()
    assert not TrainConfig(init="random").uses_pca_init()
    assert not TrainConfig().uses_pca_init(n_conditions=2)
    assert TrainConfig(hidden=(8,)).resolved_a() == 0.9  # the paper's a
    assert not TrainConfig(hidden=(8,)).resolved_early_stopping()
    assert TrainConfig(a=0.5).resolved_a() == 0.5
    X = _data(n=20, k=30)
    res = train_vae(X, config=TrainConfig(epochs=3, hidden=(8,), progress=False))
    assert res.selection is None and res.epochs == 3 and res.model.input_rank == 0
    for bad in (dict(init="zeros"), dict(a=1.0), dict(validation_every=1), dict(patience=0)):
        with pytest.raises(ValueError):
            TrainConfig(**bad)
    with pytest.raises(ValueError, match="early stopping"):
        train_vae(X, config=TrainConfig(early_stopping=True, progress=False), model=MeshVAE(30, 4))


def test_bce_loss_by_hand_on_a_tiny_batch():
    """loss="bce": targets mapped from Eq. 3's [-0.9, 0.9] to [0.1, 0.9], cross-entropy summed over the
    features and averaged over the meshes, the logged MSE back in Eq. 3 units."""
    from meshvae_lib.model.training import _Loss, from_output_range, to_output_range

    cfg = TrainConfig(loss="bce", output="sigmoid", init="random", progress=False, latent_dim=2)
    x = torch.tensor([[-0.9, 0.0, 0.9], [0.9, 0.0, -0.9]])
    np.testing.assert_allclose(to_output_range(x, 0.9).numpy(), [[0.1, 0.5, 0.9], [0.9, 0.5, 0.1]], atol=1e-7)
    np.testing.assert_allclose(from_output_range(to_output_range(x, 0.9), 0.9).numpy(), x.numpy(), atol=1e-6)
    net = MeshVAE(3, 2, output="sigmoid")
    p_hat = torch.tensor([0.2, 0.5, 0.6])
    with torch.no_grad():  # mu = 0, sigma = 2 sigmoid(0) = 1 (KL 0), decoded p_hat for every mesh
        for p in net.parameters():
            p.zero_()
        net.decoder_head.bias.copy_(torch.log(p_hat / (1 - p_hat)))
    ln = np.log
    row1 = -(0.1 * ln(0.2) + 0.9 * ln(0.8)) - ln(0.5) - (0.9 * ln(0.6) + 0.1 * ln(0.4))
    row2 = -(0.9 * ln(0.2) + 0.1 * ln(0.8)) - ln(0.5) - (0.1 * ln(0.6) + 0.9 * ln(0.4))
    got = _Loss(cfg, None, cfg.resolved_a()).evaluate(net, x, None)
    assert got["val_reconstruction"] == pytest.approx((row1 + row2) / 2, rel=1e-5) == pytest.approx(2.3230, rel=1e-4)
    assert got["val_kl"] == pytest.approx(0.0, abs=1e-6)
    assert got["val_total"] == pytest.approx(got["val_reconstruction"] + got["val_kl"], rel=1e-6)
    # decoded rows back in [-0.9, 0.9]: -0.675, 0, 0.225 against the targets
    assert got["val_mse"] == pytest.approx((0.225**2 + 0.675**2 + 1.575**2 + 1.125**2) / 6, rel=1e-5)


def test_bce_training_lowers_the_loss_with_the_same_loop():
    X = _data()
    cfg = TrainConfig(epochs=60, latent_dim=6, batch_size=8, progress=False, eval_every=20, loss="bce",
                      output="sigmoid")
    assert not cfg.uses_pca_init() and not cfg.resolved_early_stopping()  # a sigmoid network starts at random
    res = train_vae(X[:40], config=cfg, val_features=X[40:])
    h = res.history
    assert len(h) == 60 and res.model.output == "sigmoid" and res.model.sigma_floor == 0.0
    # the cross-entropy cannot fall below the targets' entropy (~34 here): it falls slowly (Sec. 5.1), the MSE clearly
    assert h[-1]["reconstruction"] < h[30]["reconstruction"] < h[0]["reconstruction"] and h[-1]["total"] < h[0]["total"]
    assert h[-1]["mse"] < 0.7 * h[0]["mse"]
    for r in h:
        assert r["total"] == pytest.approx(r["reconstruction"] + r["kl"], rel=1e-5)
    assert h[-1]["val_mse"] < h[0]["mse"]
    again = train_vae(X[:40], config=cfg, val_features=X[40:])  # seeded like the MSE runs
    assert all(torch.equal(a, b) for a, b in zip(res.model.state_dict().values(), again.model.state_dict().values()))
    with torch.no_grad():
        out = res.model.decode(torch.zeros(3, 6))
    assert torch.all((out > 0) & (out < 1))


def test_network_options_come_from_the_config_and_are_checked():
    X = _data(n=20, k=30)
    res = train_vae(X, config=TrainConfig(epochs=2, progress=False, sigma_floor=1e-3, init="random"))
    assert res.model.sigma_floor == 1e-3 and res.model.output == "tanh"
    assert TrainConfig(sigma_floor=1e-3).uses_pca_init()  # the floor keeps the PCA start (tanh output)
    assert MeshVAE.from_pca(torch.from_numpy(X.astype(np.float32)), TrainConfig(sigma_floor=1e-3)).sigma_floor == 1e-3
    for bad in (dict(loss="bce"), dict(loss="huber"), dict(output="relu"), dict(output="linear"), dict(sigma_floor=-1.0)):
        with pytest.raises(ValueError):
            TrainConfig(**bad)
    with pytest.raises(ValueError, match="output"):
        train_vae(X, config=TrainConfig(epochs=1, progress=False), model=MeshVAE(30, 4, output="sigmoid"))


def test_the_default_latent_size_covers_every_direction_of_a_pca_start():
    cfg = TrainConfig()
    assert cfg.latent_dim is None
    # the paper's 128 up to 129 rows; beyond, one dimension per direction N rows span, up to 256
    assert [cfg.resolved_latent_dim(n) for n in (2, 100, 129, 130, 165, 257, 5000)] == [128, 128, 128, 129, 164, 256, 256]
    # networks without the PCA start keep the paper's 128; an explicit size always wins
    for other in (TrainConfig(init="random"), TrainConfig(hidden=(8,)), TrainConfig(sigma_object=(0.1,))):
        assert other.resolved_latent_dim(200) == 128
    assert cfg.resolved_latent_dim(200, n_conditions=1) == 128
    assert TrainConfig(latent_dim=7).resolved_latent_dim(200) == 7
    with pytest.raises(ValueError, match="latent_dim"):
        TrainConfig(latent_dim=0)
    # 150 rows spanning 149 directions: the default network reproduces every one of them, while the
    # paper's 128 leaves the 21 smallest directions out (what held back the full real collections)
    X = _in_range(n=150, k=200, rank=150)
    x = torch.from_numpy(X.astype(np.float32))
    residual = {}
    for name, c in (("auto", TrainConfig(progress=False, early_stopping=False, epochs=1)),
                    ("128", TrainConfig(progress=False, latent_dim=128))):
        net = MeshVAE.from_pca(x, c).eval()
        with torch.no_grad():
            residual[name] = float(np.abs(net.decode(net.encode(x)[0]).double().numpy() - X).max())
        assert net.latent_dim == (149 if name == "auto" else 128)
    assert residual["auto"] < 2e-4 < 0.005 < residual["128"], residual
    res = train_vae(X, config=TrainConfig(epochs=1, progress=False, early_stopping=False))
    assert res.model.latent_dim == 149 and res.model.input_rank == 149


def test_a_start_whose_span_holds_every_row_is_kept_without_the_epoch_search():
    from meshvae_lib.model.training import START_IS_OPTIMUM, start_is_optimum

    X = _in_range(n=24)
    assert start_is_optimum(TrainConfig(), 24, 0)                       # latent 128 >= 23 rows' rank
    assert start_is_optimum(TrainConfig(latent_dim=23), 24, 0) and not start_is_optimum(TrainConfig(latent_dim=22), 24, 0)
    assert not start_is_optimum(TrainConfig(early_stopping=True), 24, 0)      # asked for: the search runs
    assert not start_is_optimum(TrainConfig(hidden=(8,)), 24, 0)             # internal layers can move
    assert not start_is_optimum(TrainConfig(sigma_object=(0.5,)), 24, 0)     # a sigma_object prior
    assert not start_is_optimum(TrainConfig(), 24, 3)                       # labels
    assert not start_is_optimum(TrainConfig(init="random"), 24, 0)          # the paper's random start
    cfg = TrainConfig(epochs=30, progress=False, eval_every=5, patience=10)
    res = train_vae(X, config=cfg)
    assert res.epochs == 0 and res.selection == {"epochs": 0, "skipped": START_IS_OPTIMUM}
    assert len(res.history) == 1 and res.history[0]["epoch"] == 0
    init = MeshVAE.from_pca(torch.from_numpy(X.astype(np.float32)), replace(cfg, latent_dim=128))
    assert all(torch.equal(a, b) for a, b in zip(res.model.state_dict().values(), init.state_dict().values()))
    # the search, forced, runs and keeps the same start here (the rows are reproduced: nothing to lower)
    searched = train_vae(X, config=replace(cfg, early_stopping=True))
    assert "history" in searched.selection and searched.epochs == 0
    assert all(torch.equal(a, b) for a, b in zip(res.model.state_dict().values(), searched.model.state_dict().values()))
