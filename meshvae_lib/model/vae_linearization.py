"""The mesh VAE's decoder, linearised in closed form: what the Gauss-Newton inference and the
posterior read of :class:`~meshvae_lib.model.vae.MeshVAE` (issue 37).

The decoder is ``act(W h + b)`` with ``h = [z, c]`` without internal layers, else the internal
layers' output. :func:`mesh_vae_decoder_jacobian` gives the decoded rows and ``d rows / d z`` in
float64: the closed form ``act'(y) W`` without internal layers, torch's autograd for the small
Jacobian of the internal layers otherwise. :func:`output_slope` is ``act`` and ``act'`` of both
output activations. Networks without a closed form get the same from autograd
(:func:`meshvae_lib.model.networks.decoder_linearization`).
"""

from __future__ import annotations

import numpy as np
import torch

__all__ = ["output_slope", "mesh_vae_decoder_jacobian"]


def output_slope(output: str, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The output activation ``output`` ("tanh", "sigmoid" or "linear") at pre-activations ``y`` and
    its slope, both float64 of y's shape."""
    if output == "linear":
        y = np.asarray(y, dtype=np.float64)
        return y.copy(), np.ones_like(y)
    if output == "sigmoid":
        r = 0.5 * (1.0 + np.tanh(0.5 * y))          # the logistic function, without overflow far out
        return r, r * (1.0 - r)
    r = np.tanh(y)
    return r, 1.0 - r * r


def mesh_vae_decoder_jacobian(network, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The decoded rows of one code and their Jacobian with respect to it.

    Parameters
    ----------
    network : MeshVAE (in eval mode: batch normalisation is then affine)
    z : (D,) float
    c : (C,) float or None
        Its condition vector (conditional networks).

    Returns
    -------
    rows : (K,) float64
        ``network.decode(z, c)``.
    J : (K, D) float64
        ``d rows / d z = act'(y) W dh/dz``.
    """
    D = network.latent_dim
    z = np.asarray(z, dtype=np.float64).reshape(D)
    W = network.decoder_head.weight.detach().double().numpy()
    b = network.decoder_head.bias.detach().double().numpy()
    if not network.hidden:
        y = W[:, :D] @ z + b
        if network.n_conditions:
            y = y + W[:, D:] @ np.asarray(c, dtype=np.float64).reshape(network.n_conditions)
        rows, slope = output_slope(network.output, y)
        return rows, slope[:, None] * W[:, :D]
    ct = None if c is None else torch.from_numpy(np.asarray(c, dtype=np.float32).reshape(1, -1))

    def body(v):
        return network.decoder_hidden(v[None], ct)[0]

    zt = torch.from_numpy(z.astype(np.float32))
    with torch.no_grad():
        h = body(zt).double().numpy()
    Jh = torch.autograd.functional.jacobian(body, zt).double().numpy()     # (width, D)
    rows, slope = output_slope(network.output, W @ h + b)
    return rows, slope[:, None] * (W @ Jh)
