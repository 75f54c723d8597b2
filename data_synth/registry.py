"""The registry of named synthetic collections: one interface for all generators.

``make_collection(name, seed=0, resolution=None, noise=0.0)`` builds a collection; ``resolution`` is
the approximate vertex count of its template (None: the collection's default); ``noise`` adds
capture noise (:mod:`data_synth.capture_noise`; off by default).
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Callable

from data_synth import bar, bodies, face, flag, hand, humanoid
from data_synth.capture_noise import with_capture_noise
from data_synth.collection import SynthCollection

__all__ = ["COLLECTIONS", "CollectionSpec", "list_collections", "make_collection", "clear_caches", "SynthCollection"]


@dataclass(frozen=True)
class CollectionSpec:
    """A registered collection: its builder ``build(seed, resolution)`` and what it stands in for."""

    name: str
    build: Callable[..., SynthCollection]
    description: str
    stands_in_for: str


COLLECTIONS: dict[str, CollectionSpec] = {
    spec.name: spec
    for spec in (
        CollectionSpec("scape", bodies.make_scape,
                       "one body in 71 distinct poses, every joint drawn (2.5k vertices)", "SCAPE (Anguelov et al.)"),
        CollectionSpec("poses", bodies.make_poses,
                       "one body in 1,200 poses of 16 joint angles drawn independently (known degrees of freedom)",
                       "a large collection: where a nonlinear decoder starts to pay"),
        CollectionSpec("dyna", bodies.make_dyna,
                       "5 body shapes x 7 motions x 6 frames, labels shape/motion/frame",
                       "Dyna (Pons-Moll et al.)"),
        CollectionSpec("jumping", bodies.make_jumping,
                       "one body doing 12 jumping jacks, 120 frames (about 8 a second)", "Vlasic et al.'s Jumping"),
        CollectionSpec("flag", flag.make_flag,
                       "a flag on a pole waving in gusty wind, 100 frames (one boundary loop)",
                       "the paper's flag"),
        CollectionSpec("bar", bar.make_bar,
                       "an open tube twisting and bending past 180 degrees, 3 motions x 20 frames",
                       "the paper's bar / cylinder examples"),
        CollectionSpec("hand", hand.make_hand,
                       "a hand making gestures (fist, point, grab, ...) with bending fingers",
                       "the paper's hand"),
        CollectionSpec("face", face.make_face,
                       "a head with blendshape expressions (smile, jaw open, brow raise, ...)",
                       "the paper's face"),
    )
}


def list_collections() -> list[tuple[str, str]]:
    """``(name, description)`` of every registered collection, in registry order."""
    return [(spec.name, spec.description) for spec in COLLECTIONS.values()]


def make_collection(name: str, seed: int = 0, resolution: int | None = None,
                    noise: float = 0.0) -> SynthCollection:
    """Build collection ``name``; deterministic for ``seed``.

    Parameters
    ----------
    name : str, one of :data:`COLLECTIONS`.
    seed : int, non-negative.
    resolution : int or None, approximate vertex count of the template.
    noise : float >= 0, capture noise: the standard deviation of independent Gaussian noise on every
        vertex coordinate, as a fraction of each mesh's bounding-box diagonal (0: exact meshes). It
        is drawn from its own generator (``[seed, NOISE_STREAM]``), so the meshes under it are the
        same for every level; ``extras['noise']`` records the level and ``extras['exact']`` keeps
        the exact meshes.

    Returns
    -------
    SynthCollection with ``vertices (N, V, 3) float64``, ``faces (F, 3) int64``, ``names``,
    ``labels`` and ``description``.
    """
    if name not in COLLECTIONS:
        raise ValueError(f"unknown collection {name!r}; collections are {list(COLLECTIONS)}")
    if isinstance(seed, bool) or not isinstance(seed, (int,)) and not hasattr(seed, "__index__"):
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if int(seed) < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if resolution is not None:
        if isinstance(resolution, bool) or not hasattr(resolution, "__index__"):
            raise ValueError(f"resolution must be an integer vertex count, got {resolution!r}")
        resolution = int(resolution)
    if isinstance(noise, bool) or not isinstance(noise, numbers.Real) or not 0 <= noise < float("inf"):
        raise ValueError(f"noise must be a finite number >= 0, got {noise!r}")
    collection = COLLECTIONS[name].build(seed=int(seed), resolution=resolution)
    return with_capture_noise(collection, float(noise), int(seed))


def clear_caches() -> None:
    """Forget the templates built so far (the body's, the hand's, the face's), so that the next
    :func:`make_collection` builds them again (benchmarks time a cold build this way)."""
    for module in (humanoid, hand, face):
        module.clear_template_cache()
