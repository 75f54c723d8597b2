"""Argument checks shared by the whole library: array shapes, dtypes, finiteness, option values.

Every helper takes the argument as the caller got it (any array-like), converts it to the dtype the
library computes in and returns it, or raises ``ValueError`` with a message that names the argument
and shows the actual shape, dtype or value (``"V0 must have shape (n_vertices, 3), got (10, 2)"``).
Public entry points call them first thing, so a wrong argument fails there and not deep inside a
solver.

This is a base module (numpy only, like ``tolerances`` and ``defaults``): every layer may import
it, the geometry layer included.

=========================  ===========================================================
helper                     accepts, returns
=========================  ===========================================================
:func:`check_faces`        triangles ``(n_faces, 3)``, integer-valued, ``>= 0`` -> int64
:func:`check_vertices`     positions ``(n_vertices, 3)`` and/or ``(n_meshes, n_vertices, 3)``
                           -> float64, optionally finite
:func:`check_mesh`         a pair ``(V, F)`` whose faces index into ``V``
:func:`check_matrices`     stacks of square matrices ``(..., 3, 3)`` -> float64
:func:`check_vectors`      stacks of vectors ``(..., 3)`` -> float64
:func:`check_rows`         one vector ``(k,)`` or rows ``(n, k)`` -> float64
:func:`check_finite`       no NaN or infinity
:func:`check_choice`       a string option among its allowed values
:func:`check_count`        an integer ``>= minimum``
:func:`check_samples`      a data matrix of at least two finite rows ``(n, k)`` -> float64
:func:`check_is_fitted`    a fitted estimator (raises :class:`NotFittedError`)
=========================  ===========================================================
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.input_checks import check_coordinate_range

__all__ = [
    "check_faces",
    "check_vertices",
    "check_mesh",
    "check_matrices",
    "check_vectors",
    "check_rows",
    "check_finite",
    "check_choice",
    "check_count",
    "check_samples",
    "check_is_fitted",
    "NotFittedError",
]


def check_faces(F, n_vertices: int | None = None, name: str = "faces") -> np.ndarray:
    """Triangles as vertex indices.

    Parameters
    ----------
    F : (n_faces, 3) int, or float holding whole numbers
    n_vertices : int, optional
        When given, every index must be below it.
    name : str
        The argument's name in error messages.

    Returns
    -------
    F : (n_faces, 3) int64
        The input itself when it already is an int64 array.

    Raises
    ------
    ValueError
        Wrong shape, non-integer values, a negative index, or an index ``>= n_vertices``.
    """
    F = np.asarray(F)
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"{name} must have shape (n_faces, 3), got {F.shape}")
    if F.size and not np.issubdtype(F.dtype, np.integer):
        if not np.all(np.equal(np.mod(F, 1), 0)):
            raise ValueError(f"{name} must hold integer vertex indices, got dtype {F.dtype} "
                             "with fractional values")
    F = F.astype(np.int64, copy=False)
    if F.size and F.min() < 0:
        raise ValueError(f"{name}: negative vertex index {F.min()}")
    if n_vertices is not None and F.size and F.max() >= n_vertices:
        raise ValueError(f"{name}: vertex index {F.max()} is out of range, there are "
                         f"{n_vertices} vertices")
    return F


def _vertex_shapes(batch: bool | None, n_vertices: int | None) -> tuple[tuple[int, ...], str]:
    n = "n_vertices" if n_vertices is None else str(n_vertices)
    one, many = f"({n}, 3)", f"(n_meshes, {n}, 3)"
    if batch is None:
        return (2, 3), f"{one} or {many}"
    return ((3,), many) if batch else ((2,), one)


def check_vertices(V, name: str = "vertices", *, batch: bool | None = None,
                   n_vertices: int | None = None, finite: bool = False) -> np.ndarray:
    """Vertex positions of one mesh or of a batch of meshes.

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    name : str
        The argument's name in error messages.
    batch : bool, optional
        ``False``: one mesh ``(n_vertices, 3)`` only; ``True``: a batch
        ``(n_meshes, n_vertices, 3)`` only; ``None`` (default): either.
    n_vertices : int, optional
        When given, the number of vertices must be exactly this.
    finite : bool
        Also refuse NaN and infinite coordinates, and coordinates whose squares overflow
        (:func:`~meshvae_lib.input_checks.check_coordinate_range`).

    Returns
    -------
    V : float64 array of the input's shape

    Raises
    ------
    ValueError
        A shape other than the accepted ones (the message shows them and the actual shape; a mesh
        has at least one vertex), or non-finite coordinates when ``finite``.
    """
    V = np.asarray(V, dtype=np.float64)
    ndims, expected = _vertex_shapes(batch, n_vertices)
    if (V.ndim not in ndims or V.shape[-1] != 3 or V.shape[-2] == 0
            or (n_vertices is not None and V.shape[-2] != n_vertices)):
        raise ValueError(f"{name} must have shape {expected}, got {V.shape}")
    if finite:
        check_finite(V, name, "coordinates")
        check_coordinate_range(V, name)
    return V


def check_mesh(V, F, *, batch: bool | None = None, name: str = "vertices"
               ) -> tuple[np.ndarray, np.ndarray]:
    """Positions and the triangles over them (:func:`check_vertices`, then :func:`check_faces`
    with every index below the number of vertices).

    Parameters
    ----------
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
    F : (n_faces, 3) int
    batch : bool, optional
        As for :func:`check_vertices`.
    name : str
        The name of ``V`` in error messages.

    Returns
    -------
    V : float64 array of the input's shape
    F : (n_faces, 3) int64
    """
    V = check_vertices(V, name, batch=batch)
    return V, check_faces(F, n_vertices=V.shape[-2])


def check_matrices(M, name: str, size: int = 3) -> np.ndarray:
    """A stack of square matrices.

    Parameters
    ----------
    M : (..., size, size) float
        At least two dimensions.
    name : str
        The argument's name in error messages.
    size : int
        The side of the matrices (3 for the library's rotations and deformation gradients).

    Returns
    -------
    M : (..., size, size) float64
    """
    M = np.asarray(M, dtype=np.float64)
    if M.ndim < 2 or M.shape[-2:] != (size, size):
        raise ValueError(f"{name} must have shape (..., {size}, {size}), got {M.shape}")
    return M


def check_vectors(w, name: str, size: int = 3) -> np.ndarray:
    """A stack of vectors.

    Parameters
    ----------
    w : (..., size) float
        At least one dimension.
    name : str
        The argument's name in error messages.
    size : int
        Length of each vector (3 for rotation vectors).

    Returns
    -------
    w : (..., size) float64
    """
    w = np.asarray(w, dtype=np.float64)
    if w.shape[-1:] != (size,):
        raise ValueError(f"{name} must have shape (..., {size}), got {w.shape}")
    return w


def check_rows(X, name: str, n_columns: int | None = None, *, single: bool = True,
               what: str = "") -> np.ndarray:
    """One vector or a matrix of rows (feature vectors, latent codes).

    Parameters
    ----------
    X : (k,) or (n_rows, k) float
    name : str
        The argument's name in error messages.
    n_columns : int, optional
        When given, ``k`` must be exactly this.
    single : bool
        Accept a single vector ``(k,)`` (default); ``False`` accepts ``(n_rows, k)`` only.
    what : str
        Appended to the error message, to say where ``n_columns`` comes from (e.g.
        ``"for this 'paper' layout"``).

    Returns
    -------
    X : float64 array of the input's shape
    """
    X = np.asarray(X, dtype=np.float64)
    k = "k" if n_columns is None else str(n_columns)
    ndims = (1, 2) if single else (2,)
    if X.ndim not in ndims or (n_columns is not None and X.shape[-1] != n_columns):
        expected = f"({k},) or (n_meshes, {k})" if single else f"(n_meshes, {k})"
        suffix = f" {what}" if what else ""
        raise ValueError(f"{name} must have shape {expected}{suffix}, got {X.shape}")
    return X


def check_finite(X, name: str, what: str = "values") -> np.ndarray:
    """Refuse NaN and infinite entries.

    Parameters
    ----------
    X : array-like of numbers, any shape
    name : str
        The argument's name in error messages.
    what : str
        What the entries are, for the message (``"coordinates"``, ``"entries"``).

    Returns
    -------
    X : the input as an ndarray (not copied)

    Raises
    ------
    ValueError
        Naming how many entries are not finite and the index of the first one.
    """
    X = np.asarray(X)
    bad = ~np.isfinite(X)
    if bad.any():
        first = tuple(int(i) for i in np.argwhere(bad)[0])
        where = first[0] if len(first) == 1 else first
        raise ValueError(f"{name}: {int(bad.sum())} of {X.size} {what} are NaN or infinite "
                         f"(first at index {where})")
    return X


def check_choice(value, choices, name: str):
    """A string option among its allowed values.

    Parameters
    ----------
    value : the option as given
    choices : tuple of str
        The allowed values (usually a tuple from :mod:`meshvae_lib.defaults`).
    name : str
        The option's name in error messages.

    Returns
    -------
    value : unchanged
    """
    if value not in choices:
        raise ValueError(f"{name} must be one of {tuple(choices)}, got {value!r}")
    return value


def check_count(value, name: str, minimum: int = 0) -> int:
    """A whole number at least ``minimum`` (an iteration count, a number of steps).

    Parameters
    ----------
    value : int, or a float holding a whole number
    name : str
        The argument's name in error messages.
    minimum : int

    Returns
    -------
    value : int
    """
    try:
        ok = int(value) == value and value >= minimum
    except (TypeError, ValueError):
        ok = False
    if not ok:
        need = "a non-negative integer" if minimum == 0 else f"an integer >= {minimum}"
        raise ValueError(f"{name} must be {need}, got {value!r}")
    return int(value)


def check_positive(value, name: str) -> float:
    """A finite number > 0 (a temperature, a scale).

    Parameters
    ----------
    value : int or float
    name : str
        The argument's name in error messages.

    Returns
    -------
    value : float
    """
    try:
        ok = bool(np.isfinite(float(value)) and float(value) > 0)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return float(value)


def check_samples(X, name: str = "X") -> np.ndarray:
    """A data matrix of at least two finite samples (the rows an embedding or a retrieval ranks).

    Parameters
    ----------
    X : (n_samples >= 2, n_features) float
    name : str
        The argument's name in error messages.

    Returns
    -------
    X : (n_samples, n_features) float64
    """
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2:
        raise ValueError(f"{name} must have shape (n_samples, n_features), got {X.shape}")
    if X.shape[0] < 2:
        raise ValueError(f"{name} needs at least 2 samples, got {X.shape[0]}")
    if not np.all(np.isfinite(X)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return X


class NotFittedError(ValueError, AttributeError):
    """An estimator was used before it was fitted (like scikit-learn's: a ``ValueError`` and an
    ``AttributeError``, so that ``hasattr`` on a fitted-only property answers False)."""


def check_is_fitted(obj, attributes, hint: str = "call fit(...) first") -> None:
    """Raise :class:`NotFittedError` unless ``obj`` has every attribute in ``attributes``.

    Parameters
    ----------
    obj : the estimator
    attributes : str or sequence of str
        Attributes that :meth:`fit` sets (``"min_"``, ``("network_", "kind_")``).
    hint : str
        What to do about it, appended to the message (``"call fit(X) first"``).
    """
    names = (attributes,) if isinstance(attributes, str) else tuple(attributes)
    if not all(hasattr(obj, a) for a in names):
        raise NotFittedError(f"this {type(obj).__name__} is not fitted yet: {hint}")
