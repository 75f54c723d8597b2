"""Capture noise: what a scanner and its registration add to every mesh of a real collection.

Real captures are reconstructed per frame, and each reconstruction carries its own small error:
vertices off the true surface by a fraction of a millimetre to a few millimetres, independently in
every frame. The stand-in collections are exact by default; :func:`add_capture_noise` adds such an
error, so a lesson can show what it does to each representation (RIMD's features are derivatives
of the surface and amplify it; PCA on coordinates averages it away).
"""

from __future__ import annotations

import numpy as np

from data_synth.quality import bounding_box_diagonals

__all__ = ["add_capture_noise", "with_capture_noise", "NOISE_STREAM"]

#: the capture noise's random stream, apart from the generators' own (which use ``seed`` alone).
NOISE_STREAM = 7


def add_capture_noise(vertices, level: float, rng: np.random.Generator) -> np.ndarray:
    """Meshes with independent Gaussian noise on every vertex coordinate.

    vertices : (N, V, 3) float; level : float >= 0, the noise's standard deviation per coordinate as
    a fraction of each mesh's bounding-box diagonal (0 returns a copy); rng : numpy Generator.

    Returns (N, V, 3) float64. Noise of standard deviation ``s`` per coordinate moves a vertex by
    ``s * sqrt(8 / pi)`` ~= 1.6 s on average.
    """
    V = np.asarray(vertices, dtype=np.float64)
    if V.ndim != 3 or V.shape[2] != 3:
        raise ValueError(f"vertices must be (n_meshes, n_vertices, 3), got {V.shape}")
    if isinstance(level, bool) or not np.isfinite(level) or level < 0:
        raise ValueError(f"level must be a finite number >= 0, got {level!r}")
    if level == 0:
        return V.copy()
    scale = level * bounding_box_diagonals(V)
    return V + rng.normal(size=V.shape) * scale[:, None, None]


def with_capture_noise(collection, level: float, seed: int):
    """``collection`` (a :class:`~data_synth.collection.SynthCollection`) with capture noise, in place.

    level : float >= 0, as in :func:`add_capture_noise`; seed : int >= 0, the collection's seed. The
    noise is drawn from its own generator (``[seed, NOISE_STREAM]``), so the meshes under it are the
    same for every level. ``extras['noise']`` records the level and, when it is not 0,
    ``extras['exact']`` keeps the exact meshes ``(N, V, 3) float64``. Returns the collection.
    """
    if level:
        exact = collection.vertices
        collection.vertices = add_capture_noise(exact, float(level), np.random.default_rng([int(seed), NOISE_STREAM]))
        collection.extras["exact"] = exact
        collection.description += f", capture noise {level:g} of the diagonal"
    collection.extras["noise"] = float(level)
    return collection
