"""A decoder of local parts: the ``"local-parts"`` architecture of :mod:`meshvae_lib.model.networks`.

The mesh VAE's PCA start decodes a mesh from global directions: after it, the decoder's image is
the span of the training meshes' features, and a held-out pose that is "this pose's arm with that
pose's legs" lies outside it. This network splits the reference mesh into regions without labels
(:func:`~meshvae_lib.geometry.regions.mesh_regions`) and gives each region its own latent
dimensions: the PCA of the training features restricted to the region
(:func:`~meshvae_lib.model.pca_start.regional_pca_start`). Region g's features are decoded from
region g's dimensions only, so a code combines the parts of different training poses; RIMD's
reconstruction stitches neighbouring parts without seams (its features are local and rotation
invariant). The idea is the authors' follow-up (Tan, Gao, Lai, Yang, Xia, "Mesh-based
Autoencoders for Localized Deformation Component Analysis", AAAI 2018), which learns localised
components with a sparsity penalty; here the parts are fixed regions and each part's components
its PCA.

It is a :class:`~meshvae_lib.model.vae.MeshVAE` without internal layers whose decoder weight is
zero outside the blocks (region's features x region's dimensions): every inference, the
mesh VAE's closed-form linearisation included, works on it unchanged. Training keeps the blocks (the weight's
gradient is masked to them), and is skipped by default: each region's start is the PCA of its
features, the optimum of a linear autoencoder of that region (``linear_optimum``).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import torch

from torch import nn

from meshvae_lib.defaults import LOCAL_PARTS_LATENT, LOCAL_PARTS_METHOD, LOCAL_PARTS_REGIONS, REGION_METHODS, SIGMA_MAX
from meshvae_lib.model.network_base import TRAIN_DEFAULTS
from meshvae_lib.model.pca_start import regional_pca_start, write_start
from meshvae_lib.model.vae import MeshVAE

__all__ = ["LocalPartsVAE", "LocalPartsOptions", "check_regions"]


def check_regions(latent_dim: int, n_regions: int) -> None:
    """ValueError unless the latent size ``latent_dim`` splits into ``n_regions`` (>= 1) regions of
    as many dimensions each."""
    if int(n_regions) < 1 or int(latent_dim) % int(n_regions):
        raise ValueError(f"latent_dim {latent_dim} is not a multiple of n_regions {n_regions}"
                         " (each region gets as many dimensions)")


@dataclass(frozen=True)
class LocalPartsOptions:
    """The decoder of local parts' options (``TrainConfig.network_options``; ``meshvae train`` flags)."""

    n_regions: int = field(default=LOCAL_PARTS_REGIONS, metadata={
        "flag": "--regions", "metavar": "R",
        "help": "regions of the mesh (the latent size must be a multiple)"})
    method: str = field(default=LOCAL_PARTS_METHOD, metadata={
        "flag": "--region-method", "choices": REGION_METHODS,
        "help": "how regions are found (spectral: k-means on the mesh graph Laplacian's eigenvectors, regions"
                " that follow the surface; kmeans: on the vertex positions)"})

    def __post_init__(self):
        if int(self.n_regions) < 1:
            raise ValueError(f"n_regions must be at least 1, got {self.n_regions}")
        if self.method not in REGION_METHODS:
            raise ValueError(f"method must be one of {REGION_METHODS}, got {self.method!r}")


