"""The fitted mesh VAE: the network with everything needed to use it on meshes.

:class:`MeshVAEModel` bundles the network (an architecture of :mod:`~meshvae_lib.model.networks`,
by default :class:`~meshvae_lib.model.vae.MeshVAE`), the fitted normaliser (Eq. 3), the feature
kind (reference mesh, faces, e.g. RIMD in a layout; :mod:`~meshvae_lib.model.feature_kinds`), the
condition encoder (label names and encodings) and the inference that finds a mesh's latent code
(:mod:`~meshvae_lib.model.inference`), so that applications and notebooks are one-liners::

    model = MeshVAEModel(features="rimd").fit(collection)     # or load_model("model.pt")
    z = model.encode_meshes(collection)                      # (N, D) codes (Gauss-Newton from the encoder's means)
    meshes = model.decode_latent(z)                          # (N, n, 3)
    model.save("model.pt")                                   # the file format: model.checkpoint

The model builds and restores its own state (``state_dict``, ``from_state_dict``);
:mod:`~meshvae_lib.model.checkpoint` writes it as one file; :func:`load_model` reads it back.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import torch

from meshvae_lib.defaults import DEFAULT_ARCHITECTURE, DEFAULT_FEATURE_KIND, DEFAULT_INFERENCE, DEFAULT_LAYOUT
from meshvae_lib.geometry.collection import mesh_fingerprints
from meshvae_lib.model import checkpoint
from meshvae_lib.model.conditions import ConditionEncoder
from meshvae_lib.model.feature_kinds import kind_from_state, make_kind
from meshvae_lib.model.inference import make_inference
from meshvae_lib.model.networks import ReferenceMesh, network_from_config
from meshvae_lib.model.normalization import FeatureNormalizer
from meshvae_lib.model.train_config import TrainConfig, pad_sigma_object
from meshvae_lib.model.training import from_output_range, train_vae, training_split
from meshvae_lib.validation import check_count, check_is_fitted, check_positive, check_rows, check_vertices

__all__ = ["MeshVAEModel", "load_model", "FITTED_ATTRIBUTES"]

#: the attributes :meth:`MeshVAEModel.fit` sets and :func:`load_model` restores, all of them.
FITTED_ATTRIBUTES = ("network_", "normalizer_", "kind_", "conditions_", "train_conditions_", "sigma_object_",
                     "holdout_mask_", "mesh_fingerprints_", "train_config_", "history_", "train_seconds_", "train_epochs_",
                     "selection_")
_HINT = "call fit(collection) or load_model(path) first"


class MeshVAEModel:
    """A mesh VAE trained on one collection, ready to encode and decode meshes.

    Parameters
    ----------
    features : a feature kind of :data:`~meshvae_lib.model.feature_kinds.KINDS` ("coords",
        "aligned", "rimd": the paper's Table 2; "rimd" is the mesh VAE proper).
    config : :class:`~meshvae_lib.model.train_config.TrainConfig` (defaults when None); its
        ``architecture`` names the network.
    labels : label columns to condition on (conditional mesh VAE, Eq. 5); empty: unconditional.
    holdout_every : hold out every k-th mesh (k >= 2) to measure generalisation; 0 trains on everything.
    layout : RIMD layout ("paper" or "compact"; a kind without layout ignores it).
    reference_index : the reference mesh (default: the first mesh of the collection).
    inference : how :meth:`encode_meshes` and :meth:`reconstruct` find latent codes: a name of
        :data:`~meshvae_lib.model.inference.METHODS` ("gauss-newton", the default: the encoder's
        mean, then Gauss-Newton steps on the vertex error; "encoder": the paper's feed-forward
        encoder; "finite-difference": the slow reference fit) or a strategy object. Not a training
        setting: it can be changed on a trained model.

    Fitted, read-only properties: ``network``, ``feature_kind``, ``latent_dim``, ``n_features``,
    ``n_conditions``, ``used_latent_dims``, ``reference_vertices``, ``faces``, ``is_conditional``.

    Fitted attributes (after :meth:`fit` or :func:`load_model`: :data:`FITTED_ATTRIBUTES`)
    -------------------------------------------------------------------------------------
    sigma_object_ : (D,) float64 deviations of the prior :meth:`sample_latent` draws from: the
        config's sigma_object with the exact prior form, ones for the standard prior and the
        sibling form (whose latent cost keeps the means' unit spread).
    holdout_mask_ : (N,) bool, the held-out meshes; ``mesh_fingerprints_`` : (N, 17) float64, every
        mesh's identity (:func:`~meshvae_lib.geometry.collection.mesh_fingerprints`; None: format 3).
    train_config_ : TrainConfig the network was trained with (``config`` or the defaults, resolved once
        by ``TrainConfig.resolve``; written into the checkpoint; ``config`` itself is left as given).
    history_ : list of per-epoch dicts (see :class:`~meshvae_lib.model.training.TrainResult`); train_seconds_ : float.
    train_epochs_ : int, epochs the network was trained for (early stopping may choose fewer than
        ``config.epochs``, or 0: the PCA initialisation itself).
    selection_ : early stopping's record (see ``TrainResult.selection``) or None.
    network_, normalizer_, kind_, conditions_, train_conditions_ : the parts (network, Eq. 3's normaliser,
        feature kind, condition encoder, training conditions); others use the properties instead.
    """

    def __init__(self, features: str = DEFAULT_FEATURE_KIND, config: TrainConfig | None = None, labels=(),
                 holdout_every: int = 0, layout: str = DEFAULT_LAYOUT, reference_index: int = 0,
                 inference=DEFAULT_INFERENCE):
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
        from the config (its ``architecture``, ``sigma_floor``, ``output`` and ``loss`` included).

        Returns ``self``.
        """
        config = self.config or TrainConfig()
        make_inference(self.inference)  # an unknown name fails before training
        V = check_vertices(collection.vertices, "collection.vertices", batch=True, finite=True)
        labels = dict(getattr(collection, "labels", {}) or {})
        mask = training_split(len(V), self.holdout_every, self.reference_index)
        missing = [c for c in self.labels if c not in labels]
        if missing:
            raise ValueError(f"no label column(s) {missing}; the data has {sorted(labels)}")
        kind = make_kind(self.features, V[self.reference_index], collection.faces, layout=self.layout)
        X = kind.encode(V)
        n_cond = len(self.labels)
        config = config.resolve(int((~mask).sum()), n_cond, self.features)   # once: the checkpoint records it
        normalizer = FeatureNormalizer(a=config.a, scale=config.feature_scale).fit(X[~mask])
        Xn = normalizer.transform(X)
        conditions = ConditionEncoder(self.labels).fit({c: np.asarray(labels[c])[~mask] for c in self.labels})
        C = conditions.transform(labels) if self.labels else None
        result = train_vae(Xn[~mask], None if C is None else C[~mask], config,
                           val_features=Xn[mask] if mask.any() else None,
                           val_conditions=None if C is None or not mask.any() else C[mask],
                           mesh=ReferenceMesh(kind.reference, kind.faces, self.features, kind.feature_vertices()))
        D = result.model.latent_dim
        so = pad_sigma_object(config.sigma_object, D)
        self.kind_, self.normalizer_, self.conditions_, self.network_ = kind, normalizer, conditions, result.model
        self.history_, self.train_seconds_ = result.history, result.seconds
        self.train_epochs_, self.selection_ = result.epochs, result.selection
        self.holdout_mask_ = mask
        self.mesh_fingerprints_ = mesh_fingerprints(V)
        self.train_conditions_ = np.zeros((int((~mask).sum()), 0), np.float32) if C is None else C[~mask]
        self.sigma_object_ = so if so is not None and config.prior_form == "exact" else np.ones(D)
        self.train_config_ = config
        return self

    # -- what it is ----------------------------------------------------------------------------
    def _fitted(self):
        check_is_fitted(self, FITTED_ATTRIBUTES, _HINT)
        return self

    @property
    def network(self):
        """The trained network (a :class:`~meshvae_lib.model.networks.Network`, eval mode, CPU)."""
        return self._fitted().network_

    @property
    def feature_kind(self):
        """The feature kind (:class:`~meshvae_lib.model.feature_kinds.base.FeatureKind`): ``name``,
        ``encode``, ``decode`` (unnormalised rows)."""
        return self._fitted().kind_

    @property
    def latent_dim(self) -> int:
        """D, the latent size."""
        return int(self._fitted().network_.latent_dim)

    @property
    def n_features(self) -> int:
        """K, the length of a feature row."""
        return int(self._fitted().network_.n_features)

    @property
    def n_conditions(self) -> int:
        """C, the length of a condition vector (0: unconditional)."""
        return int(self._fitted().conditions_.n_conditions_)

    @property
    def is_conditional(self) -> bool:
        return self.n_conditions > 0

    @property
    def used_latent_dims(self) -> np.ndarray:
        """Indices (int64) of the latent dimensions the decoder reads."""
        return np.asarray(self._fitted().network_.used_latent_dims(), dtype=np.int64)

    @property
    def reference_vertices(self) -> np.ndarray:
        """The reference mesh the features are relative to: (n_vertices, 3) float64, read-only."""
        return self.feature_kind.reference

    @property
    def faces(self) -> np.ndarray:
        """The model's triangles: (n_faces, 3) int64, read-only."""
        return self.feature_kind.faces

    def check_compatible(self, collection) -> None:
        """ValueError unless ``collection`` has this model's mesh (and its label columns)."""
        self.feature_kind.check_compatible(np.asarray(collection.vertices), getattr(collection, "faces", None))
        if self.is_conditional:
            labels = getattr(collection, "labels", {}) or {}
            missing = [c for c in self.conditions_.columns if c not in labels]
            if missing:
                raise ValueError(f"the model is conditional on {missing}, which the data lacks (has {sorted(labels)})")

    # -- conditions ----------------------------------------------------------------------------
    def condition_vector(self, values: dict | None = None, n: int = 1, seed: int | None = 0) -> np.ndarray:
        """Condition vectors (n, C) float32 from ``{column: value}``.

        Columns left out take the values of randomly chosen training meshes (drawn with ``seed``),
        so ``condition_vector({"motion": "run"}, n=8)`` varies the other columns as the data does.
        """
        return self._fitted().conditions_.sample(self.train_conditions_, values, n, seed)

    def _labels_of(self, vertices, conditions, labels):
        """A collection's own labels when neither conditions nor labels are given (conditional models)."""
        if labels is None and conditions is None and hasattr(vertices, "labels") and self.is_conditional:
            return vertices.labels
        return labels

    # -- meshes <-> rows <-> codes -------------------------------------------------------------
    def _meshes(self, vertices) -> np.ndarray:
        """Meshes (N, n, 3), one mesh (n, 3) or a collection -> checked (N, n, 3) float64."""
        self._fitted()
        V = np.asarray(getattr(vertices, "vertices", vertices), dtype=np.float64)
        V = check_vertices(V[None] if V.ndim == 2 else V, "vertices", batch=True, finite=True)
        self.kind_.check_compatible(V, getattr(vertices, "faces", None))
        return V

    def features_of(self, vertices) -> np.ndarray:
        """Meshes (N, n, 3), one mesh or a collection -> normalised feature rows (N, K) float64 (network input)."""
        return self.normalizer_.transform(self.kind_.encode(self._meshes(vertices)))

    @torch.no_grad()
    def encode_rows(self, rows, conditions=None) -> tuple[np.ndarray, np.ndarray]:
        """The encoder on normalised rows ``(N, K)`` (and condition vectors ``(N, C)``): its posterior
        ``(mu, sigma)``, both (N, D) float64."""
        X = check_rows(rows, "feature rows", self.n_features, single=False)
        c = self.conditions_.vectors(len(X), conditions)
        mu, sigma = self.network_.eval().encode(torch.from_numpy(X.astype(np.float32)),
                                                None if c is None else torch.from_numpy(c))
        return mu.double().numpy(), sigma.double().numpy()

    def encode_meshes(self, vertices, conditions=None, labels=None, return_sigma: bool = False, inference=None,
                      iterations: int | None = None, progress: bool = False):
        """Latent codes (N, D) float64 of meshes (N, n, 3), one mesh or a collection.

        inference : a name of :data:`~meshvae_lib.model.inference.METHODS` or a strategy for this
            call; None: the model's own (``self.inference``, default "gauss-newton": the encoder's
            mean refined on the vertex error, never worse than it; "encoder": the paper's means).
        iterations : steps of a fitting strategy (None: its default).
        progress : a progress bar over the meshes (fitting strategies).

        For a conditional model give ``conditions (N, C)`` or ``labels`` (dict column -> (N,)); a
        collection's own labels are used when neither is given. ``return_sigma``: also the
        encoder's posterior deviations (N, D). A Gauss-Newton call leaves its report (errors
        before and after, steps per mesh) in ``last_inference_``.
        """
        labels = self._labels_of(vertices, conditions, labels)
        V = self._meshes(vertices)
        C = self.conditions_.vectors(len(V), conditions, labels)
        options = {} if iterations is None else {"iterations": iterations}
        strategy = make_inference(self.inference if inference is None else inference, **options)
        Z = strategy.infer(self, V, C, **({"progress": True} if progress else {}))
        if strategy.report() is not None:
            self.last_inference_ = strategy.report()
        return (Z, self.encode_rows(self.features_of(V), C)[1]) if return_sigma else Z

    @torch.no_grad()
    def decode_latent(self, z, conditions=None, labels=None) -> np.ndarray:
        """Latent vectors (N, D) or (D,) -> meshes (N, n, 3) or (n, 3) float64."""
        z = check_rows(z, "latent vectors", self.latent_dim).astype(np.float32)
        single = z.ndim == 1
        z2 = z[None] if single else z
        c = self.conditions_.vectors(len(z2), conditions, labels)
        rows = self.network_.eval().decode(torch.from_numpy(np.ascontiguousarray(z2)),
                                           None if c is None else torch.from_numpy(c))
        V = self.kind_.decode(self.features_from_rows(rows.double().numpy()))
        return V[0] if single else V

    def features_from_rows(self, rows) -> np.ndarray:
        """The network's output rows (N, K) -> feature rows (N, K) float64 in the kind's units: a
        sigmoid output's range back to Eq. 3's [-a, a] (tanh: unchanged), then Eq. 3 inverted."""
        return self._fitted().normalizer_.inverse_transform(
            from_output_range(np.asarray(rows, dtype=np.float64), self.normalizer_.a, self.network_.output))

    def reconstruct(self, vertices, conditions=None, labels=None, inference=None, progress: bool = False) -> np.ndarray:
        """Encode (with the model's inference, or ``inference`` for this call) and decode: meshes
        (N, n, 3) -> (N, n, 3) float64."""
        labels = self._labels_of(vertices, conditions, labels)
        z = self.encode_meshes(vertices, conditions, labels, inference=inference, progress=progress)
        return self.decode_latent(z, conditions, labels)

    # -- the prior -----------------------------------------------------------------------------
    def sample_latent(self, n: int, seed: int = 0, temperature: float = 1.0) -> np.ndarray:
        """n draws from the prior N(0, diag(sigma_object^2)), deviations times ``temperature`` (1: the
        paper's prior; below 1 the draws stay nearer the training poses, docs/vae.md): (n, D) float64."""
        n, t = check_count(n, "n", minimum=1), check_positive(temperature, "temperature")
        return np.random.default_rng(seed).standard_normal((n, self.latent_dim)) * self.sigma_object_ * t

    def generate(self, n: int, seed: int = 0, condition: dict | None = None, return_latents: bool = False,
                 temperature: float = 1.0):
        """n new meshes decoded from prior samples (Sec. 5, "Generation"; ``temperature``: :meth:`sample_latent`).

        ``condition``: ``{column: value}`` for a conditional model (unset columns are drawn from
        the training labels, seeded by ``seed``).

        Returns ``V (n, n_vertices, 3) float64``, or with ``return_latents`` ``(V, z (n, D)
        float64, c (n, C) float32 or None)``: the prior draws and condition vectors behind them.
        """
        if condition and not self.is_conditional:
            raise ValueError(f"this model is unconditional; it takes no condition, got {condition!r}")
        z = self.sample_latent(n, seed, temperature)
        c = self.condition_vector(condition, n=n, seed=seed) if self.is_conditional else None
        V = np.asarray(self.decode_latent(z, conditions=c), dtype=np.float64).reshape(int(n), -1, 3)
        return (V, z, c) if return_latents else V

    # -- persistence ---------------------------------------------------------------------------
    def save(self, path) -> Path:
        """Write the checkpoint (one file, atomically; read it with :func:`load_model`). Returns the path."""
        return checkpoint.write_checkpoint(path, self.state_dict())

    def _params(self) -> dict:
        inference = self.inference if isinstance(self.inference, str) else \
            {"name": self.inference.name, "options": self.inference.get_options()}
        return {"features": self.features, "labels": list(self.labels), "holdout_every": int(self.holdout_every),
                "layout": self.layout, "reference_index": int(self.reference_index), "inference": inference}

    def state_dict(self) -> dict:
        """The fitted model, all of it (arrays, tensors, numbers, strings, lists, dicts): what the checkpoint stores."""
        net = self._fitted().network_
        return {
            "architecture": net.architecture,
            "network_config": net.config(),
            "network_state": {k: v.detach().cpu().clone() for k, v in net.state_dict().items()},
            "normalizer": self.normalizer_.state_dict(),
            "kind": self.kind_.state_dict(),
            "conditions": self.conditions_.state_dict(),
            "train_conditions": np.ascontiguousarray(self.train_conditions_, dtype=np.float32),
            "sigma_object": np.asarray(self.sigma_object_, dtype=np.float64),
            "train_config": self.train_config_.to_dict(),
            "estimator": self._params(),
            "holdout_mask": np.asarray(self.holdout_mask_, dtype=bool),
            "mesh_fingerprints": self.mesh_fingerprints_,
            "history": [dict(h) for h in self.history_],
            "train_seconds": float(self.train_seconds_),
            "train_epochs": int(self.train_epochs_),
            "selection": self.selection_,
        }

    @classmethod
    def from_state_dict(cls, state: dict) -> "MeshVAEModel":
        """The fitted model :meth:`state_dict` describes (the network in eval mode, on the CPU)."""
        config = TrainConfig(**{**state["train_config"], "progress": False})
        params = dict(state["estimator"])
        inference = params.pop("inference", DEFAULT_INFERENCE)
        if isinstance(inference, dict):
            inference = make_inference(inference["name"], **inference["options"])
        model = cls(**params, config=config, inference=inference)
        model.network_ = network_from_config(state.get("architecture", DEFAULT_ARCHITECTURE), state["network_config"])
        model.network_.load_state_dict(state["network_state"])
        model.network_.eval()
        model.normalizer_ = FeatureNormalizer.from_state_dict(state["normalizer"])
        model.kind_ = kind_from_state(state["kind"])
        model.conditions_ = ConditionEncoder.from_state_dict(state["conditions"])
        model.train_conditions_ = np.asarray(state["train_conditions"], dtype=np.float32)
        model.sigma_object_ = np.asarray(state["sigma_object"], dtype=np.float64)
        model.holdout_mask_ = np.asarray(state["holdout_mask"], dtype=bool)
        prints = state.get("mesh_fingerprints")
        model.mesh_fingerprints_ = None if prints is None else np.asarray(prints, dtype=np.float64)
        model.train_config_ = config
        model.history_ = list(state["history"])
        model.train_seconds_ = float(state["train_seconds"])
        model.train_epochs_ = int(state["train_epochs"])
        model.selection_ = state["selection"]
        sizes = (model.normalizer_.n_features_in_, model.kind_.n_features, model.network_.n_features)
        if len(set(sizes)) != 1 or model.conditions_.n_conditions_ != model.network_.n_conditions:
            raise ValueError(f"its parts disagree: feature lengths {sizes}, conditions"
                             f" {model.conditions_.n_conditions_} and {model.network_.n_conditions}")
        return model

    def __repr__(self) -> str:
        if not hasattr(self, "network_"):
            return f"MeshVAEModel(features={self.features!r}, unfitted)"
        net = self.network_
        arch = "" if net.architecture == DEFAULT_ARCHITECTURE else f", architecture={net.architecture!r}"
        return (f"MeshVAEModel(features={self.kind_.name!r}, n_vertices={self.kind_.n_vertices},"
                f" K={net.n_features}, latent={net.latent_dim}, hidden={list(self.train_config_.hidden)}"
                f"{arch}, conditions={self.conditions_.columns})")


def load_model(path, collection=None) -> MeshVAEModel:
    """Read a checkpoint written by ``model.save(path)``.

    path : the checkpoint file.
    collection : optional data the model will be used with; a mesh with another vertex count or
        connectivity (or lacking the model's label columns) raises ValueError.

    Raises FileNotFoundError for a missing file and ValueError for a file that is not a mesh VAE
    checkpoint, is corrupted or truncated, or was written by a newer version.
    """
    state = checkpoint.read_checkpoint(path)
    try:
        model = MeshVAEModel.from_state_dict(state)
    except (KeyError, TypeError, RuntimeError, ValueError) as exc:
        raise ValueError(f"{path} is an incomplete or inconsistent mesh VAE checkpoint: {exc}") from exc
    if collection is not None:
        model.check_compatible(collection)
    return model
