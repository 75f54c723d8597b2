"""Raw 3D vertex coordinates (the first baseline of the paper's Table 2): K = 3 n_vertices."""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import HIDDEN_COORDS
from meshvae_lib.model.feature_kinds.base import FeatureKind

__all__ = ["CoordinatesKind", "CoordinateLinearization"]


class CoordinatesKind(FeatureKind):
    """Each mesh's vertex coordinates, flattened (x0, y0, z0, x1, ...); decoding reshapes them."""

    name = "coords"
    #: one half-width for all coordinates: the normalised rows' squared error stays proportional
    #: to the squared vertex error (``FeatureNormalizer(scale="shared")``).
    pca_scale = "shared"
    random_hidden = tuple(HIDDEN_COORDS)

    @property
    def n_features(self) -> int:
        return 3 * self.n_vertices

    def feature_vertices(self) -> np.ndarray:
        """Component ``3 i + c`` is vertex i's coordinate c: ``(3 n,)`` int64."""
        return np.repeat(np.arange(self.n_vertices, dtype=np.int64), 3)

    def _encode(self, V: np.ndarray) -> np.ndarray:
        return V.reshape(len(V), -1).copy()

    def _decode(self, X: np.ndarray) -> np.ndarray:
        return X.reshape(len(X), -1, 3).copy()

    def _linearize(self, f: np.ndarray) -> "CoordinateLinearization":
        return CoordinateLinearization(f)


class CoordinateLinearization:
    """Coordinate features decode by a reshape: ``positions = f.reshape(n, 3)``, exactly linear."""

    def __init__(self, features: np.ndarray):
        self.positions = features.reshape(-1, 3).copy()
        self.positions.setflags(write=False)

    def jvp(self, dF: np.ndarray) -> np.ndarray:
        """``(3n,) -> (n, 3)`` or ``(3n, d) -> (n, 3, d)``."""
        dF = np.asarray(dF, dtype=np.float64)
        return dF.reshape(len(self.positions), 3, *dF.shape[1:])

    def vjp(self, dP: np.ndarray) -> np.ndarray:
        """``(n, 3) -> (3n,)`` or ``(n, 3, d) -> (3n, d)``."""
        dP = np.asarray(dP, dtype=np.float64)
        return dP.reshape(3 * len(self.positions), *dP.shape[2:])
