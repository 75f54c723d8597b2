"""When RIMD wins: the SCAPE-like collection under its two knobs, pose diversity and capture noise.

Not a table of the paper: the lesson of issue 24 (notebook 09). RIMD encodes each mesh by the
rotations and stretches of its one-rings, which do not change when a limb turns rigidly: where the
poses are diverse articulated motions with large rotations, a model on RIMD generalises where
coordinates (and PCA on them) cannot. Capture noise works the other way: RIMD's features are
derivatives of the surface, and noise on every vertex becomes noise on every feature, which a model
trained on few meshes learns as if it were shape; PCA on coordinates averages it away. The table
trains the paper's network on coordinates and on RIMD for every pair of levels and sets each beside
the linear floor on the same meshes.
"""

from __future__ import annotations

import logging
from types import SimpleNamespace

import numpy as np

from meshvae_lib.model.evaluation import evaluate_model
from meshvae_lib.paper.linear_floor import linear_floor
from meshvae_lib.paper.protocol import (convergence_note, converged_name, load_collection, timed, train_model,
                                        validation_curve)
from meshvae_lib.paper.settings import ExperimentSettings, resolve_settings
from meshvae_lib.paper.tables import ExperimentTable

__all__ = ["noise_diversity_table", "NOISE_LEVELS", "DIVERSITIES"]

logger = logging.getLogger(__name__)

#: capture noise: standard deviation per coordinate, fraction of the bounding-box diagonal (1e-3 of a
#: 2 m body is 2 mm, a structured-light scanner's order)
NOISE_LEVELS = (0.0, 3e-4, 1e-3)
#: pose diversity of ``data_synth.bodies.make_scape`` (0: frames of seven motions; 1: the default)
DIVERSITIES = (0.0, 0.5, 1.0)

COLUMNS = ["diversity", "noise", "ours coords", "ours rimd", "ours rimd, Gauss-Newton", "PCA coords",
           "floor / diagonal", "noise / diagonal", "rimd / PCA", "rimd, Gauss-Newton / PCA", "coords / PCA"]


def _collection(diversity: float, noise: float, settings: ExperimentSettings):
    """The SCAPE-like collection at ``diversity`` with capture noise ``noise`` (its own random stream,
    so every noise level has the same meshes under it)."""
    from data_synth.bodies import make_scape
    from data_synth.capture_noise import with_capture_noise

    c = with_capture_noise(make_scape(seed=settings.seed, resolution=settings.resolution, diversity=diversity),
                           noise, settings.seed)
    return SimpleNamespace(name=f"scape d={diversity:g} noise={noise:g}", vertices=c.vertices, faces=c.faces,
                           names=c.names, labels=c.labels, description=c.description)


@timed
def noise_diversity_table(diversities=DIVERSITIES, noise_levels=NOISE_LEVELS, settings: ExperimentSettings | None = None,
                          quick: bool = False, cache: dict | None = None) -> ExperimentTable:
    """Held-out error of the paper's network on coordinates and on RIMD (its encoder, and the library's
    default inference, Gauss-Newton on the vertex error), and of PCA on coordinates, on the SCAPE-like
    collection for every ``diversity`` (``make_scape``) and capture ``noise`` (``add_capture_noise``).

    Errors are the experiments' (mean vertex distance after rigid alignment, every
    ``settings.holdout_every``-th mesh held out), measured against the held-out meshes as captured
    (with their noise: what a user has); 'noise / diagonal' is the mean distance the noise moved a
    vertex, the error a perfect denoiser would show. ``data["errors"][(diversity, noise)]``: the row's
    numbers as a dict. Returns an :class:`ExperimentTable` named ``noise_diversity`` (with
    ``settings.converge``: ``noise_diversity_converged``, the validation curves in ``data``).
    """
    s = resolve_settings(settings, quick)
    for d in diversities:
        if not 0.0 <= float(d) <= 2.0:
            raise ValueError(f"diversities must lie in [0, 2], got {d!r}")
    for n in noise_levels:
        if not 0.0 <= float(n) < 0.1:
            raise ValueError(f"noise levels must lie in [0, 0.1), got {n!r}")
    table = ExperimentTable(*converged_name("noise_diversity", "When RIMD wins: pose diversity and capture noise (SCAPE-like)", s),
                            list(COLUMNS))
    table.data["errors"] = {}
    for d in diversities:
        for noise in noise_levels:
            coll = load_collection(_collection(float(d), float(noise), s), s)
            models = {k: train_model(coll, s, cache, features=k) for k in ("coords", "rimd")}
            if s.converge:
                table.data.setdefault("validation_curves", {})[f"d={d:g}, noise={noise:g}"] = {
                    k: validation_curve(m, s) for k, m in models.items()}
            err = {k: evaluate_model(m, coll, held_out_only=True, inference="encoder")["mean_vertex_error"]
                   for k, m in models.items()}
            gn = evaluate_model(models["rimd"], coll, held_out_only=True, inference="gauss-newton")["mean_vertex_error"]
            floor = linear_floor(coll.vertices, s.holdout_every)
            moved = float(noise) * np.sqrt(8.0 / np.pi)
            row = {"coords": err["coords"], "rimd": err["rimd"], "gauss_newton": gn, "pca": floor["pca_coords"],
                   "floor_relative": floor["relative"], "noise_relative": moved}
            table.data["errors"][(float(d), float(noise))] = row
            logger.info("noise/diversity d=%g noise=%g: %s", d, noise, row)
            table.rows.append([float(d), float(noise), err["coords"], err["rimd"], gn, floor["pca_coords"], floor["relative"],
                               moved, err["rimd"] / floor["pca_coords"], gn / floor["pca_coords"],
                               err["coords"] / floor["pca_coords"]])
    table.notes.append("diversity: the independent joint draws of make_scape (0: random frames of seven motions; 1: the"
                       " SCAPE-like default). noise: capture noise, the standard deviation of Gaussian noise on every vertex"
                       " coordinate as a fraction of the diagonal; 'noise / diagonal' is the mean distance it moves a vertex"
                       " (sqrt(8/pi) x the level), the least error any model can show against the noisy held-out meshes.")
    table.notes.append("x / PCA: the model's held-out error over PCA on coordinates (every direction the training meshes"
                       " span, the same split and error); below 1 the model beats the linear floor.")
    if s.converge:
        table.notes.append(convergence_note(table, s))
    return table
