"""Per-component feature normalisation to [-a, a] (paper Sec. 4.1, Eq. 3).

The decoder of the mesh VAE ends in ``tanh``, whose range is (-1, 1) and whose gradient vanishes
near ±1. The paper therefore maps every feature component *separately* to [-a, a] with a = 0.9::

    f~_i = 2a (f_i - min_j f_i^j) / (max_j f_i^j - min_j f_i^j) - a            (Eq. 3)

where the min and max run over the meshes j of the training set. A component that is constant over
the training set (max = min = c) is treated as spanning [c - eps, c + eps] (eps = 1e-6), so it maps
to 0 and the inverse maps the decoder's output back near c.

(The authors' sibling projects use one global min/max for all rotation entries and one for all
scaling entries, mapped to ±0.95; this module follows the paper by default.)

``scale="shared"`` keeps each component's own centre (the midpoint of its training range) but
gives every component the same half-width, the largest one: a component that barely moves over
the training set then stays near 0 instead of being stretched to [-a, a]. For vertex coordinates
this keeps the squared error of the normalised rows proportional to the squared vertex error; the
per-component scaling of the paper weights a vertex that barely moves as much as one that moves a
lot, and made linear models on real collections up to 1.8x worse (docs/vae.md, issue 12).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import NORMALIZE_A
from meshvae_lib.tolerances import NORMALIZE_EPS
from meshvae_lib.validation import check_choice, check_finite, check_is_fitted, check_rows

__all__ = ["FeatureNormalizer", "SCALES"]

#: how the per-component ranges are set: the paper's own range per component, or one shared width.
SCALES = ("component", "shared")


class FeatureNormalizer:
    """Map each feature component to [-a, a] using the training set's min and max (Eq. 3).

    Parameters
    ----------
    a : float
        half-width of the target range, 0 < a < 1 (paper: 0.9).
    eps : float
        a component constant over the training set is widened to [c - eps, c + eps] (paper: 1e-6).
    scale : "component" (the paper) or "shared": every component gets the largest half-width of
        the training ranges, around its own midpoint (see the module docstring).

    Attributes (after :meth:`fit`)
    ------------------------------
    min_ : (K,) float64
        per-component lower end (min over the training meshes, minus eps for constant components).
    max_ : (K,) float64
        per-component upper end (max over the training meshes, plus eps for constant components).
    n_features_in_ : int
        K.
    """

    def __init__(self, a: float = NORMALIZE_A, eps: float = NORMALIZE_EPS, scale: str = "component"):
        self.a = a
        self.eps = eps
        self.scale = scale

    # -- fitting -------------------------------------------------------------------------------
    def fit(self, X) -> "FeatureNormalizer":
        """Learn the per-component range.

        X : (N, K) float array, N >= 1 training feature rows. Returns ``self``.
        """
        if not (0.0 < float(self.a) < 1.0):
            raise ValueError(f"a must lie in (0, 1) so that tanh can reach it, got {self.a}")
        if not float(self.eps) > 0.0:
            raise ValueError(f"eps must be positive, got {self.eps}")
        check_choice(self.scale, SCALES, "scale")
        X = self._check_rows(X, fitted=False)
        lo = X.min(axis=0)
        hi = X.max(axis=0)
        constant = hi - lo <= 0.0
        lo = np.where(constant, lo - self.eps, lo)
        hi = np.where(constant, hi + self.eps, hi)
        if self.scale == "shared":
            mid, half = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo))
            lo, hi = mid - half, mid + half
        self.min_ = lo.astype(np.float64)
        self.max_ = hi.astype(np.float64)
        self.n_features_in_ = X.shape[1]
        return self

    def fit_transform(self, X) -> np.ndarray:
        """``fit(X)`` then ``transform(X)``: (N, K) -> (N, K) float64."""
        return self.fit(X).transform(X)

    # -- mapping -------------------------------------------------------------------------------
    def transform(self, X) -> np.ndarray:
        """Eq. 3: features (N, K) or (K,) -> normalised features of the same shape, float64.

        Training rows land in [-a, a]; other rows may fall outside (nothing is clipped).
        """
        X, single = self._prepare(X)
        Y = 2.0 * self.a * (X - self.min_) / (self.max_ - self.min_) - self.a
        return Y[0] if single else Y

    def inverse_transform(self, Y) -> np.ndarray:
        """Inverse of Eq. 3: normalised features (N, K) or (K,) -> features, float64."""
        Y, single = self._prepare(Y)
        X = (Y + self.a) * (self.max_ - self.min_) / (2.0 * self.a) + self.min_
        return X[0] if single else X

    # -- persistence ---------------------------------------------------------------------------
    def state_dict(self) -> dict:
        """Everything needed to rebuild the fitted normaliser: plain floats and float64 arrays."""
        check_is_fitted(self, "min_", "call fit(X) first")
        return {"a": float(self.a), "eps": float(self.eps), "scale": str(self.scale),
                "min": self.min_.copy(), "max": self.max_.copy()}

    @classmethod
    def from_state_dict(cls, state: dict) -> "FeatureNormalizer":
        """Rebuild a fitted normaliser from :meth:`state_dict` output."""
        try:
            norm = cls(a=float(state["a"]), eps=float(state["eps"]), scale=str(state.get("scale", "component")))
            lo = np.asarray(state["min"], dtype=np.float64)
            hi = np.asarray(state["max"], dtype=np.float64)
        except (KeyError, TypeError) as exc:
            raise ValueError(f"not a FeatureNormalizer state: {exc!r}") from exc
        if lo.ndim != 1 or lo.shape != hi.shape or not np.all(hi > lo):
            raise ValueError(f"invalid normaliser state: min {lo.shape}, max {hi.shape}")
        norm.min_, norm.max_, norm.n_features_in_ = lo, hi, lo.shape[0]
        return norm

    # -- helpers -------------------------------------------------------------------------------
    def _check_rows(self, X, fitted: bool) -> np.ndarray:
        X = check_finite(check_rows(X, "features", single=False), "features")
        if X.shape[0] < 1 or X.shape[1] < 1:
            raise ValueError(f"features must have shape (n_meshes, n_features), got {X.shape}")
        if fitted and X.shape[1] != self.n_features_in_:
            raise ValueError(
                f"features have {X.shape[1]} components, the normaliser was fitted on {self.n_features_in_}"
            )
        return X

    def _prepare(self, X):
        check_is_fitted(self, "min_", "call fit(X) first")
        X = np.asarray(X, dtype=np.float64)
        single = X.ndim == 1
        if single:
            X = X[None]
        return self._check_rows(X, fitted=True), single

    def __repr__(self) -> str:
        fitted = f", K={self.n_features_in_}" if hasattr(self, "min_") else ""
        shared = ", scale='shared'" if self.scale == "shared" else ""
        return f"FeatureNormalizer(a={self.a}, eps={self.eps}{shared}{fitted})"
