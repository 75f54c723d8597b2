"""Checks of what a user's files hold, and names cut to a readable length for messages (issue 39).

The readers (:mod:`meshvae_lib.geometry.collection_io`, :mod:`meshvae_lib.geometry.rimd_files`,
:mod:`meshvae_lib.geometry.mesh_checks`) run them on every array they load, so that a hostile or
broken file is refused with a message that names it, before its values reach a solver:

=================================  ===========================================================
helper                             accepts, returns
=================================  ===========================================================
:func:`check_coordinate_range`     coordinates whose squares do not overflow float64
:func:`check_numeric`              a real-number array (not complex, text or Python objects)
:func:`short_name`                 a name cut to a readable length for a message
=================================  ===========================================================

This is a base module (numpy only, like ``validation``): every layer may import it.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import MESSAGE_NAME_CHARS
from meshvae_lib.tolerances import MAX_ABS_COORDINATE

__all__ = ["check_coordinate_range", "check_numeric", "short_name"]


def check_coordinate_range(V, name: str) -> np.ndarray:
    """Refuse coordinates too large for the geometry's float64 arithmetic.

    Parameters
    ----------
    V : array-like of finite coordinates, any shape
    name : str
        The argument's name in error messages.

    Returns
    -------
    V : the input as an ndarray (not copied)

    Raises
    ------
    ValueError
        When some ``|coordinate| > MAX_ABS_COORDINATE`` (``tolerances``): their squares and the
        products of up to six of them that the geometry forms overflow. The message shows the
        largest one and where it is.
    """
    V = np.asarray(V)
    if V.size:
        big = np.abs(V) > MAX_ABS_COORDINATE
        if big.any():
            first = tuple(int(i) for i in np.argwhere(big)[0])
            where = first[0] if len(first) == 1 else first
            raise ValueError(f"{name}: {int(big.sum())} coordinates are too large (first at index {where}:"
                             f" {float(V[first]):.3g}; largest {float(np.abs(V).max()):.3g}): their squares"
                             f" overflow float64; scale the mesh to |coordinates| <= {MAX_ABS_COORDINATE:g}")
    return V


def check_numeric(X, name: str) -> np.ndarray:
    """A real-number array: booleans, integers or floats, not complex numbers, strings or objects.

    Parameters
    ----------
    X : array-like
    name : str
        The argument's name (a file and an array) in error messages.

    Returns
    -------
    X : the input as an ndarray (not converted)

    Raises
    ------
    ValueError
        Naming the dtype found.
    """
    X = np.asarray(X)
    if X.dtype.kind not in "biuf":
        what = {"c": "complex numbers", "U": "text", "S": "bytes", "O": "Python objects",
                "M": "dates", "m": "time spans", "V": "raw records"}.get(X.dtype.kind, "non-numbers")
        raise ValueError(f"{name} must hold real numbers, got {what} (dtype {X.dtype})")
    return X


def short_name(text, limit: int = MESSAGE_NAME_CHARS) -> str:
    """``text`` as a string cut to ``limit`` characters for a message (``abc...xyz (1234 characters)``).

    Parameters
    ----------
    text : any object (converted with ``str``)
    limit : int

    Returns
    -------
    str
    """
    text = str(text)
    if len(text) <= limit:
        return text
    keep = max(limit - 3, 2)
    return f"{text[: keep - keep // 3]}...{text[len(text) - keep // 3:]} ({len(text)} characters)"
