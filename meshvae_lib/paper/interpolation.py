"""Sec. 5.3 / Figs. 4 and 6: latent interpolation against linear RIMD and coordinate interpolation."""

from __future__ import annotations

import functools

import numpy as np

from meshvae_lib.paper.protocol import load_collection, name_of, timed, train_model
from meshvae_lib.paper.settings import ExperimentSettings, resolve_settings
from meshvae_lib.paper.tables import ExperimentTable

__all__ = ["interpolation_table"]


@timed
def interpolation_table(collection: str = "jumping", pair=None, n_steps: int = 9,
                        settings: ExperimentSettings | None = None, quick: bool = False,
                        cache: dict | None = None) -> ExperimentTable:
    """Sec. 5.3 / Figs. 4 and 6: latent interpolation against linear RIMD and coordinate interpolation.

    ``pair``: two mesh indices (default: the first mesh and the one farthest from it in RIMD
    space). Also interpolates between two generated meshes. Reports self-intersections and
    edge-length distortion against the nearest training mesh for every step.
    """
    from meshvae_lib.applications import interpolation as itp
    from meshvae_lib.geometry.intersections import self_intersections
    from meshvae_lib.geometry.rimd import rimd_features

    s = resolve_settings(settings, quick)
    coll = load_collection(collection, s, cache=cache)
    model = train_model(coll, s, cache)
    kind = model.feature_kind
    F = coll.faces
    R = np.asarray(rimd_features(model.reference_vertices, coll.vertices, F, layout=s.layout)).reshape(len(coll.vertices), -1)
    if pair is None:
        a = 0
        b = int(np.argmax(np.linalg.norm(R - R[a], axis=1)))
    else:
        a, b = (int(i) for i in pair)
    seqs = {}
    mu = model.encode_meshes(coll.vertices[[a, b]], inference="encoder")      # the paper: encoder means
    z, seqs["latent (ours)"] = itp.LatentPath(model.decode_latent, mu[0], mu[1]).steps(n_steps)
    if kind.name == "rimd":
        seqs["linear RIMD"] = itp.interpolate_features(R[a], R[b], n_steps, kind.decode)
    seqs["linear coordinates"] = itp.interpolate_coordinates(coll.vertices[a], coll.vertices[b], n_steps)
    zg = model.sample_latent(2, seed=s.seed + 1)
    _, seqs["latent, generated ends"] = itp.LatentPath(model.decode_latent, zg[0], zg[1]).steps(n_steps)
    train = coll.vertices[~model.holdout_mask_]
    imp = itp.implausibility(seqs, F, train)
    table = ExperimentTable("interpolation", f"Sec. 5.3: interpolation between meshes {a} and {b} ({name_of(collection)})",
                            ["method", "max self-intersections", "mean self-intersections", "max edge distortion",
                             "mean edge distortion"])
    for r in imp.rows():
        table.rows.append([r["method"], r["max self-intersections"], r["mean self-intersections"],
                           r["max edge distortion"], r["mean edge distortion"]])
    ends = self_intersections(coll.vertices[[a, b]], F)
    table.notes.append(f"The end meshes themselves have {int(ends[0])} and {int(ends[1])} crossing triangle pairs."
                       " Edge distortion: mean relative edge-length change against the nearest training mesh.")
    table.data.update(sequences=seqs, implausibility=imp, pair=(a, b), faces=F)
    return table
