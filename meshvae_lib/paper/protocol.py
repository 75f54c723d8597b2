"""The experiments' protocol: loading collections and the one way they train a model.

(The held-out error of a model is :func:`~meshvae_lib.model.evaluation.evaluate_model` with
``held_out_only=True``.) A ``cache`` dict shared between experiments lets one trained model serve
several tables. Cache keys are stable: a collection named in ``data_synth`` is keyed by its name,
resolution, mesh count and seed; a model by the *content* of its collection
(:func:`collection_fingerprint`, a hash of the vertices, faces and labels) and its whole training
configuration. Two equal collections share their models, and a model is never returned for other
data.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import time

import numpy as np

from meshvae_lib import defaults as hp
from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.validation import check_vertices
from meshvae_lib.paper.settings import ExperimentSettings

__all__ = ["collection_fingerprint", "load_collection", "train_model", "safe_reference", "timed", "name_of",
           "registry_names", "available"]

logger = logging.getLogger(__name__)


def collection_fingerprint(coll: MeshCollection) -> str:
    """blake2b (hex) of a collection's vertices, faces and labels: what a model trained on it sees."""
    h = hashlib.blake2b(digest_size=16)
    for a in (np.ascontiguousarray(coll.vertices, dtype=np.float64), np.ascontiguousarray(coll.faces, dtype=np.int64)):
        h.update(repr(a.shape).encode())
        h.update(a.tobytes())
    for k in sorted(coll.labels):
        h.update(f"\0{k}\0".encode())
        h.update("\0".join(map(str, np.asarray(coll.labels[k]).tolist())).encode())
    return h.hexdigest()


def name_of(entry) -> str:
    """A collection entry's name: the string itself, or the object's ``name`` / ``__name__``."""
    if isinstance(entry, str):
        return entry
    return str(getattr(entry, "name", None) or getattr(entry, "__name__", None) or "collection")


def load_collection(entry, settings: ExperimentSettings | None = None, resolution=None,
                    cache: dict | None = None) -> MeshCollection:
    """A collection for the experiments, thinned to ``settings.max_meshes`` (evenly spaced).

    entry : a ``data_synth`` collection name (made at the settings' resolution, or ``resolution``),
        a collection-like object (``vertices``, ``faces``, optional ``labels``, ``names``), or a
        callable ``resolution -> collection`` (for the density experiment with your own meshes).

    Returns a :class:`~meshvae_lib.geometry.collection.MeshCollection`: ``vertices (N, n, 3)
    float64``, ``faces (F, 3) int64``, ``names``, ``labels`` (dict column -> (N,)), ``description``
    and ``extras``. With ``cache``,
    names and callables are made once (a callable is kept alive by its entry, so its id cannot be
    reused while the entry lives); collection objects are thinned again each time (it is cheap).
    """
    settings = settings or ExperimentSettings()
    res = settings.resolution if resolution is None else resolution
    is_object = not isinstance(entry, str) and hasattr(entry, "vertices") and hasattr(entry, "faces")
    key = None
    if cache is not None and not is_object:
        key = ("collection", entry if isinstance(entry, str) else id(entry), res, settings.max_meshes, settings.seed)
        if key in cache:
            return cache[key][1]
    if isinstance(entry, str):
        from data_synth import make_collection

        c = make_collection(entry, seed=settings.seed, resolution=res)
    elif is_object:
        c = entry
    elif callable(entry):
        c = entry(res)
    else:
        raise ValueError(f"expected a collection name, a collection or a callable, got {type(entry).__name__}")
    V = check_vertices(c.vertices, "collection vertices", batch=True)
    idx = np.arange(len(V))
    if settings.max_meshes is not None and len(V) > settings.max_meshes:
        idx = np.unique(np.round(np.linspace(0, len(V) - 1, settings.max_meshes)).astype(np.int64))
    labels = {k: np.asarray(v)[idx] for k, v in (getattr(c, "labels", {}) or {}).items()}
    names = list(getattr(c, "names", None) or [])
    names = [names[i] for i in idx] if len(names) == len(V) else [str(i) for i in idx]
    data = MeshCollection(V[idx], np.asarray(c.faces, dtype=np.int64), names, labels, getattr(c, "description", ""),
                          dict(getattr(c, "extras", {}) or {}))
    if key is not None:
        cache[key] = (entry, data)
    return data


