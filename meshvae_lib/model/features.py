"""What the network sees: meshes -> feature rows -> meshes, and labels -> condition vectors.

:class:`FeatureExtractor` turns a collection of meshes that share one connectivity into rows of
features and back. Three kinds, the columns of the paper's Table 2:

- ``"rimd"``: the RIMD feature of every mesh relative to a reference mesh (Eq. 2), K = 6V + 6E;
  decoding rebuilds the mesh with :class:`~meshvae_lib.geometry.reconstruction.RIMDReconstructor`, aligned to
  the reference (the feature carries no global pose).
- ``"aligned"``: vertex coordinates after rigidly aligning each mesh to the reference (the paper's
  "aligned coordinates", global rotations found by minimising vertex differences), K = 3V.
- ``"coords"``: raw 3D vertex coordinates, K = 3V.

:class:`ConditionEncoder` turns label columns into the condition vector of the conditional mesh VAE
(Eq. 5): a text or integer column becomes a one-hot block, a float column one number scaled to
[-1, 1] by its training range.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.geometry.alignment import rigid_align

__all__ = ["FEATURE_KINDS", "FeatureExtractor", "CoordinateLinearization", "ConditionEncoder"]

#: the feature kinds, in the order of Table 2 (baseline first).
from meshvae_lib.defaults import FEATURE_KINDS  # noqa: E402  (re-exported: the kinds, in the order of Table 2)


def _unpack(vertices, faces=None):
    """MeshCollection / SynthCollection or (vertices, faces) -> (N, n, 3) float64, (F, 3) int64."""
    if hasattr(vertices, "vertices") and hasattr(vertices, "faces"):
        faces = vertices.faces if faces is None else faces
        vertices = vertices.vertices
    V = np.asarray(vertices, dtype=np.float64)
    if V.ndim == 2:
        V = V[None]
    if V.ndim != 3 or V.shape[-1] != 3:
        raise ValueError(f"vertices must have shape (n_meshes, n_vertices, 3), got {V.shape}")
    if not np.all(np.isfinite(V)):
        raise ValueError("vertices hold non-finite values")
    F = None if faces is None else np.asarray(faces, dtype=np.int64)
    return V, F


class FeatureExtractor:
    """Meshes <-> feature rows, for one reference mesh and connectivity.

    Parameters
    ----------
    kind : "rimd" | "aligned" | "coords"
    layout : RIMD layout, "paper" (K = 6V + 6E) or "compact" (see :mod:`meshvae_lib.geometry.rimd`).
    reference_index : which mesh of the training collection is the reference (default: the first).

    Attributes (after :meth:`fit`)
    ------------------------------
    reference_ : (n_vertices, 3) float64, the reference mesh V0.
    faces_ : (n_faces, 3) int64.
    n_features_ : int, K.
    """

    def __init__(self, kind: str = "rimd", layout: str = "paper", reference_index: int = 0):
        self.kind = kind
        self.layout = layout
        self.reference_index = reference_index

    def fit(self, vertices, faces=None) -> "FeatureExtractor":
        """Remember the reference mesh and faces.

        vertices : (N, n, 3) float or a collection (then faces default to its faces);
        faces : (F, 3) int. Returns ``self``.
        """
        if self.kind not in FEATURE_KINDS:
            raise ValueError(f"feature kind must be one of {FEATURE_KINDS}, got {self.kind!r}")
        V, F = _unpack(vertices, faces)
        if F is None:
            raise ValueError("faces are needed: pass a collection or (vertices, faces)")
        if F.ndim != 2 or F.shape[1] != 3:
            raise ValueError(f"faces must have shape (n_faces, 3), got {F.shape}")
        if not 0 <= self.reference_index < len(V):
            raise ValueError(f"reference_index {self.reference_index} is outside 0..{len(V) - 1}")
        if F.size and (F.min() < 0 or F.max() >= V.shape[1]):
            raise ValueError(f"faces index vertices 0..{F.max()} but meshes have {V.shape[1]} vertices")
        return self._set_reference(V[self.reference_index], F)

    def _set_reference(self, V0, F) -> "FeatureExtractor":
        self.reference_ = np.array(V0, dtype=np.float64)
        self.faces_ = np.array(F, dtype=np.int64)
        self._reconstructor = None
        self._encoder = None
        if self.kind == "rimd":
            from meshvae_lib.geometry.rimd import RIMDLayout

            self.n_features_ = int(RIMDLayout(self.faces_, len(self.reference_), layout=self.layout).K)
        else:
            self.n_features_ = 3 * len(self.reference_)
        return self

    # -- compatibility -------------------------------------------------------------------------
    def check_compatible(self, vertices, faces=None) -> None:
        """Raise ValueError unless the meshes have the reference's vertex count and faces."""
        self._check_fitted()
        V, F = _unpack(vertices, faces)
        if V.shape[1] != len(self.reference_):
            raise ValueError(
                f"the model was made for meshes with {len(self.reference_)} vertices, got {V.shape[1]}"
            )
        if F is not None and (F.shape != self.faces_.shape or not np.array_equal(F, self.faces_)):
            raise ValueError(
                f"the model was made for another connectivity ({len(self.faces_)} faces); these meshes"
                f" have {len(F)} faces" + (" in a different order" if F.shape == self.faces_.shape else "")
            )

    # -- meshes -> rows ------------------------------------------------------------------------
    def transform(self, vertices) -> np.ndarray:
        """Meshes (N, n, 3) (or a collection, or one (n, 3) mesh) -> feature rows (N, K) float64."""
        self._check_fitted()
        V, F = _unpack(vertices)
        self.check_compatible(V, F)
        if self.kind == "rimd":
            if getattr(self, "_encoder", None) is None:
                from meshvae_lib.geometry.rimd import RIMDEncoder

                self._encoder = RIMDEncoder(self.reference_, self.faces_, layout=self.layout)
            X = np.asarray(self._encoder.transform(V), dtype=np.float64).reshape(len(V), -1)
        elif self.kind == "aligned":
            X = rigid_align(V, self.reference_).reshape(len(V), -1)
        else:
            X = V.reshape(len(V), -1).copy()
        return X

    def fit_transform(self, vertices, faces=None) -> np.ndarray:
        return self.fit(vertices, faces).transform(vertices)

    # -- rows -> meshes ------------------------------------------------------------------------
    def inverse_transform(self, X) -> np.ndarray:
        """Feature rows (N, K) or (K,) -> meshes (N, n, 3) or (n, 3) float64.

        RIMD rows are reconstructed and rigidly aligned to the reference; coordinate rows are
        reshaped (no alignment).
        """
        self._check_fitted()
        X = np.asarray(X, dtype=np.float64)
        single = X.ndim == 1
        X2 = X[None] if single else X
        if X2.ndim != 2 or X2.shape[1] != self.n_features_:
            raise ValueError(f"feature rows must have shape (N, {self.n_features_}), got {X.shape}")
        if self.kind == "rimd":
            if self._reconstructor is None:
                from meshvae_lib.geometry.reconstruction import RIMDReconstructor

                self._reconstructor = RIMDReconstructor(self.reference_, self.faces_, layout=self.layout)
            V = np.asarray(self._reconstructor.reconstruct(X2), dtype=np.float64).reshape(len(X2), -1, 3)
        else:
            V = X2.reshape(len(X2), -1, 3).copy()
        return V[0] if single else V

    def linearize(self, features):
        """The decoding of one feature row and its first-order behaviour (for latent inference).

        features : (K,) float64, not normalised. Returns an object with ``positions
        (n_vertices, 3)`` (before any alignment) and ``jvp(dF)``: ``(K, d) -> (n_vertices, 3, d)``,
        ``vjp(dP)``: the transpose. RIMD: :meth:`RIMDReconstructor.linearize`; coordinates: the
        reshape, exactly linear.
        """
        self._check_fitted()
        f = np.asarray(features, dtype=np.float64)
        if f.shape != (self.n_features_,):
            raise ValueError(f"features must have shape ({self.n_features_},), got {f.shape}")
        if self.kind != "rimd":
            return CoordinateLinearization(f)
        if self._reconstructor is None:
            from meshvae_lib.geometry.reconstruction import RIMDReconstructor

            self._reconstructor = RIMDReconstructor(self.reference_, self.faces_, layout=self.layout)
        return self._reconstructor.linearize(f)

    # -- persistence ---------------------------------------------------------------------------
    def state_dict(self) -> dict:
        self._check_fitted()
        return {
            "kind": self.kind,
            "layout": self.layout,
            "reference_index": int(self.reference_index),
            "reference": self.reference_.copy(),
            "faces": self.faces_.copy(),
            "n_features": int(self.n_features_),
        }

    @classmethod
    def from_state_dict(cls, state: dict) -> "FeatureExtractor":
        try:
            ext = cls(kind=str(state["kind"]), layout=str(state["layout"]),
                      reference_index=int(state["reference_index"]))
            V0 = np.asarray(state["reference"], dtype=np.float64)
            F = np.asarray(state["faces"], dtype=np.int64)
        except (KeyError, TypeError) as exc:
            raise ValueError(f"not a FeatureExtractor state: {exc!r}") from exc
        if ext.kind not in FEATURE_KINDS or V0.ndim != 2 or V0.shape[1] != 3 or F.ndim != 2 or F.shape[1] != 3:
            raise ValueError(f"invalid feature extractor state: kind {ext.kind!r}, reference {V0.shape}, faces {F.shape}")
        if ext.kind == "rimd":
            # the feature length is known without building the layout (which needs the geometry code)
            ext.reference_, ext.faces_, ext._reconstructor, ext._encoder = V0, F, None, None
            ext.n_features_ = int(state["n_features"])
            return ext
        ext._set_reference(V0, F)
        if ext.n_features_ != int(state["n_features"]):
            raise ValueError(f"feature length {state['n_features']} does not match the reference mesh ({ext.n_features_})")
        return ext

    def _check_fitted(self) -> None:
        if not hasattr(self, "reference_"):
            raise ValueError("this FeatureExtractor is not fitted yet: call fit(collection) first")

    def __repr__(self) -> str:
        extra = f", n_vertices={len(self.reference_)}, K={self.n_features_}" if hasattr(self, "reference_") else ""
        return f"FeatureExtractor(kind={self.kind!r}, layout={self.layout!r}{extra})"


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


