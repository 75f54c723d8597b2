"""MeshVAE network, KL term (closed form and Monte-Carlo) and loss (Eq. 4)."""

import math

import numpy as np
import pytest
import torch

from meshvae_lib.model.inplace_grad import Linear, start_step
from meshvae_lib.model.loss import kl_divergence, vae_loss
from meshvae_lib.model.vae import MeshVAE

torch.set_num_threads(1)  # tiny models: one thread is faster on the shared 2-core machine


@pytest.mark.parametrize("hidden", [(), (32,), (48, 16)])
@pytest.mark.parametrize("n_cond", [0, 3])
def test_shapes_and_output_ranges(hidden, n_cond):
    torch.manual_seed(0)
    net = MeshVAE(100, latent_dim=8, hidden=hidden, n_conditions=n_cond, sigma_max=2.0)
    x = torch.rand(5, 100) * 1.8 - 0.9
    c = torch.eye(3)[torch.tensor([0, 1, 2, 0, 1])] if n_cond else None
    mu, sigma = net.encode(x, c)
    assert mu.shape == (5, 8) and sigma.shape == (5, 8)
    assert torch.all(sigma > 0) and torch.all(sigma < 2.0)
    z = net.reparameterize(mu, sigma, torch.Generator().manual_seed(1))
    out = net.decode(z, c)
    assert out.shape == (5, 100)
    assert torch.all(out.abs() < 1)
    x_hat, mu2, sigma2 = net(x, c, generator=torch.Generator().manual_seed(1))
    assert x_hat.shape == (5, 100)
    # internal layers carry batch norm and leaky ReLU; none when hidden == ()
    n_bn = sum(isinstance(m, torch.nn.BatchNorm1d) for m in net.modules())
    assert n_bn == 2 * len(hidden)
    assert MeshVAE(**net.config()).config() == net.config()


def test_bad_inputs_give_clear_errors():
    net = MeshVAE(10, latent_dim=4, n_conditions=2)
    with pytest.raises(ValueError, match=r"\(batch, 10\).*\(3, 7\)"):
        net.encode(torch.zeros(3, 7), torch.zeros(3, 2))
    with pytest.raises(ValueError, match="conditional"):
        net.encode(torch.zeros(3, 10))
    with pytest.raises(ValueError, match=r"\(3, 2\)"):
        net.decode(torch.zeros(3, 4), torch.zeros(3, 5))
    with pytest.raises(ValueError, match="unconditional"):
        MeshVAE(10, 4).encode(torch.zeros(2, 10), torch.zeros(2, 1))
    with pytest.raises(ValueError, match="latent_dim"):
        MeshVAE(10, 0)


def _closed_form_kl(mu, sigma, so):
    """KL(N(mu, s^2) || N(0, so^2)) summed over dims, from torch.distributions."""
    q = torch.distributions.Normal(mu.double(), sigma.double())
    p = torch.distributions.Normal(torch.zeros_like(mu).double(), so.double().expand_as(mu))
    return torch.distributions.kl_divergence(q, p).sum(-1)


def test_kl_matches_closed_form_standard_and_sigma_object():
    g = torch.Generator().manual_seed(3)
    mu = torch.randn(6, 5, generator=g, dtype=torch.float64)
    sigma = torch.rand(6, 5, generator=g, dtype=torch.float64) * 1.5 + 0.1
    so = torch.tensor([0.1, 0.5, 1.0, 2.0, 1.0], dtype=torch.float64)
    torch.testing.assert_close(kl_divergence(mu, sigma), _closed_form_kl(mu, sigma, torch.ones(5)), rtol=1e-12, atol=1e-12)
    torch.testing.assert_close(kl_divergence(mu, sigma, so), _closed_form_kl(mu, sigma, so), rtol=1e-12, atol=1e-12)
    # zero exactly when posterior equals prior
    assert float(kl_divergence(torch.zeros(1, 5), so[None].float(), so.float()).abs().max()) < 1e-6


