"""The mesh VAE's decoder, linearised in closed form: its override of ``Network.linearization``
(issue 37), which the Gauss-Newton inference and the posterior read through the public
:class:`~meshvae_lib.model.linearization.DecoderLinearization`.

The decoder is ``act(W h + b)`` with ``h = [z, c]`` without internal layers, else the internal
layers' output. :class:`LinearDecoderLinearization` converts the used columns of ``W`` to float64
once and evaluates ``act(W h + b)`` and ``act'(y) W`` per code; :class:`HiddenLayersLinearization`
takes torch's autograd for the small Jacobian of the internal layers and the closed form for the
output layer.
"""

from __future__ import annotations

import numpy as np
import torch

from meshvae_lib.model.linearization import DecoderLinearization, DecoderPoint, output_slope

__all__ = ["LinearDecoderLinearization", "HiddenLayersLinearization"]


class _LinearPoint(DecoderPoint):
    """The decoder ``act(W [z, c] + b)`` at one code: ``rows (K,)`` and the slope ``act'(y) (K,)``."""

    def __init__(self, rows: np.ndarray, slope: np.ndarray, W: np.ndarray):
        self.rows, self.slope, self._W = rows, slope, W

    def jacobian(self, scale: np.ndarray) -> np.ndarray:
        return (scale * self.slope)[:, None] * self._W


class LinearDecoderLinearization(DecoderLinearization):
    """A mesh VAE without internal layers: ``W (K, n_used)``, ``b (K,)`` and ``Wc (K, C)`` float64,
    the output layer's used columns, bias and condition columns, converted once. The output layer's
    weights (K x D, K ~ 1e5-1e6) are selected in torch's float32 and only the used columns
    converted: converting all of them first took 0.3 s per call at 10k vertices."""

    def __init__(self, network, used: np.ndarray):
        super().__init__(network, used)
        W = network.decoder_head.weight.detach()
        self.W = W.index_select(1, torch.from_numpy(self.used)).double().numpy()
        self.b = network.decoder_head.bias.detach().double().numpy()
        self.Wc = W[:, network.latent_dim:].double().numpy()

    def at(self, z: np.ndarray, c: np.ndarray | None = None) -> DecoderPoint:
        z = np.asarray(z, dtype=np.float64).reshape(self.network.latent_dim)
        y = self.W @ z[self.used] + self.b
        if self.network.n_conditions:
            y = y + self.Wc @ np.asarray(c, dtype=np.float64).reshape(self.network.n_conditions)
        rows, slope = output_slope(self.network.output, y)
        return _LinearPoint(rows, slope, self.W)


class HiddenLayersLinearization(DecoderLinearization):
    """A mesh VAE with internal layers (in eval mode: batch normalisation is then affine):
    ``d rows / d z = act'(y) W dh/dz``, ``dh/dz`` by autograd."""

    def __init__(self, network, used: np.ndarray):
        super().__init__(network, used)
        self.W = network.decoder_head.weight.detach().double().numpy()
        self.b = network.decoder_head.bias.detach().double().numpy()

    def jacobian_at(self, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        network = self.network
        z = np.asarray(z, dtype=np.float64).reshape(network.latent_dim)
        ct = None if c is None else torch.from_numpy(np.asarray(c, dtype=np.float32).reshape(1, -1))

        def body(v):
            return network.decoder_hidden(v[None], ct)[0]

        zt = torch.from_numpy(z.astype(np.float32))
        with torch.no_grad():
            h = body(zt).double().numpy()
        Jh = torch.autograd.functional.jacobian(body, zt).double().numpy()     # (width, D)
        rows, slope = output_slope(network.output, self.W @ h + self.b)
        return rows, slope[:, None] * (self.W @ Jh)
