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

from meshvae_lib.model.gram_pca import principal_directions
from meshvae_lib.model.posterior import linear_gaussian_sigma
from meshvae_lib.tolerances import PCA_INIT_RTOL

__all__ = ["PCAStart", "pca_start", "regional_pca_start", "write_start"]


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
    # SVD through the small (N, N) Gram matrix: K may be ~1e5-1e6, N ~ 1e2
    mean, V, c = principal_directions(X, latent_dim, rtol=PCA_INIT_RTOL)  # V: (r, K) orthonormal directions
    r = len(c)
    Xc = X - mean
    Z = Xc @ V.T / c  # (N, r) whitened coefficients
    A = np.arctanh(np.clip(X, -1 + 1e-6, 1 - 1e-6))
    sol, *_ = np.linalg.lstsq(np.c_[Z, np.ones(n)], A, rcond=None)  # (r + 1, K)
    sigma = linear_gaussian_sigma(c, alpha, k)
    return PCAStart(mean=mean, basis=V / c[:, None], sigma=sigma, decoder_weight=sol[:r].T, decoder_bias=sol[r])


def regional_pca_start(X: np.ndarray, feature_region: np.ndarray, n_regions: int, per_region: int,
                       alpha: float) -> tuple[PCAStart, np.ndarray]:
    """The PCA start of a decoder of local parts: :func:`pca_start` of each region's own columns.

    X : (N >= 2, K) float64 normalised rows; feature_region : (K,) int, the region of each column
    (``0..n_regions-1``); per_region : the latent dimensions of each region.

    Region g owns latent dimensions ``g * per_region ..`` (its first ``r_g = min(per_region, rank,
    N - 1)`` are used): its basis rows and decoder columns are zero outside its own features, so
    each region's features are decoded from its own dimensions only. The deviations use the full
    row's K (the noise variance K / alpha of Eq. 4 is per component of the whole row).

    Returns (the start, with ``n_regions * per_region`` directions, those beyond a region's rank
    all zero with deviation 1; ``latent_region (n_regions * per_region,)`` int64, the region of each
    latent dimension).
    """
    n, k = X.shape
    feature_region = np.asarray(feature_region, dtype=np.int64)
    if feature_region.shape != (k,) or feature_region.min() < 0 or feature_region.max() >= n_regions:
        raise ValueError(f"feature_region must be ({k},) in 0..{n_regions - 1}, got shape {feature_region.shape}"
                         f" and values {feature_region.min()}..{feature_region.max()}")
    D = n_regions * per_region
    start = PCAStart(mean=X.mean(axis=0), basis=np.zeros((D, k)), sigma=np.ones(D),
                     decoder_weight=np.zeros((k, D)), decoder_bias=np.zeros(k))
    for g in range(n_regions):
        cols = np.flatnonzero(feature_region == g)
        if cols.size == 0:
            continue
        part = pca_start(X[:, cols], per_region, alpha)
        dims = g * per_region + np.arange(part.rank)
        start.basis[np.ix_(dims, cols)] = part.basis
        c = 1.0 / np.linalg.norm(part.basis, axis=1)  # basis row = v / c with |v| = 1
        start.sigma[dims] = linear_gaussian_sigma(c, alpha, k)
        start.decoder_weight[np.ix_(cols, dims)] = part.decoder_weight
        start.decoder_bias[cols] = part.decoder_bias
    return start, np.repeat(np.arange(n_regions, dtype=np.int64), per_region)


def write_start(net, start: PCAStart) -> None:
    """Set a network without internal layers (a :class:`~meshvae_lib.model.vae.MeshVAE` with
    ``input_rank = start.rank``) to ``start``: the input projection, an encoder whose means are the
    projected coefficients and whose deviations are ``start.sigma`` (1 in the latent dimensions
    beyond the start's rank), the decoder's weight and bias; condition inputs get zero weights."""
    import torch

    from meshvae_lib.model.network_base import deviation_logit

    r, D = start.rank, net.latent_dim
    sigma_logit = deviation_logit(start.sigma, net.sigma_max)
    f32 = lambda a: torch.as_tensor(np.ascontiguousarray(a), dtype=torch.float32)  # noqa: E731
    with torch.no_grad():
        net.input_mean.copy_(f32(start.mean))
        net.input_basis.copy_(f32(start.basis))
        net.encoder_head.weight.zero_()
        net.encoder_head.bias.zero_()
        net.encoder_head.weight[:r, :r] = torch.eye(r)
        net.encoder_head.bias[D:] = float(deviation_logit(1.0, net.sigma_max))  # sigma = 1
        net.encoder_head.bias[D:D + r] = f32(sigma_logit)
        net.decoder_head.weight.zero_()
        net.decoder_head.weight[:, :r] = f32(start.decoder_weight)
        net.decoder_head.bias.copy_(f32(start.decoder_bias))
