"""The encoder's mean (the paper's amortised inference): z = mu(x, c) of q(z | x, c)."""

from __future__ import annotations

import numpy as np

from meshvae_lib.model.inference.base import InferenceStrategy

__all__ = ["EncoderMean"]


class EncoderMean(InferenceStrategy):
    """The latent code of a mesh is the encoder's mean of its normalised feature row."""

    name = "encoder"

    def infer(self, model, vertices: np.ndarray, conditions: np.ndarray | None, progress: bool = False) -> np.ndarray:
        mu, _ = model.encode_rows(model.features_of(vertices), conditions)
        return mu
