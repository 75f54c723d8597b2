"""A spiral-convolution variational autoencoder on vertex positions: the ``"spiral"`` architecture
of :mod:`meshvae_lib.model.networks` (SpiralNet++, Gong et al., ICCV Workshops 2019, with the
down- and up-sampling of CoMA, Ranjan et al., ECCV 2018), written here from the papers.

Encoder: at each of the hierarchy's levels (:func:`~meshvae_lib.geometry.spirals.mesh_hierarchy`)
a spiral convolution -- one linear map of the features along each vertex's spiral, shared by all
vertices -- and an ELU, then down-sampling to the next level; a linear map of the coarsest level's
features to the latent mean and deviation. Decoder: a linear map to the coarsest level, then at each
level up-sampling and a spiral convolution with an ELU, and a last spiral convolution to the three
coordinates (no activation: the output is ``"linear"``). The defaults are the authors'
reconstruction settings (``defaults.SPIRAL_*``: channels 32, 32, 32, 64, spiral length 9, four
levels of 4, latent 16, L1 loss, Adam at 1e-3, 300 epochs); the two departures are a VAE's
deviation head (the authors train a plain autoencoder; with the paper's alpha = 1e6 the latent cost
is negligible, so this trains as one) and a constant learning rate (the authors decay it by 0.99 a
epoch). It works on feature kinds whose rows are positions (``defaults.POSITION_KINDS``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch
from torch import nn

from meshvae_lib.defaults import (POSITION_KINDS, SIGMA_MAX, SPIRAL_CHANNELS, SPIRAL_DOWNSAMPLING,
                                  SPIRAL_EPOCHS, SPIRAL_LATENT, SPIRAL_LENGTH)
from meshvae_lib.model.network_base import Network

__all__ = ["SpiralVAE", "SpiralOptions"]


@dataclass(frozen=True)
class SpiralOptions:
    """The spiral network's options (``TrainConfig.network_options``; ``meshvae train`` flags)."""

    channels: tuple[int, ...] = field(default=tuple(SPIRAL_CHANNELS), metadata={
        "help": "the spiral convolutions' widths, finest level first"})
    spiral_length: int = field(default=SPIRAL_LENGTH, metadata={"help": "the length of every spiral"})
    factors: tuple[int, ...] = field(default=tuple(SPIRAL_DOWNSAMPLING), metadata={
        "help": "the down-sampling factor of each level (one per channel width)"})

    def __post_init__(self):
        object.__setattr__(self, "channels", tuple(int(c) for c in self.channels))
        object.__setattr__(self, "factors", tuple(int(f) for f in self.factors))
        if min(self.channels, default=0) < 1 or int(self.spiral_length) < 1 or min(self.factors, default=0) < 1:
            raise ValueError(f"channels, spiral_length and factors must be positive, got {list(self.channels)},"
                             f" {self.spiral_length}, {list(self.factors)}")


