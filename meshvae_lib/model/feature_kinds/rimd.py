"""The RIMD feature (paper Sec. 3, Eq. 2), the mesh VAE's own input: K = 6 n_vertices + 6 n_edges
(``layout="paper"``) or 6 n_vertices + 3 n_edges (``"compact"``).

Encoding is :class:`~meshvae_lib.geometry.rimd.RIMDEncoder`; decoding rebuilds each mesh with
:class:`~meshvae_lib.geometry.reconstruction.RIMDReconstructor`, rigidly aligned to the reference
(the feature carries no global pose). This kind owns both, built once each when first needed, on
one deformation-gradient operator of the reference mesh.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import DEFAULT_LAYOUT, LAYOUTS
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator
from meshvae_lib.geometry.reconstruction import RIMDReconstructor
from meshvae_lib.geometry.rimd import RIMDEncoder, RIMDLayout
from meshvae_lib.model.feature_kinds.base import FeatureKind
from meshvae_lib.validation import check_choice

__all__ = ["RIMDKind"]


class RIMDKind(FeatureKind):
    """RIMD features relative to the reference mesh.

    Parameters
    ----------
    reference, faces : see :class:`~meshvae_lib.model.feature_kinds.base.FeatureKind`.
    layout : "paper" or "compact" (:class:`~meshvae_lib.geometry.rimd.RIMDLayout`).
    """

    name = "rimd"
    options = ("layout",)

    def __init__(self, reference, faces, layout: str = DEFAULT_LAYOUT):
        super().__init__(reference, faces)
        self.layout = check_choice(layout, LAYOUTS, "layout")
        self._n_features = None
        self._operator = None
        self._encoder = None
        self._reconstructor = None

    @property
    def n_features(self) -> int:
        if self._n_features is None:
            lay = self._encoder.layout if self._encoder is not None else RIMDLayout(self._faces, self.n_vertices,
                                                                                   self.layout)
            self._n_features = int(lay.K)
        return self._n_features

    def _restore_n_features(self, n_features: int) -> None:
        # known without building the layout: a loaded model decodes without computing the edges first
        self._n_features = int(n_features)

    @property
    def operator(self) -> DeformationGradientOperator:
        """The deformation-gradient operator of the reference mesh, shared by the encoder and the
        reconstructor (built on first use)."""
        if self._operator is None:
            self._operator = DeformationGradientOperator(self._reference, self._faces)
        return self._operator

    @property
    def encoder(self) -> RIMDEncoder:
        """The RIMD encoder of this reference mesh (built on first use)."""
        if self._encoder is None:
            self._encoder = RIMDEncoder(self._reference, self._faces, layout=self.layout, operator=self.operator)
        return self._encoder

    @property
    def reconstructor(self) -> RIMDReconstructor:
        """The reconstructor of this reference mesh (built on first use; the exact method)."""
        if self._reconstructor is None:
            self._reconstructor = RIMDReconstructor(self._reference, self._faces, layout=self.layout,
                                                    operator=self.operator)
        return self._reconstructor

    def feature_vertices(self) -> np.ndarray:
        """``(K,)`` int64: a rotation block ``log dR_ij`` (3 numbers) belongs to vertex i, the
        edge's first vertex (in the paper's layout every edge out of i is i's), an S block (6
        numbers) to its vertex."""
        lay = self._encoder.layout if self._encoder is not None else RIMDLayout(self._faces, self.n_vertices, self.layout)
        return np.concatenate([np.repeat(lay.rotation_edges[:, 0], 3),
                               np.repeat(np.arange(self.n_vertices, dtype=np.int64), 6)]).astype(np.int64)

    def _encode(self, V: np.ndarray) -> np.ndarray:
        return np.asarray(self.encoder.transform(V), dtype=np.float64).reshape(len(V), -1)

    def _decode(self, X: np.ndarray) -> np.ndarray:
        return np.asarray(self.reconstructor.reconstruct(X), dtype=np.float64).reshape(len(X), -1, 3)

    def _linearize(self, f: np.ndarray):
        return self.reconstructor.linearize(f)