class LocalPartsVAE(MeshVAE):
    """A mesh VAE whose latent dimensions each belong to one region of the mesh.

    Parameters
    ----------
    n_features, latent_dim, sigma_max, sigma_floor, n_conditions : as :class:`MeshVAE`'s (no
        internal layers; ``n_conditions`` must be 0).
    n_vertices : int, the reference mesh's vertex count.
    n_regions : int, R; ``latent_dim`` must be a multiple of it (``latent_dim / R`` dimensions a region).

    Buffers (zeros until :meth:`start` fills them or a checkpoint is loaded): ``vertex_region
    (n_vertices,)`` int64, ``feature_region (K,)`` int64 and ``latent_region (D,)`` int64, the
    region of each vertex, feature component and latent dimension.
    """

    architecture = "local-parts"
    description = f"a decoder of local parts (regions of the mesh, latent {LOCAL_PARTS_LATENT} shared among them, each region's PCA)"
    outputs = ("tanh",)
    Options = LocalPartsOptions
    train_defaults = {**TRAIN_DEFAULTS, "latent_dim": LOCAL_PARTS_LATENT}
    conditional = False
    takes_hidden = False
    pca_start = True
    #: why its start is kept untrained by default (:func:`~meshvae_lib.model.training.start_is_optimum`).
    linear_optimum = ("each region's decoder starts at the PCA of the region's own features, the optimum of a"
                      " linear autoencoder of the region; the epoch search is skipped (early_stopping=True asks for it)")

    def __init__(self, n_features: int, latent_dim: int = LOCAL_PARTS_LATENT, n_vertices: int = 1,
                 n_regions: int = LOCAL_PARTS_REGIONS, n_conditions: int = 0, sigma_max: float = SIGMA_MAX,
                 sigma_floor: float = 0.0):
        check_regions(latent_dim, n_regions)
        if n_conditions:
            raise ValueError("the local-parts network is unconditional (no labels)")
        super().__init__(n_features, latent_dim, (), 0, sigma_max, input_rank=int(latent_dim), sigma_floor=sigma_floor)
        self.n_vertices, self.n_regions = int(n_vertices), int(n_regions)
        # autograd's own linear layer (the in-place one writes its gradient past the hook below)
        self.decoder_head = nn.Linear(self.latent_dim, self.n_features)
        self.register_buffer("vertex_region", torch.zeros(self.n_vertices, dtype=torch.int64))
        self.register_buffer("feature_region", torch.zeros(self.n_features, dtype=torch.int64))
        self.register_buffer("latent_region", torch.arange(self.latent_dim) // (self.latent_dim // self.n_regions))
        self.decoder_head.weight.register_hook(self._keep_blocks)

    def _keep_blocks(self, grad: torch.Tensor) -> torch.Tensor:
        """The decoder weight's gradient with the entries outside the region blocks zeroed."""
        return grad * (self.feature_region[:, None] == self.latent_region[None, :]).to(grad.dtype)

    def config(self) -> dict:
        """Constructor arguments: ``LocalPartsVAE(**net.config())`` (the regions come with the state dict)."""
        return {"n_features": self.n_features, "latent_dim": self.latent_dim, "n_vertices": self.n_vertices,
                "n_regions": self.n_regions, "sigma_max": self.sigma_max, "sigma_floor": self.sigma_floor}

    @classmethod
    def start(cls, x: torch.Tensor, n_conditions: int, config, mesh) -> "LocalPartsVAE":
        """The regional PCA start for rows ``x (N, K)`` of ``mesh`` (a
        :class:`~meshvae_lib.model.networks.ReferenceMesh` with ``feature_vertex``):
        ``config.network_options`` may set ``n_regions`` and ``method`` (a rule of
        :data:`~meshvae_lib.geometry.regions.REGION_METHODS`); ``config.latent_dim / n_regions``
        dimensions a region."""
        from meshvae_lib.geometry.regions import mesh_regions

        if mesh is None or mesh.feature_vertex is None:
            raise ValueError("the local-parts network needs the reference mesh and where each feature lies"
                             f" (the feature kind's feature_vertices()); {None if mesh is None else mesh.kind!r} does not say")
        if config.hidden or config.output != "tanh" or n_conditions:
            raise ValueError(f"the local-parts network has no internal layers, a tanh output and no labels;"
                             f" got hidden={config.hidden}, output={config.output!r}, {n_conditions} conditions")
        opts = cls.options(config)
        R, D = int(opts.n_regions), int(config.latent_dim)
        check_regions(D, R)
        if x.shape[1] != len(mesh.feature_vertex):
            raise ValueError(f"rows have {x.shape[1]} numbers; the feature kind has {len(mesh.feature_vertex)}")
        vertex_region = mesh_regions(mesh.vertices, mesh.faces, R, opts.method)
        feature_region = vertex_region[np.asarray(mesh.feature_vertex)]
        start, latent_region = regional_pca_start(x.detach().double().cpu().numpy(), feature_region, R, D // R,
                                                  config.alpha)
        net = cls(x.shape[1], D, len(mesh.vertices), R, sigma_floor=config.sigma_floor)
        write_start(net, start)
        with torch.no_grad():
            net.vertex_region.copy_(torch.from_numpy(vertex_region))
            net.feature_region.copy_(torch.from_numpy(feature_region))
            net.latent_region.copy_(torch.from_numpy(latent_region))
        return net

    @classmethod
    def check_config(cls, config) -> None:
        """The latent size (``config.nominal_latent_dim()``: the architecture's default when unset)
        must split into the regions."""
        check_regions(config.nominal_latent_dim(), cls.options(config).n_regions)

    @classmethod
    def weights_estimate(cls, n_features: int, config) -> None:
        """None: the network has as many weights as the latent size allows (no internal layers)."""
        return None

    def describe(self) -> str:
        """The network in a few words (for summaries)."""
        return (f"local parts: {self.n_regions} regions of the mesh, {self.latent_dim // self.n_regions} latent"
                f" dimensions each, a tanh output")
