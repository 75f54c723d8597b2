"""A network's decoder linearised around codes: what the Gauss-Newton inference and the posterior
read of any network (issue 37, issue 48). It belongs to no network.

:class:`DecoderLinearization` is built once per network and set of latent dimensions (whatever
can be precomputed, e.g. weights converted to float64) and evaluated at many codes; each
evaluation is a :class:`DecoderPoint`, the decoded rows and the Jacobian of (a per-row scaling of)
them with respect to those dimensions. The base classes here are the autograd default every network
inherits (``Network.linearization``); a network with a closed form overrides it
(:mod:`~meshvae_lib.model.vae_linearization`, the mesh VAE's). :func:`output_slope` is the output
activation and its slope, shared by closed forms.
"""

from __future__ import annotations

import warnings

import numpy as np
import torch

__all__ = ["output_slope", "DecoderPoint", "DecoderLinearization"]


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


class DecoderPoint:
    """The decoder at one code: ``rows (K,)`` float64, ``decode(z, c)``, and the Jacobian
    ``J (K, D)`` float64 of the rows with respect to the code (autograd's, or a closed form's)."""

    def __init__(self, rows: np.ndarray, jacobian: np.ndarray, used: np.ndarray):
        self.rows, self._jacobian, self._used = rows, jacobian, used

    def jacobian(self, scale: np.ndarray) -> np.ndarray:
        """``d (scale * rows) / d z[used]``: (K, n_used) float64 for ``scale (K,)`` float64 (the
        affine maps from rows to features scale each row component)."""
        return scale[:, None] * self._jacobian[:, self._used]


class DecoderLinearization:
    """A network's decoder linearised at codes of the latent dimensions ``used`` (int64 indices):
    the default, forward-mode autograd (``torch.func.jacfwd``, one pass per latent dimension) of
    ``network.decode``. A network with a closed form returns its own subclass from
    ``Network.linearization``.

    network : a network in eval mode; used : (n_used,) int64.
    """

    def __init__(self, network, used: np.ndarray):
        self.network, self.used = network, np.asarray(used, dtype=np.int64)

    def at(self, z: np.ndarray, c: np.ndarray | None = None) -> DecoderPoint:
        """The decoder at code ``z (D,)`` float and condition ``c (C,)`` float or None."""
        rows, J = self.jacobian_at(z, c)
        return DecoderPoint(rows, J, self.used)

    def jacobian_at(self, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """``rows (K,)`` and ``d rows / d z (K, D)``, float64, by autograd."""
        network = self.network
        zt = torch.as_tensor(np.asarray(z, dtype=np.float32).reshape(network.latent_dim))
        ct = None if c is None else torch.as_tensor(np.asarray(c, dtype=np.float32).reshape(1, -1))

        def decode(v):
            return network.decode(v[None], ct)[0]

        with torch.no_grad():
            rows = decode(zt)
        with warnings.catch_warnings():  # torch's first forward-mode use scripts its decompositions (torch 2.13 warns)
            warnings.filterwarnings("ignore", message=r".*torch\.jit\.script.* is deprecated", category=DeprecationWarning)
            J = torch.func.jacfwd(decode)(zt)
        return rows.double().numpy(), J.detach().double().numpy()
