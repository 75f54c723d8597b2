"""The corrected decoder as a registered network (issue 47): the same decoder and codes as the
estimator, through the estimator, the checkpoint, Gauss-Newton inference and ``meshvae train``."""

from __future__ import annotations

import argparse

import numpy as np
import pytest
import torch

from test_corrected_decoder import FAST, torus_rows
from meshvae_lib.model.corrected_decoder import CorrectedLinearDecoder
from meshvae_lib.model.corrected_network import CorrectedVAE
from meshvae_lib.model.networks import network_class
from meshvae_lib.model.train_config import TrainConfig

torch.set_num_threads(1)  # small networks: one thread is faster on the shared 2-core machine


def tanh_rows(n: int, seed: int) -> np.ndarray:
    """Rows in (-1, 1) on a curved 2-D set (a flat torus through a tanh), K = 20."""
    Y = torus_rows(n, seed=seed, K=20)
    return np.tanh(0.4 * Y / np.abs(torus_rows(300, seed=0, K=20)).max())


def config(**kw) -> TrainConfig:
    return TrainConfig(architecture="corrected", latent_dim=3, seed=0, device="cpu", progress=False,
                       network_options={"correction_hidden": FAST["hidden"]}, **kw)


@pytest.fixture(scope="module")
def curved():
    """The network and the estimator fitted alike on 300 curved rows (the correction is kept)."""
    X = tanh_rows(300, seed=0)
    net = CorrectedVAE.start(torch.tensor(X, dtype=torch.float32), 0, config())
    est = CorrectedLinearDecoder(3, hidden=FAST["hidden"], output="tanh", seed=0).fit(X.astype(np.float32).astype(np.float64))
    return X, net, est


def test_the_network_is_the_estimator(curved):
    """Registered by name; decode and encode's means are the estimator's decode and codes (float32
    output), on rows it never saw; the deviations are fixed, in (0, 1]."""
    X, net, est = curved
    assert network_class("corrected") is CorrectedVAE and net.corrected and est.kept_ == "corrected"
    assert net.choice.startswith("corrected: ")
    new = tanh_rows(40, seed=1)
    mu, sigma = net.encode(torch.tensor(new, dtype=torch.float32))
    np.testing.assert_allclose(mu.numpy(), est.codes(new, through_output=False), atol=2e-5)
    Z = np.random.default_rng(0).normal(size=(16, 3))
    with torch.no_grad():
        rows = net.decode(torch.tensor(Z, dtype=torch.float32)).numpy()
    np.testing.assert_allclose(rows, est.decode(Z), atol=1e-6)
    assert sigma.shape == (40, 3) and torch.all((sigma > 0) & (sigma <= 1))
    assert net.used_latent_dims().tolist() == [0, 1, 2]


def test_the_network_reconstructs_new_rows_better_than_its_linear_decoder(curved):
    """Where the correction is kept it pays on rows that neither trained nor chose it (< 0.6x the
    squared row error of the linear decoder of the same latent size)."""
    X, net, _ = curved
    new = tanh_rows(80, seed=2)
    linear = CorrectedLinearDecoder(3, output="tanh").fit_linear(X)
    with torch.no_grad():
        rows = net.decode(net.encode(torch.tensor(new, dtype=torch.float32))[0]).double().numpy()
    err = np.mean(np.sum((rows - new) ** 2, axis=1))
    lin = np.mean(np.sum((linear.reconstruct(new) - new) ** 2, axis=1))
    assert err < 0.6 * lin, (err, lin)


def test_the_linear_decoder_kept_has_no_correction_and_is_the_pca_of_the_pre_activations():
    """On rows of rank 2 with a latent size of 3 the estimator keeps the linear decoder: the network
    has no correction module, reads 2 dimensions and reproduces every row."""
    rng = np.random.default_rng(3)
    X = np.tanh(0.3 * (rng.normal(size=(30, 2)) @ rng.normal(size=(2, 12))))
    net = CorrectedVAE.start(torch.tensor(X, dtype=torch.float32), 0, config())
    assert not net.corrected and net.correction is None and "span" in net.choice
    assert net.used_latent_dims().tolist() == [0, 1]
    with torch.no_grad():
        rows = net.decode(net.encode(torch.tensor(X, dtype=torch.float32))[0]).double().numpy()
    np.testing.assert_allclose(rows, X, atol=1e-5)


