"""The latent cost of one dimension under the σ_object prior, exact KL against the sibling formula
(notebook 07, Sec. 4.4).

:func:`prior_cost_figure` draws two panels, each computed with
:func:`meshvae_lib.model.loss.kl_divergence` for a single latent dimension:

- left, the price of moving a posterior mean ``mu`` (its width at its cheapest, ``sigma = s``):
  the exact KL with ``s`` small is a parabola ``1/s^2`` times steeper than the sibling formula's,
  which is the standard ``mu^2 / 2`` of N(0, 1) whatever ``s``;
- right, the price of a posterior width ``sigma`` (``mu = 0``), the same in both forms: zero at
  ``sigma = s``, so a dimension with a small ``s`` lets the encoder be precise for free, while a
  dimension with ``s = 1`` charges for it.
"""

from __future__ import annotations

import numpy as np

__all__ = ["prior_cost_figure", "one_dimension_cost"]


def one_dimension_cost(mu, sigma, s: float, form: str = "exact") -> np.ndarray:
    """The latent cost of a single dimension, ``kl_divergence`` evaluated elementwise.

    mu, sigma : arrays of one shape (sigma > 0); s : that dimension's σ_object; form : "exact" or
    "sibling". Returns float64 of the broadcast shape.
    """
    import torch

    from meshvae_lib.model.loss import kl_divergence

    mu, sigma = np.broadcast_arrays(np.asarray(mu, dtype=np.float64), np.asarray(sigma, dtype=np.float64))
    cost = kl_divergence(torch.from_numpy(mu.reshape(-1, 1).copy()), torch.from_numpy(sigma.reshape(-1, 1).copy()),
                         torch.tensor([float(s)], dtype=torch.float64), form=form)
    return cost.numpy().reshape(mu.shape)


def prior_cost_figure(s_small: float = 0.1, mu_max: float = 2.0, cost_max: float = 4.0, figsize=(10.0, 3.6),
                      fontsize: float = 10.0):
    """Two panels: the cost of a mean (exact vs sibling, ``s = s_small``) and of a width
    (``s = s_small`` vs ``s = 1``).

    Parameters
    ----------
    s_small : float in (0, 1), the chosen dimensions' σ_object
    mu_max : float, the left panel's x range is ``[-mu_max, mu_max]``
    cost_max : float, the y limit of the left panel (the exact curve leaves it early)

    Returns
    -------
    matplotlib.figure.Figure
        Two axes titled "cost of a mean (σ = s)" and "cost of a width (μ = 0), both forms"; the left one has
        the lines "exact KL, s = …" and "sibling formula, s = …", the right one "s = …" and "s = 1".
    """
    import matplotlib.pyplot as plt

    if not 0 < s_small < 1:
        raise ValueError(f"s_small must lie in (0, 1), got {s_small}")
    mu = np.linspace(-mu_max, mu_max, 401)
    sigma = np.geomspace(s_small / 5, 3.0, 400)
    fig, (left, right) = plt.subplots(1, 2, figsize=figsize)
    left.plot(mu, one_dimension_cost(mu, s_small, s_small, "exact"), color="C3", lw=2.2, label=f"exact KL, s = {s_small:g}")
    left.plot(mu, one_dimension_cost(mu, s_small, s_small, "sibling"), color="C0", lw=2.2,
              label=f"sibling formula, s = {s_small:g}\n(= the standard N(0, 1) cost)")
    left.set_ylim(0, cost_max)
    left.set_xlabel("posterior mean μ", fontsize=fontsize)
    left.set_ylabel("latent cost of the dimension", fontsize=fontsize)
    left.set_title("cost of a mean (σ = s)", fontsize=fontsize + 1)
    for s, color in ((s_small, "C3"), (1.0, "C7")):
        right.plot(sigma, one_dimension_cost(0.0, sigma, s, "sibling"), color=color, lw=2.2, label=f"s = {s:g}")
        right.axvline(s, color=color, ls=":", lw=1)
    right.set_xscale("log")
    right.set_ylim(0, cost_max)
    right.set_xlabel("posterior width σ (log scale)", fontsize=fontsize)
    right.set_title("cost of a width (μ = 0), both forms", fontsize=fontsize + 1)
    ticks = [t for t in (0.03, 0.1, 0.3, 1.0, 3.0) if sigma[0] <= t <= sigma[-1]]
    right.set_xticks(ticks, [f"{t:g}" for t in ticks])
    left.legend(fontsize=fontsize - 1, loc="upper right")
    right.legend(fontsize=fontsize - 1, loc="upper center")
    for ax in (left, right):
        ax.tick_params(labelsize=fontsize - 1)
    fig.tight_layout()
    return fig
