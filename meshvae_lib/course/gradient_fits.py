"""What goes wrong in the least-squares fits of the deformation gradients (notebook 01, Sec. 5).

:func:`gradient_fit_stats` measures, for one :class:`~meshvae_lib.geometry.DeformationGradientOperator`
and one deformed mesh, the three ways a fit ``T_i = B_i A_i^{-1}`` goes wrong: a badly conditioned
``A_i`` (and along which direction it is weak), an indefinite ``A_i`` (negative cotangent weights),
and the resulting ``T_i``: reflections (``det T_i < 0``) and large stretches.
"""

from __future__ import annotations

import numpy as np

__all__ = ["gradient_fit_stats"]


def gradient_fit_stats(op, X, cond_limit: float = 100.0, cos_limit: float = 0.9) -> dict:
    """The conditioning of the matrices ``A_i`` of ``op`` and what the fit makes of the mesh ``X``.

    op : a :class:`~meshvae_lib.geometry.DeformationGradientOperator` (its ``A``, (n, 3, 3) float64,
    and ``normals``, (n, 3) float64 unit reference vertex normals, are read; ``op(X)`` gives the
    (n, 3, 3) gradients); X : (n, 3) float, the deformed mesh; cond_limit : float > 1, above it an
    ``A_i`` counts as badly conditioned; cos_limit : float in (0, 1), an ``A_i``'s weak direction
    counts as the normal when ``|cos|`` between the normal and the eigenvector of the eigenvalue of
    smallest magnitude exceeds it.

    Returns a dict of plain Python numbers: ``median_cond``, ``max_cond`` (floats: 2-norm condition
    numbers of the ``A_i``); ``ill`` (int: how many ``A_i`` have a condition number above
    ``cond_limit``); ``ill_along_normal`` (int: of those, how many are weakest along the vertex
    normal); ``indefinite`` (int: ``A_i`` with a negative eigenvalue); ``reflections`` (int:
    ``det T_i < 0``); ``max_stretch`` (float: the largest singular value of any ``T_i``); and
    ``T``, the (n, 3, 3) float64 gradients ``op(X)``.
    """
    if not cond_limit > 1 or not 0 < cos_limit < 1:
        raise ValueError(f"need cond_limit > 1 and 0 < cos_limit < 1, got {cond_limit} and {cos_limit}")
    A = np.asarray(op.A, dtype=np.float64)
    T = np.asarray(op(X), dtype=np.float64)
    eigenvalues, eigenvectors = np.linalg.eigh(A)                     # ascending, (n, 3) and (n, 3, 3)
    cond = np.linalg.cond(A)
    weakest = np.argmin(np.abs(eigenvalues), axis=1)
    weak_direction = eigenvectors[np.arange(len(A)), :, weakest]      # (n, 3) unit eigenvectors
    along_normal = np.abs(np.einsum("ia,ia->i", weak_direction, op.normals)) > cos_limit
    ill = cond > cond_limit
    return {"median_cond": float(np.median(cond)), "max_cond": float(cond.max()), "ill": int(ill.sum()),
            "ill_along_normal": int(np.sum(ill & along_normal)), "indefinite": int(np.sum(eigenvalues[:, 0] < 0)),
            "reflections": int(np.sum(np.linalg.det(T) < 0)),
            "max_stretch": float(np.linalg.norm(T, ord=2, axis=(1, 2)).max()), "T": T}