def train_model(coll: MeshCollection, settings: ExperimentSettings, cache: dict | None, *, features=hp.DEFAULT_FEATURE_KIND,
                latent_dim=None, sigma_object=None, labels=(), reference_index=0, holdout=True, epochs=None,
                prior: str = "sibling", hidden=None, alpha=None, seed=None, loss: str = "mse"):
    """A MeshVAEModel trained the paper's way (from the cache when the same model was trained already).

    The experiments reproduce the paper's protocol: random start, a = 0.9, all epochs
    (``TrainConfig(init="random", early_stopping=False)``), not the library's default PCA start
    (``benchmarks/feature_comparison.py`` measures that one). With ``settings.converge`` (and no
    ``epochs`` given) the epochs are chosen by early stopping instead: the model trains until its
    validation error stops improving (``model.selection_`` keeps the validation curve). The deviation has a floor,
    ``sigma_floor = tolerances.SIGMA_FLOOR``: with the paper's alpha = 1e6 the reconstruction term
    drives the posterior deviation towards 0, and before ``MeshVAE`` floored the sigmoid's input
    (``SIGMA_LOGIT_MIN``) sigma underflowed in float32 and training turned to NaN (measured: epoch
    78 of 300 on a 160-mesh body collection); the floor is kept so that the tables stay comparable
    with earlier runs, and changes nothing measurable otherwise. It is an option of the network,
    so the model survives ``save`` / ``load_model``.

    ``prior`` (only with ``sigma_object``): "sibling" -- the authors' sibling-code formula (posterior
    widths shrink, means keep unit spread), or "exact" -- the exact KL to N(0, diag sigma_object^2);
    see ``vae.kl_divergence``. ``hidden``, ``alpha``, ``seed``: override the defaults (the feature
    kind's ``default_hidden``, the paper's alpha = 1e6, the settings' seed). ``loss``: "mse" (Eq. 4)
    or "bce" (sigmoid output, binary cross-entropy; Sec. 5.1).
    """
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.train_config import TrainConfig, default_hidden
    from meshvae_lib.model.training import holdout_mask

    hidden = default_hidden(features, "random") if hidden is None else tuple(int(h) for h in hidden)
    every = settings.holdout_every if holdout else 0
    n_train = int((~holdout_mask(len(coll.vertices), every)).sum())
    converge = settings.converge and epochs is None
    if converge:
        epochs = settings.converge_epochs
    cfg = TrainConfig(epochs=settings.epochs_for(n_train) if epochs is None else int(epochs),
                      batch_size=settings.batch_size,
                      latent_dim=settings.latent_dim if latent_dim is None else int(latent_dim), hidden=hidden,
                      alpha=hp.DEFAULT_ALPHA if alpha is None else float(alpha), sigma_object=sigma_object,
                      prior_form=prior, seed=settings.seed if seed is None else int(seed), device="cpu",
                      progress=False, init="random", early_stopping=converge, patience=settings.patience,
                      sigma_floor=tol.SIGMA_FLOOR,
                      output="sigmoid" if loss == "bce" else "tanh", loss=loss)
    key = ("model", collection_fingerprint(coll), features, tuple(labels), int(reference_index), every, settings.layout,
           json.dumps(cfg.to_dict(), sort_keys=True))
    if cache is not None and key in cache:
        return cache[key]
    model = MeshVAEModel(features=features, config=cfg, labels=labels, holdout_every=every,
                         layout=settings.layout, reference_index=reference_index).fit(coll)
    if cache is not None:
        cache[key] = model
    return model


def validation_curve(model, settings: ExperimentSettings) -> dict:
    """A model trained with ``settings.converge``: its validation curve, ``epochs`` and ``val_mse``
    (lists), ``chosen`` (the best epoch, which the model was retrained for) and ``flat`` (the run
    stopped after ``patience`` epochs without improvement, not at the epoch limit)."""
    history = model.selection_["history"]
    epochs = [int(h["epoch"]) for h in history]
    return {"epochs": epochs, "val_mse": [float(h["val_mse"]) for h in history], "chosen": int(model.train_epochs_),
            "flat": bool(epochs[-1] - int(model.train_epochs_) >= settings.patience and epochs[-1] < settings.converge_epochs)}


def converged_name(name: str, title: str, settings: ExperimentSettings) -> tuple[str, str]:
    """A table's name and title, marked when ``settings.converge`` trains every model to convergence."""
    if settings.converge:
        return name + "_converged", title + ", every model trained until its validation error stops improving"
    return name, title


def convergence_note(table, settings: ExperimentSettings) -> str:
    """The note of a converged table: how its models were trained and which curves, if any, ended at the
    epoch limit (``table.data["validation_curves"]``: row -> model -> :func:`validation_curve`)."""
    open_ended = [f"{c} {k}" for c, kinds in table.data["validation_curves"].items() for k, cv in kinds.items() if not cv["flat"]]
    return (f"Every model trained until its validation MSE (every 8th training mesh) did not improve for"
            f" {settings.patience} epochs (at most {settings.converge_epochs}), then retrained on all training meshes"
            " for the best number of epochs; the curves are in data['validation_curves'] ("
            + ("all flat at the end)" if not open_ended else "still falling at the last epoch: " + ", ".join(open_ended) + ")") + ".")


def safe_reference(index: int, n: int, every: int) -> int:
    """``index`` clipped to the collection and moved off held-out meshes."""
    i = int(min(max(index, 0), n - 1))
    while every and (i + 1) % every == 0:
        i = i - 1 if i > 0 else i + 1
    return i


def timed(fn):
    """Decorator: store the experiment's wall-clock time in the returned table's ``seconds``."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        table = fn(*args, **kwargs)
        table.seconds = time.perf_counter() - t0
        logger.info("%s: %.1f s", table.name, table.seconds)
        return table

    return wrapper


def registry_names() -> list[str]:
    """Names of the ``data_synth`` collections, in registry order."""
    from data_synth import list_collections

    return [e if isinstance(e, str) else e[0] for e in list_collections()]


def available(entries) -> list:
    """Collection names the registry has (others are skipped with a log line); objects pass."""
    names = [e for e in entries if isinstance(e, str)]
    have = set(registry_names()) if names else set()
    out = []
    for e in entries:
        if not isinstance(e, str) or e in have:
            out.append(e)
        else:
            logger.warning("no data_synth collection %r; skipped", e)
    return out