def test_kl_matches_monte_carlo_estimate():
    g = torch.Generator().manual_seed(7)
    mu = torch.tensor([[0.9, -1.2, 0.2]], dtype=torch.float64)
    sigma = torch.tensor([[0.5, 0.9, 1.4]], dtype=torch.float64)
    so = torch.tensor([0.4, 1.0, 2.0], dtype=torch.float64)
    n = 400_000
    z = mu + sigma * torch.randn(n, 3, generator=g, dtype=torch.float64)
    log_q = torch.distributions.Normal(mu, sigma).log_prob(z).sum(-1)
    log_p = torch.distributions.Normal(torch.zeros(3, dtype=torch.float64), so).log_prob(z).sum(-1)
    samples = log_q - log_p
    estimate, stderr = float(samples.mean()), float(samples.std() / math.sqrt(n))
    exact = float(kl_divergence(mu, sigma, so)[0])
    assert abs(estimate - exact) < 5 * stderr, (estimate, exact, stderr)
    assert stderr < 0.02 * exact  # the check is tight enough to tell the formulas apart:
    sibling = 0.5 * float(torch.sum(mu**2 + (sigma / so) ** 2 - torch.log((sigma / so) ** 2) - 1))
    assert abs(sibling - exact) > 20 * stderr


def test_sibling_form_hand_computed_and_its_minimiser():
    mu = torch.tensor([[0.5, -2.0]], dtype=torch.float64)
    sigma = torch.tensor([[0.05, 1.0]], dtype=torch.float64)
    so = torch.tensor([0.1, 1.0], dtype=torch.float64)
    # by hand: dim 1: 1/2 [0.25 + 0.25 - ln 0.25 - 1] = 0.4431472; dim 2: 1/2 [4 + 1 - 0 - 1] = 2
    expected = 0.5 * (0.25 + 0.25 - math.log(0.25) - 1) + 2.0
    assert float(kl_divergence(mu, sigma, so, form="sibling")[0]) == pytest.approx(expected, rel=1e-12)
    # without sigma_object both forms are the standard KL
    torch.testing.assert_close(kl_divergence(mu, sigma, form="sibling"), kl_divergence(mu, sigma))
    # minimised over sigma at sigma = sigma_object, over mu at mu = 0 (unit price on the means)
    s = torch.linspace(0.02, 0.5, 481, dtype=torch.float64)[:, None]
    cost = kl_divergence(torch.zeros_like(s), s, so[:1], form="sibling")
    assert float(s[torch.argmin(cost), 0]) == pytest.approx(0.1, abs=1e-3)
    m = torch.linspace(-1, 1, 201, dtype=torch.float64)[:, None]
    cost = kl_divergence(m, torch.full_like(m, 0.1), so[:1], form="sibling")
    assert abs(float(m[torch.argmin(cost), 0])) < 1e-12
    # a mean offset costs mu^2 / 2, as in a unit-prior dimension (the exact KL charges mu^2 / (2 s^2))
    assert float(cost[-1] - cost[100]) == pytest.approx(0.5, rel=1e-12)
    with pytest.raises(ValueError, match="form must be one of"):
        kl_divergence(mu, sigma, so, form="paper")


def test_exact_form_is_invariant_under_latent_rescaling_and_sibling_is_not():
    """z_i -> z_i / s_i maps (mu, sigma) to (mu/s, sigma/s): the exact KL to N(0, diag s^2) equals the
    standard KL of the rescaled posterior, so a linear decoder can undo sigma_object; the sibling
    formula charges the means at unit price and so tells the two apart."""
    g = torch.Generator().manual_seed(11)
    mu = torch.randn(5, 4, generator=g, dtype=torch.float64)
    sigma = torch.rand(5, 4, generator=g, dtype=torch.float64) + 0.05
    so = torch.tensor([0.1, 0.1, 1.0, 1.0], dtype=torch.float64)
    exact = kl_divergence(mu * so, sigma * so, so)
    torch.testing.assert_close(exact, kl_divergence(mu, sigma), rtol=1e-12, atol=1e-12)
    sibling = kl_divergence(mu * so, sigma * so, so, form="sibling")
    assert float((sibling - kl_divergence(mu, sigma)).abs().min()) > 1e-3


def test_loss_terms_follow_equation_4():
    g = torch.Generator().manual_seed(0)
    x = torch.rand(4, 10, generator=g)
    x_hat = torch.rand(4, 10, generator=g)
    mu, sigma = torch.randn(4, 3, generator=g), torch.rand(4, 3, generator=g) + 0.5
    parts = vae_loss(x_hat, x, mu, sigma, alpha=1e6)
    expected_rec = 1e6 / (2 * 4 * 10) * float(((x_hat - x) ** 2).sum())
    assert float(parts["reconstruction"]) == pytest.approx(expected_rec, rel=1e-5)
    assert float(parts["kl"]) == pytest.approx(float(kl_divergence(mu, sigma).mean()), rel=1e-6)
    assert float(parts["total"]) == pytest.approx(float(parts["reconstruction"] + parts["kl"]), rel=1e-6)
    # batch mean: duplicating the batch leaves every term unchanged
    parts2 = vae_loss(torch.cat([x_hat, x_hat]), torch.cat([x, x]), torch.cat([mu, mu]), torch.cat([sigma, sigma]))
    for key in ("reconstruction", "kl", "total"):
        assert float(parts2[key]) == pytest.approx(float(parts[key]), rel=1e-5)


