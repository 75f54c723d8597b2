"""The course's models: trained once at a real budget, cached outside the clone, loaded in seconds.

Each entry of :data:`COURSE_MODELS` names a ``data_synth`` collection (name, seed, resolution), what
the lesson needs from the model (features, labels, a sigma_object prior) and a training budget.
:func:`course_model` returns the fitted :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`: from the
cache when an entry with the same key is there, else trained (with a progress bar), written to the
cache and returned.

The cache lives in ``$MESHVAE_CACHE`` when set, else ``$XDG_CACHE_HOME/meshvae``, else
``~/.cache/meshvae`` (:func:`cache_dir`). An entry's file name holds its key (:func:`model_key`): a
hash of everything that determines the model -- the specification, the full training
configuration, the numpy and torch versions and the code that makes the data and trains the model:
the import closure of :data:`TRAINING_ENTRY_POINTS` (:mod:`~meshvae_lib.course.closure`; its syntax
trees: editing a comment or a docstring, or a module training never imports, keeps the cache). A
change to any of them gives another key, so a stale entry is never loaded; it is removed when the
new one is written. A damaged entry (a failed checksum, a truncated
file) is logged, removed and rebuilt. Checkpoints are written atomically (``model.save``), so an
interrupted build leaves no half-written entry.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

from meshvae_lib.course.closure import closure_fingerprint
from meshvae_lib.defaults import (CONDITIONAL_ALPHA, CONDITIONAL_HIDDEN, COURSE_SMALL_LATENT, DEFAULT_FEATURE_KIND,
                                  DEFAULT_LATENT, EMBEDDING_ALPHA, EMBEDDING_HIDDEN, EMBEDDING_SEEDS,
                                  EMBEDDING_SIGMA_OBJECT, EXPLORATION_SIGMA_OBJECT)
from meshvae_lib.model.train_config import pad_sigma_object

logger = logging.getLogger(__name__)

#: environment variable that overrides the cache folder.
CACHE_ENV = "MESHVAE_CACHE"

#: where a course model's making starts: the estimator that trains it and the builder of its data.
#: Their import closure is the code in the key (:func:`code_fingerprint`).
TRAINING_ENTRY_POINTS = ("meshvae_lib.model.meshvae_model", "data_synth.registry")
#: packages in that closure that do not change a trained model: the latent inference strategies
#: (they use a model, not train it; training only checks the inference's name).
NOT_TRAINING = ("meshvae_lib.model.inference",)


@dataclass(frozen=True)
class CourseModelSpec:
    """One course model: the data, the model and its training budget.

    name : registry key; lesson : the notebook that uses it; collection : a ``data_synth`` name;
    resolution : template vertices (approximate); data_seed : the collection's seed;
    features, labels, layout, holdout_every : :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`'s
    arguments; config : :class:`~meshvae_lib.model.train_config.TrainConfig` keywords (the budget: ``epochs``,
    ``latent_dim``, ...; ``progress`` is set by :func:`course_model`); minutes : the measured build
    time on 2 CPU cores, for the message shown before a build; description : one line.
    """

    name: str
    lesson: str
    collection: str
    resolution: int | None
    description: str
    minutes: float
    data_seed: int = 0
    features: str = DEFAULT_FEATURE_KIND
    labels: tuple[str, ...] = ()
    layout: str = "compact"
    holdout_every: int = 5
    config: dict = field(default_factory=dict)

    def train_config(self, progress: bool = False):
        """The :class:`~meshvae_lib.model.train_config.TrainConfig` this model is trained with."""
        from meshvae_lib.model.train_config import TrainConfig

        return TrainConfig(**{"device": "cpu", **self.config, "progress": progress})

    def make_collection(self):
        """The ``data_synth`` collection this model is trained on (deterministic)."""
        from data_synth.registry import make_collection

        return make_collection(self.collection, seed=self.data_seed, resolution=self.resolution)


#: 06's two models share their data: the conditional one is the plain one with labels and its own budget.
_PLAIN_BODIES = CourseModelSpec(
    name="plain-bodies",
    lesson="06_conditional_vae",
    collection="dyna",
    resolution=1600,
    description="5 bodies x 7 motions x 6 frames, 1,584 vertices, all meshes; the library's defaults, latent 16",
    minutes=0.2,
    holdout_every=0,
    config={"epochs": 1000, "latent_dim": COURSE_SMALL_LATENT, "batch_size": 32, "seed": 0},
)

#: 07's models: the sigma_object prior (0.1 for dims 1-2, 1 for the rest) on 06's collection, once
#: per seed of the embedding experiment (the map depends on the run), and the two ablations.
_EMBEDDING_BODIES = replace(
    _PLAIN_BODIES,
    name="embedding-bodies-0",
    lesson="07_sigma_object_embeddings",
    description="06's collection; sigma_object 0.1 for dims 1-2 (sibling form), alpha 1e3, a hidden layer of 256, "
                "latent 128, 153 epochs (918 Adam steps: 6 batches of 35 meshes)",
    minutes=0.5,
    config={"epochs": 153, "latent_dim": DEFAULT_LATENT, "batch_size": 32, "alpha": EMBEDDING_ALPHA, "hidden": EMBEDDING_HIDDEN,
            "sigma_object": tuple(float(s) for s in pad_sigma_object(EMBEDDING_SIGMA_OBJECT, DEFAULT_LATENT)), "prior_form": "sibling", "seed": 0},
)
_EMBEDDING_ABLATIONS = (
    replace(_EMBEDDING_BODIES, name="embedding-bodies-exact-kl",
            description="as embedding-bodies-0 with the exact KL of the sigma_object prior",
            config={**_EMBEDDING_BODIES.config, "prior_form": "exact"}),
    replace(_EMBEDDING_BODIES, name="embedding-bodies-alpha1e6",
            description="as embedding-bodies-0 with alpha 1e6 and no hidden layer", minutes=0.3,
            config={**_EMBEDDING_BODIES.config, "alpha": 1e6, "hidden": ()}),
)

COURSE_MODELS: dict[str, CourseModelSpec] = {
    spec.name: spec
    for spec in (
        CourseModelSpec(
            name="generation-body",
            lesson="05_generation_interpolation",
            collection="scape",
            resolution=2100,
            description="one body in 71 poses, 2,107 vertices, every 5th held out; the library's defaults, latent 128",
            minutes=1.0,
            config={"epochs": 1000, "latent_dim": DEFAULT_LATENT, "batch_size": 16, "seed": 0},
        ),
        _PLAIN_BODIES,
        replace(
            _PLAIN_BODIES,
            name="conditional-bodies",
            description="the same collection, conditioned on shape and motion; alpha 1e3, a hidden layer of 256, 1000 epochs",
            minutes=3.0,
            labels=("shape", "motion"),
            config={**_PLAIN_BODIES.config, "alpha": CONDITIONAL_ALPHA, "hidden": CONDITIONAL_HIDDEN},
        ),
        *(replace(_EMBEDDING_BODIES, name=f"embedding-bodies-{seed}", config={**_EMBEDDING_BODIES.config, "seed": seed},
                  description=_EMBEDDING_BODIES.description + f", seed {seed}") for seed in EMBEDDING_SEEDS),
        *_EMBEDDING_ABLATIONS,
        CourseModelSpec(
            name="exploration-body",
            lesson="08_exploration",
            collection="scape",
            resolution=2100,
            description="one body in 71 poses, 2,107 vertices, all meshes; graded sigma_object (sibling form), alpha 1e3, "
                        "a hidden layer of 256, 1000 epochs",
            minutes=2.0,
            holdout_every=0,
            config={"epochs": 1000, "latent_dim": COURSE_SMALL_LATENT, "batch_size": 16, "alpha": EMBEDDING_ALPHA,
                    "hidden": EMBEDDING_HIDDEN, "sigma_object": tuple(float(s) for s in pad_sigma_object(EXPLORATION_SIGMA_OBJECT, COURSE_SMALL_LATENT)),
                    "prior_form": "sibling", "seed": 0},
        ),
    )
}


def cache_dir() -> Path:
    """The cache folder: ``$MESHVAE_CACHE``, else ``$XDG_CACHE_HOME/meshvae``, else ``~/.cache/meshvae``."""
    if os.environ.get(CACHE_ENV):
        return Path(os.environ[CACHE_ENV]).expanduser()
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base).expanduser() / "meshvae"


def code_fingerprint(roots: dict | None = None) -> str:
    """sha256 of the code that makes a course model: the import closure of
    :data:`TRAINING_ENTRY_POINTS` in ``meshvae_lib`` and ``data_synth`` (``roots``: package name ->
    folder, default the installed ones), its module names and syntax trees without docstrings
    (:func:`~meshvae_lib.course.closure.closure_fingerprint`). Comments, docstrings and modules
    that training does not import do not change a trained model, so editing them keeps the cache;
    any change to the code itself (or a new Python whose syntax trees print differently) rebuilds
    it."""
    if roots is None:
        import data_synth
        import meshvae_lib

        roots = {p.__name__: Path(p.__file__).parent for p in (meshvae_lib, data_synth)}
    return closure_fingerprint(TRAINING_ENTRY_POINTS, roots, exclude=NOT_TRAINING)


def model_key(spec: CourseModelSpec) -> str:
    """The cache key of ``spec``: sha256 (hex) of the specification, its full training configuration,
    the numpy and torch versions and :func:`code_fingerprint`."""
    import numpy
    import torch

    what = {
        "spec": {k: v for k, v in asdict(spec).items() if k not in ("description", "minutes", "lesson")},
        "train_config": spec.train_config().to_dict(),
        "versions": {"numpy": numpy.__version__, "torch": torch.__version__.split("+")[0]},
        "code": code_fingerprint(),
    }
    return hashlib.sha256(json.dumps(what, sort_keys=True, default=list).encode()).hexdigest()


def cache_path(name: str, key: str | None = None) -> Path:
    """Where the entry of course model ``name`` (with ``key``, default: its current key) lives."""
    spec = get_spec(name)
    return cache_dir() / f"{spec.name}-{(key or model_key(spec))[:20]}.pt"


def get_spec(name: str) -> CourseModelSpec:
    """The registry entry ``name``; ValueError listing the names for an unknown one."""
    if name not in COURSE_MODELS:
        raise ValueError(f"unknown course model {name!r}; the course has {sorted(COURSE_MODELS)}")
    return COURSE_MODELS[name]


def is_cached(name: str) -> bool:
    """Whether an entry with the current key exists (it is not opened: see :func:`course_model`)."""
    return cache_path(name).is_file()


def build_model(name: str, progress: bool = True):
    """Train course model ``name`` from scratch (no cache). Returns the fitted MeshVAEModel."""
    from meshvae_lib.model.meshvae_model import MeshVAEModel

    spec = get_spec(name)
    model = MeshVAEModel(spec.features, spec.train_config(progress), labels=spec.labels,
                         holdout_every=spec.holdout_every, layout=spec.layout)
    return model.fit(spec.make_collection())


def course_model(name: str, progress: bool = True, rebuild: bool = False):
    """The fitted course model ``name`` (a :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`).

    Loaded from the cache when an entry with the current key is there and reads back intact; else
    trained (a progress bar when ``progress``; a log message says how long the build takes),
    written to the cache atomically, and returned. ``rebuild``: train even when cached. Older
    entries of the same model (other keys) are removed when a new one is written.
    """
    from meshvae_lib.model.meshvae_model import load_model

    spec = get_spec(name)
    key = model_key(spec)
    path = cache_path(name, key)
    if path.is_file() and not rebuild:
        try:
            return load_model(path)
        except (ValueError, OSError) as exc:
            logger.warning("course model %r: the cached file %s is damaged (%s); rebuilding it", name, path, exc)
            path.unlink(missing_ok=True)
    logger.warning("course model %r is not in the cache (%s): training it, about %.0f min on 2 CPU cores",
                   name, cache_dir(), max(spec.minutes, 1.0))
    start = time.perf_counter()
    model = build_model(name, progress=progress)
    path.parent.mkdir(parents=True, exist_ok=True)
    model.save(path)
    for old in path.parent.glob(f"{spec.name}-*.pt"):
        tail = old.stem[len(spec.name) + 1:]
        if old != path and len(tail) == 20 and all(c in "0123456789abcdef" for c in tail):
            old.unlink(missing_ok=True)
    logger.info("course model %r trained in %.0f s and cached at %s", name, time.perf_counter() - start, path)
    return load_model(path)  # what a later call loads, bit for bit (eval mode, float32 weights)
