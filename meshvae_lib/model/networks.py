"""Networks: the registry of architectures and what the estimator, the trainer and the checkpoint
ask of one by name.

A network subclasses :class:`~meshvae_lib.model.network_base.Network` (the contract: every hook
declared with its default). :data:`ARCHITECTURES` maps each architecture's name (the network's
``architecture`` attribute, recorded in checkpoints) to its class.

To add an architecture: write a module with a subclass of ``Network`` and add one line to
:data:`ARCHITECTURES`; ``TrainConfig(architecture=...)`` trains it, the checkpoint stores and
rebuilds it by name, every inference works on it (its decoder's linearisation is autograd's unless
it overrides ``linearization``), and ``meshvae train`` offers its ``Options`` as flags.

This module imports neither numpy nor torch (``Network`` itself is imported on first use).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from meshvae_lib.model.registry import registered_class

if TYPE_CHECKING:  # pragma: no cover
    import numpy as np

    from meshvae_lib.model.network_base import Network

__all__ = ["Network", "ReferenceMesh", "ARCHITECTURES", "ARCHITECTURE_NAMES", "network_class", "start_network",
           "network_from_config", "train_defaults", "decoder_linearization"]

#: architecture name -> "module:Class" of a subclass of :class:`~meshvae_lib.model.network_base.Network`.
ARCHITECTURES = {
    "mesh-vae": "meshvae_lib.model.vae:MeshVAE",
    "spiral": "meshvae_lib.model.spiral_net:SpiralVAE",
    "local-parts": "meshvae_lib.model.local_parts:LocalPartsVAE",
    "corrected": "meshvae_lib.model.corrected_network:CorrectedVAE",
}
#: the registered architectures' names when this module was imported (use ``tuple(ARCHITECTURES)``
#: for the current ones).
ARCHITECTURE_NAMES = tuple(ARCHITECTURES)


def __getattr__(name: str):
    """``Network``, the base class, imported on first use (it needs torch)."""
    if name == "Network":
        from meshvae_lib.model.network_base import Network

        return Network
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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


def network_class(architecture: str) -> "type[Network]":
    """The class registered as ``architecture``; ValueError naming the architectures for an unknown one."""
    return registered_class(ARCHITECTURES, architecture, "architecture")


def start_network(architecture: str, x, n_conditions: int, config, mesh: ReferenceMesh | None = None) -> "Network":
    """A new network of ``architecture`` to train on rows ``x (N, K)`` float32 of ``mesh`` with
    ``n_conditions`` condition inputs and the :class:`~meshvae_lib.model.train_config.TrainConfig`
    ``config``, its latent size resolved (the caller seeds torch's generator)."""
    return network_class(architecture).start(x, n_conditions, config, mesh)


def train_defaults(architecture: str) -> dict:
    """What ``TrainConfig``'s ``epochs``, ``output`` and ``loss`` (and, where the class says,
    ``latent_dim``) mean for ``architecture`` when left unset: the class's ``train_defaults``."""
    return dict(network_class(architecture).train_defaults)


def network_from_config(architecture: str, config: dict) -> "Network":
    """The network of ``architecture`` that ``config`` (its ``config()``) describes, weights untrained."""
    return network_class(architecture).from_config(dict(config))


def decoder_linearization(network, z, c=None) -> "tuple[np.ndarray, np.ndarray]":
    """A network's decoded rows at one code and their Jacobian with respect to it.

    Parameters
    ----------
    network : a :class:`~meshvae_lib.model.network_base.Network` in eval mode.
    z : (D,) float
    c : (C,) float or None (a conditional network's condition vector).

    Returns
    -------
    rows : (K,) float64, ``network.decode(z, c)``.
    J : (K, D) float64, ``d rows / d z``: ``network.decoder_jacobian(z, c)``, its
        ``linearization`` (the mesh VAE's closed form, or autograd).
    """
    return network.decoder_jacobian(z, c)
