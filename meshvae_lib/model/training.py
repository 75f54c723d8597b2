"""Training the mesh VAE: seeded, repeatable, with a progress bar and a per-epoch history.

:func:`train_vae` trains a :class:`~meshvae_lib.model.vae.MeshVAE` on rows of *normalised* features
(Eq. 3) with Adam (lr 1e-3, the fused implementation: about 4x faster on a CPU than the default)
and the loss of Eq. 4 (or, with ``TrainConfig(loss="bce", output="sigmoid")``, the binary
cross-entropy that Sec. 5.1 compares it with: the same batching and optimiser). Everything random
(initial weights, shuffling, the reparameterisation noise) comes from ``config.seed``: the same
seed gives bit-identical weights on a CPU.

The higher-level entry point, from a mesh collection to a model that decodes meshes, is
:meth:`meshvae_lib.model.meshvae_model.MeshVAEModel.fit`.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field

import numpy as np
import torch

from meshvae_lib.tolerances import PCA_INIT_RTOL
from meshvae_lib.defaults import BCE_TARGET_RANGE
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.vae import MeshVAE, start_step, vae_loss
from meshvae_lib.progress import progress as progress_bar

__all__ = ["TrainResult", "TrainingDiverged", "train_vae", "holdout_mask", "resolve_device", "pad_sigma_object",
           "pca_network", "to_output_range", "from_output_range"]

logger = logging.getLogger(__name__)


class TrainingDiverged(ValueError):
    """Training produced a non-finite loss (a ValueError: the settings, e.g. the learning rate, were
    too large for the data; the command line reports it as a failure on valid input)."""


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


def to_output_range(x, a: float, output: str = "sigmoid"):
    """Rows normalised to [-a, a] (Eq. 3) -> what a network with ``output`` reproduces: the rows
    themselves for "tanh", for "sigmoid" the affine map onto ``BCE_TARGET_RANGE`` ([0.1, 0.9]).
    numpy arrays or tensors."""
    if output == "tanh":
        return x
    lo, hi = BCE_TARGET_RANGE
    return lo + (x + a) * (hi - lo) / (2 * a)


def from_output_range(p, a: float, output: str = "sigmoid"):
    """The inverse of :func:`to_output_range`: a network's decoded rows -> rows in [-a, a]."""
    if output == "tanh":
        return p
    lo, hi = BCE_TARGET_RANGE
    return (p - lo) * (2 * a) / (hi - lo) - a


def _mse_scale(model, config) -> float | None:
    """Factor from the network's output units to Eq. 3's for the logged MSE (None: the same)."""
    if model.output == "tanh":
        return None
    lo, hi = BCE_TARGET_RANGE
    return (2 * config.resolved_feature_range(False) / (hi - lo)) ** 2


def _targets(model, x, config):
    """The rows the network's output is compared with (``x`` itself for a tanh output)."""
    return to_output_range(x, config.resolved_feature_range(False), model.output)


def _loss(x_hat, y, mu, sigma, config, so_t, mse_scale) -> dict:
    parts = vae_loss(x_hat, y, mu, sigma, config.alpha, so_t, config.prior_form, config.loss)
    if mse_scale is not None:
        parts["mse"] = parts["mse"] * mse_scale
    return parts


def _batches(n: int, batch_size: int, perm: torch.Tensor) -> list[torch.Tensor]:
    n_batches = max(1, n // batch_size)  # the remainder joins the other batches: none of size 1
    return list(torch.tensor_split(perm, n_batches))


@torch.no_grad()
def _evaluate(model, x, c, config, so_t) -> dict:
    model.eval()
    mu, sigma = model.encode(x, c)
    parts = _loss(model.decode(mu, c), _targets(model, x, config), mu, sigma, config, so_t, _mse_scale(model, config))
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
    if config.output != "tanh":
        raise ValueError("the PCA initialisation is for a tanh output (it fits the tanh's pre-activations)")
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
    net = MeshVAE(k, D, (), n_conditions, input_rank=r, sigma_floor=config.sigma_floor)
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
        return MeshVAE(x.shape[1], config.latent_dim, config.hidden, n_cond, sigma_floor=config.sigma_floor,
                       output=config.output)


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

    history: list[dict] = []
    best_epoch, best_val = 0, np.inf
    y, scale = _targets(model, x, config), _mse_scale(model, config)
    if select:
        best_val = _evaluate(model, xv, cv, config, so_t)["val_mse"]
        history.append({"epoch": 0, "val_mse": best_val})
    bar = progress_bar(range(epochs), desc=desc, unit="epoch", disable=not config.progress)
    for epoch in bar:
        model.train()
        sums = {"total": 0.0, "reconstruction": 0.0, "kl": 0.0, "mse": 0.0}
        perm = torch.randperm(n, generator=shuffle_gen)
        for idx in _batches(n, config.batch_size, perm):
            idx = idx.to(device)
            xb = x[idx]
            cb = None if c is None else c[idx]
            x_hat, mu, sigma = model(xb, cb, generator=noise_gen)
            parts = _loss(x_hat, xb if y is x else y[idx], mu, sigma, config, so_t, scale)
            start_step(model)  # zero the gradients, keeping the big buffers (see vae.Linear)
            parts["total"].backward()
            optimizer.step()
            w = len(idx) / n
            for key in sums:
                sums[key] += w * float(parts[key].detach())
        if not np.isfinite(sums["total"]):
            bar.close()
            raise TrainingDiverged(f"training diverged at epoch {epoch + 1} (loss {sums['total']}); try a smaller"
                                   f" learning rate (now {config.lr:g}) or alpha (now {config.alpha:g})")
        last = epoch + 1 == epochs
        if select:
            if (epoch + 1) % config.eval_every == 0 or last:
                val = _evaluate(model, xv, cv, config, so_t)["val_mse"]
                history.append({"epoch": epoch + 1, "mse": sums["mse"], "val_mse": val})
                if val < best_val:
                    best_epoch, best_val = epoch + 1, val
                elif epoch + 1 - best_epoch >= config.patience:
                    break
            continue
        record = {"epoch": epoch + 1, **sums}
        if xv is not None and ((epoch + 1) % config.eval_every == 0 or last):
            record.update(_evaluate(model, xv, cv, config, so_t))
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
        if (model.output, model.sigma_floor) != (config.output, float(config.sigma_floor)):
            raise ValueError(f"the given model has output={model.output!r}, sigma_floor={model.sigma_floor:g};"
                             f" the config asks for output={config.output!r}, sigma_floor={config.sigma_floor:g}")
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
        record = {"epoch": 0, **{k_[4:]: v for k_, v in _evaluate(model, x, c, config, so_t).items()}}
        if xv is not None:
            record.update(_evaluate(model, xv, cv, config, so_t))
        history.append(record)
    seconds = time.perf_counter() - t0
    logger.info("trained %d epochs in %.1f s on %s; final %s", epochs, seconds, device, history[-1])
    model.eval()
    model.to("cpu")
    return TrainResult(model=model, history=history, seconds=seconds, device=str(device), epochs=int(epochs),
                       selection=selection)