def test_in_place_linear_gives_the_same_gradients_as_nn_linear():
    torch.manual_seed(0)
    ours = Linear(7, 4)
    ref = torch.nn.Linear(7, 4)
    ref.load_state_dict(ours.state_dict())
    x = torch.randn(5, 7, requires_grad=True)
    x2 = x.detach().clone().requires_grad_(True)
    for step in range(3):  # accumulate, then start_step (overwrite), then accumulate again
        if step == 1:
            start_step(ours)
            ref.zero_grad()
        (ours(x) ** 2).sum().backward()
        (ref(x2) ** 2).sum().backward()
        torch.testing.assert_close(ours.weight.grad, ref.weight.grad)
        torch.testing.assert_close(ours.bias.grad, ref.bias.grad)
        torch.testing.assert_close(x.grad, x2.grad)


def test_kl_stays_finite_when_the_deviation_head_saturates():
    # alpha = 1e6 drives sigma to 0 and one Adam step at large K can move the logit by ~10:
    # the floor keeps log(sigma^2) finite (without it: sigmoid underflow, -inf, NaN gradients)
    net = MeshVAE(20, latent_dim=3)
    with torch.no_grad():
        net.encoder_head.bias[3:] = -1000.0
    x = torch.rand(4, 20) * 1.8 - 0.9
    x_hat, mu, sigma = net(x, generator=torch.Generator().manual_seed(0))
    assert torch.all(sigma > 0)
    parts = vae_loss(x_hat, x, mu, sigma)
    assert torch.isfinite(parts["total"])
    parts["total"].backward()
    assert all(torch.isfinite(p.grad).all() for p in net.parameters() if p.grad is not None)


def test_sigma_floor_and_sigmoid_output_are_options_of_the_network():
    torch.manual_seed(0)
    plain = MeshVAE(12, 3, hidden=(5,))
    torch.manual_seed(0)
    other = MeshVAE(12, 3, hidden=(5,), sigma_floor=1e-3, output="sigmoid")
    # no new parameters and the same creation order: the same seed gives the same weights
    assert list(plain.state_dict()) == list(other.state_dict())
    assert all(torch.equal(a, b) for a, b in zip(plain.state_dict().values(), other.state_dict().values()))
    assert plain.config()["sigma_floor"] == 0.0 and plain.config()["output"] == "tanh"
    assert MeshVAE(**other.config()).config() == other.config()
    plain.eval(), other.eval()
    x = torch.rand(4, 12) * 1.8 - 0.9
    (mu_a, s_a), (mu_b, s_b) = plain.encode(x), other.encode(x)
    assert torch.equal(mu_a, mu_b) and torch.equal(s_b, s_a + 1e-3)
    _, s_sat = other.encode(torch.full((2, 12), -1e4))
    assert torch.all(s_sat >= 1e-3)
    z = torch.randn(4, 3)
    h = plain.decoder_body(z)
    assert torch.equal(plain.decode(z), torch.tanh(plain.decoder_head(h)))
    assert torch.equal(other.decode(z), torch.sigmoid(other.decoder_head(h)))
    for bad in (dict(output="relu"), dict(sigma_floor=-1.0), dict(sigma_floor=float("nan"))):
        with pytest.raises(ValueError):
            MeshVAE(12, 3, **bad)
    with pytest.raises(ValueError, match="loss"):
        vae_loss(x, x, mu_a, s_a, loss="huber")
    # the spiral network's L1 term, by hand: alpha / (M K) sum |x_hat - x|, the MSE logged beside it
    x_hat = x + torch.arange(48, dtype=torch.float32).reshape(4, 12) / 100
    parts = vae_loss(x_hat, x, mu_a, s_a, alpha=10.0, loss="l1")
    assert float(parts["reconstruction"]) == pytest.approx(10.0 * np.arange(48).mean() / 100, rel=1e-6)
    assert float(parts["mse"]) == pytest.approx(np.mean((np.arange(48) / 100) ** 2), rel=1e-5)
