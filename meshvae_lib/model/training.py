"""Training the mesh VAE: seeded, repeatable, with a progress bar and a per-epoch history.

:func:`train_vae` trains a network (:mod:`~meshvae_lib.model.networks`; by default the mesh VAE,
:class:`~meshvae_lib.model.vae.MeshVAE`) on rows of *normalised* features
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
from dataclasses import dataclass, field, replace

import numpy as np
import torch

from meshvae_lib.defaults import BCE_TARGET_RANGE
from meshvae_lib.model.inplace_grad import start_step
from meshvae_lib.model.networks import Network, network_class, start_network
from meshvae_lib.model.train_config import TrainConfig, pad_sigma_object
from meshvae_lib.model.loss import vae_loss
from meshvae_lib.progress import progress as progress_bar
from meshvae_lib.validation import check_count, check_finite, check_rows

__all__ = ["TrainResult", "TrainingDiverged", "train_vae", "start_is_optimum", "START_IS_OPTIMUM", "holdout_mask", "resolve_device", "to_output_range",
           "from_output_range"]

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
        "validation_rows": [...], "history": [{"epoch", "val_mse"}, ...]}``; when the start is
        already the network's optimum (:func:`start_is_optimum`) ``{"epochs": 0, "skipped": why}``.
    """

    model: Network
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
    if check_count(every, "holdout every") == 1:
        raise ValueError(f"holdout every must be 0 (none) or >= 2, got {every}")
    mask = np.zeros(n, dtype=bool)
    if every:
        mask[every - 1 :: every] = True
    return mask


def training_split(n: int, every: int, reference_index: int) -> np.ndarray:
    """:func:`holdout_mask` ``(n,) bool`` for a collection of ``n`` meshes whose reference is mesh
    ``reference_index``: ValueError when the reference is outside the collection or held out, or
    fewer than 2 meshes are left to train on."""
    mask = holdout_mask(n, every)
    check_count(reference_index, "reference_index")
    if reference_index >= n:
        raise ValueError(f"reference_index {reference_index} is outside 0..{n - 1}")
    if mask[reference_index]:
        raise ValueError(f"the reference mesh {reference_index} would be held out")
    if np.sum(~mask) < 2:
        raise ValueError(f"need at least 2 training meshes, got {int(np.sum(~mask))}")
    return mask


def _as_tensor(x, name: str, rows: int | None = None) -> torch.Tensor:
    a = check_finite(check_rows(x, name, single=False), name).astype(np.float32)
    if rows is not None and a.shape[0] != rows:
        raise ValueError(f"{name} has {a.shape[0]} rows, expected {rows}")
    return torch.from_numpy(np.ascontiguousarray(a))


def to_output_range(x, a: float, output: str = "sigmoid"):
    """Rows normalised to [-a, a] (Eq. 3) -> what a network with ``output`` reproduces: the rows
    themselves for "tanh" and "linear", for "sigmoid" the affine map onto ``BCE_TARGET_RANGE`` ([0.1, 0.9]).
    numpy arrays or tensors."""
    if output != "sigmoid":
        return x
    lo, hi = BCE_TARGET_RANGE
    return lo + (x + a) * (hi - lo) / (2 * a)


def from_output_range(p, a: float, output: str = "sigmoid"):
    """The inverse of :func:`to_output_range`: a network's decoded rows -> rows in [-a, a]."""
    if output != "sigmoid":
        return p
    lo, hi = BCE_TARGET_RANGE
    return (p - lo) * (2 * a) / (hi - lo) - a


@dataclass
class _Loss:
    """What the loss of every step needs besides the batch: the config (alpha, prior form, loss), the
    prior deviations (a tensor or None) and a of Eq. 3 (a sigmoid output's targets)."""

    config: TrainConfig
    so_t: torch.Tensor | None
    a: float

    def targets(self, model, x):
        """The rows the network's output is compared with (``x`` itself for a tanh output)."""
        return to_output_range(x, self.a, model.output)

    def mse_scale(self, model) -> float | None:
        """Factor from the network's output units to Eq. 3's for the logged MSE (None: the same)."""
        if model.output != "sigmoid":
            return None
        lo, hi = BCE_TARGET_RANGE
        return (2 * self.a / (hi - lo)) ** 2

    def __call__(self, x_hat, y, mu, sigma, mse_scale) -> dict:
        c = self.config
        parts = vae_loss(x_hat, y, mu, sigma, c.alpha, self.so_t, c.prior_form, c.loss)
        if mse_scale is not None:
            parts["mse"] = parts["mse"] * mse_scale
        return parts

    @torch.no_grad()
    def evaluate(self, model, x, c) -> dict:
        """``val_*`` of rows ``x`` encoded to their mean (no sampling), the network in eval mode."""
        model.eval()
        mu, sigma = model.encode(x, c)
        parts = self(model.decode(mu, c), self.targets(model, x), mu, sigma, self.mse_scale(model))
        return {f"val_{k}": float(v) for k, v in parts.items()}


