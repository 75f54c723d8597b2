"""The training configuration of the mesh VAE (every option of :func:`~meshvae_lib.model.training.train_vae`),
the default network size per feature kind and the prior deviations sigma_object padded to the latent size.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields, replace

import numpy as np

from meshvae_lib.defaults import (DEFAULT_ALPHA, DEFAULT_ARCHITECTURE, DEFAULT_BATCH_SIZE,
                                  DEFAULT_FEATURE_KIND, DEFAULT_INIT, DEFAULT_LATENT, DEFAULT_LR, PCA_LATENT_MAX,
                                  EARLY_STOPPING_PATIENCE, INIT_MODES, LOSSES, NORMALIZE_A,
                                  PCA_NORMALIZE_A, PRIOR_FORMS, VALIDATION_EVERY)
from meshvae_lib.model.feature_kinds import kind_class
from meshvae_lib.model.networks import ARCHITECTURES, network_class
from meshvae_lib.validation import check_choice

__all__ = ["TrainConfig", "default_hidden", "pad_sigma_object"]


def default_hidden(kind: str = DEFAULT_FEATURE_KIND, init: str = DEFAULT_INIT) -> tuple[int, ...]:
    """Internal layer sizes that did best for each feature kind (measured: see docs/vae.md).

    With the paper's random initialisation: the kind's ``random_hidden`` (none for RIMD,
    ``defaults.HIDDEN_COORDS`` for the coordinate baselines). With the PCA initialisation
    (``init="pca"``, see ``TrainConfig.init``): none for every kind, since a network without
    internal layers then starts at the linear floor, and on the real collections nothing trained
    from a random start came near it (docs/vae.md, issue 12).
    """
    check_choice(init, INIT_MODES, "init")
    hidden = kind_class(kind).random_hidden
    return () if init == "pca" else tuple(hidden)


def pad_sigma_object(sigma_object, latent_dim: int) -> np.ndarray | None:
    """Prior deviations sigma_object (Sec. 4.4) of length <= D, padded with 1 to (D,) float64
    (``defaults.EMBEDDING_SIGMA_OBJECT`` and ``EXPLORATION_SIGMA_OBJECT`` are such heads); None
    stays None."""
    if sigma_object is None:
        return None
    s = np.asarray(sigma_object, dtype=np.float64).ravel()
    if s.size > latent_dim:
        raise ValueError(f"sigma_object has {s.size} entries but the latent size is {latent_dim}")
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"sigma_object entries must be positive and finite, got {s.tolist()}")
    return np.concatenate([s, np.ones(latent_dim - s.size)])


@dataclass
class TrainConfig:
    """Training settings. The defaults train a good model for collections of 50-200 meshes.

    epochs : passes over the training set (None: the architecture's, 1000 for the mesh VAE, 300
        for the spiral network).
    batch_size : meshes per Adam step (the last batch is merged so that none has a single mesh,
        which batch norm cannot handle).
    lr : Adam learning rate (paper: 1e-3).
    alpha : weight of the reconstruction term (Eq. 4; paper: 1e6).
    latent_dim : D (paper: 128). None (default): the architecture's (128; the spiral network's 16), except for a network that starts at the
        PCA of its rows (``uses_pca_init``), which gets one dimension per direction its N training
        rows span, ``N - 1``, when that is more (at most ``PCA_LATENT_MAX``): with fewer, the PCA
        start drops the smallest directions and the training meshes themselves are not reproduced
        (:meth:`resolved_latent_dim`; docs/vae.md, "Inference by Gauss-Newton").
    hidden : internal layer sizes, outermost first (default: none).
    sigma_object : prior deviations (length D) or None for N(0, I) (Sec. 4.4). Shorter vectors are
        padded with 1 by :func:`pad_sigma_object`.
    prior_form : how sigma_object enters the latent cost, "exact" (the KL to N(0, diag
        sigma_object^2)) or "sibling" (the authors' sibling-code formula, which makes the chosen
        dimensions carry the dominant variation; see :func:`~meshvae_lib.model.loss.kl_divergence`).
    seed : seeds initial weights, shuffling and sampling.
    device : "auto" (a GPU when there is one, else the CPU), "cpu", "cuda", ...
    progress : show a tqdm progress bar (terminal or notebook).
    eval_every : evaluate the held-out rows every this many epochs (and at the last epoch); also
        how often early stopping looks at its validation meshes.
    architecture : the network (a name of :data:`~meshvae_lib.model.networks.ARCHITECTURES`;
        default ``"mesh-vae"``, :class:`~meshvae_lib.model.vae.MeshVAE`; ``"spiral"``,
        :class:`~meshvae_lib.model.spiral_net.SpiralVAE`). What ``epochs``, ``output``, ``loss`` and
        ``latent_dim`` left at None mean is the architecture's (:func:`~meshvae_lib.model.networks.train_defaults`).
    network_options : the architecture's own options (the spiral network's ``channels``,
        ``spiral_length``, ``factors``); empty: its defaults.
    init : "pca" (default) or "random" (PyTorch's initialisation: the paper's training; with
        ``early_stopping=False`` all ``epochs`` are trained, as the paper does). The PCA start is
        the library's departure from the paper: on real meshes the paper's training generalised
        2-6x worse than PCA of the coordinates (docs/vae.md, "Generalisation on real meshes").
        "pca": an unconditional network without internal layers
        and with the standard prior (``hidden=()``, ``sigma_object=None``) is built by
        :meth:`~meshvae_lib.model.vae.MeshVAE.from_pca`:
        its encoder sees the whitened principal coefficients of the training features and its
        decoder starts as the PCA reconstruction, so training starts at the linear floor. Other
        networks (internal layers, a sigma_object prior) and ``"random"`` use PyTorch's random
        initialisation on the K features (the paper's network); so do conditional networks, whose
        use of the condition has to be learned.
    a : the half-width a of the normalised range [-a, a] (Eq. 3) that
        :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` normalises to and a sigmoid output is
        mapped from. None: ``defaults.PCA_NORMALIZE_A`` (0.3) for PCA-initialised networks, the
        paper's ``NORMALIZE_A`` (0.9) otherwise (:meth:`resolved_a`).
    early_stopping : None (default: on for PCA-initialised networks), True or False. When on and
        there are at least ``2 * validation_every`` training rows, every ``validation_every``-th
        row is set aside, a network is trained on the others and evaluated on them (feature MSE,
        encoded to the mean) before training and every ``eval_every`` epochs, until ``patience``
        epochs bring no improvement; then a new network is trained on *all* rows for the best
        number of epochs (which may be 0: the initialisation itself). ``epochs`` is the maximum.
    validation_every, patience : see ``early_stopping``.
    feature_scale : "component" (the paper's Eq. 3) or "shared" (one half-width for all components,
        see :class:`~meshvae_lib.model.normalization.FeatureNormalizer`). None: the feature kind's
        ``pca_scale`` for PCA-initialised networks ("shared" for the coordinate kinds), "component"
        otherwise.
    sigma_floor, output : the new network's options (see :class:`~meshvae_lib.model.vae.MeshVAE`):
        a floor added to the deviation (default 0) and the decoder's last activation, "tanh"
        (the mesh VAE's default) or "sigmoid" ("linear" for the spiral network). A sigmoid network is trained on the rows mapped to
        ``BCE_TARGET_RANGE`` (:func:`to_output_range`) and is never PCA-initialised.
    loss : the reconstruction term, "mse" (Eq. 4, the mesh VAE's default), "bce" (binary
        cross-entropy, needs ``output="sigmoid"``) or "l1" (the spiral network's default; see
        :func:`~meshvae_lib.model.loss.vae_loss`).
    """

    epochs: int | None = None
    batch_size: int = DEFAULT_BATCH_SIZE
    lr: float = DEFAULT_LR
    alpha: float = DEFAULT_ALPHA
    latent_dim: int | None = None
    hidden: tuple[int, ...] = ()
    sigma_object: tuple[float, ...] | None = None
    prior_form: str = "exact"
    seed: int = 0
    device: str = "auto"
    progress: bool = True
    eval_every: int = 10
    init: str = DEFAULT_INIT
    a: float | None = None
    early_stopping: bool | None = None
    validation_every: int = VALIDATION_EVERY
    patience: int = EARLY_STOPPING_PATIENCE
    feature_scale: str | None = None
    sigma_floor: float = 0.0
    output: str | None = None
    loss: str | None = None
    architecture: str = DEFAULT_ARCHITECTURE
    network_options: dict = field(default_factory=dict)

    # The resolvers: what the options left at None mean for a network with ``n_conditions``
    # condition inputs (the estimator and the trainer both ask these, nobody else decides).
    def uses_pca_init(self, n_conditions: int = 0) -> bool:
        """True when a new network starts at the PCA of its rows (:meth:`~meshvae_lib.model.vae.MeshVAE.from_pca`;
        see ``init``)."""
        return (self.init == "pca" and not self.hidden and self.sigma_object is None and n_conditions == 0
                and self.output == "tanh" and network_class(self.architecture).pca_start)

    def resolved_latent_dim(self, n_rows: int, n_conditions: int = 0) -> int:
        """D for a new network trained on ``n_rows`` rows (see ``latent_dim``)."""
        if self.latent_dim is None and "latent_dim" not in network_class(self.architecture).train_defaults \
                and self.uses_pca_init(n_conditions):
            return int(min(max(DEFAULT_LATENT, int(n_rows) - 1), max(PCA_LATENT_MAX, DEFAULT_LATENT)))
        return self.nominal_latent_dim()

    def nominal_latent_dim(self) -> int:
        """D before the rows are known: ``latent_dim``, or the architecture's default (the PCA start
        may choose more, :meth:`resolved_latent_dim`)."""
        if self.latent_dim is not None:
            return int(self.latent_dim)
        return int(network_class(self.architecture).train_defaults.get("latent_dim", DEFAULT_LATENT))

    def resolved_a(self, n_conditions: int = 0) -> float:
        """a of Eq. 3 (see ``a``)."""
        if self.a is not None:
            return float(self.a)
        return PCA_NORMALIZE_A if self.uses_pca_init(n_conditions) else NORMALIZE_A

    def resolved_feature_scale(self, kind: str, n_conditions: int = 0) -> str:
        """How :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` sets the ranges of Eq. 3 for
        the feature kind ``kind`` (see ``feature_scale``)."""
        if self.feature_scale is not None:
            return self.feature_scale
        return kind_class(kind).pca_scale if self.uses_pca_init(n_conditions) else "component"

    def resolved_early_stopping(self, n_conditions: int = 0) -> bool:
        """Whether a new network's epochs are chosen by early stopping (see ``early_stopping``)."""
        if self.early_stopping is not None:
            return bool(self.early_stopping)
        return self.uses_pca_init(n_conditions)

    def resolve(self, n_rows: int, n_conditions: int = 0, kind: str | None = None) -> "TrainConfig":
        """The configuration a new network on ``n_rows`` training rows with ``n_conditions``
        condition inputs and the feature kind ``kind`` is trained with: every option left at None
        that the rows decide resolved, once, by the rules above (``latent_dim``, ``a`` and, given
        ``kind``, ``feature_scale``). ``early_stopping`` keeps None, "the default"
        (:meth:`resolved_early_stopping`; True asks for an epoch search the default may skip). The
        estimator writes the result into its checkpoint."""
        return replace(self,
                       latent_dim=self.resolved_latent_dim(n_rows, n_conditions),
                       a=self.resolved_a(n_conditions),
                       feature_scale=self.feature_scale if kind is None else self.resolved_feature_scale(kind, n_conditions))

    def __post_init__(self):
        if self.architecture not in ARCHITECTURES:
            raise ValueError(f"TrainConfig.architecture must be one of {tuple(ARCHITECTURES)}, got {self.architecture!r}")
        net = network_class(self.architecture)
        self.epochs = net.train_defaults["epochs"] if self.epochs is None else self.epochs
        self.output = net.train_defaults["output"] if self.output is None else self.output
        self.loss = net.train_defaults["loss"] if self.loss is None else self.loss
        self.network_options = dict(self.network_options or {})
        known = [f.name for f in fields(net.Options)]
        if set(self.network_options) - set(known):
            raise ValueError(f"TrainConfig.network_options: the {self.architecture!r} network takes"
                             f" {sorted(known) or 'none'}, got {sorted(self.network_options)}")
        net.options(self)  # the options' own checks
        self.hidden = tuple(int(h) for h in self.hidden)
        if self.sigma_object is not None:
            self.sigma_object = tuple(float(s) for s in self.sigma_object)
        self.sigma_floor = float(self.sigma_floor)
        checks = {
            "epochs": self.epochs >= 1,
            "batch_size": self.batch_size >= 2,
            "lr": self.lr > 0,
            "alpha": self.alpha > 0,
            "latent_dim": self.latent_dim is None or int(self.latent_dim) >= 1,
            "eval_every": self.eval_every >= 1,
            "prior_form": self.prior_form in PRIOR_FORMS,
            "init": self.init in INIT_MODES,
            "a": self.a is None or 0.0 < float(self.a) < 1.0,
            "validation_every": self.validation_every >= 2,
            "patience": self.patience >= 1,
            "feature_scale": self.feature_scale in (None, "component", "shared"),
            "sigma_floor": 0.0 <= float(self.sigma_floor) < float("inf"),
            "output": self.output in net.outputs,
            "loss": self.loss in LOSSES and (self.loss != "bce" or self.output == "sigmoid"),
        }
        for name, ok in checks.items():
            if not ok:
                raise ValueError(f"TrainConfig.{name} is out of range: {asdict(self)[name]!r}")
        if self.sigma_object is not None and len(self.sigma_object) > self.nominal_latent_dim():
            raise ValueError(f"TrainConfig.sigma_object has {len(self.sigma_object)} values, more than latent_dim"
                             f" {self.nominal_latent_dim()}")
        net.check_config(self)

    def to_dict(self) -> dict:
        d = asdict(self)
        d["hidden"] = list(self.hidden)
        d["sigma_object"] = None if self.sigma_object is None else list(self.sigma_object)
        d["network_options"] = {k: (list(v) if isinstance(v, (tuple, list)) else v) for k, v in self.network_options.items()}
        return d