def test_a_checkpoint_rebuilds_the_same_network(curved):
    """config() and the state dict rebuild the network: the same decoded rows and codes."""
    X, net, _ = curved
    again = CorrectedVAE.from_config(net.config())
    again.load_state_dict(net.state_dict())
    again.eval()
    Z = torch.tensor(np.random.default_rng(1).normal(size=(5, 3)), dtype=torch.float32)
    torch.set_grad_enabled(False)
    assert torch.equal(again.decode(Z), net.decode(Z))
    x = torch.tensor(X[:4], dtype=torch.float32)
    assert torch.equal(again.encode(x)[0], net.encode(x)[0])
    torch.set_grad_enabled(True)


def test_the_decoder_linearisation_is_its_finite_difference(curved):
    """Gauss-Newton reads the decoder's autograd Jacobian: it matches central differences."""
    _, net, _ = curved
    z = np.array([0.3, -0.5, 0.8])
    rows, J = net.decoder_jacobian(z)
    h = 1e-2
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        with torch.no_grad():
            up, down = (net.decode(torch.tensor((z + s * e)[None], dtype=torch.float32))[0].double().numpy()
                        for s in (1, -1))
        np.testing.assert_allclose(J[:, k], (up - down) / (2 * h), atol=2e-3 * np.abs(J).max())


@pytest.mark.parametrize("kw, match", [
    (dict(init="random"), "TrainConfig.init"),
    (dict(early_stopping=False), "TrainConfig.early_stopping"),
    (dict(early_stopping=True), "TrainConfig.early_stopping"),
    (dict(sigma_object=(0.5,)), "TrainConfig.sigma_object"),
])
def test_what_the_corrected_decoder_does_not_train_is_refused(kw, match):
    with pytest.raises(ValueError, match=match):
        config(**kw)


def test_bad_options_and_conditions_are_refused_showing_the_value():
    with pytest.raises(ValueError, match=r"correction_hidden must be one or more positive integers, got \(0,\)"):
        TrainConfig(architecture="corrected", network_options={"correction_hidden": (0,)})
    with pytest.raises(ValueError, match="min_gain must lie in \\[0, 1\\), got 1.5"):
        TrainConfig(architecture="corrected", network_options={"min_gain": 1.5})
    with pytest.raises(ValueError, match="unconditional"):
        CorrectedVAE.start(torch.zeros(10, 4), 1, config())


def _args(**kw) -> argparse.Namespace:
    base = dict(decoder="auto", architecture="mesh-vae", init="pca", hidden=None, labels=[], sigma_object=None,
                no_early_stopping=False, latent=8)
    return argparse.Namespace(**{**base, **kw})


@pytest.mark.parametrize("kw, n_train, expected", [
    ({}, 20, "corrected"),                       # latent 8 below the rank 19
    ({}, 9, "mesh-vae"),                         # latent 8 = rank 8: the linear start is the optimum
    ({"latent": None}, 100, "mesh-vae"),         # no --latent: one dimension per direction
    ({"decoder": "linear"}, 100, "mesh-vae"),
    ({"decoder": "corrected"}, 5, "corrected"),
    ({"init": "random"}, 100, "mesh-vae"),       # the paper's path
    ({"hidden": [64]}, 100, "mesh-vae"),
    ({"labels": ["shape"]}, 100, "mesh-vae"),
    ({"sigma_object": [0.5]}, 100, "mesh-vae"),
    ({"no_early_stopping": True}, 100, "mesh-vae"),
    ({"architecture": "spiral"}, 100, "spiral"),
])
def test_the_command_lines_decoder_choice(kw, n_train, expected):
    from meshvae_lib.cli.train import _decoder_architecture

    assert _decoder_architecture(_args(**kw), n_train) == expected
