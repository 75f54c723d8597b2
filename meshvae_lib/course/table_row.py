"""One held-out mesh under every column of a Table 2 row, for the colour map of notebook 09.

:func:`column_reconstructions` reconstructs one mesh with the linear floor (PCA on the training
meshes' vertex coordinates with a given number of directions, as
:func:`~meshvae_lib.model.evaluation.pca_baseline` measures it) and with each model through each
inference, and aligns every reconstruction rigidly to the mesh: the distances that remain per
vertex are the ones the held-out error averages.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.evaluation import CoordinatePCA
from meshvae_lib.validation import check_vertices

__all__ = ["FLOOR_COLUMN", "column_reconstructions"]

#: the label of the floor's column.
FLOOR_COLUMN = "PCA on coordinates (floor)"


def column_reconstructions(mesh, V_train, n_components: int, models=None,
                           inferences=("encoder", "gauss-newton")) -> dict:
    """``mesh`` reconstructed by the linear floor and by each model through each inference, aligned to it.

    Parameters
    ----------
    mesh : (n, 3) float
        The mesh to reconstruct (a held-out mesh).
    V_train : (N, n, 3) float
        The training meshes the floor is fitted on (N >= 2).
    n_components : int
        The floor's principal directions (equal capacity: the models' latent dimensions in use).
    models : dict, optional
        label -> fitted model with ``reconstruct(V (k, n, 3), inference=name) -> (k, n, 3)`` (a
        :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`).
    inferences : sequence of str
        Inference names passed to each model's ``reconstruct``.

    Returns
    -------
    dict
        :data:`FLOOR_COLUMN` -> (n, 3) float64, then ``f"{label}, {inference}"`` -> (n, 3) float64 for
        each model and inference, in that order; every mesh rigidly aligned to ``mesh`` (rotation
        and translation that best fit it, :func:`~meshvae_lib.geometry.alignment.rigid_align`).
    """
    M = check_vertices(mesh, "mesh", batch=False)
    T = check_vertices(V_train, "V_train", batch=True, n_vertices=len(M))
    out = {FLOOR_COLUMN: CoordinatePCA(int(n_components)).fit(T).reconstruct(M[None])[0]}
    for label, model in (models or {}).items():
        for inference in inferences:
            out[f"{label}, {inference}"] = np.asarray(model.reconstruct(M[None], inference=inference)[0], dtype=np.float64)
    return {column: rigid_align(V, M) for column, V in out.items()}
