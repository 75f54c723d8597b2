"""The network contract: the base class every registered architecture subclasses (issue 48).

:class:`Network` declares every member the library reads of a network, each with its default, so
that nothing is probed: a new architecture is one module with a subclass (its ``encode``,
``decode``, ``config``, ``start`` and, where it has any, an ``Options`` dataclass) and one line in
:data:`~meshvae_lib.model.networks.ARCHITECTURES`. The trainer, the checkpoint, every inference, the
summaries and ``meshvae train`` (whose flags come from ``Options``) then take it by name.

What the base class writes once for every network: the reparameterisation, the deviation head
(``sigma = sigma_max * sigmoid(s) + sigma_floor``), ``forward``, ``from_config``, the shape and
condition checks of ``encode``/``decode`` inputs, and the decoder's linearisation by autograd.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import torch
from torch import nn

from meshvae_lib.defaults import DEFAULT_EPOCHS
from meshvae_lib.model.linearization import DecoderLinearization
from meshvae_lib.tolerances import SIGMA_LOGIT_MIN

__all__ = ["Network", "NoOptions", "TRAIN_DEFAULTS", "deviation_logit"]

#: what a ``TrainConfig`` leaves unset means unless the network's class says otherwise: the mesh VAE's.
TRAIN_DEFAULTS = {"epochs": DEFAULT_EPOCHS, "output": "tanh", "loss": "mse"}


@dataclass(frozen=True)
class NoOptions:
    """The options of a network that has none."""


def deviation_logit(sigma, sigma_max: float) -> np.ndarray:
    """The deviation head's pre-activation that gives ``sigma`` (float64 array, 0 < sigma <
    sigma_max) with no floor: the inverse of :meth:`Network.deviation`."""
    sigma = np.asarray(sigma, dtype=np.float64)
    return np.log(sigma / (sigma_max - sigma))


class Network(nn.Module):
    """What the library needs of a network, and what a network class may declare.

    Shapes: x : (B, K) float32 normalised feature rows; c : (B, C) float32 condition vectors or
    None; z, mu, sigma : (B, D) float32.

    Instance attributes a subclass sets: ``n_features`` (K), ``latent_dim`` (D), ``n_conditions``
    (C, 0: unconditional), ``output`` (the decoder's last activation, one of ``outputs``),
    ``sigma_max`` and ``sigma_floor`` (the deviation head's).

    Class attributes (declared here with their defaults):

    - ``architecture``: its key in ``ARCHITECTURES`` (recorded in checkpoints).
    - ``description``: a line for ``meshvae train --architecture``'s help.
    - ``Options``: a frozen dataclass of its own options (``TrainConfig.network_options``; each field
      a ``meshvae train`` flag, named by the field's ``metadata["flag"]`` or ``--field-name``,
      helped by ``metadata["help"]``); :class:`NoOptions` by default.
    - ``outputs``: the last activations it has; ``train_defaults``: what ``TrainConfig``'s
      ``epochs``, ``output``, ``loss`` (and ``latent_dim``) left unset mean for it.
    - ``kinds``: the feature kinds it reads (None: every kind).
    - ``conditional``: whether it takes condition vectors (labels); ``takes_hidden``: whether it
      takes ``TrainConfig.hidden``.
    - ``pca_start``: whether it starts at the PCA of its rows (``TrainConfig.uses_pca_init``);
      ``linear_optimum``: None, or why its start is its optimum (the epoch search is skipped).
    - ``trains_in_start``: whether ``start`` does all its training (the trainer then trains no epoch,
      with or without early stopping, and refuses to continue training it).
    """

    architecture: ClassVar[str] = ""
    description: ClassVar[str] = ""
    Options: ClassVar[type] = NoOptions
    outputs: ClassVar[tuple[str, ...]] = ("tanh",)
    train_defaults: ClassVar[dict] = TRAIN_DEFAULTS
    kinds: ClassVar[tuple[str, ...] | None] = None
    conditional: ClassVar[bool] = False
    takes_hidden: ClassVar[bool] = False
    pca_start: ClassVar[bool] = False
    linear_optimum: ClassVar[str | None] = None
    trains_in_start: ClassVar[bool] = False

    n_features: int
    latent_dim: int
    n_conditions: int = 0
    output: str = "tanh"
    sigma_max: float
    sigma_floor: float = 0.0

    # -- configuration -------------------------------------------------------------------------
    def config(self) -> dict:
        """Everything :meth:`from_config` needs to rebuild the network (plain numbers, strings, lists)."""
        raise NotImplementedError

    @classmethod
    def from_config(cls, config: dict) -> "Network":
        """The network :meth:`config` describes (untrained weights; buffers come with the state dict)."""
        return cls(**config)

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh) -> "Network":
        """A new network to train on rows ``x (N, K)`` float32 of ``mesh`` (a
        :class:`~meshvae_lib.model.networks.ReferenceMesh` or None) with ``n_conditions`` condition
        inputs and the resolved :class:`~meshvae_lib.model.train_config.TrainConfig` ``config``
        (the caller seeds torch's generator)."""
        raise NotImplementedError

    @classmethod
    def options(cls, config) -> "NoOptions":
        """``config.network_options`` as the class's ``Options`` (its defaults where unset)."""
        return cls.Options(**dict(config.network_options))

    @classmethod
    def check_config(cls, config) -> None:
        """ValueError when ``config`` (a TrainConfig, its latent size possibly unresolved) cannot
        train this network; called when the config is made. Default: nothing to check."""

    @classmethod
    def weights_estimate(cls, n_features: int, config) -> int | None:
        """About how many weights a network for ``n_features`` features would have with ``config``
        (before it is built, for the command line's size limit); None: no estimate."""
        return None

    def describe(self) -> str:
        """The network in a few words (for summaries)."""
        return type(self).__name__

    def used_latent_dims(self) -> np.ndarray:
        """Indices (int64) of the latent dimensions the decoder reads: all of them unless the
        network knows better."""
        return np.arange(self.latent_dim)

    # -- the four steps ------------------------------------------------------------------------
    def encode(self, x: torch.Tensor, c: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """q(z | x, c): ``(mu, sigma)``."""
        raise NotImplementedError

    def decode(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """The decoder's mean: rows (B, K)."""
        raise NotImplementedError

    def reparameterize(
        self, mu: torch.Tensor, sigma: torch.Tensor, generator: torch.Generator | None = None
    ) -> torch.Tensor:
        """z = mu + sigma * eps, eps ~ N(0, I) drawn from ``generator``. (B, D) -> (B, D)."""
        eps = torch.randn(mu.shape, generator=generator, dtype=mu.dtype, device=mu.device)
        return mu + sigma * eps

    def forward(
        self, x: torch.Tensor, c: torch.Tensor | None = None, generator: torch.Generator | None = None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Encode, sample z, decode. Returns (x_hat (B, K), mu (B, D), sigma (B, D))."""
        mu, sigma = self.encode(x, c)
        z = self.reparameterize(mu, sigma, generator)
        return self.decode(z, c), mu, sigma

    # -- shared pieces -------------------------------------------------------------------------
    def deviation(self, s: torch.Tensor) -> torch.Tensor:
        """The deviation head: ``sigma = sigma_max * sigmoid(s) + sigma_floor`` (B, D). The
        sigmoid's input is floored at ``SIGMA_LOGIT_MIN`` (-30), so sigma >= 1.9e-13 even without a
        floor and log sigma^2 stays finite: with K ~ 1e4-1e5 inputs an Adam step can move s by ~10,
        and alpha = 1e6 pushes sigma to 0; without the floor sigmoid underflows and training turns
        to NaN."""
        sigma = self.sigma_max * torch.sigmoid(s.clamp(min=SIGMA_LOGIT_MIN))
        if self.sigma_floor:
            sigma = sigma + self.sigma_floor
        return sigma

    def with_condition(self, x: torch.Tensor, c: torch.Tensor | None, width: int, what: str) -> torch.Tensor:
        """``x (B, width)`` checked, with ``c (B, C)`` appended for a conditional network (ValueError
        showing the shapes otherwise)."""
        if x.ndim != 2 or x.shape[1] != width:
            raise ValueError(f"{what} must have shape (batch, {width}), got {tuple(x.shape)}")
        if self.n_conditions == 0:
            if c is not None and c.numel() > 0:
                raise ValueError("this network is unconditional; got a condition tensor")
            return x
        if c is None:
            raise ValueError(f"this network is conditional: give a condition of shape (batch, {self.n_conditions})")
        if c.ndim != 2 or c.shape != (x.shape[0], self.n_conditions):
            raise ValueError(
                f"condition must have shape ({x.shape[0]}, {self.n_conditions}), got {tuple(c.shape)}"
            )
        return torch.cat([x, c.to(x.dtype)], dim=1)

    # -- linearisation -------------------------------------------------------------------------
    def linearization(self, used: np.ndarray) -> DecoderLinearization:
        """The decoder linearised at codes, over the latent dimensions ``used (n_used,)`` int64:
        forward-mode autograd by default; a network with a closed form overrides this."""
        return DecoderLinearization(self, used)

    def decoder_jacobian(self, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Decoded rows ``(K,)`` and ``d rows / d z`` ``(K, D)``, float64, at one code ``z (D,)`` and
        condition ``c (C,)`` or None: :meth:`linearization` over every dimension (network in eval mode)."""
        point = self.linearization(np.arange(self.latent_dim)).at(z, c)
        return point.rows, point.jacobian(np.ones(self.n_features))
