"""The mesh VAE network, its KL term and its loss (paper Sec. 4.2-4.4, Eqs. 4 and 5).

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

Extended model (Sec. 4.4): the prior is N(0, diag(sigma_object^2)); ``kl_divergence`` has the
exact KL to it and the authors' sibling-code formula (``form="sibling"``).

Loss (Eq. 4), for a batch of M meshes with K features each::

    L = alpha / (2 M K) * sum_j sum_i (f^_i^j - f~_i^j)^2  +  (1/M) sum_j KL(q(z | f~^j) || p(z))

i.e. both terms are *means over the meshes of the batch*: the loss is the batch average of the
per-mesh quantity ``alpha/(2K) |f^ - f~|^2 + KL_j``, where ``KL_j`` sums over the D latent
dimensions. The mean is taken the same way for both terms, so the balance set by alpha does not
depend on the batch size.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import torch
from torch import nn

from meshvae_lib.defaults import DEFAULT_ALPHA, DEFAULT_EPOCHS, DEFAULT_LATENT, LEAKY_RELU_SLOPE, LOSSES, PRIOR_FORMS, SIGMA_MAX
from meshvae_lib.model.inplace_grad import Linear
from meshvae_lib.model.pca_start import pca_start, write_start
from meshvae_lib.tolerances import GN_UNUSED_DIM_RTOL, SIGMA_LOGIT_MIN

__all__ = ["MeshVAE", "kl_divergence", "vae_loss"]


def _block(n_in: int, n_out: int, slope: float) -> list[nn.Module]:
    return [Linear(n_in, n_out), nn.BatchNorm1d(n_out), nn.LeakyReLU(slope)]


class MeshVAE(nn.Module):
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
    #: the decoder's last activations it has, and what ``TrainConfig`` leaves unset means for it.
    outputs = ("tanh", "sigmoid")
    train_defaults = {"epochs": DEFAULT_EPOCHS, "output": "tanh", "loss": "mse"}
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
    def from_config(cls, config: dict) -> "MeshVAE":
        """The network :meth:`config` describes (untrained weights)."""
        return cls(**config)

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh=None) -> "MeshVAE":
        """A new network to train on rows ``x (N, K)`` float32 with ``config`` (a
        :class:`~meshvae_lib.model.train_config.TrainConfig` whose ``latent_dim`` the trainer has
        resolved): the PCA start (:meth:`from_pca`) when ``config.uses_pca_init(n_conditions)``, else
        PyTorch's random initialisation (seeded by the caller). The mesh is not needed (the rows are
        all it reads)."""
        if config.uses_pca_init(n_conditions):
            return cls.from_pca(x, config, n_conditions)
        return cls(x.shape[1], _latent(config, x.shape[0], n_conditions), config.hidden, n_conditions,
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
        D = _latent(config, x.shape[0], n_conditions)
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
        layer), else None: the Gauss-Newton inference's fast path."""
        if self.hidden:
            return None
        return self.decoder_head.weight.detach(), self.decoder_head.bias.detach()

    def decoder_hidden(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """The input of the decoder's output layer: the internal layers' output for ``z (B, D)``
        [+ ``c (B, C)``], or ``[z, c]`` itself without internal layers."""
        return self.decoder_body(self._with_condition(z, c, self.latent_dim, "latent vectors"))

    def decoder_jacobian(self, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Decoded rows ``(K,)`` and ``d rows / d z`` ``(K, D)``, float64, in closed form
        (:func:`~meshvae_lib.model.vae_linearization.mesh_vae_decoder_jacobian`)."""
        from meshvae_lib.model.vae_linearization import mesh_vae_decoder_jacobian

        return mesh_vae_decoder_jacobian(self, z, c)

    def _with_condition(self, x: torch.Tensor, c, width: int, what: str) -> torch.Tensor:
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
            h = self.encoder_body(self._with_condition(x, c, self.input_rank, "projected features"))
        else:
            h = self.encoder_body(self._with_condition(x, c, self.n_features, "features"))
        out = self.encoder_head(h)
        mu, s = out[:, : self.latent_dim], out[:, self.latent_dim :]
        # With K ~ 1e4-1e5 inputs an Adam step can move s by ~10, and alpha = 1e6 pushes sigma to
        # 0: without a floor sigmoid underflows, log(sigma^2) = -inf and training turns to NaN.
        sigma = self.sigma_max * torch.sigmoid(s.clamp(min=SIGMA_LOGIT_MIN))
        if self.sigma_floor:
            sigma = sigma + self.sigma_floor
        return mu, sigma

    def reparameterize(
        self, mu: torch.Tensor, sigma: torch.Tensor, generator: torch.Generator | None = None
    ) -> torch.Tensor:
        """z = mu + sigma * eps, eps ~ N(0, I) drawn from ``generator``. (B, D) -> (B, D)."""
        eps = torch.randn(mu.shape, generator=generator, dtype=mu.dtype, device=mu.device)
        return mu + sigma * eps

    def decode(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """Probabilistic decoder's mean: z (B, D) [+ c (B, C)] -> features (B, K) in (-1, 1)
        (``output="sigmoid"``: in (0, 1))."""
        h = self.decoder_hidden(z, c)
        if self.output == "sigmoid":
            return torch.sigmoid(self.decoder_head(h))
        return torch.tanh(self.decoder_head(h))

    def forward(
        self, x: torch.Tensor, c: torch.Tensor | None = None, generator: torch.Generator | None = None
    ) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
        """Encode, sample z, decode. Returns (x_hat (B, K), mu (B, D), sigma (B, D))."""
        mu, sigma = self.encode(x, c)
        z = self.reparameterize(mu, sigma, generator)
        return self.decode(z, c), mu, sigma


def _latent(config, n_rows: int, n_conditions: int) -> int:
    """The latent size of a new network: the one rule,
    :meth:`~meshvae_lib.model.train_config.TrainConfig.resolved_latent_dim` (the trainer has already
    applied it; a start called directly applies it here)."""
    return config.resolved_latent_dim(n_rows, n_conditions)


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
