"""The fitted mesh VAE: the network with everything needed to use it on meshes.

:class:`MeshVAEModel` bundles the network (:class:`~meshvae_lib.model.vae.MeshVAE`), the fitted
normaliser (Eq. 3), the feature extractor (reference mesh, faces, feature kind and RIMD layout) and
the condition encoder (label names and encodings), so that applications and notebooks are
one-liners::

    model = MeshVAEModel(features="rimd").fit(collection)     # or load_model("model.pt")
    z = model.encode_meshes(collection)                      # (N, D) codes (Gauss-Newton from the encoder's means)
    meshes = model.decode_latent(z)                          # (N, n, 3)
    model.save("model.pt")                                   # the file format: model.checkpoint
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from meshvae_lib.defaults import DEFAULT_INFERENCE, GAUSS_NEWTON_ITERATIONS, INFERENCE_METHODS
from meshvae_lib.model.features import ConditionEncoder, FeatureExtractor
from meshvae_lib.model.normalization import FeatureNormalizer
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import from_output_range, holdout_mask, pad_sigma_object, train_vae
from meshvae_lib.tolerances import FIT_LATENT_STEP

__all__ = ["MeshVAEModel"]


def _read_only(a: np.ndarray) -> np.ndarray:
    """A view of ``a`` that cannot be written through (the model's own array stays writable)."""
    view = a.view()
    view.flags.writeable = False
    return view


class MeshVAEModel:
    """A mesh VAE trained on one collection, ready to encode and decode meshes.

    Parameters
    ----------
    features : "rimd" | "aligned" | "coords" (the paper's Table 2; "rimd" is the mesh VAE proper).
    config : :class:`~meshvae_lib.model.train_config.TrainConfig` (defaults when None).
    labels : label columns to condition on (conditional mesh VAE, Eq. 5); empty: unconditional.
    holdout_every : hold out every k-th mesh (k >= 2) from training to measure generalisation;
        0 trains on everything.
    layout : RIMD layout ("paper" or "compact").
    reference_index : the reference mesh (default: the first mesh of the collection).
    inference : how :meth:`encode_meshes` finds a mesh's code when a call does not say
        (``defaults.INFERENCE_METHODS``, :mod:`~meshvae_lib.model.inference`): "gauss-newton"
        (default: the encoder's mean, then Gauss-Newton steps on the vertex error), "encoder" (the
        paper's feed-forward encoder), "finite-difference" (:meth:`fit_latent`). Not a training
        setting: it can be changed on a trained model.

    Attributes (after :meth:`fit` or :func:`load_model`)
    ----------------------------------------------------
    network_ : MeshVAE, eval mode, CPU.
    normalizer_ : FeatureNormalizer (Eq. 3).
    extractor_ : FeatureExtractor (reference_, faces_, kind, layout).
    conditions_ : ConditionEncoder (columns, categories).
    train_conditions_ : (N_train, C) float32, the training meshes' condition vectors (to sample
        values of columns a user leaves unset).
    sigma_object_ : (D,) float64 deviations of the latent prior that :meth:`sample_latent` draws
        from: the config's sigma_object with the exact prior form, ones for the standard prior and
        for the sibling form (whose latent cost keeps the means' unit spread).
    holdout_mask_ : (N,) bool, which meshes of the training collection were held out.
    train_config_ : TrainConfig the network was trained with (``config``, or the defaults when it
        was None; ``config`` itself is left as given).
    history_ : list of per-epoch dicts (see :class:`~meshvae_lib.model.training.TrainResult`).
    train_seconds_ : float.
    train_epochs_ : int, epochs the network was trained for (early stopping may choose fewer than
        ``config.epochs``, or 0: the PCA initialisation itself). Not stored in checkpoints.
    selection_ : early stopping's record (see ``TrainResult.selection``) or None.
    last_inference_ : :class:`~meshvae_lib.model.inference.GaussNewtonReport` of the latest
        Gauss-Newton :meth:`encode_meshes` (errors before and after, steps, decodes per mesh).
    """

    def __init__(self, features: str = "rimd", config: TrainConfig | None = None, labels=(),
                 holdout_every: int = 0, layout: str = "paper", reference_index: int = 0,
                 inference: str = DEFAULT_INFERENCE):
        self.features = features
        self.config = config
        self.labels = tuple(labels)
        self.holdout_every = holdout_every
        self.layout = layout
        self.reference_index = reference_index
        self.inference = inference

    # -- training ------------------------------------------------------------------------------
    def fit(self, collection) -> "MeshVAEModel":
        """Extract features, normalise them, train the network.

        collection : a MeshCollection / SynthCollection (``vertices (N, n, 3)``, ``faces (F, 3)``,
        ``labels``). The network is the one :func:`~meshvae_lib.model.training.train_vae` builds
        from the config (its ``sigma_floor``, ``output`` and ``loss`` included).

        Returns ``self``.
        """
        config = self.config or TrainConfig()
        V = np.asarray(collection.vertices, dtype=np.float64)
        labels = dict(getattr(collection, "labels", {}) or {})
        mask = holdout_mask(len(V), self.holdout_every)
        if mask[self.reference_index]:
            raise ValueError(f"the reference mesh {self.reference_index} would be held out")
        if np.sum(~mask) < 2:
            raise ValueError(f"need at least 2 training meshes, got {int(np.sum(~mask))}")
        self.extractor_ = FeatureExtractor(self.features, self.layout, self.reference_index)
        self.extractor_.fit(V, collection.faces)
        X = self.extractor_.transform(V)
        pca = config.uses_pca_init(len(self.labels))
        self.normalizer_ = FeatureNormalizer(a=config.resolved_feature_range(pca),
                                             scale=config.resolved_feature_scale(self.features, pca)).fit(X[~mask])
        Xn = self.normalizer_.transform(X)
        missing = [c for c in self.labels if c not in labels]
        if missing:
            raise ValueError(f"no label column(s) {missing}; the data has {sorted(labels)}")
        self.conditions_ = ConditionEncoder(self.labels).fit({c: np.asarray(labels[c])[~mask] for c in self.labels})
        C = self.conditions_.transform(labels) if self.labels else None
        result = train_vae(
            Xn[~mask], None if C is None else C[~mask], config,
            val_features=Xn[mask] if mask.any() else None,
            val_conditions=None if C is None or not mask.any() else C[mask],
        )
        self.network_ = result.model
        self.history_ = result.history
        self.train_seconds_ = result.seconds
        self.train_epochs_ = result.epochs
        self.selection_ = result.selection
        self.holdout_mask_ = mask
        self.train_conditions_ = (np.zeros((int((~mask).sum()), 0), np.float32) if C is None else C[~mask])
        so = pad_sigma_object(config.sigma_object, self.network_.latent_dim)
        exact = so is not None and config.prior_form == "exact"
        self.sigma_object_ = so if exact else np.ones(self.network_.latent_dim)
        self.train_config_ = config
        return self

    # -- conditions ----------------------------------------------------------------------------
    @property
    def is_conditional(self) -> bool:
        self._check_fitted()
        return self.network_.n_conditions > 0

    def _conditions(self, n: int, conditions=None, labels=None) -> torch.Tensor | None:
        """(n, C) float32 tensor from explicit vectors, a label dict, or None for unconditional."""
        if not self.is_conditional:
            if conditions is not None and np.size(conditions):
                raise ValueError("this model is unconditional; it takes no conditions")
            return None
        if conditions is None:
            if labels is None:
                raise ValueError(
                    f"this model is conditional on {self.conditions_.columns}: give labels or conditions"
                )
            conditions = self.conditions_.transform(labels)
        c = np.asarray(conditions, dtype=np.float32)
        if c.ndim == 1:
            c = np.broadcast_to(c, (n, c.shape[0]))
        if c.shape != (n, self.network_.n_conditions):
            raise ValueError(f"conditions must have shape ({n}, {self.network_.n_conditions}), got {c.shape}")
        return torch.from_numpy(np.ascontiguousarray(c))

    def condition_vector(self, values: dict | None = None, n: int = 1, seed: int | None = 0) -> np.ndarray:
        """Condition vectors (n, C) float32 from ``{column: value}``.

        Columns left out take the values of randomly chosen training meshes (drawn with ``seed``),
        so ``condition_vector({"motion": "run"}, n=8)`` varies the other columns as the data does.
        """
        self._check_fitted()
        values = dict(values or {})
        unknown = [k for k in values if k not in self.conditions_.columns]
        if unknown:
            raise ValueError(f"unknown condition columns {unknown}; the model knows {self.conditions_.columns}")
        rng = np.random.default_rng(seed)
        rows = rng.integers(0, len(self.train_conditions_), size=n) if len(self.train_conditions_) else np.zeros(n, int)
        out = np.array(self.train_conditions_[rows], dtype=np.float32).reshape(n, -1)
        slices = self.conditions_.column_slices()
        for col, val in values.items():
            out[:, slices[col]] = self.conditions_.encode_column(col, np.asarray([val]))[0]
        return out

    # -- encode / decode -----------------------------------------------------------------------
    def features_of(self, vertices) -> np.ndarray:
        """Meshes (N, n, 3) or a collection -> normalised feature rows (N, K) float64."""
        self._check_fitted()
        return self.normalizer_.transform(self.extractor_.transform(vertices))

    def encode_meshes(self, vertices, conditions=None, labels=None, return_sigma: bool = False,
                      inference: str | None = None, iterations: int = GAUSS_NEWTON_ITERATIONS, progress: bool = False):
        """Latent codes (N, D) float64 of meshes (N, n, 3) or of a collection.

        inference : "gauss-newton" | "encoder" | "finite-difference", or None for the model's own
            (``self.inference``, default "gauss-newton"); see :mod:`~meshvae_lib.model.inference`.
            "encoder" gives the paper's posterior means; the others start there and fit the code
            to the vertex positions (any rigid pose), never ending worse than the encoder's mean.
        iterations : Gauss-Newton steps per mesh for the fitting strategies (>= 1).
        progress : a progress bar over the meshes (fitting strategies).

        For a conditional model give ``conditions (N, C)`` or ``labels`` (dict column -> (N,));
        a collection's own labels are used when neither is given. With ``return_sigma`` also the
        encoder's posterior deviations (N, D).
        """
        self._check_fitted()
        method = self.inference if inference is None else inference
        if method not in INFERENCE_METHODS:
            raise ValueError(f"inference must be one of {INFERENCE_METHODS}, got {method!r}")
        if labels is None and conditions is None and hasattr(vertices, "labels"):
            labels = vertices.labels if self.is_conditional else None
        mu, sigma = self._encoder_means(vertices, conditions, labels)
        if method == "gauss-newton":
            from meshvae_lib.model.inference import gauss_newton_codes

            if iterations < 1:
                raise ValueError(f"iterations must be >= 1, got {iterations}")
            C = self._conditions(len(mu), conditions, labels)
            mu, self.last_inference_ = gauss_newton_codes(
                self, self._vertex_array(vertices), mu, None if C is None else C.double().numpy(),
                iterations=iterations, progress=progress)
        elif method == "finite-difference":
            mu = self.fit_latent(vertices, iterations=iterations, z0=mu, conditions=conditions, labels=labels)
        return (mu, sigma) if return_sigma else mu

    @staticmethod
    def _vertex_array(vertices) -> np.ndarray:
        V = np.asarray(getattr(vertices, "vertices", vertices), dtype=np.float64)
        return V[None] if V.ndim == 2 else V

    @torch.no_grad()
    def _encoder_means(self, vertices, conditions, labels) -> tuple[np.ndarray, np.ndarray]:
        X = self.features_of(vertices)
        x = torch.from_numpy(X.astype(np.float32))
        mu, sigma = self.network_.eval().encode(x, self._conditions(len(X), conditions, labels))
        return mu.double().numpy(), sigma.double().numpy()

    @torch.no_grad()
    def decode_latent(self, z, conditions=None, labels=None) -> np.ndarray:
        """Latent vectors (N, D) or (D,) -> meshes (N, n, 3) or (n, 3) float64."""
        self._check_fitted()
        z = np.asarray(z, dtype=np.float32)
        single = z.ndim == 1
        z2 = z[None] if single else z
        if z2.ndim != 2 or z2.shape[1] != self.network_.latent_dim:
            raise ValueError(f"latent vectors must have shape (N, {self.network_.latent_dim}), got {z.shape}")
        rows = self.network_.eval().decode(torch.from_numpy(np.ascontiguousarray(z2)),
                                           self._conditions(len(z2), conditions, labels))
        # a sigmoid output decodes to BCE_TARGET_RANGE: back to Eq. 3's [-a, a] (tanh: unchanged)
        rows = from_output_range(rows.double().numpy(), self.normalizer_.a, self.network_.output)
        V = self.extractor_.inverse_transform(self.normalizer_.inverse_transform(rows))
        return V[0] if single else V

    def reconstruct(self, vertices, conditions=None, labels=None, fit_iterations: int = 0,
                    inference: str | None = None, progress: bool = False) -> np.ndarray:
        """Encode (:meth:`encode_meshes`, the model's inference unless ``inference`` says) and
        decode: meshes (N, n, 3) -> (N, n, 3) float64.

        ``fit_iterations > 0``: the finite-difference fit with that many steps (:meth:`fit_latent`;
        the same as ``inference="finite-difference"``, kept for ``meshvae evaluate --fit-latent``).
        ``progress``: a progress bar while codes are fitted.
        """
        if labels is None and conditions is None and hasattr(vertices, "labels") and self.is_conditional:
            labels = vertices.labels
        if fit_iterations:
            z = self.encode_meshes(vertices, conditions, labels, inference="finite-difference",
                                   iterations=fit_iterations)
        else:
            z = self.encode_meshes(vertices, conditions, labels, inference=inference, progress=progress)
        return self.decode_latent(z, conditions, labels)

    def fit_latent(self, vertices, iterations: int = 3, z0=None, conditions=None, labels=None,
                   step: float = FIT_LATENT_STEP) -> np.ndarray:
        """Latent codes fitted to vertex positions through the decoder (an option beside the paper's encoder).

        The paper's encoder picks z from the *features*; on real collections the features of a
        held-out mesh are mostly reproduced in directions that matter little for the vertices
        (docs/vae.md, issue 12). This minimises instead the decoded mesh's squared vertex error,
        ``sum_k |decode(z)_k - (R v_k + t)|^2`` over z and the best rigid motion (R, t), by
        Gauss-Newton from the encoder's means (or ``z0``): each iteration takes the Jacobian of the
        decoded vertices with respect to the latent dimensions the decoder uses by forward
        differences (one decode + reconstruction per dimension), solves the linear least-squares
        step and halves it (up to 3 times) until the error falls. The decoder, normaliser and
        reconstruction are not changed; this is the same model, encoded by fitting.

        vertices : (N, n, 3) meshes or a collection; iterations : Gauss-Newton steps (>= 1);
        z0 : (N, D) starting codes; step : finite-difference step in latent units.
        Returns (N, D) float64 codes. Cost: iterations x (dimensions used + 1) decodes per mesh.
        """
        self._check_fitted()
        if iterations < 1:
            raise ValueError(f"iterations must be >= 1, got {iterations}")
        if labels is None and conditions is None and hasattr(vertices, "labels") and self.is_conditional:
            labels = vertices.labels
        V = self._vertex_array(vertices)
        Z = np.array(self.encode_meshes(V, conditions, labels, inference="encoder") if z0 is None else z0,
                     dtype=np.float64)
        if Z.shape != (len(V), self.network_.latent_dim):
            raise ValueError(f"z0 must have shape ({len(V)}, {self.network_.latent_dim}), got {Z.shape}")
        C = None
        if self.is_conditional:
            C = self._conditions(len(V), conditions, labels).numpy()
        W = self.network_.decoder_head.weight.detach()
        used = np.flatnonzero(W[:, : self.network_.latent_dim].abs().sum(0).numpy() > 0) if not self.network_.hidden \
            else np.arange(self.network_.latent_dim)
        eye = np.eye(self.network_.latent_dim)[used] * step
        from meshvae_lib.geometry.alignment import rigid_align

        for j in range(len(V)):
            c = None if C is None else C[j]
            err = None
            for _ in range(iterations):
                batch = np.vstack([Z[j][None], Z[j][None] + eye])
                P = self.decode_latent(batch, conditions=None if c is None else np.broadcast_to(c, (len(batch), len(c))))
                P0 = P[0]
                target = rigid_align(V[j], P0)
                r0 = (target - P0).ravel()
                err = float(r0 @ r0) if err is None else err
                J = ((P[1:] - P0).reshape(len(used), -1) / step).T  # (3n, d)
                dz, *_ = np.linalg.lstsq(J, r0, rcond=None)
                t = 1.0
                for _ in range(4):
                    z_new = Z[j].copy()
                    z_new[used] += t * dz
                    Pn = self.decode_latent(z_new, conditions=c)
                    rn = (rigid_align(V[j], Pn) - Pn).ravel()
                    if float(rn @ rn) < err:
                        Z[j], err = z_new, float(rn @ rn)
                        break
                    t *= 0.5
                else:
                    break  # no step lowered the error: done
        return Z

    def sample_latent(self, n: int, seed: int = 0) -> np.ndarray:
        """n draws from the prior N(0, diag(sigma_object^2)): (n, D) float64."""
        self._check_fitted()
        if n < 1:
            raise ValueError(f"n must be >= 1, got {n}")
        rng = np.random.default_rng(seed)
        return rng.standard_normal((n, self.network_.latent_dim)) * self.sigma_object_

    def generate(self, n: int, seed: int = 0, condition: dict | None = None, return_latents: bool = False):
        """n new meshes decoded from prior samples (Sec. 5, "Generation").

        ``condition``: ``{column: value}`` for a conditional model (unset columns are drawn from
        the training labels, seeded by ``seed``).

        Returns ``V (n, n_vertices, 3) float64``, or with ``return_latents`` ``(V, z (n, D)
        float64, c (n, C) float32 or None)``: the prior draws and condition vectors behind them.
        """
        z = self.sample_latent(n, seed)
        c = None
        if self.is_conditional:
            c = self.condition_vector(condition, n=n, seed=seed)
        elif condition:
            raise ValueError(f"this model is unconditional; it takes no condition, got {condition!r}")
        V = np.asarray(self.decode_latent(z, conditions=c), dtype=np.float64).reshape(int(n), -1, 3)
        return (V, z, c) if return_latents else V

    # -- persistence ---------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write the checkpoint (one file, written atomically; read it with
        :func:`~meshvae_lib.model.checkpoint.load_model`). Returns the path."""
        from meshvae_lib.model.checkpoint import write_checkpoint

        return write_checkpoint(path, self)

    # -- the mesh ------------------------------------------------------------------------------
    @property
    def reference_vertices(self) -> np.ndarray:
        """The reference mesh the features are relative to: (n_vertices, 3) float64, read-only."""
        self._check_fitted()
        return _read_only(self.extractor_.reference_)

    @property
    def faces(self) -> np.ndarray:
        """The model's triangles: (n_faces, 3) int64, read-only."""
        self._check_fitted()
        return _read_only(self.extractor_.faces_)

    def check_compatible(self, collection) -> None:
        """ValueError unless ``collection`` has this model's mesh (and its label columns)."""
        self._check_fitted()
        self.extractor_.check_compatible(collection)
        if self.is_conditional:
            labels = getattr(collection, "labels", {}) or {}
            missing = [c for c in self.conditions_.columns if c not in labels]
            if missing:
                raise ValueError(f"the model is conditional on {missing}, which the data lacks (has {sorted(labels)})")

    def _check_fitted(self) -> None:
        if not hasattr(self, "network_"):
            raise ValueError("this MeshVAEModel is not trained yet: call fit(collection) or load_model(path)")

    def __repr__(self) -> str:
        if not hasattr(self, "network_"):
            return f"MeshVAEModel(features={self.features!r}, unfitted)"
        net = self.network_
        return (f"MeshVAEModel(features={self.extractor_.kind!r}, n_vertices={len(self.extractor_.reference_)},"
                f" K={net.n_features}, latent={net.latent_dim}, hidden={list(net.hidden)},"
                f" conditions={self.conditions_.columns})")
