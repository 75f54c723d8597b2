"""Networks: what the estimator, the trainer and the checkpoint need of one, and the registry of
architectures.

A network is a ``torch.nn.Module`` that follows :class:`Network`: the four steps of a VAE
(``encode``, ``reparameterize``, ``decode``, ``forward``), its sizes, the activation its decoder
ends in, the latent dimensions its decoder reads, and a ``config()`` from which ``from_config``
rebuilds it; ``start`` makes a new one to train. :data:`ARCHITECTURES` maps each architecture's
name (the network's ``architecture`` attribute, recorded in checkpoints) to its class.

To add an architecture: write a module with a class that follows :class:`Network` and add one
line to :data:`ARCHITECTURES`; ``TrainConfig(architecture=...)`` trains it, and the checkpoint
stores and rebuilds it by name. The class owns its configuration: ``start`` receives the rows, the
resolved config and the :class:`ReferenceMesh` (faces, reference positions, feature kind), and
optional class attributes say what ``TrainConfig`` leaves unset means for it (``train_defaults``:
epochs, output, loss, latent size), which outputs it has (``outputs``), which
``TrainConfig.network_options`` it takes (``options``) and whether it has the PCA start
(``pca_start``). Every inference works on it unchanged: the decoder's linearisation
(:func:`decoder_linearization`) comes from autograd unless the class has a closed form of its own
(``decoder_jacobian``), and a decoder that is one linear map and an activation can say so
(``linear_decoder``) for the Gauss-Newton inference's fast path.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from meshvae_lib.defaults import DEFAULT_EPOCHS
from meshvae_lib.model.registry import registered_class

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np
    import torch

__all__ = ["Network", "ReferenceMesh", "ARCHITECTURES", "ARCHITECTURE_NAMES", "network_class", "start_network",
           "network_from_config", "train_defaults", "decoder_linearization"]

#: architecture name -> "module:Class" of a network that follows :class:`Network`.
ARCHITECTURES = {
    "mesh-vae": "meshvae_lib.model.vae:MeshVAE",
    "spiral": "meshvae_lib.model.spiral_net:SpiralVAE",
    "local-parts": "meshvae_lib.model.local_parts:LocalPartsVAE",
}
#: the registered architectures' names (the ``choices`` of ``meshvae train --architecture``).
ARCHITECTURE_NAMES = tuple(ARCHITECTURES)

#: what a network's ``TrainConfig`` leaves unset means unless its class says otherwise
#: (``train_defaults``): the mesh VAE's.
_TRAIN_DEFAULTS = {"epochs": DEFAULT_EPOCHS, "output": "tanh", "loss": "mse"}


@dataclass(frozen=True)
class ReferenceMesh:
    """What a network's ``start`` may read of the mesh besides the rows: ``vertices (n, 3)`` float64
    (the reference mesh), ``faces (n_faces, 3)`` int64, ``kind``, the feature kind's name, and
    ``feature_vertex (K,)`` int64, the vertex each feature component belongs to (the kind's
    ``feature_vertices()``; None where unknown)."""

    vertices: "np.ndarray"
    faces: "np.ndarray"
    kind: str
    feature_vertex: "np.ndarray | None" = None


@runtime_checkable
class Network(Protocol):
    """What the library needs of a network (a ``torch.nn.Module``).

    x : (B, K) float32 normalised feature rows; c : (B, C) float32 condition vectors or None;
    z, mu, sigma : (B, D) float32.
    """

    architecture: str  # its key in ARCHITECTURES
    n_features: int  # K
    latent_dim: int  # D
    n_conditions: int  # C (0: unconditional)
    output: str  # the decoder's last activation, "tanh" (rows in (-1, 1)) or "sigmoid" ((0, 1))

    def encode(self, x: "torch.Tensor", c: "torch.Tensor | None" = None) -> "tuple[torch.Tensor, torch.Tensor]":
        """q(z | x, c): (mu, sigma)."""

    def reparameterize(self, mu, sigma, generator=None) -> "torch.Tensor":
        """A draw z = mu + sigma * eps."""

    def decode(self, z: "torch.Tensor", c: "torch.Tensor | None" = None) -> "torch.Tensor":
        """The decoder's mean: rows (B, K)."""

    def forward(self, x, c=None, generator=None) -> "tuple[torch.Tensor, torch.Tensor, torch.Tensor]":
        """(decode(reparameterize(encode(x, c)), c), mu, sigma)."""

    def config(self) -> dict:
        """Everything ``from_config`` needs to rebuild the network (plain numbers, strings, lists)."""

    @classmethod
    def start(cls, x, n_conditions: int, config, mesh: ReferenceMesh | None) -> "Network":
        """A new network to train on rows ``x`` of ``mesh`` (``config.latent_dim`` resolved)."""

    def used_latent_dims(self) -> "np.ndarray":
        """Indices of the latent dimensions the decoder reads (all of them unless it knows better)."""


def network_class(architecture: str) -> type:
    """The class registered as ``architecture``; ValueError naming the architectures for an unknown one."""
    return registered_class(ARCHITECTURES, architecture, "architecture")


def start_network(architecture: str, x, n_conditions: int, config, mesh: ReferenceMesh | None = None) -> Network:
    """A new network of ``architecture`` to train on rows ``x (N, K)`` float32 of ``mesh`` with
    ``n_conditions`` condition inputs and the :class:`~meshvae_lib.model.train_config.TrainConfig`
    ``config``, its latent size resolved (the caller seeds torch's generator)."""
    return network_class(architecture).start(x, n_conditions, config, mesh)


def train_defaults(architecture: str) -> dict:
    """What ``TrainConfig``'s ``epochs``, ``output`` and ``loss`` (and, where the class says,
    ``latent_dim``) mean for ``architecture`` when left unset: the class's ``train_defaults`` over
    the mesh VAE's."""
    return {**_TRAIN_DEFAULTS, **getattr(network_class(architecture), "train_defaults", {})}


def network_from_config(architecture: str, config: dict) -> Network:
    """The network of ``architecture`` that ``config`` (its ``config()``) describes, weights untrained."""
    return network_class(architecture).from_config(dict(config))


def decoder_linearization(network, z, c=None) -> "tuple[np.ndarray, np.ndarray]":
    """A network's decoded rows at one code and their Jacobian with respect to it.

    Parameters
    ----------
    network : a :class:`Network` in eval mode.
    z : (D,) float
    c : (C,) float or None (a conditional network's condition vector).

    Returns
    -------
    rows : (K,) float64, ``network.decode(z, c)``.
    J : (K, D) float64, ``d rows / d z``: the class's own ``decoder_jacobian(z, c)`` where it has one
        (the mesh VAE's closed form), else forward-mode autograd (``torch.func.jacfwd``, one pass
        per latent dimension) of ``decode``.
    """
    import numpy as np
    import torch

    if callable(getattr(type(network), "decoder_jacobian", None)):
        return network.decoder_jacobian(z, c)
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

