"""The posterior deviation that Eq. 4 implies for a given decoder (the closed form behind notebook
04's α sweep and the PCA start's σ).

Linearise the decoder at the code's mean, ``f(μ + σ⊙ε) ≈ f(μ) + J (σ⊙ε)`` with ``J = ∂f/∂z``
(K, D). The expected loss of one mesh (Eq. 4 with a sampled code) becomes

    α/(2K) (|f(μ) − x|² + Σ_k σ_k² c_k²) + ½ Σ_k (σ_k² + μ_k² − 1 − log σ_k²),   c_k = |J[:, k]|,

and setting its derivative in σ_k to zero, ``α c_k² σ_k / K + σ_k − 1/σ_k = 0``, gives

    σ_k = (1 + α c_k² / K)^(−1/2).

A dimension the decoder reads strongly (large c_k) or a large α gives a narrow posterior; one the
decoder ignores (c_k = 0) keeps the prior's σ = 1. It is the posterior deviation of the
linear-Gaussian model with noise variance K/α per feature, which is how
:func:`~meshvae_lib.model.pca_start.pca_start` sets σ (there c_k is the coefficient spread). For a
trained network it is the optimum the encoder's σ head is pulled towards; the encoder's σ
reaches it only as far as training converged and a linear map of the features can express it.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.validation import check_count

__all__ = ["linear_gaussian_sigma", "decoder_column_norms", "decoder_sigma"]


def linear_gaussian_sigma(c, alpha: float, n_features: int) -> np.ndarray:
    """σ_k = (1 + α c_k² / K)^(−1/2), the stationary point of Eq. 4 in σ (module docstring).

    Parameters
    ----------
    c : (..., D) float
        Decoder column norms |∂f/∂z_k| (non-negative).
    alpha : float > 0
        Eq. 4's weight of the reconstruction term.
    n_features : int > 0
        K, the number of features the reconstruction term averages over.

    Returns
    -------
    sigma : (..., D) float64 in (0, 1]
    """
    if not (np.isfinite(alpha) and alpha > 0):
        raise ValueError(f"alpha must be a positive number, got {alpha!r}")
    check_count(n_features, "n_features", minimum=1)
    c = np.asarray(c, dtype=np.float64)
    if np.any(c < 0) or not np.all(np.isfinite(c)):
        raise ValueError(f"column norms must be finite and non-negative, got min {np.min(c)}")
    return 1.0 / np.sqrt(1.0 + alpha * c**2 / n_features)


def decoder_column_norms(network, mu) -> np.ndarray:
    """c_k = |∂f/∂z_k| at each code: the column norms of the decoder's Jacobian in the network's
    output range (normalised features), as Eq. 4's reconstruction term measures them.

    Parameters
    ----------
    network : MeshVAE without conditions, in eval mode (batch normalisation affine)
    mu : (N, D) or (D,) float
        Codes (the encoder's means of the meshes).

    Returns
    -------
    c : (N, D) float64 (or (D,) for one code)
    """
    from meshvae_lib.model.networks import decoder_linearization

    if network.n_conditions:
        raise ValueError("decoder_column_norms takes an unconditional network; this one has "
                         f"{network.n_conditions} condition inputs")
    mu = np.asarray(mu, dtype=np.float64)
    single = mu.ndim == 1
    Z = mu[None] if single else mu
    if Z.ndim != 2 or Z.shape[1] != network.latent_dim:
        raise ValueError(f"mu must have shape (N, {network.latent_dim}), got {mu.shape}")
    c = np.stack([np.linalg.norm(decoder_linearization(network, z)[1], axis=0) for z in Z])
    return c[0] if single else c


def decoder_sigma(network, mu, alpha: float) -> np.ndarray:
    """The posterior deviation Eq. 4 implies at each code for this decoder:
    :func:`linear_gaussian_sigma` of :func:`decoder_column_norms`.

    Parameters
    ----------
    network : MeshVAE without conditions (evaluated in eval mode; its mode is restored)
    mu : (N, D) or (D,) float
    alpha : float > 0

    Returns
    -------
    sigma : (N, D) float64 in (0, 1] (or (D,) for one code)
    """
    was_training = network.training
    network.eval()
    try:
        return linear_gaussian_sigma(decoder_column_norms(network, mu), alpha, network.n_features)
    finally:
        network.train(was_training)
