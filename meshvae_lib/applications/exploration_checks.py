"""Stand-in latent spaces and a spread measure, for checking an exploration of the latent space (Sec. 5.5).

- :class:`WhitenedPCA`: PCA on vertex coordinates (the linear floor,
  :class:`~meshvae_lib.model.evaluation.CoordinatePCA`) seen as a latent space: ``z_k`` is the k-th
  principal coefficient over its standard deviation on the training meshes, so that ``N(0, I)`` and
  the browsing range [-2, 2] mean for it what they mean for a VAE with an ``N(0, I)`` prior. Whatever
  takes a model with ``latent_dim`` and ``decode_latent`` (``exploration.explore``,
  ``dimension_effects``, ``dimension_displacement``) takes it: the linear floor of a browsing study.
- :class:`RelabelledLatents`: a model's latent space with its axes reordered and flipped; it decodes
  the same shapes under other coordinates. A self-check reruns a student's cell on it: a typed-in
  dimension or latent vector then points at another shape.
- :func:`grid_spread`: how far the panels of an exploration grid lie from its centre panel, in units of
  the data's own spread (:func:`~meshvae_lib.applications.exploration.data_spread`).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.applications.exploration import ExplorationGrid, data_spread
from meshvae_lib.model.evaluation import CoordinatePCA, per_vertex_error
from meshvae_lib.validation import check_is_fitted, check_rows, check_vertices

__all__ = ["WhitenedPCA", "RelabelledLatents", "grid_spread"]


class WhitenedPCA:
    """PCA on vertex coordinates as a latent space with unit-variance coordinates.

    Parameters
    ----------
    n_components : int, the latent size (principal directions kept; at most N - 1 for N training meshes)

    Attributes (after :meth:`fit`)
    ------------------------------
    latent_dim : int
    pca_ : CoordinatePCA (not aligned: plain coordinates)
    scale_ : (latent_dim,) float64 > 0, the standard deviation of each principal coefficient over the
        training meshes (population, ddof 0)
    """

    def __init__(self, n_components: int):
        self.n_components = int(n_components)

    def fit(self, V) -> "WhitenedPCA":
        """Fit on training meshes ``V (N, n, 3)`` float; returns self."""
        V = check_vertices(V, "V", batch=True)
        self.pca_ = CoordinatePCA(self.n_components).fit(V)
        scale = self.pca_.transform(V).std(axis=0)
        if not np.all(scale > 0):
            raise ValueError("a kept principal direction has no spread over the training meshes: keep fewer")
        self.scale_ = scale
        self.latent_dim = int(scale.size)
        return self

    def encode_meshes(self, V) -> np.ndarray:
        """Meshes ``(N, n, 3)`` -> whitened coefficients ``(N, latent_dim)`` float64 (unit variance
        and zero mean over the training meshes)."""
        check_is_fitted(self, "scale_", "call fit(V_train) first")
        return self.pca_.transform(V) / self.scale_

    def decode_latent(self, z) -> np.ndarray:
        """Latent vectors ``(N, latent_dim)`` or ``(latent_dim,)`` -> meshes ``(N, n, 3)`` or ``(n, 3)``
        float64: the mean mesh plus ``sum_k z_k scale_k u_k``."""
        check_is_fitted(self, "scale_", "call fit(V_train) first")
        z = check_rows(z, "latent vectors", self.latent_dim)
        V = self.pca_.inverse_transform(np.atleast_2d(z) * self.scale_)
        return V[0] if z.ndim == 1 else V


class RelabelledLatents:
    """A model's latent space under other coordinates: new axis ``i`` is the model's axis ``order[i]``
    times ``signs[i]``.

    Parameters
    ----------
    model : anything with ``latent_dim`` and ``decode_latent((N, D)) -> (N, n, 3)``
    order : permutation of ``range(D)`` (default the identity)
    signs : (D,) of +1 / -1 (default all +1)

    ``decode_latent(z)`` decodes the model's ``w`` with ``w[order[i]] = signs[i] * z[i]``, and
    ``encode_meshes`` (where the model has it) maps the model's codes the other way; a prior
    ``N(0, I)`` and a box ``[-r, r]^D`` stay what they were, so browsing it is browsing the model.
    """

    def __init__(self, model, order=None, signs=None):
        self.model = model
        self.latent_dim = D = int(model.latent_dim)
        self.order = np.arange(D) if order is None else np.asarray(order, dtype=np.int64)
        self.signs = np.ones(D) if signs is None else np.asarray(signs, dtype=np.float64)
        if sorted(self.order.tolist()) != list(range(D)):
            raise ValueError(f"order must be a permutation of range({D}), got {self.order.tolist()}")
        if self.signs.shape != (D,) or not np.all(np.abs(self.signs) == 1):
            raise ValueError(f"signs must be {D} values of +1 or -1, got {self.signs.tolist()}")

    def model_latents(self, z) -> np.ndarray:
        """New coordinates ``(N, D)`` or ``(D,)`` -> the model's, same shape, float64."""
        z = check_rows(z, "latent vectors", self.latent_dim)
        w = np.empty_like(z, dtype=np.float64)
        w[..., self.order] = z * self.signs
        return w

    def decode_latent(self, z) -> np.ndarray:
        """Latent vectors ``(N, D)`` or ``(D,)`` in the new coordinates -> the model's meshes."""
        return self.model.decode_latent(self.model_latents(z))

    def encode_meshes(self, vertices, *args, **kwargs):
        """The model's ``encode_meshes`` (same arguments), in the new coordinates: codes ``(N, D)`` or
        ``(D,)`` float64 with ``z[..., i] = signs[i] * w[..., order[i]]``, so that ``decode_latent``
        of them decodes what the model decodes of its own ``w``. With ``return_sigma=True`` also the
        posterior deviations, reordered (a deviation has no sign)."""
        out = self.model.encode_meshes(vertices, *args, **kwargs)
        W, sigma = out if isinstance(out, tuple) else (out, None)
        Z = np.asarray(W, dtype=np.float64)[..., self.order] * self.signs
        return Z if sigma is None else (Z, np.asarray(sigma, dtype=np.float64)[..., self.order])


def grid_spread(grid: ExplorationGrid, reference_vertices=None) -> float:
    """Mean distance of a grid's panels to its centre panel (the centre one counted, at 0).

    grid : an ``ExplorationGrid`` with an odd number of rows and columns (``vertices (na, nb, n, 3)``);
    reference_vertices : (M, n, 3) meshes whose spread is the unit (:func:`data_spread`); default
    mesh units. Distances are mean vertex distances after rigid alignment (``per_vertex_error``).

    Returns a float >= 0.
    """
    V = np.asarray(grid.vertices, dtype=np.float64)
    na, nb = V.shape[:2]
    if na % 2 == 0 or nb % 2 == 0:
        raise ValueError(f"a grid with a centre panel has odd sides, got {na} x {nb}")
    panels = V.reshape(na * nb, *V.shape[2:])
    dist = per_vertex_error(panels, np.broadcast_to(V[na // 2, nb // 2], panels.shape))
    unit = 1.0 if reference_vertices is None else data_spread(reference_vertices)
    return float(np.mean(dist) / unit)