class SpiralVAE(Network):
    """Spiral-convolution VAE on rows of ``3 n`` normalised vertex coordinates (x0, y0, z0, x1, ...).

    Parameters
    ----------
    latent_dim : int, D.
    channels : sequence of int, the spiral convolutions' widths from the finest level down.
    spiral_length : int, the length of every spiral.
    level_sizes : sequence of int, vertices per level, finest first (``len(channels) + 1`` of them).
    down_nnz, up_nnz : sequence of int, the non-zeros of each level's down- and up-sampling matrix.
    sigma_max, sigma_floor : as :class:`~meshvae_lib.model.vae.MeshVAE`'s.

    The spirals and sampling matrices are buffers (``spirals_l (n_l, L)`` int64, ``down_l_index
    (2, nnz)`` int64 and ``down_l_value (nnz,)`` float32, the same for ``up_l``), zeros until
    :meth:`start` fills them or a checkpoint is loaded.
    """

    architecture = "spiral"
    description = (f"a spiral-convolution network on vertex positions (SpiralNet++'s settings, latent {SPIRAL_LATENT},"
                   f" {SPIRAL_EPOCHS} epochs, L1 loss)")
    n_conditions = 0
    output = "linear"
    #: the options ``TrainConfig`` takes for this architecture (``network_options``).
    Options = SpiralOptions
    #: what ``TrainConfig`` leaves unset means for this architecture (the authors' settings).
    train_defaults = {"epochs": SPIRAL_EPOCHS, "output": "linear", "loss": "l1", "latent_dim": SPIRAL_LATENT}
    outputs = ("linear",)
    #: the feature kinds it can read: rows of vertex positions.
    kinds = POSITION_KINDS

    def __init__(self, latent_dim, channels, spiral_length, level_sizes, down_nnz, up_nnz,
                 sigma_max: float = SIGMA_MAX, sigma_floor: float = 0.0):
        super().__init__()
        channels, level_sizes = [int(c) for c in channels], [int(n) for n in level_sizes]
        if len(level_sizes) != len(channels) + 1 or len(down_nnz) != len(channels) or len(up_nnz) != len(channels):
            raise ValueError(f"{len(channels)} channel widths need {len(channels) + 1} level sizes and"
                             f" {len(channels)} sampling matrices each way, got {level_sizes}, {down_nnz}, {up_nnz}")
        if int(latent_dim) < 1 or min(channels, default=0) < 1 or int(spiral_length) < 1:
            raise ValueError(f"latent_dim, channels and spiral_length must be positive, got"
                             f" {latent_dim}, {channels}, {spiral_length}")
        self.latent_dim, self.channels, self.spiral_length = int(latent_dim), channels, int(spiral_length)
        self.level_sizes = level_sizes
        self.down_nnz, self.up_nnz = [int(n) for n in down_nnz], [int(n) for n in up_nnz]
        self.sigma_max, self.sigma_floor = float(sigma_max), float(sigma_floor)
        self.n_vertices = level_sizes[0]
        self.n_features = 3 * self.n_vertices
        for level, (n, dn, un) in enumerate(zip(level_sizes, self.down_nnz, self.up_nnz)):
            self.register_buffer(f"spirals_{level}", torch.zeros(n, self.spiral_length, dtype=torch.int64))
            self.register_buffer(f"down_{level}_index", torch.zeros(2, dn, dtype=torch.int64))
            self.register_buffer(f"down_{level}_value", torch.zeros(dn))
            self.register_buffer(f"up_{level}_index", torch.zeros(2, un, dtype=torch.int64))
            self.register_buffer(f"up_{level}_value", torch.zeros(un))
        widths = [3] + channels
        L = self.spiral_length
        self.encoder_convs = nn.ModuleList(nn.Linear(L * widths[i], widths[i + 1]) for i in range(len(channels)))
        coarse = level_sizes[-1] * channels[-1]
        self.encoder_head = nn.Linear(coarse, 2 * self.latent_dim)
        self.decoder_head = nn.Linear(self.latent_dim, coarse)
        # decoder level l (finest 0): up from l + 1, then a convolution channels[l + 1 or l] -> channels[l]
        ins = [channels[min(i + 1, len(channels) - 1)] for i in range(len(channels))]
        self.decoder_convs = nn.ModuleList(nn.Linear(L * ins[i], channels[i]) for i in range(len(channels)))
        self.output_conv = nn.Linear(L * channels[0], 3)
        for layer in [*self.encoder_convs, *self.decoder_convs, self.output_conv]:
            nn.init.xavier_uniform_(layer.weight)
            nn.init.zeros_(layer.bias)

    # -- configuration -------------------------------------------------------------------------
    def config(self) -> dict:
        """Constructor arguments: ``SpiralVAE(**net.config())`` has the same shapes (the buffers
        come with the state dict)."""
        return {"latent_dim": self.latent_dim, "channels": list(self.channels), "spiral_length": self.spiral_length,
                "level_sizes": list(self.level_sizes), "down_nnz": list(self.down_nnz), "up_nnz": list(self.up_nnz),
                "sigma_max": self.sigma_max, "sigma_floor": self.sigma_floor}

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh) -> "SpiralVAE":
        """A new network (Xavier-uniform weights, seeded by the caller) for rows ``x (N, 3 n)`` of
        ``mesh`` (a :class:`~meshvae_lib.model.networks.ReferenceMesh` whose kind's rows are
        positions); its hierarchy is built from the reference mesh. ``config.network_options`` may
        set ``channels``, ``spiral_length`` and ``factors``."""
        from meshvae_lib.geometry.spirals import mesh_hierarchy

        if mesh is None or mesh.kind not in cls.kinds:
            raise ValueError(f"the spiral network works on vertex positions, features {cls.kinds};"
                             f" got {None if mesh is None else mesh.kind!r}")
        if n_conditions:
            raise ValueError("the spiral network is unconditional (no labels)")
        if config.hidden:
            raise ValueError(f"the spiral network has no 'hidden' layers (its widths are network_options"
                             f" 'channels'), got hidden={config.hidden}")
        opts = cls.options(config)
        if x.shape[1] != 3 * len(mesh.vertices):
            raise ValueError(f"rows have {x.shape[1]} numbers; the mesh has {len(mesh.vertices)} vertices")
        levels = mesh_hierarchy(mesh.vertices, mesh.faces, list(opts.factors), opts.spiral_length)
        if len(levels) - 1 != len(opts.channels):
            raise ValueError(f"{len(opts.channels)} channel widths need as many down-sampling factors,"
                             f" got factors {list(opts.factors)}")
        net = cls(config.latent_dim, list(opts.channels), opts.spiral_length, [len(lv.vertices) for lv in levels],
                  [lv.down.nnz for lv in levels[:-1]], [lv.up.nnz for lv in levels[:-1]],
                  sigma_floor=config.sigma_floor)
        with torch.no_grad():
            for level, lv in enumerate(levels[:-1]):  # the coarsest level has no convolution
                net.get_buffer(f"spirals_{level}").copy_(torch.from_numpy(lv.spirals))
                for name, m in (("down", lv.down), ("up", lv.up)):
                    m = m.tocoo()
                    net.get_buffer(f"{name}_{level}_index").copy_(torch.from_numpy(np.stack([m.row, m.col]).astype(np.int64)))
                    net.get_buffer(f"{name}_{level}_value").copy_(torch.from_numpy(m.data.astype(np.float32)))
        return net

    def describe(self) -> str:
        """The network in a few words (for summaries)."""
        return (f"spiral convolutions {' -> '.join(map(str, self.channels))} (spirals of {self.spiral_length}) on"
                f" {' -> '.join(map(str, self.level_sizes))} vertices, a linear output")

    # -- the layers ----------------------------------------------------------------------------
    def _conv(self, layer: nn.Linear, h: torch.Tensor, level: int) -> torch.Tensor:
        """Spiral convolution: (B, n_l, C) -> (B, n_l, C')."""
        s = self.get_buffer(f"spirals_{level}")
        return layer(h.index_select(1, s.reshape(-1)).reshape(h.shape[0], s.shape[0], -1))

    def _pool(self, h: torch.Tensor, level: int, way: str) -> torch.Tensor:
        """Sparse sampling ``(B, n_in, C) -> (B, n_out, C)`` with level ``level``'s ``way`` matrix."""
        index, value = self.get_buffer(f"{way}_{level}_index"), self.get_buffer(f"{way}_{level}_value")
        n_out = self.level_sizes[level + 1] if way == "down" else self.level_sizes[level]
        src = h.index_select(1, index[1]) * value[None, :, None].to(h.dtype)
        return torch.zeros(h.shape[0], n_out, h.shape[2], dtype=h.dtype, device=h.device).index_add(1, index[0], src)

    # -- the four steps ------------------------------------------------------------------------
    def encode(self, x: torch.Tensor, c: torch.Tensor | None = None) -> tuple[torch.Tensor, torch.Tensor]:
        """x (B, 3n) float32 -> mu (B, D), sigma (B, D) (sigma as the mesh VAE's)."""
        self.with_condition(x, c, self.n_features, "features")
        h = x.reshape(x.shape[0], self.n_vertices, 3)
        for level, conv in enumerate(self.encoder_convs):
            h = self._pool(nn.functional.elu(self._conv(conv, h, level)), level, "down")
        out = self.encoder_head(h.reshape(h.shape[0], -1))
        return out[:, : self.latent_dim], self.deviation(out[:, self.latent_dim:])

    def decode(self, z: torch.Tensor, c: torch.Tensor | None = None) -> torch.Tensor:
        """z (B, D) -> rows (B, 3n), unbounded (a linear output)."""
        self.with_condition(z, c, self.latent_dim, "latent vectors")
        h = self.decoder_head(z).reshape(z.shape[0], self.level_sizes[-1], self.channels[-1])
        for level in reversed(range(len(self.channels))):
            h = nn.functional.elu(self._conv(self.decoder_convs[level], self._pool(h, level, "up"), level))
        return self._conv(self.output_conv, h, 0).reshape(z.shape[0], self.n_features)