def _batches(n: int, batch_size: int, perm: torch.Tensor) -> list[torch.Tensor]:
    n_batches = max(1, n // batch_size)  # the remainder joins the other batches: none of size 1
    return list(torch.tensor_split(perm, n_batches))


def _new_network(x, n_cond, config, mesh) -> Network:
    with torch.random.fork_rng(devices=[]):
        torch.manual_seed(config.seed)
        return start_network(config.architecture, x, n_cond, config, mesh)


def _epochs(model, x, c, loss: _Loss, epochs: int, device, desc: str):
    """Train ``model`` in place with Adam, one epoch per step of the iteration: yields ``(epoch,
    sums, bar)`` after each epoch (1-based; ``sums``: the training means of the loss terms; ``bar``:
    the progress bar). Raises :class:`TrainingDiverged` on a non-finite loss."""
    config = loss.config
    n = x.shape[0]
    if not epochs:  # nothing to train (a network without weights to train may have no parameters)
        return
    optimizer = torch.optim.Adam(model.parameters(), lr=config.lr, fused=True)
    shuffle_gen = torch.Generator().manual_seed(config.seed + 1)
    noise_gen = torch.Generator(device=device).manual_seed(config.seed + 2)
    y, scale = loss.targets(model, x), loss.mse_scale(model)
    bar = progress_bar(range(epochs), desc=desc, unit="epoch", disable=not config.progress)
    try:
        for epoch in bar:
            model.train()
            sums = {"total": 0.0, "reconstruction": 0.0, "kl": 0.0, "mse": 0.0}
            perm = torch.randperm(n, generator=shuffle_gen)
            for idx in _batches(n, config.batch_size, perm):
                idx = idx.to(device)
                xb = x[idx]
                cb = None if c is None else c[idx]
                x_hat, mu, sigma = model(xb, cb, generator=noise_gen)
                parts = loss(x_hat, xb if y is x else y[idx], mu, sigma, scale)
                start_step(model)  # zero the gradients, keeping the big buffers (see inplace_grad)
                parts["total"].backward()
                optimizer.step()
                w = len(idx) / n
                for key in sums:
                    sums[key] += w * float(parts[key].detach())
            if not np.isfinite(sums["total"]):
                raise TrainingDiverged(f"training diverged at epoch {epoch + 1} (loss {sums['total']}); try a smaller"
                                       f" learning rate (now {config.lr:g}) or alpha (now {config.alpha:g})")
            yield epoch + 1, sums, bar
    finally:
        bar.close()


def _choose_epochs(model, x, c, xv, cv, loss: _Loss, device) -> tuple[list[dict], int]:
    """Early stopping's run: train ``model`` on (x, c), evaluating the validation rows (xv, cv)
    before training and every ``eval_every`` epochs, until ``patience`` epochs bring no lower
    validation MSE. Returns (history, best epoch; 0: before training)."""
    config = loss.config
    best_val = loss.evaluate(model, xv, cv)["val_mse"]
    history, best_epoch = [{"epoch": 0, "val_mse": best_val}], 0
    run = _epochs(model, x, c, loss, config.epochs, device, "choosing epochs")
    for epoch, sums, _ in run:
        if epoch % config.eval_every == 0 or epoch == config.epochs:
            val = loss.evaluate(model, xv, cv)["val_mse"]
            history.append({"epoch": epoch, "mse": sums["mse"], "val_mse": val})
            if val < best_val:
                best_epoch, best_val = epoch, val
            elif epoch - best_epoch >= config.patience:
                run.close()
                break
    return history, best_epoch


def _train(model, x, c, xv, cv, loss: _Loss, epochs: int, device) -> list[dict]:
    """Train ``model`` for ``epochs`` epochs; the history records the training means every epoch
    and the validation rows' ``val_*`` every ``eval_every`` epochs (and at the last)."""
    config = loss.config
    history: list[dict] = []
    for epoch, sums, bar in _epochs(model, x, c, loss, epochs, device, "training mesh VAE"):
        record = {"epoch": epoch, **sums}
        if xv is not None and (epoch % config.eval_every == 0 or epoch == epochs):
            record.update(loss.evaluate(model, xv, cv))
        history.append(record)
        logger.debug("epoch %d: %s", epoch, record)
        if config.progress:
            post = {"loss": f"{sums['total']:.4g}", "kl": f"{sums['kl']:.3g}"}
            if "val_mse" in record:
                post["val_mse"] = f"{record['val_mse']:.3g}"
            bar.set_postfix(post, refresh=False)
    return history


def _rows(features, conditions, val_features, val_conditions):
    """The checked tensors (x, c, xv, cv) of :func:`train_vae`'s arguments."""
    x = _as_tensor(features, "features")
    n = x.shape[0]
    if n < 2:
        raise ValueError(f"need at least 2 training meshes, got {n}")
    c = None if conditions is None else _as_tensor(conditions, "conditions", n)
    xv = None if val_features is None or len(val_features) == 0 else _as_tensor(val_features, "val_features")
    cv = None
    if xv is not None and c is not None and c.shape[1]:
        if val_conditions is None:
            raise ValueError("the model is conditional: give val_conditions with val_features")
        cv = _as_tensor(val_conditions, "val_conditions", xv.shape[0])
    return x, c, xv, cv


def _check_given(model, k: int, n_cond: int, config: TrainConfig) -> None:
    """ValueError unless the network to continue training fits the rows and the config."""
    if config.early_stopping:
        raise ValueError("early stopping builds its own networks; it cannot continue a given model")
    if model.n_features != k or model.n_conditions != n_cond:
        raise ValueError(
            f"the given model expects {model.n_features} features and {model.n_conditions} conditions,"
            f" got {k} and {n_cond}"
        )
    floor = float(model.sigma_floor)
    if (model.output, floor) != (config.output, float(config.sigma_floor)):
        raise ValueError(f"the given model has output={model.output!r}, sigma_floor={floor:g};"
                         f" the config asks for output={config.output!r}, sigma_floor={config.sigma_floor:g}")


def _select(x, c, n_cond: int, loss: _Loss, device, mesh) -> tuple[int, dict]:
    """Early stopping: a network trained on all but every ``validation_every``-th row, validated on
    those. Returns (the best number of epochs, the record of ``TrainResult.selection``)."""
    config = loss.config
    vmask = holdout_mask(x.shape[0], config.validation_every)
    fit_i, val_i = torch.from_numpy(np.flatnonzero(~vmask)), torch.from_numpy(np.flatnonzero(vmask))
    x_fit = x[fit_i]
    probe = _new_network(x_fit, n_cond, config, mesh).to(device)
    history, epochs = _choose_epochs(probe, x_fit.to(device), None if c is None else c[fit_i].to(device),
                                     x[val_i].to(device), None if c is None else c[val_i].to(device), loss, device)
    logger.info("early stopping chose %d epochs (validation MSE %s)", epochs, min(h["val_mse"] for h in history))
    return epochs, {"epochs": int(epochs), "validation_rows": [int(i) for i in val_i], "history": history}


#: Why :func:`train_vae` keeps a PCA start untrained (``TrainResult.selection["skipped"]``).
START_IS_OPTIMUM = ("the PCA start's span holds every training row (latent size >= rows - 1), so its decoder"
                    " reproduces them all and a network without internal layers has nothing left to lower;"
                    " early stopping chose 0 epochs here on every real collection measured (issue 38)")


def start_is_optimum(config: TrainConfig, n_rows: int, n_conditions: int) -> bool:
    """True when a new network's start cannot be improved by training, so early stopping's search is
    skipped: the PCA start (no internal layer, the standard prior, no labels, a tanh output), early
    stopping left to its default (``config.early_stopping is None``; True asks for the search) and a
    latent size (resolved) of at least ``n_rows - 1``, the rank of the centred rows, or a network
    class whose ``linear_optimum`` says why its start is its optimum."""
    return _skip_reason(config.resolve(n_rows, n_conditions), n_rows, n_conditions) is not None


def _skip_reason(config: TrainConfig, n_rows: int, n_conditions: int) -> str | None:
    """Why a new network's start is kept untrained (``config`` resolved; see :func:`start_is_optimum`),
    or None: the span rule's :data:`START_IS_OPTIMUM`, or the class's own ``linear_optimum`` (the
    local-parts network's: every region starts at its own optimum whatever the latent size)."""
    if config.early_stopping is not None or not config.uses_pca_init(n_conditions):
        return None
    own = network_class(config.architecture).linear_optimum
    if own is None and config.latent_dim >= n_rows - 1:
        return START_IS_OPTIMUM
    return own


def train_vae(
    features,
    conditions=None,
    config: TrainConfig | None = None,
    val_features=None,
    val_conditions=None,
    model: Network | None = None,
    mesh=None,
) -> TrainResult:
    """Train a mesh VAE on normalised feature rows.

    Parameters
    ----------
    features : (N, K) float, normalised (Eq. 3), N >= 2.
    conditions : (N, C) float or None (conditional mesh VAE, Eq. 5).
    config : TrainConfig (defaults when None): the network is ``config.architecture``'s ``start``
        (the mesh VAE with ``init="pca"``, the default, starts at the PCA of the rows,
        :meth:`~meshvae_lib.model.vae.MeshVAE.from_pca`), and the number of epochs is chosen by early
        stopping on every ``validation_every``-th training row (see :class:`TrainConfig`); none for a
        network that ``trains_in_start``.
    val_features, val_conditions : (M, K), (M, C) held-out rows, optional: only recorded in the
        history (``val_*``), never used to choose anything.
    model : continue training this network instead of building a new one (no PCA initialisation
        and no early stopping then, unless ``config.early_stopping`` is True, which is refused).
    mesh : the :class:`~meshvae_lib.model.networks.ReferenceMesh` the rows come from, for a network
        built on the mesh's connectivity (the spiral network); None where the network needs none.

    A config whose latent size is unset is resolved here (:meth:`TrainConfig.resolve`, the one
    function that resolves a configuration; the estimator has already applied it) before the
    network's ``start``; continuing ``model``, the latent size is the model's.

    Returns a TrainResult: the network (eval mode, CPU), the per-epoch history, the number of epochs
    and early stopping's record.
    """
    config = config or TrainConfig()
    x, c, xv, cv = _rows(features, conditions, val_features, val_conditions)
    n, k = x.shape
    n_cond = 0 if c is None else c.shape[1]
    config = config.resolve(n, n_cond)                  # explicit options kept: the estimator's is unchanged
    device = resolve_device(config.device)
    if model is not None:
        config = replace(config, latent_dim=model.latent_dim)
        _check_given(model, k, n_cond, config)
    early = model is None and config.resolved_early_stopping(n_cond) and n >= 2 * config.validation_every
    so = pad_sigma_object(config.sigma_object, config.latent_dim)
    loss = _Loss(config, None if so is None else torch.as_tensor(so, dtype=torch.float32, device=device),
                 config.a)

    t0 = time.perf_counter()
    epochs, selection = config.epochs, None
    own = network_class(config.architecture)
    if own.trains_in_start and model is not None:
        raise ValueError(f"the {own.architecture} network is trained in its start; it cannot be trained further")
    skipped = own.linear_optimum if own.trains_in_start else _skip_reason(config, n, n_cond) if early else None
    if skipped:
        epochs, selection = 0, {"epochs": 0, "skipped": skipped}
        logger.info("no epoch search: %s", skipped)
    elif early:
        epochs, selection = _select(x, c, n_cond, loss, device, mesh)
    if model is None:
        model = _new_network(x, n_cond, config, mesh)
    model.to(device)
    x, c = x.to(device), None if c is None else c.to(device)
    xv, cv = (None, None) if xv is None else (xv.to(device), None if cv is None else cv.to(device))
    history = _train(model, x, c, xv, cv, loss, epochs, device)
    if not history:  # not trained at all: record the starting point
        record = {"epoch": 0, **{k_[4:]: v for k_, v in loss.evaluate(model, x, c).items()}}
        if xv is not None:
            record.update(loss.evaluate(model, xv, cv))
        history.append(record)
    seconds = time.perf_counter() - t0
    logger.info("trained %d epochs in %.1f s on %s; final %s", epochs, seconds, device, history[-1])
    model.eval()
    model.to("cpu")
    return TrainResult(model=model, history=history, seconds=seconds, device=str(device), epochs=int(epochs),
                       selection=selection)
