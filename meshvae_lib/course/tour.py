"""Helpers of notebook 00 (the tour): the linear floor with both of its fits, and the inputs its
self-checks run a student's cells on (meshes and collections the student has not seen).

Collections here are duck-typed like ``data_synth``'s: any object with ``vertices`` ((M, n, 3)
float64), ``faces`` ((F, 3) int64) and ``names`` (M str); the ones built here are
:class:`types.SimpleNamespace` with those and ``labels`` (empty) and ``description``. A *gallery* is
the notebook's dict name -> (collection, (P,) int64 indices of the meshes it shows).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

__all__ = ["linear_floor_detail", "unseen_surfaces", "shuffled_gallery"]


def linear_floor_detail(vertices, holdout_every: int) -> dict:
    """:func:`~meshvae_lib.paper.linear_floor` with each of its two fits' relative errors.

    vertices : (N, n, 3) float, a collection; holdout_every : int >= 2, the split (every
    ``holdout_every``-th mesh held out, ``holdout_mask``).

    Returns ``linear_floor``'s dict (the same values: ``pca_coords``, ``pca_aligned``, ``relative``,
    ``n_components``, ``informative``) plus ``relative_coords`` and ``relative_aligned`` (float: PCA on
    the raw and on the rigidly aligned coordinates, held-out mean vertex error over the held-out
    meshes' bounding-box diagonal, mean over meshes; ``relative`` is the lower of the two) and
    ``n_train``, ``n_held`` (int: meshes fitted on, meshes measured).
    """
    from meshvae_lib import tolerances as tol
    from meshvae_lib.model.evaluation import pca_baseline
    from meshvae_lib.model.training import holdout_mask
    from meshvae_lib.validation import check_vertices

    V = check_vertices(vertices, "vertices", batch=True)
    every = int(holdout_every)
    if every < 2:
        raise ValueError(f"the linear floor needs held-out meshes: holdout_every must be >= 2, got {holdout_every!r}")
    held = holdout_mask(len(V), every)
    if held.sum() < 1 or (~held).sum() < 2:
        raise ValueError(f"{len(V)} meshes with every {every}th held out leave {(~held).sum()} training and "
                         f"{held.sum()} held-out meshes; the floor needs >= 2 and >= 1")
    coords = pca_baseline(V[~held], V[held])
    aligned = pca_baseline(V[~held], V[held], aligned=True)
    rel = min(coords["relative_error"], aligned["relative_error"])
    return {"pca_coords": coords["mean_vertex_error"], "pca_aligned": aligned["mean_vertex_error"],
            "relative": float(rel), "n_components": coords["n_components"],
            "informative": bool(rel >= tol.LINEAR_DATA_RTOL),
            "relative_coords": float(coords["relative_error"]), "relative_aligned": float(aligned["relative_error"]),
            "n_train": int((~held).sum()), "n_held": int(held.sum())}


def _one_mesh(V, F, name: str) -> SimpleNamespace:
    """A collection of one mesh: ``vertices`` (1, n, 3) float64, ``faces`` (F, 3) int64."""
    V = np.asarray(V, dtype=np.float64)
    return SimpleNamespace(vertices=V[None].copy(), faces=np.asarray(F, dtype=np.int64).copy(), names=[name],
                           labels={}, description=f"{name}: one mesh, {len(V)} vertices")


def _side_by_side(parts) -> tuple[np.ndarray, np.ndarray]:
    """Several (V (n_i, 3), F (F_i, 3)) as one mesh of disjoint pieces, each shifted along x past the last."""
    Vs, Fs, offset, x = [], [], 0, 0.0
    for V, F in parts:
        V = np.asarray(V, dtype=np.float64)
        Vs.append(V + [x - V[:, 0].min(), 0.0, 0.0])
        Fs.append(np.asarray(F, dtype=np.int64) + offset)
        offset, x = offset + len(V), x + np.ptp(V[:, 0]) * 1.2
    return np.concatenate(Vs), np.concatenate(Fs)


def _holes(F, n_holes: int, seed: int) -> np.ndarray:
    """F without ``n_holes`` triangles, no two sharing a vertex (chosen at random with ``seed``), so that
    each removed triangle opens its own boundary loop on a closed surface."""
    rng = np.random.default_rng(seed)
    used, removed = set(), []
    for t in rng.permutation(len(F)):
        if not used & set(F[t].tolist()):
            removed.append(t)
            used |= set(F[t].tolist())
        if len(removed) == n_holes:
            break
    return np.delete(F, removed, axis=0)


def unseen_surfaces(gallery: dict, seed: int = 0) -> dict:
    """Three one-mesh collections whose Euler characteristics no earlier output shows, built from the
    first meshes of the gallery's ``scape``, ``hand``, ``flag`` and ``bar`` (a self-check's input).

    gallery : dict name -> (collection, indices) with those four names; seed : int, which triangles
    the holes take and how many (3 to 5).

    Returns a gallery (dict name -> (collection, array([0]))): ``two_bodies`` (two disjoint closed
    bodies, chi = 4, no boundary loop), ``holed_hand`` (the closed hand with 3 to 5 triangles removed,
    chi = 2 - holes, one loop per hole) and ``flag_and_bar`` (the disc and the open tube as one mesh,
    chi = 1, three loops): 2 minus the loop count is wrong for two of them.
    """
    first = {name: (gallery[name][0].vertices[0], gallery[name][0].faces) for name in ("scape", "hand", "flag", "bar")}
    hand_V, hand_F = first["hand"]
    built = {"two_bodies": _side_by_side([first["scape"], first["scape"]]),
             "holed_hand": (hand_V, _holes(hand_F, 3 + seed % 3, seed)),
             "flag_and_bar": _side_by_side([first["flag"], first["bar"]])}
    return {name: (_one_mesh(V, F, name), np.zeros(1, dtype=np.int64)) for name, (V, F) in built.items()}


def shuffled_gallery(gallery: dict, names, seed: int = 0) -> dict:
    """Some of the gallery's collections with their meshes in a new order (a self-check's input: each
    collection's first mesh, the reference of "how far from the first mesh", changes).

    gallery : dict name -> (collection, indices); names : the collections to take; seed : int, the
    order (``numpy.random.default_rng(seed).permutation`` per collection, redrawn until the first
    mesh changes).

    Returns a gallery (dict name -> (collection, (P,) int64 the shown meshes' new indices)) whose
    collections hold ``vertices`` (M, n, 3), ``faces``, ``names`` in the new order.
    """
    rng = np.random.default_rng(seed)
    out = {}
    for name in names:
        c, idx = gallery[name]
        order = rng.permutation(len(c.vertices))
        while order[0] == 0 and len(order) > 1:
            order = rng.permutation(len(c.vertices))
        new_index = np.argsort(order)
        out[name] = (SimpleNamespace(vertices=np.asarray(c.vertices)[order].copy(), faces=np.asarray(c.faces).copy(),
                                     names=[c.names[i] for i in order], labels={},
                                     description=f"{name}, meshes reordered"),
                     new_index[np.asarray(idx)].astype(np.int64))
    return out
