"""Training the mesh VAE: seeded, repeatable, with a progress bar and a per-epoch history.

:func:`train_vae` trains a :class:`~meshvae_lib.model.vae.MeshVAE` on rows of *normalised* features
(Eq. 3) with Adam (lr 1e-3, the fused implementation: about 4x faster on a CPU than the default)
and the loss of Eq. 4. Everything random (initial weights, shuffling, the reparameterisation noise)
comes from ``config.seed``: the same seed gives bit-identical weights on a CPU.

The higher-level entry point, from a mesh collection to a model that decodes meshes, is
:meth:`meshvae_lib.model.meshvae_model.MeshVAEModel.fit`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import asdict, dataclass, field

import numpy as np
import torch

from meshvae_lib.tolerances import PCA_INIT_RTOL
from meshvae_lib.defaults import DEFAULT_ALPHA, DEFAULT_BATCH_SIZE, DEFAULT_EPOCHS, DEFAULT_LATENT, DEFAULT_LR, EARLY_STOPPING_PATIENCE, HIDDEN_COORDS, NORMALIZE_A, PCA_FEATURE_RANGE, VALIDATION_EVERY
from meshvae_lib.model.vae import PRIOR_FORMS, MeshVAE, start_step, vae_loss

__all__ = ["default_hidden", "TrainConfig", "TrainResult", "train_vae", "holdout_mask", "resolve_device",
           "pad_sigma_object", "pca_network", "INIT_MODES"]

#: how :func:`train_vae` initialises a new network.
from meshvae_lib.defaults import DEFAULT_INIT, INIT_MODES  # noqa: E402  (re-exported)

logger = logging.getLogger(__name__)


def default_hidden(kind: str = "rimd", init: str = "pca") -> tuple[int, ...]:
    """Internal layer sizes that did best for each feature kind (measured: see docs/vae.md).

    With the paper's random initialisation: none for RIMD, HIDDEN_COORDS for the coordinate
    baselines. With the PCA initialisation (``init="pca"``, see ``TrainConfig.init``): none for
    every kind, since a network without internal layers then starts at the linear floor, and on the
    real collections nothing trained from a random start came near it (docs/vae.md, issue 12).
    """
    if init not in INIT_MODES:
        raise ValueError(f"unknown init {init!r}; expected one of {INIT_MODES}")
    if kind not in ("rimd", "coords", "aligned"):
        raise ValueError(f"unknown feature kind {kind!r}")
    if kind == "rimd" or init == "pca":
        return ()
    return tuple(HIDDEN_COORDS)


@dataclass
class TrainConfig:
    """Training settings. The defaults train a good model for collections of 50-200 meshes.

    epochs : passes over the training set.
    batch_size : meshes per Adam step (the last batch is merged so that none has a single mesh,
        which batch norm cannot handle).
    lr : Adam learning rate (paper: 1e-3).
    alpha : weight of the reconstruction term (Eq. 4; paper: 1e6).
    latent_dim : D (paper: 128).
    hidden : internal layer sizes, outermost first (default: none).
    sigma_object : prior deviations (length D) or None for N(0, I) (Sec. 4.4). Shorter vectors are
        padded with 1 by :func:`pad_sigma_object`.
    prior_form : how sigma_object enters the latent cost, "exact" (the KL to N(0, diag
        sigma_object^2)) or "sibling" (the authors' sibling-code formula, which makes the chosen
        dimensions carry the dominant variation; see :func:`~meshvae_lib.model.vae.kl_divergence`).
    seed : seeds initial weights, shuffling and sampling.
    device : "auto" (a GPU when there is one, else the CPU), "cpu", "cuda", ...
    progress : show a tqdm progress bar (terminal or notebook).
    eval_every : evaluate the held-out rows every this many epochs (and at the last epoch); also
        how often early stopping looks at its validation meshes.
    init : "pca" (default) or "random" (PyTorch's initialisation: the paper's training; with
        ``early_stopping=False`` all ``epochs`` are trained, as the paper does). The PCA start is
        the library's departure from the paper: on real meshes the paper's training generalised
        2-6x worse than PCA of the coordinates (docs/vae.md, "Generalisation on real meshes").
        "pca": an unconditional network without internal layers
        and with the standard prior (``hidden=()``, ``sigma_object=None``) is built by
        :func:`pca_network`:
        its encoder sees the whitened principal coefficients of the training features and its
        decoder starts as the PCA reconstruction, so training starts at the linear floor. Other
        networks (internal layers, a sigma_object prior) and ``"random"`` use PyTorch's random
        initialisation on the K features (the paper's network); so do conditional networks, whose
        use of the condition has to be learned.
    feature_range : half-width a of the normalised range (Eq. 3) that
        :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` uses. None: PCA_FEATURE_RANGE (0.3) for
        PCA-initialised networks, the paper's 0.9 otherwise.
    early_stopping : None (default: on for PCA-initialised networks), True or False. When on and
        there are at least ``2 * validation_every`` training rows, every ``validation_every``-th
        row is set aside, a network is trained on the others and evaluated on them (feature MSE,
        encoded to the mean) before training and every ``eval_every`` epochs, until ``patience``
        epochs bring no improvement; then a new network is trained on *all* rows for the best
        number of epochs (which may be 0: the initialisation itself). ``epochs`` is the maximum.
    validation_every, patience : see ``early_stopping``.
    feature_scale : "component" (the paper's Eq. 3) or "shared" (one half-width for all components,
        see :class:`~meshvae_lib.model.normalization.FeatureNormalizer`). None: "shared" for coordinate
        features (``"coords"``, ``"aligned"``) of PCA-initialised networks, "component" otherwise.
    """

    epochs: int = DEFAULT_EPOCHS
    batch_size: int = DEFAULT_BATCH_SIZE
    lr: float = DEFAULT_LR
    alpha: float = DEFAULT_ALPHA
    latent_dim: int = DEFAULT_LATENT
    hidden: tuple[int, ...] = ()
    sigma_object: tuple[float, ...] | None = None
    prior_form: str = "exact"
    seed: int = 0
    device: str = "auto"
    progress: bool = True
    eval_every: int = 10
    init: str = DEFAULT_INIT
    feature_range: float | None = None
    early_stopping: bool | None = None
    validation_every: int = VALIDATION_EVERY
    patience: int = EARLY_STOPPING_PATIENCE
    feature_scale: str | None = None

    def uses_pca_init(self, n_conditions: int = 0) -> bool:
        """True when a new network is built by :func:`pca_network` (see ``init``)."""
        return self.init == "pca" and not self.hidden and self.sigma_object is None and n_conditions == 0

    def resolved_feature_range(self, pca: bool | None = None) -> float:
        """a of Eq. 3 for this config (``pca``: whether the PCA initialisation applies; None: ask)."""
        if self.feature_range is not None:
            return float(self.feature_range)
        pca = self.uses_pca_init() if pca is None else pca
        return PCA_FEATURE_RANGE if pca else NORMALIZE_A

    def resolved_feature_scale(self, kind: str, pca: bool | None = None) -> str:
        """How :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` sets the ranges of Eq. 3 for ``kind``."""
        if self.feature_scale is not None:
            return self.feature_scale
        pca = self.uses_pca_init() if pca is None else pca
        return "shared" if pca and kind in ("coords", "aligned") else "component"

    def resolved_early_stopping(self, pca: bool | None = None) -> bool:
        if self.early_stopping is not None:
            return bool(self.early_stopping)
        return self.uses_pca_init() if pca is None else bool(pca)

    def __post_init__(self):
        self.hidden = tuple(int(h) for h in self.hidden)
        if self.sigma_object is not None:
            self.sigma_object = tuple(float(s) for s in self.sigma_object)
        checks = {
            "epochs": self.epochs >= 1,
            "batch_size": self.batch_size >= 2,
            "lr": self.lr > 0,
            "alpha": self.alpha > 0,
            "latent_dim": self.latent_dim >= 1,
            "eval_every": self.eval_every >= 1,
            "prior_form": self.prior_form in PRIOR_FORMS,
            "init": self.init in INIT_MODES,
            "feature_range": self.feature_range is None or 0.0 < float(self.feature_range) < 1.0,
            "validation_every": self.validation_every >= 2,
            "patience": self.patience >= 1,
            "feature_scale": self.feature_scale in (None, "component", "shared"),
        }
        for name, ok in checks.items():
            if not ok:
                raise ValueError(f"TrainConfig.{name} is out of range: {getattr(self, name)!r}")

    def to_dict(self) -> dict:
        d = asdict(self)
        d["hidden"] = list(self.hidden)
        d["sigma_object"] = None if self.sigma_object is None else list(self.sigma_object)
        return d


@dataclass
class TrainResult:
    """What :func:`train_vae` returns.

    model : the trained network, in eval mode, on the CPU.
    history : one dict per epoch with the training means of ``total``, ``reconstruction``, ``kl``,
        ``mse`` and, on evaluation epochs, ``val_total``, ``val_reconstruction``, ``val_kl``,
        ``val_mse`` (held-out rows, encoded to their mean, no sampling).
        When the final network was not trained at all (early stopping chose 0 epochs) the history
        holds one record, epoch 0, with the training rows evaluated at their means.
    seconds : wall-clock training time (early stopping's selection run included).
    device : where it trained.
    epochs : epochs the returned network was trained for.
    selection : early stopping's record, or None when it was off: ``{"epochs": best,
        "validation_rows": [...], "history": [{"epoch", "val_mse"}, ...]}``.
    """

    model: MeshVAE
    history: list[dict] = field(default_factory=list)
    seconds: float = 0.0
    device: str = "cpu"
    epochs: int = 0
    selection: dict | None = None


def resolve_device(device: str = "auto") -> torch.device:
    """"auto" -> cuda when available, else cpu; anything else is passed to ``torch.device``."""
    if device == "auto":
        return torch.device("cuda" if torch.cuda.is_available() else "cpu")
    return torch.device(device)


def holdout_mask(n: int, every: int) -> np.ndarray:
    """Boolean (n,) mask of held-out meshes: every ``every``-th one (indices every-1, 2*every-1, ...).

    ``every = 0`` holds nothing out. Mesh 0 (the usual reference) is never held out.
    """
    if every < 0 or every == 1:
        raise ValueError(f"holdout every must be 0 (none) or >= 2, got {every}")
    mask = np.zeros(n, dtype=bool)
    if every:
        mask[every - 1 :: every] = True
    return mask


def pad_sigma_object(sigma_object, latent_dim: int) -> np.ndarray | None:
    """sigma_object of length <= D, padded with 1 to (D,) float64; None stays None."""
    if sigma_object is None:
        return None
    s = np.asarray(sigma_object, dtype=np.float64).ravel()
    if s.size > latent_dim:
        raise ValueError(f"sigma_object has {s.size} entries but the latent size is {latent_dim}")
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"sigma_object entries must be positive and finite, got {s.tolist()}")
    return np.concatenate([s, np.ones(latent_dim - s.size)])


def _as_tensor(x, name: str, rows: int | None = None) -> torch.Tensor:
    a = np.asarray(x, dtype=np.float32)
    if a.ndim != 2:
        raise ValueError(f"{name} must be 2-D (n_meshes, n), got shape {a.shape}")
    if rows is not None and a.shape[0] != rows:
        raise ValueError(f"{name} has {a.shape[0]} rows, expected {rows}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} holds non-finite values")
    return torch.from_numpy(np.ascontiguousarray(a))


def _batches(n: int, batch_size: int, perm: torch.Tensor) -> list[torch.Tensor]:
    n_batches = max(1, n // batch_size)  # the remainder joins the other batches: none of size 1
    return list(torch.tensor_split(perm, n_batches))


@torch.no_grad()
def _evaluate(model, x, c, alpha, sigma_object, prior_form) -> dict:
    model.eval()
    mu, sigma = model.encode(x, c)
    parts = vae_loss(model.decode(mu, c), x, mu, sigma, alpha, sigma_object, prior_form)
    return {f"val_{k}": float(v) for k, v in parts.items()}


def pca_network(x: torch.Tensor, config: "TrainConfig", n_conditions: int = 0) -> MeshVAE:
    """A network without internal layers whose decoded means start as the training rows' PCA.

    x : (N, K) float32 normalised training rows (N >= 2); config : the latent size, alpha and
    sigma_max come from it (``config.hidden`` must be empty). With r = min(D, rank, N - 1)
    principal directions v_k of the centred rows and their coefficient spreads c_k (singular
    value / sqrt(N - 1)):

    - input projection: ``input_mean`` = the rows' mean, ``input_basis`` row k = v_k / c_k, so the
      encoder sees whitened coefficients w (unit variance over the training rows, as the prior);
    - encoder: mu = w in the first r latent dimensions (0 in the others); the deviation is the
      posterior deviation of a linear-Gaussian model with this decoder and the noise variance
      K / alpha that Eq. 4 implies, sigma_k = (1 + alpha c_k^2 / K)^(-1/2) (1 in unused
      dimensions, where the latent cost is then 0);
    - decoder: pre-activations ``b + W mu`` fitted by least squares to atanh of the training rows,
      so that tanh(b + W mu) reproduces every training row when r = N - 1.

    Condition inputs (n_conditions > 0) start with zero weights. Returns a MeshVAE in train mode.
    """
    if config.hidden:
        raise ValueError("the PCA initialisation is for networks without internal layers (hidden=())")
    X = x.detach().double().cpu().numpy()
    n, k = X.shape
    mean = X.mean(axis=0)
    Xc = X - mean
    # SVD through the small (N, N) Gram matrix: K may be ~1e5-1e6, N ~ 1e2
    w, U = np.linalg.eigh(Xc @ Xc.T)
    order = np.argsort(w)[::-1]
    s = np.sqrt(np.clip(w[order], 0.0, None))
    U = U[:, order]
    r = int(min(config.latent_dim, n - 1, np.sum(s > s[0] * PCA_INIT_RTOL))) if s[0] > 0 else 0
    r = max(r, 1)
    s_r = np.maximum(s[:r], s[0] * PCA_INIT_RTOL if s[0] > 0 else 1.0)
    V = (U[:, :r].T @ Xc) / s_r[:, None]  # (r, K) orthonormal directions
    c = s_r / np.sqrt(max(n - 1, 1))
    Z = Xc @ V.T / c  # (N, r) whitened coefficients
    A = np.arctanh(np.clip(X, -1 + 1e-6, 1 - 1e-6))
    sol, *_ = np.linalg.lstsq(np.c_[Z, np.ones(n)], A, rcond=None)  # (r + 1, K)
    D = config.latent_dim
    net = MeshVAE(k, D, (), n_conditions, input_rank=r)
    sigma = 1.0 / np.sqrt(1.0 + config.alpha * c ** 2 / k)
    sigma_logit = np.log(sigma / (net.sigma_max - sigma))
    f32 = lambda a: torch.as_tensor(np.ascontiguousarray(a), dtype=torch.float32)  # noqa: E731
    with torch.no_grad():
        net.input_mean.copy_(f32(mean))
        net.input_basis.copy_(f32(V / c[:, None]))
        net.encoder_head.weight.zero_()
        net.encoder_head.bias.zero_()
        net.encoder_head.weight[:r, :r] = torch.eye(r)
        net.encoder_head.bias[D:] = float(np.log(1.0 / (net.sigma_max - 1.0)))  # sigma = 1
        net.encoder_head.bias[D:D + r] = f32(sigma_logit)
        net.decoder_head.weight.zero_()
        net.decoder_head.weight[:, :r] = f32(sol[:r].T)
        net.decoder_head.bias.copy_(f32(sol[r]))
    return net


def _new_network(x, n_cond, config, pca: bool) -> MeshVAE:
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(config.seed)
        if pca:
            return pca_network(x, config, n_cond)
        return MeshVAE(x.shape[1], config.latent_dim, config.hidden, n_cond)


def _run(model, x, c, config, epochs, device, xv=None, cv=None, so_t=None, select=False, desc="training mesh VAE"):
    """Train ``model`` in place for up to ``epochs`` epochs. Returns (history, best_epoch).

    With ``select`` the validation rows (xv, cv) are evaluated before training and every
    ``eval_every`` epochs; training stops after ``config.patience`` epochs without a lower
    validation MSE, and best_epoch is the epoch of the lowest (0: before training).
    """
    n = x.shape[0]
    optimizer = torch.optim.Adam(model.parameters(), lr=config.lr, fused=True)
    shuffle_gen = torch.Generator().manual_seed(config.seed + 1)
    noise_gen = torch.Generator(device=device).manual_seed(config.seed + 2)

    from tqdm.auto import tqdm

    history: list[dict] = []
    best_epoch, best_val = 0, np.inf
    if select:
        best_val = _evaluate(model, xv, cv, config.alpha, so_t, config.prior_form)["val_mse"]
        history.append({"epoch": 0, "val_mse": best_val})
    bar = tqdm(range(epochs), desc=desc, unit="epoch", disable=not config.progress)
    for epoch in bar:
        model.train()
        sums = {"total": 0.0, "reconstruction": 0.0, "kl": 0.0, "mse": 0.0}
        perm = torch.randperm(n, generator=shuffle_gen)
        for idx in _batches(n, config.batch_size, perm):
            idx = idx.to(device)
            xb = x[idx]
            cb = None if c is None else c[idx]
            x_hat, mu, sigma = model(xb, cb, generator=noise_gen)
            parts = vae_loss(x_hat, xb, mu, sigma, config.alpha, so_t, config.prior_form)
            start_step(model)  # zero the gradients, keeping the big buffers (see vae.Linear)
            parts["total"].backward()
            optimizer.step()
            w = len(idx) / n
            for key in sums:
                sums[key] += w * float(parts[key].detach())
        if not np.isfinite(sums["total"]):
            bar.close()
            raise ValueError(f"training diverged at epoch {epoch + 1} (loss {sums['total']}); try a smaller"
                             f" learning rate (now {config.lr:g}) or alpha (now {config.alpha:g})")
        last = epoch + 1 == epochs
        if select:
            if (epoch + 1) % config.eval_every == 0 or last:
                val = _evaluate(model, xv, cv, config.alpha, so_t, config.prior_form)["val_mse"]
                history.append({"epoch": epoch + 1, "mse": sums["mse"], "val_mse": val})
                if val < best_val:
                    best_epoch, best_val = epoch + 1, val
                elif epoch + 1 - best_epoch >= config.patience:
                    break
            continue
        record = {"epoch": epoch + 1, **sums}
        if xv is not None and ((epoch + 1) % config.eval_every == 0 or last):
            record.update(_evaluate(model, xv, cv, config.alpha, so_t, config.prior_form))
        history.append(record)
        logger.debug("epoch %d: %s", epoch + 1, record)
        if config.progress:
            post = {"loss": f"{sums['total']:.4g}", "kl": f"{sums['kl']:.3g}"}
            if "val_mse" in record:
                post["val_mse"] = f"{record['val_mse']:.3g}"
            bar.set_postfix(post, refresh=False)
    bar.close()
    return history, best_epoch


def train_vae(
    features,
    conditions=None,
    config: TrainConfig | None = None,
    val_features=None,
    val_conditions=None,
    model: MeshVAE | None = None,
) -> TrainResult:
    """Train a mesh VAE on normalised feature rows.

    Parameters
    ----------
    features : (N, K) float, normalised (Eq. 3), N >= 2.
    conditions : (N, C) float or None (conditional mesh VAE, Eq. 5).
    config : TrainConfig (defaults when None). With ``init="pca"`` (the default) a network without internal layers is PCA-initialised (:func:`pca_network`)
        and the number of epochs is chosen by early stopping on every ``validation_every``-th
        training row (see :class:`TrainConfig`).
    val_features, val_conditions : (M, K), (M, C) held-out rows, optional: only recorded in the
        history (``val_*``), never used to choose anything.
    model : continue training this network instead of building a new one (no PCA initialisation
        and no early stopping then, unless ``config.early_stopping`` is True, which is refused).

    Returns
    -------
    TrainResult with the network (eval mode, CPU), the per-epoch history, the number of epochs and
    early stopping's record.
    """
    config = config or TrainConfig()
    x = _as_tensor(features, "features")
    n, k = x.shape
    if n < 2:
        raise ValueError(f"need at least 2 training meshes, got {n}")
    c = None if conditions is None else _as_tensor(conditions, "conditions", n)
    n_cond = 0 if c is None else c.shape[1]
    xv = None if val_features is None or len(val_features) == 0 else _as_tensor(val_features, "val_features")
    cv = None
    if xv is not None and n_cond:
        if val_conditions is None:
            raise ValueError("the model is conditional: give val_conditions with val_features")
        cv = _as_tensor(val_conditions, "val_conditions", xv.shape[0])

    device = resolve_device(config.device)
    pca = model is None and config.uses_pca_init(n_cond)
    if model is not None:
        if config.early_stopping:
            raise ValueError("early stopping builds its own networks; it cannot continue a given model")
        if model.n_features != k or model.n_conditions != n_cond:
            raise ValueError(
                f"the given model expects {model.n_features} features and {model.n_conditions} conditions,"
                f" got {k} and {n_cond}"
            )
    early = model is None and config.resolved_early_stopping(pca) and n >= 2 * config.validation_every
    latent = model.latent_dim if model is not None else config.latent_dim
    so = pad_sigma_object(config.sigma_object, latent)
    so_t = None if so is None else torch.as_tensor(so, dtype=torch.float32, device=device)

    t0 = time.perf_counter()
    epochs, selection = config.epochs, None
    if early:
        vmask = holdout_mask(n, config.validation_every)
        fit_i, val_i = torch.from_numpy(np.flatnonzero(~vmask)), torch.from_numpy(np.flatnonzero(vmask))
        x_fit = x[fit_i]
        probe = _new_network(x_fit, n_cond, config, pca).to(device)
        sel_history, epochs = _run(probe, x_fit.to(device), None if c is None else c[fit_i].to(device), config,
                                   config.epochs, device, x[val_i].to(device),
                                   None if c is None else c[val_i].to(device), so_t, select=True,
                                   desc="choosing epochs")
        selection = {"epochs": int(epochs), "validation_rows": [int(i) for i in val_i], "history": sel_history}
        logger.info("early stopping chose %d epochs (validation MSE %s)", epochs,
                    min(h["val_mse"] for h in sel_history))
        del probe
    if model is None:
        model = _new_network(x, n_cond, config, pca)
    model.to(device)
    x = x.to(device)
    c = None if c is None else c.to(device)
    if xv is not None:
        xv = xv.to(device)
        cv = None if cv is None else cv.to(device)
    history, _ = _run(model, x, c, config, epochs, device, xv, cv, so_t)
    if not history:  # not trained at all: record the starting point
        record = {"epoch": 0, **{k_[4:]: v for k_, v in _evaluate(model, x, c, config.alpha, so_t,
                                                                    config.prior_form).items()}}
        if xv is not None:
            record.update(_evaluate(model, xv, cv, config.alpha, so_t, config.prior_form))
        history.append(record)
    seconds = time.perf_counter() - t0
    logger.info("trained %d epochs in %.1f s on %s; final %s", epochs, seconds, device, history[-1])
    model.eval()
    model.to("cpu")
    return TrainResult(model=model, history=history, seconds=seconds, device=str(device), epochs=int(epochs),
                       selection=selection)
