"""The PCA start of a network without internal layers: the linear floor it begins training at.

A departure from the paper (issue 12, ``docs/vae.md``, "Generalisation on real meshes"): instead of
PyTorch's random initialisation, :func:`pca_start` computes from the normalised training rows a
start at which the encoder means are the rows' whitened principal coefficients and the decoder
reproduces the rows' PCA reconstruction through its ``tanh``.
:meth:`~meshvae_lib.model.vae.MeshVAE.from_pca` builds the network from it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvae_lib.tolerances import PCA_INIT_RTOL

__all__ = ["PCAStart", "pca_start"]


@dataclass
class PCAStart:
    """What :func:`pca_start` computes (r principal directions of K features).

    mean : (K,) float64, the rows' mean; basis : (r, K) float64, row k = v_k / c_k (the encoder's
    input projection: whitened coefficients); sigma : (r,) float64, the posterior deviations;
    decoder_weight : (K, r) float64 and decoder_bias : (K,) float64, the decoder's least-squares fit
    to atanh of the rows.
    """

    mean: np.ndarray
    basis: np.ndarray
    sigma: np.ndarray
    decoder_weight: np.ndarray
    decoder_bias: np.ndarray

    @property
    def rank(self) -> int:
        return len(self.sigma)


def pca_start(X: np.ndarray, latent_dim: int, alpha: float) -> PCAStart:
    """The PCA start of normalised training rows ``X (N >= 2, K) float64``.

    With r = min(latent_dim, rank, N - 1) principal directions v_k of the centred rows and their
    coefficient spreads c_k (singular value / sqrt(N - 1)):

    - input projection: ``mean`` = the rows' mean, ``basis`` row k = v_k / c_k, so the encoder sees
      whitened coefficients w (unit variance over the training rows, as the prior);
    - encoder: mu = w in the first r latent dimensions; the deviation is the posterior deviation of
      a linear-Gaussian model with this decoder and the noise variance K / alpha that Eq. 4
      implies, sigma_k = (1 + alpha c_k^2 / K)^(-1/2);
    - decoder: pre-activations ``b + W mu`` fitted by least squares to atanh of the training rows,
      so that tanh(b + W mu) reproduces every training row when r = N - 1.
    """
    n, k = X.shape
    mean = X.mean(axis=0)
    Xc = X - mean
    # SVD through the small (N, N) Gram matrix: K may be ~1e5-1e6, N ~ 1e2
    w, U = np.linalg.eigh(Xc @ Xc.T)
    order = np.argsort(w)[::-1]
    s = np.sqrt(np.clip(w[order], 0.0, None))
    U = U[:, order]
    r = int(min(latent_dim, n - 1, np.sum(s > s[0] * PCA_INIT_RTOL))) if s[0] > 0 else 0
    r = max(r, 1)
    s_r = np.maximum(s[:r], s[0] * PCA_INIT_RTOL if s[0] > 0 else 1.0)
    V = (U[:, :r].T @ Xc) / s_r[:, None]  # (r, K) orthonormal directions
    c = s_r / np.sqrt(max(n - 1, 1))
    Z = Xc @ V.T / c  # (N, r) whitened coefficients
    A = np.arctanh(np.clip(X, -1 + 1e-6, 1 - 1e-6))
    sol, *_ = np.linalg.lstsq(np.c_[Z, np.ones(n)], A, rcond=None)  # (r + 1, K)
    sigma = 1.0 / np.sqrt(1.0 + alpha * c ** 2 / k)
    return PCAStart(mean=mean, basis=V / c[:, None], sigma=sigma, decoder_weight=sol[:r].T, decoder_bias=sol[r])
