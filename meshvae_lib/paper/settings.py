"""How big the experiments are (:class:`ExperimentSettings`) and the paper's numbers (``PAPER``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshvae_lib import defaults as hp

__all__ = ["ExperimentSettings", "PAPER", "resolve_settings"]

#: the paper's numbers, as printed.
PAPER = {
    # Table 1: (scale, [16, 128, 256])
    "table1": {"jumping": (1e-4, [4.9129, 4.4325, 4.2442]), "face": (1e-2, [8.3833, 7.8025, 7.9192])},
    # Table 2: (n shapes, scale, [3D coordinates, aligned coordinates, RIMD])
    "table2": {
        "scape": (71, 1e-3, [15.7249, 7.3582, 3.7418]),
        "jumping": (150, 1e-4, [49.4876, 11.2226, 4.4325]),
        "bouncing": (75, 1e-4, [28.1823, 6.6970, 3.7358]),
        "face": (385, 1e-2, [47.1863, 27.8445, 7.8025]),
        "flag": (90, 1e-3, [29.5490, 2.4462, 1.7916]),
        "dyna": (2168, 1e-3, [2.9488, 1.7634, 1.2128]),
    },
    # Table 3 (chicken wings, Dyna): (base mesh, points, error x 1e-4)
    "table3": [("No. 1", 6890, 2.77), ("No. 1", 6002, 2.49), ("No. 1", 8002, 3.01),
               ("No. 6", 6890, 2.85), ("No. 72", 6890, 2.80)],
    # Sec. 5.4: retrieval AUC on Dyna
    "auc": {"sigma_object VAE": 0.5168, "t-SNE": 0.4961, "PCA": 0.2272, "NPE": 0.1391},
}


@dataclass
class ExperimentSettings:
    """How big the experiments are.

    resolution : vertex count asked of ``data_synth`` (None: the collection's default)
    max_meshes : keep at most this many meshes of a collection, evenly spaced (None: all)
    train_steps : Adam steps per model; epochs = ceil(steps * batch / n_train), so every model
        costs about the same whatever its collection's size
    min_epochs, max_epochs : bounds on the epochs
    batch_size, latent_dim : as ``TrainConfig`` (paper: latent 128)
    holdout_every : every k-th mesh is held out to measure the error (k = 5: 20 %)
    layout : RIMD layout; "compact" stores each edge's rotation once (the paper's layout stores
        both directions, ``log dR_ji = -log dR_ij``: the same information, twice the columns)
    seed : seeds data, initial weights, shuffling and sampling
    embedding_steps : Adam steps of the embedding models (Sec. 5.4), which need longer training
        than the error tables for the latent cost to shape the map
    converge : False (default): every model trains ``train_steps``; True: every model trains until
        its validation error stops improving (the library's early stopping on every 8th training
        mesh, ``patience`` epochs without a lower validation MSE, at most ``converge_epochs``), the
        validation curve kept with the model (``benchmarks/experiments.py`` runs Table 2 this way)
    converge_epochs, patience : bounds of ``converge``
    """

    resolution: int | None = 400
    max_meshes: int | None = 210
    train_steps: int = 300
    min_epochs: int = 20
    max_epochs: int = 600
    batch_size: int = 32
    latent_dim: int = hp.DEFAULT_LATENT
    holdout_every: int = 5
    layout: str = "compact"
    seed: int = 0
    embedding_steps: int = 1000
    converge: bool = False
    converge_epochs: int = 10000
    patience: int = 200

    @classmethod
    def quick(cls, **kw) -> "ExperimentSettings":
        """A tiny preset: minimal meshes, at most 40 of them, 60 steps (seconds per model)."""
        base = dict(resolution=300, max_meshes=40, train_steps=60, min_epochs=5, latent_dim=16, embedding_steps=60)
        base.update(kw)
        return cls(**base)

    def epochs_for(self, n_train: int) -> int:
        e = int(np.ceil(self.train_steps * self.batch_size / max(int(n_train), 1)))
        return int(np.clip(e, self.min_epochs, self.max_epochs))

    def embedding_epochs_for(self, n_train: int) -> int:
        """Epochs of the sigma_object models (``embedding_steps``; at least ``min_epochs``)."""
        return max(self.min_epochs, int(np.ceil(self.embedding_steps * self.batch_size / max(int(n_train), 1))))


def resolve_settings(settings: ExperimentSettings | None, quick: bool) -> ExperimentSettings:
    """``settings``, else the quick preset (``quick=True``) or the full defaults."""
    if settings is not None:
        return settings
    return ExperimentSettings.quick() if quick else ExperimentSettings()
