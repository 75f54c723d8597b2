"""The mesh VAE network (paper Sec. 4.2-4.3); its loss, Eqs. 4 and 5, is :mod:`~meshvae_lib.model.loss`.

Architecture (Sec. 4.2, "Network structure"): a fully connected encoder and decoder. Every
*internal* layer is ``Linear -> BatchNorm1d -> LeakyReLU``. The encoder ends in two heads, the mean
``mu`` (no activation) and the deviation ``sigma = sigma_max * sigmoid(.) + sigma_floor`` (sigma_max =
2, so that sigma can cover the prior's 1; ``sigma_floor`` = 0 by default). The decoder ends in
``tanh``, matching features normalised to [-a, a] (Eq. 3), or, with ``output="sigmoid"``, in a
sigmoid (the cross-entropy model of Sec. 5.1, trained on rows mapped to ``BCE_TARGET_RANGE``). With
``hidden=()`` (the default) the encoder is one linear map K -> 2D and the decoder one linear map
D -> K, so there are no internal layers.

Input projection (``input_rank = r > 0``, a departure from the paper, issue 12): the encoder does
not see the K features themselves but their r whitened principal coefficients
``(x - input_mean) @ input_basis.T``, a fixed linear map onto the span of the training features
(set by :meth:`MeshVAE.from_pca`, stored in the checkpoint as buffers). On real
collections 4-35% of a held-out mesh's (centred) feature energy lies outside the span of the
training meshes; a K-wide encoder trained with Adam gives those directions arbitrary weights
(Adam's per-weight steps leave the span), and held-out meshes get arbitrary latent codes.

Conditional mesh VAE (Sec. 4.3, Eq. 5): a condition vector c (one-hot labels or any given vector)
is concatenated to the encoder's input and to the decoder's input.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import torch
from torch import nn

from meshvae_lib.defaults import DEFAULT_LATENT, LEAKY_RELU_SLOPE, SIGMA_MAX
from meshvae_lib.model.inplace_grad import Linear
from meshvae_lib.model.linearization import DecoderLinearization
from meshvae_lib.model.network_base import Network
from meshvae_lib.model.pca_start import pca_start, write_start
from meshvae_lib.tolerances import GN_UNUSED_DIM_RTOL

__all__ = ["MeshVAE"]


def _block(n_in: int, n_out: int, slope: float) -> list[nn.Module]:
    return [Linear(n_in, n_out), nn.BatchNorm1d(n_out), nn.LeakyReLU(slope)]


class MeshVAE(Network):
    """Fully connected (conditional) variational autoencoder on normalised mesh features: the
    ``"mesh-vae"`` architecture of :mod:`meshvae_lib.model.networks`.

    Parameters
    ----------
    n_features : int
        K, the length of a feature row.
    latent_dim : int
        D, the size of the latent vector z (paper: 128).
    hidden : sequence of int
        sizes of the internal encoder layers, outermost first; the decoder mirrors them.
        Default ``()``: no internal layer (see ``docs/vae.md`` for the measurements behind it).
    n_conditions : int
        C, the length of the condition vector (0: unconditional).
    sigma_max : float
        upper bound of the deviation output (paper: 2).
    negative_slope : float
        slope of the leaky ReLUs.
    input_rank : int
        r > 0: the encoder sees r fixed principal coefficients of its input (buffers
        ``input_mean (K,)`` and ``input_basis (r, K)``, zeros until set); 0: the K features.
    sigma_floor : float
        added to the deviation output, so that sigma >= sigma_floor (default 0: none; the paper's
        experiments use ``tolerances.SIGMA_FLOOR``).
    output : "tanh" | "sigmoid"
        the decoder's last activation: tanh (the paper, features in [-a, a]) or sigmoid (outputs in
        (0, 1), for the binary cross-entropy loss).
    """

    #: the architecture's name in :data:`meshvae_lib.model.networks.ARCHITECTURES`.
    architecture = "mesh-vae"
    description = "the paper's fully connected mesh VAE"
    #: the decoder's last activations it has (``train_defaults`` are the base class's).
    outputs = ("tanh", "sigmoid")
    conditional = True
    takes_hidden = True
    #: it can start at the PCA of its rows (:meth:`from_pca`; ``TrainConfig.uses_pca_init``).
    pca_start = True

    def __init__(
        self,
        n_features: int,
        latent_dim: int = DEFAULT_LATENT,
        hidden: Sequence[int] = (),
        n_conditions: int = 0,
        sigma_max: float = SIGMA_MAX,
        negative_slope: float = LEAKY_RELU_SLOPE,
        input_rank: int = 0,
        sigma_floor: float = 0.0,
        output: str = "tanh",
    ):
        super().__init__()
        hidden = tuple(int(h) for h in hidden)
        for name, value in (("n_features", n_features), ("latent_dim", latent_dim)):
            if int(value) < 1:
                raise ValueError(f"{name} must be a positive integer, got {value}")
        if int(n_conditions) < 0:
            raise ValueError(f"n_conditions must be >= 0, got {n_conditions}")
        if not 0 <= int(input_rank) <= int(n_features):
            raise ValueError(f"input_rank must lie in 0..n_features, got {input_rank}")
        if any(h < 1 for h in hidden):
            raise ValueError(f"hidden layer sizes must be positive, got {hidden}")
        if not sigma_max > 0:
            raise ValueError(f"sigma_max must be positive, got {sigma_max}")
        if not 0.0 <= float(sigma_floor) < float("inf"):
            raise ValueError(f"sigma_floor must be finite and >= 0, got {sigma_floor}")
        if output not in self.outputs:
            raise ValueError(f"output must be one of {self.outputs}, got {output!r}")
        self.n_features = int(n_features)
        self.latent_dim = int(latent_dim)
        self.hidden = hidden
        self.n_conditions = int(n_conditions)
        self.sigma_max = float(sigma_max)
        self.negative_slope = float(negative_slope)
        self.input_rank = int(input_rank)
        self.sigma_floor = float(sigma_floor)
        self.output = str(output)
        if self.input_rank:
            self.register_buffer("input_mean", torch.zeros(self.n_features))
            self.register_buffer("input_basis", torch.zeros(self.input_rank, self.n_features))

        layers: list[nn.Module] = []
        width = (self.input_rank or self.n_features) + self.n_conditions
        for h in hidden:
            layers += _block(width, h, negative_slope)
            width = h
        self.encoder_body = nn.Sequential(*layers)
        # one matrix for both heads: a single (cheaper) matmul over the K inputs
        self.encoder_head = Linear(width, 2 * self.latent_dim)

        layers = []
        width = self.latent_dim + self.n_conditions
        for h in reversed(hidden):
            layers += _block(width, h, negative_slope)
            width = h
        self.decoder_body = nn.Sequential(*layers)
        self.decoder_head = Linear(width, self.n_features)

    # -- configuration -------------------------------------------------------------------------
    def config(self) -> dict:
        """Constructor arguments, enough to rebuild the network: ``MeshVAE(**net.config())``."""
        return {
            "n_features": self.n_features,
            "latent_dim": self.latent_dim,
            "hidden": list(self.hidden),
            "n_conditions": self.n_conditions,
            "sigma_max": self.sigma_max,
            "negative_slope": self.negative_slope,
            "input_rank": self.input_rank,
            "sigma_floor": self.sigma_floor,
            "output": self.output,
        }

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh=None) -> "MeshVAE":
        """A new network to train on rows ``x (N, K)`` float32 with ``config`` (a
        :class:`~meshvae_lib.model.train_config.TrainConfig` whose ``latent_dim`` the trainer has
        resolved): the PCA start (:meth:`from_pca`) when ``config.uses_pca_init(n_conditions)``, else
        PyTorch's random initialisation (seeded by the caller). The mesh is not needed (the rows are
        all it reads)."""
        config = config.resolve(x.shape[0], n_conditions)   # a no-op on the trainer's resolved config
        if config.uses_pca_init(n_conditions):
            return cls.from_pca(x, config, n_conditions)
        return cls(x.shape[1], config.latent_dim, config.hidden, n_conditions,
                   sigma_floor=config.sigma_floor, output=config.output)

    @classmethod
    def from_pca(cls, x: torch.Tensor, config, n_conditions: int = 0) -> "MeshVAE":
        """A network without internal layers whose decoded means start as the training rows' PCA.

        x : (N, K) float32 normalised training rows (N >= 2); config : the latent size
        (``config.latent_dim``, resolved by the trainer), alpha and sigma_floor come from it (``config.hidden``
        must be empty, ``config.output`` "tanh"). The
        input projection, encoder and decoder start as :func:`~meshvae_lib.model.pca_start.pca_start`
        says (the deviation is 1 in the latent dimensions beyond its rank, where the latent cost is
        then 0); condition inputs start with zero weights. Returns the network in train mode.
        """
        if config.hidden:
            raise ValueError("the PCA initialisation is for networks without internal layers (hidden=())")
        if config.output != "tanh":
            raise ValueError("the PCA initialisation is for a tanh output (it fits the tanh's pre-activations)")
        D = config.resolve(x.shape[0], n_conditions).latent_dim     # the trainer's, or the rule's for a direct call
        start = pca_start(x.detach().double().cpu().numpy(), D, config.alpha)
        net = cls(x.shape[1], D, (), n_conditions, input_rank=start.rank, sigma_floor=config.sigma_floor)
        write_start(net, start)
        return net

    def describe(self) -> str:
        """The network in a few words (for summaries)."""
        layers = " -> ".join(map(str, self.hidden)) if self.hidden else "no internal layer"
        return f"fully connected, {layers}, a {self.output} output"

    def used_latent_dims(self) -> np.ndarray:
        """Indices (int64) of the latent dimensions the decoder reads: with no internal layer, those
        whose column of the decoder's weight exceeds ``GN_UNUSED_DIM_RTOL`` of the largest column
        (the PCA start leaves the others at exactly zero); with internal layers, all of them. The
        library's one rule for used dimensions."""
        if self.hidden:
            return np.arange(self.latent_dim)
        size = self.decoder_head.weight.detach()[:, : self.latent_dim].abs().amax(dim=0).double().numpy()
        return np.flatnonzero(size > GN_UNUSED_DIM_RTOL * size.max()) if size.max() > 0 else np.arange(0)

    def linear_decoder(self) -> tuple[torch.Tensor, torch.Tensor] | None:
        """``(W (K, D + C), b (K,))`` float32 when the decoder is ``act(W [z, c] + b)`` (no internal
        layer), else None: the blocks a decoder of local parts keeps (notebook 10)."""
        if self.hidden:
            return None
        return self.decoder_head.weight.detach(), self.decoder_head.bias.detach()

    def decoder_hidden(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """The input of the decoder's output layer: the internal layers' output for ``z (B, D)``
        [+ ``c (B, C)``], or ``[z, c]`` itself without internal layers."""
        return self.decoder_body(self.with_condition(z, c, self.latent_dim, "latent vectors"))

    def linearization(self, used: np.ndarray) -> DecoderLinearization:
        """The decoder linearised in closed form over the latent dimensions ``used``
        (:mod:`~meshvae_lib.model.vae_linearization`): ``act'(y) W`` without internal layers (the
        used columns converted once), autograd for the internal layers otherwise."""
        from meshvae_lib.model.vae_linearization import HiddenLayersLinearization, LinearDecoderLinearization

        return (HiddenLayersLinearization if self.hidden else LinearDecoderLinearization)(self, used)

    @classmethod
    def weights_estimate(cls, n_features: int, config) -> int:
        """About how many weights the encoder and the decoder have (K -> hidden -> 2 x latent,
        latent -> hidden reversed -> K), the latent size ``config.latent_dim`` or, unresolved, the
        most the PCA start may choose (``PCA_LATENT_MAX``)."""
        from meshvae_lib.defaults import PCA_LATENT_MAX

        latent = config.latent_dim or PCA_LATENT_MAX
        sizes = [n_features, *config.hidden]
        enc = sum(a * b for a, b in zip(sizes, sizes[1:])) + sizes[-1] * 2 * latent
        dec = sum(a * b for a, b in zip(sizes, sizes[1:])) + sizes[-1] * latent
        return enc + dec

    # -- the four steps ------------------------------------------------------------------------
    def encode(self, x: torch.Tensor, c: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """Probabilistic encoder q(z | x, c).

        x : (B, K) float32 normalised features; c : (B, C) float32 or None.
        Returns mu : (B, D) and sigma : (B, D) float32, sigma_floor < sigma < sigma_max + sigma_floor
        (the sigmoid's input is floored at SIGMA_LOGIT_MIN = -30, so sigma >= 1.9e-13 even without
        a floor and log sigma^2 stays finite).
        """
        if self.input_rank:
            if x.ndim != 2 or x.shape[1] != self.n_features:
                raise ValueError(f"features must have shape (batch, {self.n_features}), got {tuple(x.shape)}")
            x = (x - self.input_mean) @ self.input_basis.t()
            h = self.encoder_body(self.with_condition(x, c, self.input_rank, "projected features"))
        else:
            h = self.encoder_body(self.with_condition(x, c, self.n_features, "features"))
        out = self.encoder_head(h)
        return out[:, : self.latent_dim], self.deviation(out[:, self.latent_dim :])

    def decode(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """Probabilistic decoder's mean: z (B, D) [+ c (B, C)] -> features (B, K) in (-1, 1)
        (``output="sigmoid"``: in (0, 1))."""
        h = self.decoder_hidden(z, c)
        if self.output == "sigmoid":
            return torch.sigmoid(self.decoder_head(h))
        return torch.tanh(self.decoder_head(h))
