"""The loss every network trains with: the KL term and the loss of Eq. 4 (paper Sec. 4.2-4.4, Eqs. 4 and 5).

It belongs to no network: the trainer applies it to whatever ``(x_hat, mu, sigma)`` a network's
``forward`` returns.

Extended model (Sec. 4.4): the prior is N(0, diag(sigma_object^2)); :func:`kl_divergence` has the
exact KL to it and the authors' sibling-code formula (``form="sibling"``).

Loss (Eq. 4), for a batch of M meshes with K features each::

    L = alpha / (2 M K) * sum_j sum_i (f^_i^j - f~_i^j)^2  +  (1/M) sum_j KL(q(z | f~^j) || p(z))

i.e. both terms are *means over the meshes of the batch*: the loss is the batch average of the
per-mesh quantity ``alpha/(2K) |f^ - f~|^2 + KL_j``, where ``KL_j`` sums over the D latent
dimensions. The mean is taken the same way for both terms, so the balance set by alpha does not
depend on the batch size.
"""

from __future__ import annotations

import torch

from meshvae_lib.defaults import DEFAULT_ALPHA, LOSSES, PRIOR_FORMS

__all__ = ["kl_divergence", "vae_loss"]


def kl_divergence(
    mu: torch.Tensor, sigma: torch.Tensor, sigma_object: torch.Tensor | None = None, form: str = "exact"
) -> torch.Tensor:
    """The latent cost of Eq. (4) with the extended prior of Sec. 4.4, summed over the dimensions.

    ``form="exact"``: KL( N(mu, diag sigma^2) || N(0, diag sigma_object^2) ), per dimension::

        1/2 [ (sigma^2 + mu^2) / sigma_object^2 - 1 - log(sigma^2 / sigma_object^2) ]

    ``form="sibling"``: the formula of the authors' sibling code, per dimension::

        1/2 [ mu^2 + (sigma / sigma_object)^2 - log((sigma / sigma_object)^2) - 1 ]

    which does not divide mu^2 by sigma_object^2. It is not a KL to a fixed prior: it makes a
    *narrow* posterior (width about sigma_object) cheap in the chosen dimensions while the means
    keep the unit spread of N(0, I). The exact form is invariant under ``z_i -> z_i / s_i`` (a
    linear decoder absorbs the rescaling), so on its own it cannot make a dimension more important;
    the sibling form can (see ``docs/applications.md``, "Embedding"). With ``sigma_object=None``
    both forms are the standard KL to N(0, I) (paper Eq. 4).

    mu, sigma : (B, D) float tensors, sigma > 0; sigma_object : (D,) positive or None;
    form : "exact" or "sibling".
    Returns (B,) latent cost per sample.
    """
    if form not in PRIOR_FORMS:
        raise ValueError(f"form must be one of {PRIOR_FORMS}, got {form!r}")
    if mu.shape != sigma.shape:
        raise ValueError(f"mu and sigma must have the same shape, got {tuple(mu.shape)} and {tuple(sigma.shape)}")
    var = sigma * sigma
    if sigma_object is None:
        return 0.5 * torch.sum(var + mu * mu - 1.0 - torch.log(var), dim=-1)
    so = torch.as_tensor(sigma_object, dtype=mu.dtype, device=mu.device)
    if so.shape != mu.shape[-1:]:
        raise ValueError(f"sigma_object must have shape ({mu.shape[-1]},), got {tuple(so.shape)}")
    var_o = so * so
    if form == "sibling":
        return 0.5 * torch.sum(mu * mu + var / var_o - 1.0 - torch.log(var / var_o), dim=-1)
    return 0.5 * torch.sum((var + mu * mu) / var_o - 1.0 - torch.log(var / var_o), dim=-1)


def vae_loss(
    x_hat: torch.Tensor,
    x: torch.Tensor,
    mu: torch.Tensor,
    sigma: torch.Tensor,
    alpha: float = DEFAULT_ALPHA,
    sigma_object: torch.Tensor | None = None,
    prior_form: str = "exact",
    loss: str = "mse",
) -> dict[str, torch.Tensor]:
    """Mesh VAE loss (Eq. 4; Eq. 5 for the conditional model, whose prior does not depend on c).

    x_hat, x : (M, K) decoder output and normalised target; mu, sigma : (M, D); sigma_object and
    prior_form : see :func:`kl_divergence`; loss : the reconstruction term, "mse" (the paper's),
    "bce" (binary cross-entropy of a sigmoid output against targets in [0, 1] -- others are clipped --,
    summed over the K components and averaged over the meshes, as DRAW; alpha is not used; Sec. 5.1)
    or "l1" (SpiralNet++'s: alpha/(MK) sum |x_hat - x|).
    Returns a dict of scalar tensors: ``reconstruction`` = alpha/(2MK) sum (x_hat - x)^2 (or
    the cross-entropy, or the L1 term), ``kl`` = (1/M) sum_j KL_j, ``total`` = their sum (the value to minimise),
    and ``mse`` = mean squared error per component (for logging; alpha-free).
    """
    if x_hat.shape != x.shape or x.ndim != 2:
        raise ValueError(f"x_hat and x must be (M, K) of the same shape, got {tuple(x_hat.shape)} and {tuple(x.shape)}")
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {LOSSES}, got {loss!r}")
    if loss == "bce":
        # targets beyond [0, 1] (held-out rows outside the training range) are clipped: BCE needs [0, 1]
        reconstruction = torch.nn.functional.binary_cross_entropy(x_hat, x.clamp(0.0, 1.0), reduction="sum") / x.shape[0]
        mse = torch.nn.functional.mse_loss(x_hat.detach(), x)
    elif loss == "l1":
        mse = torch.nn.functional.mse_loss(x_hat.detach(), x)
        reconstruction = alpha * torch.nn.functional.l1_loss(x_hat, x)
    else:
        mse = torch.nn.functional.mse_loss(x_hat, x)  # one fused kernel: mean over M and K
        reconstruction = 0.5 * alpha * mse
    kl = torch.mean(kl_divergence(mu, sigma, sigma_object, prior_form))
    return {"total": reconstruction + kl, "reconstruction": reconstruction, "kl": kl, "mse": mse.detach()}
