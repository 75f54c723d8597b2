"""The inference strategy base class: meshes -> latent codes through a fitted model's public API."""

from __future__ import annotations

import numpy as np

__all__ = ["InferenceStrategy"]


class InferenceStrategy:
    """How a fitted model finds latent codes for meshes.

    A subclass sets ``name`` (its registry key) and ``options`` (its constructor keywords, stored as
    instance attributes of the same names) and writes :meth:`infer`; one with something to say about
    its latest call overrides :meth:`report`. ``iterations`` is the number of refinement steps after
    the encoder (0 for the encoder itself): what ``evaluate_model`` reports.
    """

    name: str = ""
    options: tuple[str, ...] = ()
    iterations: int = 0

    def infer(self, model, vertices: np.ndarray, conditions: np.ndarray | None, progress: bool = False) -> np.ndarray:
        """Latent codes ``(N, D) float64`` of meshes ``vertices (N, n_vertices, 3) float64`` (checked
        against the model) with condition vectors ``conditions (N, C) float32`` (None for an
        unconditional model); ``progress``: a progress bar over the meshes where the work is long."""
        raise NotImplementedError

    def report(self) -> object | None:
        """What the latest :meth:`infer` did (the estimator keeps it as ``last_inference_``), or
        None: a strategy with nothing to report (the default)."""
        return None

    def get_options(self) -> dict:
        """``{keyword: value}`` of the strategy's options (what rebuilds it)."""
        return {k: vars(self)[k] for k in self.options}

    def describe(self) -> str:
        """A few words for reports: how the codes were found."""
        return self.name

    def __repr__(self) -> str:
        opts = ", ".join(f"{k}={v!r}" for k, v in self.get_options().items())
        return f"{type(self).__name__}({opts})"
