"""Labels -> condition vectors of the conditional mesh VAE (paper Sec. 4.3, Eq. 5).

:class:`ConditionEncoder` turns label columns into the condition vector: a text or integer column
becomes a one-hot block, a float column one number scaled to [-1, 1] by its training range.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.validation import check_is_fitted

__all__ = ["ConditionEncoder"]


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
        check_is_fitted(self, "kinds_", "call fit(labels) first")
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
        check_is_fitted(self, "kinds_", "call fit(labels) first")
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

    def vectors(self, n: int, conditions=None, labels=None) -> np.ndarray | None:
        """The condition vectors of ``n`` meshes, (n, C) float32, from explicit vectors (one (C,)
        vector is repeated) or a label dict; None when there are no condition columns (then
        ``conditions`` must be None or empty)."""
        check_is_fitted(self, "kinds_", "call fit(labels) first")
        if self.n_conditions_ == 0:
            if conditions is not None and np.size(conditions):
                raise ValueError("this model is unconditional; it takes no conditions")
            return None
        if conditions is None:
            if labels is None:
                raise ValueError(f"this model is conditional on {self.columns}: give labels or conditions")
            conditions = self.transform(labels)
        c = np.asarray(conditions, dtype=np.float32)
        if c.ndim == 1:
            c = np.broadcast_to(c, (n, c.shape[0]))
        if c.shape != (n, self.n_conditions_):
            raise ValueError(f"conditions must have shape ({n}, {self.n_conditions_}), got {c.shape}")
        return np.array(c, dtype=np.float32, order="C")

    def sample(self, train_vectors: np.ndarray, values: dict | None = None, n: int = 1,
               seed: int | None = 0) -> np.ndarray:
        """Condition vectors (n, C) float32 with the columns in ``values`` ({column: value}) set and the
        others taken from randomly chosen rows of ``train_vectors`` (N, C) (drawn with ``seed``)."""
        check_is_fitted(self, "kinds_", "call fit(labels) first")
        values = dict(values or {})
        unknown = [k for k in values if k not in self.columns]
        if unknown:
            raise ValueError(f"unknown condition columns {unknown}; the model knows {self.columns}")
        rng = np.random.default_rng(seed)
        rows = rng.integers(0, len(train_vectors), size=n) if len(train_vectors) else np.zeros(n, int)
        out = np.array(train_vectors[rows], dtype=np.float32).reshape(n, -1)
        slices = self.column_slices()
        for col, val in values.items():
            out[:, slices[col]] = self.encode_column(col, np.asarray([val]))[0]
        return out

    def column_slices(self) -> dict:
        """dict column -> slice of the condition vector that encodes it."""
        check_is_fitted(self, "kinds_", "call fit(labels) first")
        out, start = {}, 0
        for col in self.columns:
            width = 1 if self.kinds_[col] == "numeric" else len(self.categories_[col])
            out[col] = slice(start, start + width)
            start += width
        return out

    def state_dict(self) -> dict:
        check_is_fitted(self, "kinds_", "call fit(labels) first")
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