class ConditionEncoder:
    """Label columns -> condition vectors (N, C) float32 for the conditional mesh VAE (Eq. 5).

    Parameters
    ----------
    columns : names of the label columns to condition on, in order.

    Attributes (after :meth:`fit`)
    ------------------------------
    kinds_ : dict column -> "onehot" (text, integer or boolean column) or "numeric" (float column).
    categories_ : dict column -> list of str, the one-hot order (sorted) for "onehot" columns.
    ranges_ : dict column -> (min, max) float for "numeric" columns (mapped to [-1, 1]).
    n_conditions_ : int, C.
    """

    def __init__(self, columns=()):
        self.columns = [str(c) for c in columns]

    def fit(self, labels: dict) -> "ConditionEncoder":
        """labels : dict column -> (N,) array (e.g. ``collection.labels``). Returns ``self``."""
        self.kinds_, self.categories_, self.ranges_ = {}, {}, {}
        for col in self.columns:
            values = self._column(labels, col)
            if values.dtype.kind == "f":
                lo, hi = float(np.min(values)), float(np.max(values))
                if not (np.isfinite(lo) and np.isfinite(hi)):
                    raise ValueError(f"label column {col!r} holds non-finite values")
                self.kinds_[col], self.ranges_[col] = "numeric", (lo, hi)
            else:
                self.kinds_[col] = "onehot"
                self.categories_[col] = sorted({str(v) for v in values})
        self.n_conditions_ = sum(1 if self.kinds_[c] == "numeric" else len(self.categories_[c]) for c in self.columns)
        return self

    @staticmethod
    def _column(labels: dict, col: str) -> np.ndarray:
        if col not in labels:
            raise ValueError(f"no label column {col!r}; the data has {sorted(labels)}")
        return np.asarray(labels[col])

    def encode_column(self, col: str, values) -> np.ndarray:
        """Encode the values (n,) of one column -> (n, width) float64 block of the condition."""
        self._check_fitted()
        if col not in self.kinds_:
            raise ValueError(f"unknown condition column {col!r}; known: {self.columns}")
        values = np.asarray(values)
        if self.kinds_[col] == "numeric":
            try:
                v = values.astype(np.float64)
            except ValueError as exc:
                raise ValueError(f"label {col!r} is numeric; got {values[:3].tolist()}") from exc
            lo, hi = self.ranges_[col]
            scaled = np.zeros_like(v) if hi <= lo else 2.0 * (v - lo) / (hi - lo) - 1.0
            return scaled[:, None]
        cats = self.categories_[col]
        index = {c: i for i, c in enumerate(cats)}
        out = np.zeros((len(values), len(cats)))
        for r, v in enumerate(values):
            key = str(v)
            if key not in index:
                raise ValueError(f"label {col!r} has no value {key!r}; known values: {cats}")
            out[r, index[key]] = 1.0
        return out

    def transform(self, labels: dict) -> np.ndarray:
        """dict column -> (N,) values -> condition vectors (N, C) float32."""
        self._check_fitted()
        blocks = [self.encode_column(col, self._column(labels, col)) for col in self.columns]
        n = {len(b) for b in blocks}
        if len(n) > 1:
            raise ValueError(f"label columns have different lengths: {sorted(n)}")
        return np.concatenate(blocks, axis=1).astype(np.float32) if blocks else np.zeros((0, 0), np.float32)

    def encode_values(self, values: dict) -> np.ndarray:
        """One condition from ``{column: value}`` (every column needed) -> (C,) float32."""
        missing = [c for c in self.columns if c not in values]
        if missing:
            raise ValueError(f"missing condition values for {missing}")
        return self.transform({c: np.asarray([values[c]]) for c in self.columns})[0]

    def column_slices(self) -> dict:
        """dict column -> slice of the condition vector that encodes it."""
        self._check_fitted()
        out, start = {}, 0
        for col in self.columns:
            width = 1 if self.kinds_[col] == "numeric" else len(self.categories_[col])
            out[col] = slice(start, start + width)
            start += width
        return out

    def state_dict(self) -> dict:
        self._check_fitted()
        return {
            "columns": list(self.columns),
            "kinds": dict(self.kinds_),
            "categories": {k: list(v) for k, v in self.categories_.items()},
            "ranges": {k: [float(a), float(b)] for k, (a, b) in self.ranges_.items()},
        }

    @classmethod
    def from_state_dict(cls, state: dict) -> "ConditionEncoder":
        try:
            enc = cls(state["columns"])
            enc.kinds_ = {str(k): str(v) for k, v in state["kinds"].items()}
            enc.categories_ = {str(k): [str(x) for x in v] for k, v in state["categories"].items()}
            enc.ranges_ = {str(k): (float(v[0]), float(v[1])) for k, v in state["ranges"].items()}
        except (KeyError, TypeError, AttributeError) as exc:
            raise ValueError(f"not a ConditionEncoder state: {exc!r}") from exc
        enc.n_conditions_ = sum(1 if enc.kinds_[c] == "numeric" else len(enc.categories_[c]) for c in enc.columns)
        return enc

    def _check_fitted(self) -> None:
        if not hasattr(self, "kinds_"):
            raise ValueError("this ConditionEncoder is not fitted yet: call fit(labels) first")
