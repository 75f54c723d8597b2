"""What makes a triangle mesh usable here, and the fix for the most common defect.

:func:`validate_mesh` refuses, with a ``ValueError`` naming the mesh and the first offending vertex
or face: non-finite coordinates, coordinates whose squares overflow (``MAX_ABS_COORDINATE``), faces that are not triangles, face indices out of range, faces
that repeat a vertex, vertices that no face uses, and zero-area faces (unless
``allow_degenerate=True``). Reading a mesh file (:mod:`meshvae_lib.geometry.mesh_files`) or a
collection (:mod:`meshvae_lib.geometry.collection_io`) runs it on every mesh.
:func:`remove_unreferenced_vertices` is the fix for unused vertices.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.input_checks import check_coordinate_range
from meshvae_lib.validation import check_faces, check_vertices

__all__ = ["validate_mesh", "remove_unreferenced_vertices"]


def validate_mesh(V, F, *, name: str = "mesh", allow_degenerate: bool = False) -> None:
    """Check that ``(V, F)`` is a usable triangle mesh; raise ``ValueError`` otherwise.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int
    name : str
        Used in error messages (a file name, say).
    allow_degenerate : bool
        Accept zero-area faces (area below ``DEGENERATE_AREA_RTOL`` times the squared mean edge
        length). The geometry core copes with them (their cotangent weights fall back to 1, see
        :mod:`meshvae_lib.geometry.cotangent`), but they usually signal a broken file.

    Raises
    ------
    ValueError
        Wrong shapes, non-finite or too large coordinates, indices out of range, faces repeating a vertex,
        unreferenced vertices, or (unless allowed) zero-area faces. The message names the first
        offending vertex or face.
    """
    V = check_vertices(V, f"{name}: vertices", batch=False)
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(
            f"{name}: faces must be triangles with shape (n_faces, 3), got {F.shape}"
        )
    if len(F) == 0:
        raise ValueError(f"{name}: has no faces")
    if not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"{name}: faces must be integers, got dtype {F.dtype}")
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{name}: {int(bad.sum())} vertices have NaN or infinite coordinates "
            f"(first: vertex {k} = {V[k].tolist()})"
        )
    check_coordinate_range(V, f"{name}: vertices")
    n = len(V)
    if F.min() < 0 or F.max() >= n:
        raise ValueError(
            f"{name}: face indices must lie in [0, {n - 1}], found range [{F.min()}, {F.max()}]"
        )
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if rep.any():
        k = int(np.flatnonzero(rep)[0])
        raise ValueError(
            f"{name}: {int(rep.sum())} faces repeat a vertex (first: face {k} = {F[k].tolist()})"
        )
    used = np.zeros(n, bool)
    used[F.reshape(-1)] = True
    if not used.all():
        k = np.flatnonzero(~used)
        raise ValueError(
            f"{name}: {len(k)} unreferenced vertices (no face uses them; first: {k[:5].tolist()}); "
            "remove them with meshvae_lib.geometry.mesh_checks.remove_unreferenced_vertices"
        )
    if not allow_degenerate:
        Vf = V.astype(np.float64)
        c = np.cross(Vf[F[:, 1]] - Vf[F[:, 0]], Vf[F[:, 2]] - Vf[F[:, 0]])
        area = 0.5 * np.linalg.norm(c, axis=1)
        e = np.linalg.norm(Vf[F] - Vf[np.roll(F, -1, axis=1)], axis=2)
        scale = np.mean(e) ** 2
        zero = area <= tol.DEGENERATE_AREA_RTOL * scale
        if zero.any():
            k = int(np.flatnonzero(zero)[0])
            raise ValueError(
                f"{name}: {int(zero.sum())} zero-area faces (first: face {k} = {F[k].tolist()}, "
                f"area {area[k]:.3g}); pass allow_degenerate=True (meshvae: --allow-degenerate) to accept them"
            )


def remove_unreferenced_vertices(V, F) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop vertices that no face uses, renumbering the faces.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    V_kept : (n_kept, 3) float64
    F_new : (n_faces, 3) int64
    kept : (n_kept,) int64
        Old ids of the kept vertices (``V_kept = V[kept]``).
    """
    V = check_vertices(V, "V", batch=False)
    F = check_faces(F, n_vertices=len(V), name="F")
    used = np.zeros(len(V), bool)
    used[F.reshape(-1)] = True
    kept = np.flatnonzero(used)
    new_id = np.full(len(V), -1, np.int64)
    new_id[kept] = np.arange(len(kept))
    return V[kept], new_id[F], kept
