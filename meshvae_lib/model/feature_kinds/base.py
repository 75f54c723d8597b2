"""The feature kind base class: meshes <-> rows of features, for one reference mesh and connectivity.

A kind is built from the reference mesh ``V0 (n_vertices, 3) float64`` and the faces ``F (n_faces,
3) int64`` (plus its own options, e.g. the RIMD layout), and then

- :meth:`FeatureKind.encode`: meshes ``(N, n_vertices, 3)`` -> rows ``(N, K) float64``;
- :meth:`FeatureKind.decode`: rows ``(N, K)`` -> meshes ``(N, n_vertices, 3) float64``;
- :meth:`FeatureKind.check_compatible`: ValueError unless meshes have the reference's vertex count
  and faces;
- :meth:`FeatureKind.state_dict` / :meth:`FeatureKind.from_state_dict`: what a checkpoint stores.

A subclass sets ``name`` (its registry key) and ``options`` (its constructor keywords) and writes
``n_features``, ``_encode`` and ``_decode`` (and ``_linearize``, for :meth:`FeatureKind.linearize`,
which the Gauss-Newton inference needs); the base class checks the arguments.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.tolerances import FD_LINEARIZE_STEP
from meshvae_lib.validation import check_mesh, check_rows, check_vertices

__all__ = ["FeatureKind", "FiniteDifferenceLinearization"]


def _read_only(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


class FeatureKind:
    """Meshes <-> feature rows for one reference mesh (see the module docstring).

    Parameters
    ----------
    reference : (n_vertices, 3) float, the reference mesh V0.
    faces : (n_faces, 3) int.

    Attributes
    ----------
    name : str, the registry key.
    options : tuple of str, the constructor keywords beyond ``reference`` and ``faces``.
    pca_scale, random_hidden : the kind's training defaults (see ``TrainConfig``).
    reference : (n_vertices, 3) float64, read-only.
    faces : (n_faces, 3) int64, read-only.
    n_vertices : int.
    n_features : int, K.
    """

    name: str = ""
    options: tuple[str, ...] = ()
    #: how the PCA-started network's rows are normalised (``TrainConfig.feature_scale``).
    pca_scale: str = "component"
    #: internal layers that did best with the paper's random start (``train_config.default_hidden``).
    random_hidden: tuple[int, ...] = ()

    def __init__(self, reference, faces):
        V0, F = check_mesh(reference, faces, batch=False, name="reference")
        self._reference = np.array(V0, dtype=np.float64)
        self._faces = np.array(F, dtype=np.int64)

    # -- what it is ----------------------------------------------------------------------------
    @property
    def reference(self) -> np.ndarray:
        return _read_only(self._reference)

    @property
    def faces(self) -> np.ndarray:
        return _read_only(self._faces)

    @property
    def n_vertices(self) -> int:
        return len(self._reference)

    @property
    def n_features(self) -> int:
        raise NotImplementedError

    def feature_vertices(self) -> np.ndarray | None:
        """The vertex each feature component belongs to: ``(K,)`` int64 in ``0..n_vertices-1`` (for a
        decoder of local parts, :class:`~meshvae_lib.model.local_parts.LocalPartsVAE`), or None for a
        kind that does not say (the base class's answer; such a kind cannot train a decoder of parts)."""
        return None

    def get_options(self) -> dict:
        """The kind's options, ``{keyword: value}`` (what :meth:`__init__` takes beyond the mesh)."""
        return {k: getattr(self, k) for k in self.options}

    # -- meshes <-> rows -----------------------------------------------------------------------
    def check_compatible(self, vertices, faces=None) -> None:
        """ValueError unless ``vertices (..., n, 3)`` have the reference's vertex count and ``faces``
        (when given) are the reference's."""
        V = np.asarray(vertices)
        if V.shape[-2] != self.n_vertices:
            raise ValueError(f"the model was made for meshes with {self.n_vertices} vertices, got {V.shape[-2]}")
        if faces is not None:
            F = np.asarray(faces)
            if F.shape != self._faces.shape or not np.array_equal(F, self._faces):
                raise ValueError(
                    f"the model was made for another connectivity ({len(self._faces)} faces); these meshes"
                    f" have {len(F)} faces" + (" in a different order" if F.shape == self._faces.shape else "")
                )

    def encode(self, vertices) -> np.ndarray:
        """Meshes (N, n_vertices, 3) float -> feature rows (N, K) float64."""
        V = check_vertices(vertices, "vertices", batch=True, finite=True)
        self.check_compatible(V)
        return self._encode(V)

    def decode(self, rows) -> np.ndarray:
        """Feature rows (N, K) float -> meshes (N, n_vertices, 3) float64."""
        X = check_rows(rows, "feature rows", self.n_features, single=False)
        return self._decode(X)

    def linearize(self, features):
        """The decoding of one feature row and its first-order behaviour (for latent inference).

        features : (K,) float64, not normalised. Returns an object with ``positions
        (n_vertices, 3)`` (the decoded mesh) and ``jvp(dF)``: ``(K, d) -> (n_vertices, 3, d)``,
        ``vjp(dP)``: its transpose.
        """
        f = np.asarray(features, dtype=np.float64)
        if f.shape != (self.n_features,):
            raise ValueError(f"features must have shape ({self.n_features},), got {f.shape}")
        return self._linearize(f)

    def _encode(self, V: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _linearize(self, f: np.ndarray):
        """A kind without an analytic linearisation gets forward differences of its decoder (one
        decode per column of ``jvp``'s argument); RIMD and the coordinates have exact ones."""
        return FiniteDifferenceLinearization(self._decode, f)

    def _decode(self, X: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    # -- persistence ---------------------------------------------------------------------------
    def state_dict(self) -> dict:
        """Everything needed to rebuild the kind: its name, mesh, options and K."""
        return {"kind": self.name, "reference": self._reference.copy(), "faces": self._faces.copy(),
                "options": self.get_options(), "n_features": int(self.n_features)}

    @classmethod
    def from_state_dict(cls, state: dict) -> "FeatureKind":
        """Rebuild a kind from :meth:`state_dict` output; ValueError for a foreign or inconsistent one."""
        try:
            kind = cls(state["reference"], state["faces"], **dict(state.get("options") or {}))
            n_features = int(state["n_features"])
        except (KeyError, TypeError) as exc:
            raise ValueError(f"not a {cls.__name__} state: {exc!r}") from exc
        kind._restore_n_features(n_features)
        return kind

    def _restore_n_features(self, n_features: int) -> None:
        if n_features != self.n_features:
            raise ValueError(f"feature length {n_features} does not match the reference mesh ({self.n_features})")

    def __repr__(self) -> str:
        opts = "".join(f", {k}={v!r}" for k, v in self.get_options().items())
        return f"{type(self).__name__}(n_vertices={self.n_vertices}{opts}, K={self.n_features})"


class FiniteDifferenceLinearization:
    """The decoding of one row ``f (K,)`` by ``decode`` (rows ``(N, K)`` -> meshes ``(N, n, 3)``) and
    its directional derivatives by forward differences: ``positions (n, 3)``, ``jvp(dF)``: ``(K,)
    -> (n, 3)`` or ``(K, d) -> (n, 3, d)``, each column stepped by ``FD_LINEARIZE_STEP`` times
    ``(1 + |f|) / |column|``."""

    def __init__(self, decode, f: np.ndarray):
        self._decode, self._f = decode, np.asarray(f, dtype=np.float64)
        self.positions = np.asarray(decode(self._f[None]), dtype=np.float64)[0]
        self.positions.setflags(write=False)

    def jvp(self, dF: np.ndarray) -> np.ndarray:
        dF = np.asarray(dF, dtype=np.float64)
        cols = dF.reshape(len(self._f), -1)
        norms = np.linalg.norm(cols, axis=0)
        h = np.where(norms > 0, FD_LINEARIZE_STEP * (1.0 + np.linalg.norm(self._f)) / np.where(norms > 0, norms, 1.0), 0.0)
        out = np.zeros(self.positions.shape + (cols.shape[1],))
        moved = np.flatnonzero(h > 0)
        if moved.size:
            P = np.asarray(self._decode(self._f[None] + (cols[:, moved] * h[moved]).T), dtype=np.float64)
            out[..., moved] = np.moveaxis(P - self.positions, 0, -1) / h[moved]
        return out.reshape(self.positions.shape + dF.shape[1:])
