"""Sec. 5.5 / Fig. 8: exploring the latent space; what the first latent dimensions control."""

from __future__ import annotations

import numpy as np

from meshvae_lib import defaults as hp
from meshvae_lib.model.train_config import pad_sigma_object
from meshvae_lib.paper.protocol import load_collection, name_of, timed, train_model
from meshvae_lib.paper.settings import ExperimentSettings, resolve_settings
from meshvae_lib.paper.tables import ExperimentTable

__all__ = ["exploration_table"]


@timed
def exploration_table(collection: str = "scape", dims=(0, 1, 2, 3), grid: int = 5, second_level_point=(1.0, 1.0),
                      settings: ExperimentSettings | None = None, quick: bool = False,
                      cache: dict | None = None) -> ExperimentTable:
    """Sec. 5.5 / Fig. 8: sigma_object = (0.1, 0.1, 0.5, 0.5, 1, ...), what each dimension controls.

    The model is trained as the embedding model (sibling-form latent cost, alpha =
    ``defaults.EMBEDDING_ALPHA``, hidden layers ``EMBEDDING_HIDDEN``, ``settings.embedding_steps``).

    Trains the exploration model on the whole collection, decodes a ``grid x grid`` first level over
    dimensions 1-2 and a second level over 3-4 with 1-2 fixed at ``second_level_point``, and sweeps
    each of ``dims`` alone, measuring height, supporting leg, arm height and facing direction.
    """
    from meshvae_lib.applications import exploration as ex

    s = resolve_settings(settings, quick)
    coll = load_collection(collection, s, cache=cache)
    ep = s.embedding_epochs_for(len(coll.vertices))
    model = train_model(coll, s, cache, sigma_object=pad_sigma_object(hp.EXPLORATION_SIGMA_OBJECT, s.latent_dim),
                        holdout=False, prior="sibling", alpha=hp.EMBEDDING_ALPHA, hidden=hp.EMBEDDING_HIDDEN, epochs=ep)
    rest = np.asarray(coll.extras.get("rest", coll.vertices[0]), dtype=np.float64)  # the A-pose template
    regions = ex.humanoid_regions(rest)
    measure = lambda V: ex.measure_humanoid(V, regions)  # noqa: E731
    effects = ex.dimension_effects(model, measure, dims=dims, reference_vertices=coll.vertices)
    level1 = ex.explore(model, dims=(0, 1), n=grid)
    base = np.zeros(s.latent_dim)
    base[:2] = second_level_point
    level2 = ex.explore(model, dims=(2, 3), base=base, n=grid)
    cols = ["dim", "controls most", "correlation", "change over [-2, 2] (data std)"] + [
        f"corr {n}" for n in effects.names]
    table = ExperimentTable("exploration", f"Sec. 5.5: what the first latent dimensions control ({name_of(collection)})", cols)
    for r in effects.rows():
        table.rows.append([r["dim"], r["controls"], r["correlation"], r["effect (std)"]]
                          + [r[f"corr {n}"] for n in effects.names])
    # also: correlation of the encoder means with the measurements over the data set
    mu = model.encode_meshes(coll.vertices, inference="encoder")   # the paper: encoder means
    C, names = ex.latent_measurement_correlation(mu[:, list(dims)], measure(coll.vertices))
    table.data.update(effects=effects, level1=level1, level2=level2, faces=coll.faces, data_correlation=C,
                      data_correlation_names=names)
    table.notes.append("Paper (SCAPE): dim 1 height (standing to squatting), dim 2 supporting leg, dim 3 arm height,"
                       " dim 4 facing direction. Measurements: height = vertical extent; support = (right foot"
                       " height - left foot height) / height, > 0 stands on the left leg; arm_height = mean hand"
                       " height over body height; facing = torso yaw in degrees (> 0 turned left).")
    return table
