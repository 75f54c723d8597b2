"""The corrected decoder (issue 47): the linear decoder plus a correction that is zero at the start,
kept only where it helps on validation rows that neither trained nor stopped it."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.model.corrected_decoder import CorrectedLinearDecoder
from meshvae_lib.model.gram_pca import principal_directions


def torus_rows(n: int, seed: int, K: int = 40) -> np.ndarray:
    """Rows on a curved 2-D set (a flat torus) embedded in K dimensions: 2 degrees of freedom that
    need 8 principal directions; the embedding is the same for every seed."""
    t = np.random.default_rng(seed).uniform(0.0, 2 * np.pi, size=(n, 2))
    F = np.stack([np.cos(t[:, 0]), np.sin(t[:, 0]), np.cos(2 * t[:, 0]), np.sin(2 * t[:, 0]),
                  np.cos(t[:, 1]), np.sin(t[:, 1]), 0.5 * np.cos(2 * t[:, 1]), 0.5 * np.sin(2 * t[:, 1])], axis=1)
    return F @ np.random.default_rng(1234).normal(size=(8, K))


#: a smaller, shorter training than the defaults (the tests' curved sets are small)
FAST = dict(hidden=(64, 64), max_steps=1500)


def projection(Y_train, Y, D):
    mean, basis, _ = principal_directions(Y_train, D)
    return mean + ((Y - mean) @ basis.T) @ basis


def test_principal_directions_match_numpy_svd():
    Y = np.random.default_rng(0).normal(size=(30, 12)) @ np.diag(np.arange(12, 0, -1.0))
    mean, basis, scale = principal_directions(Y, 5)
    _, s, Vt = np.linalg.svd(Y - Y.mean(0), full_matrices=False)
    np.testing.assert_allclose(mean, Y.mean(0), atol=1e-12)
    np.testing.assert_allclose(np.abs(basis @ Vt[:5].T), np.eye(5), atol=1e-9)
    np.testing.assert_allclose(scale, s[:5] / np.sqrt(29), rtol=1e-10)
    np.testing.assert_allclose(basis @ basis.T, np.eye(5), atol=1e-10)


def test_linear_rows_of_rank_at_most_latent_are_reproduced_exactly_by_the_linear_decoder():
    rng = np.random.default_rng(1)
    Y = rng.normal(size=(40, 3)) @ rng.normal(size=(3, 20)) + rng.normal(size=20)
    m = CorrectedLinearDecoder(4, max_steps=50).fit(Y)
    assert m.kept_ == "linear" and m.correction_ is None
    assert "span" in m.report_.reason
    new = rng.normal(size=(5, 3)) @ (Y[:3] - Y.mean(0))  # in the span of the centred rows
    new = new / 10 + Y.mean(0)
    np.testing.assert_allclose(m.reconstruct(new), new, atol=1e-9)
    np.testing.assert_allclose(m.reconstruct(Y), Y, atol=1e-9)


def test_the_correction_pays_on_a_curved_set_and_never_on_noise():
    Y, Y_new = torus_rows(300, seed=0), torus_rows(100, seed=1)
    m = CorrectedLinearDecoder(4, seed=0, **FAST).fit(Y)
    assert m.kept_ == "corrected", m.report_.reason
    err = np.mean(np.sum((m.reconstruct(Y_new) - Y_new) ** 2, axis=1))
    lin = np.mean(np.sum((projection(Y, Y_new, 4) - Y_new) ** 2, axis=1))
    assert err < 0.5 * lin, (err, lin)
    r = m.report_
    assert r.corrected_score < r.linear_score and r.gain_lower_bound > 0.02 * r.linear_score
    assert len(r.linear_errors) == len(r.corrected_errors) == r.n_validation // 2
    # isotropic noise has no curved set to find: the linear decoder comes back, refitted on all rows
    noise = np.random.default_rng(2).normal(size=(120, 30))
    n = CorrectedLinearDecoder(4, seed=0, hidden=(64, 64), max_steps=600).fit(noise)
    assert n.kept_ == "linear", n.report_.reason
    test = np.random.default_rng(3).normal(size=(10, 30))
    np.testing.assert_allclose(n.reconstruct(test), projection(noise, test, 4), atol=1e-9)


def test_the_correction_starts_at_zero_so_training_starts_at_the_linear_optimum():
    """The correction network's last layer starts at zero: before any step, the corrected decoder
    decodes every code exactly as the linear one does."""
    import torch

    m = CorrectedLinearDecoder(4, seed=0)
    net = m._network(4, 8)
    z = torch.randn(7, 4, dtype=torch.float64, generator=torch.Generator().manual_seed(0))
    s = torch.linspace(1.0, 0.5, 4, dtype=torch.float64)
    corrected, linear = m._decode_coeff(net, z, s, 8).detach().numpy(), m._decode_coeff(None, z, s, 8).numpy()
    np.testing.assert_array_equal(corrected, linear)
    assert np.abs(linear).max() > 0.1  # not trivially zero


def test_fitting_leaves_the_callers_random_state_alone():
    import torch

    torch.manual_seed(123)
    expected = torch.rand(3)
    torch.manual_seed(123)
    CorrectedLinearDecoder(3, seed=9, hidden=(16,), max_steps=60, check_every=20).fit(torus_rows(60, seed=0))
    np.testing.assert_array_equal(torch.rand(3).numpy(), expected.numpy())


def test_a_few_lucky_validation_rows_do_not_choose_the_correction():
    """With 40 rows of a curved set the correction may look better on the rows that stopped it
    (it picks its best step there); the choice is made on the others, with a margin of standard
    errors: at 40 rows it must keep the linear decoder unless it wins clearly on those."""
    Y, Y_new = torus_rows(40, seed=5), torus_rows(200, seed=6)
    m = CorrectedLinearDecoder(4, seed=0, **FAST).fit(Y)
    err = np.mean(np.sum((m.reconstruct(Y_new) - Y_new) ** 2, axis=1))
    lin = np.mean(np.sum((projection(Y, Y_new, 4) - Y_new) ** 2, axis=1))
    assert err <= 1.02 * lin, (m.report_.reason, err, lin)


def test_tanh_output_fits_codes_through_the_tanh():
    Y = torus_rows(300, seed=0, K=20)
    X = np.tanh(0.4 * Y / np.abs(Y).max())
    m = CorrectedLinearDecoder(8, output="tanh").fit_linear(X)
    # 8 directions span the pre-activations exactly: the rows come back through the tanh
    np.testing.assert_allclose(m.reconstruct(X[:10]), X[:10], atol=1e-6)
    assert np.all(np.abs(m.decode(np.zeros((1, 8)))) < 1)
    # with fewer directions the fit through the tanh is at least as good as the clipped projection's
    few = CorrectedLinearDecoder(3, output="tanh").fit_linear(X)
    mean, basis, _ = principal_directions(np.arctanh(X), 3)
    proj = np.tanh(mean + ((np.arctanh(X) - mean) @ basis.T) @ basis)
    assert np.sum((few.reconstruct(X) - X) ** 2) <= np.sum((proj - X) ** 2) * (1 + 1e-9)


def test_deterministic_for_a_seed():
    Y = torus_rows(150, seed=0)
    a = CorrectedLinearDecoder(3, seed=4, max_steps=200).fit(Y)
    b = CorrectedLinearDecoder(3, seed=4, max_steps=200).fit(Y)
    np.testing.assert_array_equal(a.codes(Y[:5]), b.codes(Y[:5]))
    assert a.report_.curve == b.report_.curve


def test_the_score_chooses():
    """The same fit that keeps the correction on the squared error (the curved-set test) keeps the
    linear decoder when the score calls better reconstructions worse: the choice follows ``score``,
    measured on the 30 choosing rows only, for both decoders."""
    Y = torus_rows(300, seed=0)
    seen = []

    def inverted(rows, idx):
        seen.append(np.array(idx))
        return 1.0 / (1e-3 + np.sum((rows - Y[idx]) ** 2, axis=1))

    m = CorrectedLinearDecoder(4, seed=0, **FAST).fit(Y, score=inverted)
    assert m.kept_ == "linear", m.report_.reason
    assert m.report_.corrected_score > m.report_.linear_score  # inverted: the correction reconstructs better
    assert len(seen) == 2 and len(seen[0]) == 30
    np.testing.assert_array_equal(seen[0], seen[1])
    np.testing.assert_array_equal(seen[0], np.arange(300)[2::5][1::2])  # every 5th from the 2nd, alternate ones
    with pytest.raises(ValueError, match=r"score must return \(30,\) finite errors, got shape \(1,\)"):
        CorrectedLinearDecoder(4, seed=0, hidden=(16,), max_steps=100).fit(Y, score=lambda rows, idx: np.ones(1))


def test_tanh_codes_do_not_depend_on_the_rows_beside_them_and_the_correction_pays_through_the_tanh():
    """A tanh output (normalised RIMD rows): each row's code is the same fitted alone or in a batch
    (within 2e-6: the fit's unit is the training rows' spread, and it runs to convergence), with the
    linear and with the corrected decoder; on a curved set the correction is kept and reconstructs
    new rows better than the linear decoder through the tanh."""
    Y, Y_new = torus_rows(300, seed=0, K=20), torus_rows(60, seed=1, K=20)
    scale = np.abs(Y).max()
    X, X_new = np.tanh(0.4 * Y / scale), np.tanh(0.4 * Y_new / scale)
    linear = CorrectedLinearDecoder(3, output="tanh").fit_linear(X)
    corrected = CorrectedLinearDecoder(3, output="tanh", seed=0, **FAST).fit(X)
    assert corrected.kept_ == "corrected", corrected.report_.reason
    for m in (linear, corrected):
        batch = m.codes(X_new[:8])
        alone = np.concatenate([m.codes(X_new[i:i + 1]) for i in range(8)])
        np.testing.assert_allclose(alone, batch, atol=2e-6)
    err = np.mean(np.sum((corrected.reconstruct(X_new) - X_new) ** 2, axis=1))
    lin = np.mean(np.sum((linear.reconstruct(X_new) - X_new) ** 2, axis=1))
    assert err < 0.5 * lin, (err, lin)
    with pytest.raises(ValueError, match="training rows of a tanh output must lie in \\[-1, 1\\], got a value of 1.5"):
        CorrectedLinearDecoder(3, output="tanh").fit_linear(np.vstack([X[:10], np.full((1, 20), 1.5)]))
    beyond = np.clip(1.2 * X_new[:4], -1.3, 1.3)  # held-out rows may lie beyond the training range
    assert np.isfinite(corrected.codes(beyond)).all() and np.isfinite(linear.reconstruct(beyond)).all()


@pytest.mark.parametrize("kwargs, match", [
    (dict(latent_dim=0), "latent_dim must be a positive integer, got 0"),
    (dict(latent_dim=2, hidden=(0,)), r"hidden must be positive integers, got \(0,\)"),
    (dict(latent_dim=2, min_gain=1.0), "min_gain must lie in"),
    (dict(latent_dim=2, validation_every=1), "validation_every must be an integer >= 2, got 1"),
    (dict(latent_dim=2, output="sigmoid"), "output must be 'linear' or 'tanh', got 'sigmoid'"),
    (dict(latent_dim=2, lr=0.0), "lr must be positive, got 0.0"),
    (dict(latent_dim=2, confidence=2.0), r"confidence must lie in \[0.5, 1\), got 2.0"),
])
def test_bad_parameters_are_refused_showing_the_value(kwargs, match):
    with pytest.raises(ValueError, match=match):
        CorrectedLinearDecoder(**kwargs).fit(torus_rows(30, seed=0))


def test_bad_rows_are_refused_showing_the_value():
    with pytest.raises(ValueError, match=r"at least latent_dim \+ 2 = 6 training rows, got 5"):
        CorrectedLinearDecoder(4).fit(torus_rows(5, seed=0))
    with pytest.raises(ValueError, match="non-finite"):
        CorrectedLinearDecoder(2).fit(np.full((10, 3), np.nan))
    m = CorrectedLinearDecoder(2).fit_linear(torus_rows(20, seed=0))
    with pytest.raises(ValueError, match="rows must have 40 components, got 3"):
        m.codes(np.zeros((2, 3)))
    with pytest.raises(ValueError, match="codes must have 2 components, got 3"):
        m.decode(np.zeros((2, 3)))


def test_gain_lower_bound_is_the_t_bound():
    from scipy.stats import t

    from meshvae_lib.model.correction_choice import gain_lower_bound

    g = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    # mean 3, std sqrt(2.5), t_0.975(4) = 2.776
    assert gain_lower_bound(g, 0.975) == pytest.approx(3.0 - t.ppf(0.975, 4) * np.sqrt(2.5) / np.sqrt(5), rel=1e-12)
    assert gain_lower_bound(g, 0.975) == pytest.approx(1.0367, abs=1e-4)
    assert gain_lower_bound(np.full(4, 0.5), 0.99) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="need at least 2 gains for a bound, got 1"):
        gain_lower_bound([1.0], 0.9)
