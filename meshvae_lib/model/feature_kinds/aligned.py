"""Rigidly aligned vertex coordinates (the paper's "aligned coordinates", Table 2): K = 3 n_vertices.

Each mesh is first moved rigidly onto the reference (the rotation and translation that minimise
the vertex differences, :func:`~meshvae_lib.geometry.alignment.rigid_align`), then flattened.
Decoding reshapes the rows (the meshes stay in the reference's frame).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.feature_kinds.coords import CoordinatesKind

__all__ = ["AlignedKind"]


class AlignedKind(CoordinatesKind):
    """Vertex coordinates after rigidly aligning each mesh to the reference."""

    name = "aligned"

    def _encode(self, V: np.ndarray) -> np.ndarray:
        return rigid_align(V, self._reference).reshape(len(V), -1)
