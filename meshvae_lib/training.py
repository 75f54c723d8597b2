"""Training the mesh VAE: seeded, repeatable, with a progress bar and a per-epoch history.

:func:`train_vae` trains a :class:`~meshvae_lib.vae.MeshVAE` on rows of *normalised* features
(Eq. 3) with Adam (lr 1e-3, the fused implementation: about 4x faster on a CPU than the default)
and the loss of Eq. 4. Everything random (initial weights, shuffling, the reparameterisation noise)
comes from ``config.seed``: the same seed gives bit-identical weights on a CPU.

The higher-level entry point, from a mesh collection to a model that decodes meshes, is
:meth:`meshvae_lib.checkpoint.MeshVAEModel.fit`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import asdict, dataclass, field

import numpy as np
import torch

from .tolerances import DEFAULT_ALPHA, DEFAULT_BATCH_SIZE, DEFAULT_EPOCHS, DEFAULT_LATENT, DEFAULT_LR, HIDDEN_COORDS
from .vae import PRIOR_FORMS, MeshVAE, start_step, vae_loss

__all__ = ["default_hidden", "TrainConfig", "TrainResult", "train_vae", "holdout_mask", "resolve_device", "pad_sigma_object"]

logger = logging.getLogger(__name__)


def default_hidden(kind: str = "rimd") -> tuple[int, ...]:
    """Internal layer sizes that did best for each feature kind (measured: see docs/vae.md).

    RIMD: none (the paper's features are already nearly linear in the latent factors; a hidden
    layer costs about 5x per step at K ~ 165k). Coordinate baselines: HIDDEN_COORDS.
    """
    if kind == "rimd":
        return ()
    if kind in ("coords", "aligned"):
        return tuple(HIDDEN_COORDS)
    raise ValueError(f"unknown feature kind {kind!r}")


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
        dimensions carry the dominant variation; see :func:`~meshvae_lib.vae.kl_divergence`).
    seed : seeds initial weights, shuffling and sampling.
    device : "auto" (a GPU when there is one, else the CPU), "cpu", "cuda", ...
    progress : show a tqdm progress bar (terminal or notebook).
    eval_every : evaluate the held-out rows every this many epochs (and at the last epoch).
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
    seconds : wall-clock training time.
    device : where it trained.
    """

    model: MeshVAE
    history: list[dict] = field(default_factory=list)
    seconds: float = 0.0
    device: str = "cpu"


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
    config : TrainConfig (defaults when None).
    val_features, val_conditions : (M, K), (M, C) held-out rows, optional.
    model : continue training this network instead of building a new one.

    Returns
    -------
    TrainResult with the network (eval mode, CPU) and the per-epoch history.
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
    if model is None:
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(config.seed)
            model = MeshVAE(k, config.latent_dim, config.hidden, n_cond)
    elif model.n_features != k or model.n_conditions != n_cond:
        raise ValueError(
            f"the given model expects {model.n_features} features and {model.n_conditions} conditions,"
            f" got {k} and {n_cond}"
        )
    so = pad_sigma_object(config.sigma_object, model.latent_dim)
    so_t = None if so is None else torch.as_tensor(so, dtype=torch.float32, device=device)
    model.to(device)
    x = x.to(device)
    c = None if c is None else c.to(device)
    if xv is not None:
        xv = xv.to(device)
        cv = None if cv is None else cv.to(device)

    optimizer = torch.optim.Adam(model.parameters(), lr=config.lr, fused=True)
    shuffle_gen = torch.Generator().manual_seed(config.seed + 1)
    noise_gen = torch.Generator(device=device).manual_seed(config.seed + 2)

    from tqdm.auto import tqdm

    history: list[dict] = []
    t0 = time.perf_counter()
    bar = tqdm(range(config.epochs), desc="training mesh VAE", unit="epoch", disable=not config.progress)
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
        record = {"epoch": epoch + 1, **sums}
        last = epoch + 1 == config.epochs
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
    seconds = time.perf_counter() - t0
    logger.info("trained %d epochs in %.1f s on %s; final %s", config.epochs, seconds, device, history[-1])
    model.eval()
    model.to("cpu")
    return TrainResult(model=model, history=history, seconds=seconds, device=str(device))
