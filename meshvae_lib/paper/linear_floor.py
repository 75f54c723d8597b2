"""The linear floor under every learned result: PCA on coordinates, same split, same error.

A mesh VAE's held-out error says something about its representation only where a linear projection
does not already reproduce the held-out meshes. :func:`linear_floor` measures PCA on vertex
coordinates and on rigidly aligned coordinates, with every direction the training meshes span, on the
split the experiments use (every ``holdout_every``-th mesh held out), with the experiments' error
(mean vertex distance after rigid alignment, :func:`~meshvae_lib.model.evaluation.pca_baseline`).
A collection whose lower floor is below ``tolerances.LINEAR_DATA_RTOL`` (1e-4) of the held-out
meshes' bounding-box diagonal is *linear data*: the tables mark its rows "not informative" and no
summary of the ordering uses them. Deterministic up to floating-point summation order (no training).
"""

from __future__ import annotations

from meshvae_lib import tolerances as tol
from meshvae_lib.model.evaluation import pca_baseline
from meshvae_lib.validation import check_vertices

__all__ = ["linear_floor", "FLOOR_COLUMNS", "floor_cells", "informative_rows", "NOT_INFORMATIVE"]

#: the columns the tables gain, in this order (cells: :func:`floor_cells`).
FLOOR_COLUMNS = ("PCA coords", "PCA aligned", "floor / diagonal", "informative")
#: the "informative" cell of a row on linear data.
NOT_INFORMATIVE = "linear data: not informative"


def linear_floor(vertices, holdout_every: int) -> dict:
    """PCA on coordinates and on aligned coordinates, fitted on the training meshes, on the held-out ones.

    vertices : (N, n, 3) float, the collection as the experiment uses it (after thinning);
    holdout_every : int >= 2, the experiments' split (``holdout_mask``).

    Returns a dict: ``pca_coords``, ``pca_aligned`` (held-out mean vertex error, mesh units),
    ``relative`` (the lower of the two divided by the held-out meshes' bounding-box diagonal, mean over
    meshes), ``n_components`` (directions the training meshes span), ``informative`` (bool: ``relative
    >= tolerances.LINEAR_DATA_RTOL``).
    """
    from meshvae_lib.model.training import holdout_mask  # imports torch: not at import time of the package

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
            "informative": bool(rel >= tol.LINEAR_DATA_RTOL)}


def floor_cells(floor: dict) -> list:
    """The cells of :data:`FLOOR_COLUMNS` for one row: two errors, the relative floor and "yes" or
    :data:`NOT_INFORMATIVE`."""
    return [floor["pca_coords"], floor["pca_aligned"], floor["relative"],
            "yes" if floor["informative"] else NOT_INFORMATIVE]


def informative_rows(table) -> list[dict]:
    """The rows of a table (live or read back) whose "informative" cell is "yes", as dicts; the rows
    a summary of the ordering may use."""
    return [r for r in table.as_dicts() if r.get("informative") == "yes"]

