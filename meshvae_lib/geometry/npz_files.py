"""Reading ``.npz`` files a user gives: named arrays without pickles, with errors that name the file.

:func:`open_npz` opens the archive (refusing a file that is not one, and never loading pickles),
:func:`npz_array` reads one array (refusing arrays of Python objects) and :func:`npz_names` a
1-D array of names. The collection reader (:mod:`~meshvae_lib.geometry.collection_io`) and the
feature files (:mod:`~meshvae_lib.geometry.rimd_files`) read through them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshvae_lib.input_checks import short_name

__all__ = ["open_npz", "npz_array", "npz_names"]


#: how the files :func:`open_npz` reads begin: a zip archive (an ``.npz``) or a ``.npy`` array.
_NPZ_MAGIC = (b"PK\x03\x04", b"PK\x05\x06", b"\x93NUMPY")


def open_npz(path):
    """``np.load(path)`` without pickles, with errors that name the file and never advise loading
    it with pickles (which would run whatever code a foreign file holds).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    NpzFile (use it as a context manager)

    Raises
    ------
    ValueError
        The file is not an ``.npz`` archive (or is damaged).
    """
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            head = fh.read(6)
    except OSError:
        head = _NPZ_MAGIC[0]  # np.load reports it
    if not head.startswith(_NPZ_MAGIC):  # np.load would take it for a pickle and blame pickled data
        what = "it is empty" if not head else f"it does not start like one (first bytes {head[:4]!r})"
        raise ValueError(f"{short_name(path.name)}: cannot be read as .npz: {what}; an .npz is a zip archive"
                         " of named arrays (numpy.savez)")
    try:
        data = np.load(path, allow_pickle=False)
    except Exception as exc:
        raise ValueError(f"{short_name(path.name)}: cannot be read as .npz ({_npz_reason(exc)})") from None
    if not hasattr(data, "files"):  # a plain .npy file under an .npz name
        raise ValueError(f"{short_name(path.name)}: is a single .npy array, not an .npz archive of named arrays")
    return data


def _npz_reason(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    if "allow_pickle" in text or "pickle" in text.lower():
        return "it holds Python objects (pickled data), which are never loaded"
    return short_name(text, 160)


def npz_array(data, key: str, path) -> np.ndarray:
    """Array ``key`` of an open ``.npz`` (:func:`open_npz`), with errors that name the file and the
    array: an array of Python objects is refused (it would need a pickle), never loaded.

    Returns
    -------
    ndarray
    """
    try:
        return np.asarray(data[key])
    except Exception as exc:  # ValueError: object arrays; zipfile/zlib errors: damaged member
        raise ValueError(f"{short_name(Path(path).name)}: array {short_name(repr(key))} cannot be read"
                         f" ({_npz_reason(exc)}); store numbers or text (fixed-width strings)") from None


def npz_names(data, key: str, path) -> list[str]:
    """A 1-D array of names (text or numbers) of an open ``.npz``, as a list of str."""
    val = npz_array(data, key, path)
    if val.dtype.kind not in "biuUS" or val.ndim != 1:
        raise ValueError(f"{short_name(Path(path).name)}: {key!r} must be a 1-D array of text or whole numbers,"
                         f" got dtype {val.dtype} and shape {val.shape}")
    return [v.decode(errors="replace") if isinstance(v, bytes) else str(v) for v in val.tolist()]
