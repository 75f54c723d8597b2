"""The posterior deviation Eq. 4 implies for a decoder: closed form, its derivation, the column norms."""

import numpy as np
import pytest
import torch

from meshvae_lib.model.posterior import decoder_column_norms, decoder_sigma, linear_gaussian_sigma
from meshvae_lib.model.loss import vae_loss
from meshvae_lib.model.vae import MeshVAE

torch.set_num_threads(1)


def test_closed_form_hand_values():
    # c = 0: the decoder ignores the dimension, the prior's sigma 1; alpha c^2 / K = 3: sigma 1/2
    K = 12
    sigma = linear_gaussian_sigma([0.0, 6.0, 1.0], alpha=1.0, n_features=K)
    assert np.allclose(sigma, [1.0, 0.5, (1 + 1 / 12) ** -0.5], rtol=0, atol=1e-15)
    assert linear_gaussian_sigma(np.full((2, 3), 6.0), 1.0, K).shape == (2, 3)


@pytest.mark.parametrize("c, alpha, K, match", [
    ([-1.0], 1.0, 4, "non-negative"), ([np.nan], 1.0, 4, "finite"), ([1.0], 0.0, 4, "alpha.*0.0"),
    ([1.0], 1.0, 0, "n_features.*0"),
])
def test_closed_form_rejects_bad_input(c, alpha, K, match):
    with pytest.raises(ValueError, match=match):
        linear_gaussian_sigma(c, alpha, K)


def test_closed_form_minimises_the_expected_loss_in_sigma():
    # The expected per-mesh loss of a linearised decoder, as a function of one sigma_k:
    # alpha/(2K) sigma^2 c^2 + (sigma^2 - 1 - log sigma^2)/2. A fine grid finds its minimum.
    K, alpha = 1000, 1e4
    s = np.linspace(1e-4, 2.0, 400001)
    for c in (0.0, 0.05, 0.3, 2.0, 10.0):
        loss = alpha / (2 * K) * s**2 * c**2 + 0.5 * (s**2 - 1 - np.log(s**2))
        assert abs(s[np.argmin(loss)] - linear_gaussian_sigma([c], alpha, K)[0]) < 1e-4


def test_closed_form_is_the_minimiser_of_eq4_monte_carlo():
    # Eq. 4 itself (vae_loss, sampled codes) on a small tanh decoder in its near-linear range: the
    # loss averaged over many draws is lowest at the closed form's sigma among nearby scalings.
    torch.manual_seed(0)
    net = MeshVAE(n_features=200, latent_dim=3).double().eval()
    with torch.no_grad():
        net.decoder_head.weight.mul_(0.05)
        net.decoder_head.bias.zero_()
    mu = torch.tensor([[0.3, -0.2, 0.1]], dtype=torch.float64)
    x = net.decode(mu).detach()
    alpha = 2e4
    sigma_star = torch.from_numpy(decoder_sigma(net, mu.numpy(), alpha))
    eps = torch.randn(20000, 3, generator=torch.Generator().manual_seed(1), dtype=torch.float64)

    def expected_loss(scale):
        sigma = sigma_star * scale
        with torch.no_grad():
            x_hat = net.decode(mu + sigma * eps)
            return float(vae_loss(x_hat, x.expand_as(x_hat), mu.expand(len(eps), 3), sigma.expand(len(eps), 3), alpha=alpha)["total"])

    best = expected_loss(1.0)
    assert 0.2 < float(sigma_star.min()) and float(sigma_star.max()) < 0.9, "an informative regime, neither end"
    for scale in (0.8, 0.9, 1.1, 1.25):
        assert best < expected_loss(scale), scale


@pytest.mark.parametrize("hidden", [(), (16,)])
def test_column_norms_match_autograd(hidden):
    torch.manual_seed(2)
    net = MeshVAE(n_features=50, latent_dim=4, hidden=hidden).eval()
    mu = np.random.default_rng(0).normal(size=(3, 4))
    c = decoder_column_norms(net, mu)
    net64 = MeshVAE(**net.config()).double().eval()
    net64.load_state_dict(net.state_dict())
    for i, z in enumerate(mu):
        J = torch.autograd.functional.jacobian(lambda v: net64.decode(v[None])[0], torch.from_numpy(z))
        assert np.allclose(c[i], J.norm(dim=0).numpy(), rtol=1e-5, atol=1e-9)
    assert decoder_column_norms(net, mu[0]).shape == (4,)


def test_decoder_sigma_uses_eval_mode_and_restores_the_mode():
    torch.manual_seed(3)
    net = MeshVAE(n_features=30, latent_dim=3, hidden=(8,))
    net.train()
    mu = np.zeros((2, 3))
    got = decoder_sigma(net, mu, 1e3)
    assert net.training, "the caller's mode is restored"
    net.eval()
    assert np.array_equal(got, decoder_sigma(net, mu, 1e3)) and not net.training


def test_decoder_sigma_checks_its_input():
    net = MeshVAE(n_features=20, latent_dim=4)
    with pytest.raises(ValueError, match=r"\(N, 4\).*\(2, 3\)"):
        decoder_sigma(net, np.zeros((2, 3)), 1e3)
    with pytest.raises(ValueError, match="2 condition inputs"):
        decoder_sigma(MeshVAE(n_features=20, latent_dim=4, n_conditions=2), np.zeros((2, 4)), 1e3)
