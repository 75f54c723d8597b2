"""Atomic output: every file and folder the library and ``meshvae`` write appears whole or not at all.

A file is written to a temporary file in its destination's folder and renamed over the destination
with ``os.replace`` (:func:`atomic_file`); a folder of files is written to a temporary folder next
to its destination and swapped in as a whole (:func:`atomic_folder`): an older folder of that name
is replaced, never merged with the new files. When writing fails -- a full
disk, a permission, Ctrl-C -- the temporary output is removed, an older file or folder of that name
is left as it was (byte for byte), and the error is an :class:`OutputError` (an ``OSError``) that
names the file: ``cannot write FILE: reason``. :func:`check_writable` says before any work whether a
destination can be written at all.

This is a base module (standard library only, like ``tolerances`` and ``defaults``): every layer
may import it.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import uuid
from pathlib import Path

__all__ = ["OutputError", "atomic_file", "atomic_folder", "check_writable"]


class OutputError(OSError):
    """Writing an output failed: ``cannot write FILE: reason`` (the partial output is removed and any
    older output of that name kept). ``errno`` is the cause's, when it had one."""

    def __init__(self, path, reason: str, errno: int | None = None):
        super().__init__(f"cannot write {path}: {reason}")
        self.path = Path(path)
        self.reason = reason
        self.errno = errno


def _reason(exc: BaseException) -> str:
    """An exception as a few words, without Python's ``[Errno N]`` prefix and the file name it may
    repeat."""
    if isinstance(exc, OSError) and exc.strerror:
        return exc.strerror
    text = str(exc).strip()
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _temp_name(path: Path, kind: str) -> Path:
    """A hidden name next to ``path`` that no other writer uses (process id and a random part)."""
    return path.with_name(f".{path.name}.{kind}-{os.getpid()}-{uuid.uuid4().hex[:8]}")


def _is_special(path: Path) -> bool:
    """Whether ``path`` exists and is neither a regular file nor a folder (a device such as
    /dev/null or /dev/full, a pipe): such a destination is written in place, not replaced."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return False
    return not (stat.S_ISREG(mode) or stat.S_ISDIR(mode))


def _remove(path: Path) -> None:
    with contextlib.suppress(OSError):
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        else:
            path.unlink()


def _is_output(name: str, outputs) -> bool:
    """Whether a file called ``name`` is one a writer of ``outputs`` writes: an entry starting with a
    dot is a suffix (".obj"), any other an exact name ("labels.csv")."""
    lower = name.lower()
    return any(lower.endswith(o) if o.startswith(".") else lower == o for o in outputs)


def _foreign_entries(path: Path, outputs) -> list[str]:
    """The names in the existing folder ``path`` that are not plain files of ``outputs``, sorted."""
    return sorted(e.name for e in path.iterdir()
                  if e.is_symlink() or not e.is_file() or not _is_output(e.name, outputs))


def _check_replaceable(path: Path, outputs) -> None:
    """ValueError when the existing folder ``path`` holds anything but files of ``outputs`` (it would
    be replaced as a whole, and those files lost), or is the current folder (which cannot be renamed)."""
    if not path.is_dir():
        return
    if path.name in ("", ".", "..") or path.resolve() == Path.cwd().resolve():
        raise ValueError(f"cannot write {path}: an output folder is replaced as a whole, and this is the current"
                         " folder (or names no folder of its own): name a new folder")
    if outputs is None:
        return
    foreign = _foreign_entries(path, outputs)
    if foreign:
        shown = ", ".join(repr(n) if len(n) <= 60 else repr(n[:57] + "...") for n in foreign[:3])
        raise ValueError(f"cannot write {path}: it holds {len(foreign)} file(s) or folder(s) that are not outputs"
                         f" ({shown}{', ...' if len(foreign) > 3 else ''}); an output folder is replaced as a"
                         " whole: choose a new folder, or empty this one")


def check_writable(path, *, folder: bool = False, parents: bool = False, outputs=None) -> Path:
    """Raise ``ValueError`` unless ``path`` can be written (before any work is done for it).

    Parameters
    ----------
    path : str or Path
        The destination: a file, or with ``folder=True`` a folder of files.
    folder : bool
        The destination is a folder (it may exist; its temporary folder is made next to it, and
        missing parent folders are created when writing, so the nearest existing ancestor must be
        a writable folder). An existing folder is replaced as a whole: it must be writable too
        (its old files are removed).
    parents : bool
        A file whose missing parent folders the writer creates (``write_checkpoint`` does): the
        nearest existing ancestor must then be a writable folder.
    outputs : sequence of str, optional
        With ``folder``: what an existing folder may hold (suffixes such as ".obj", or exact names
        such as "labels.csv", lower case), since replacing it removes everything in it; anything
        else is refused. None: no check.

    Returns
    -------
    path : Path

    Raises
    ------
    ValueError
        The destination is a folder where a file is expected (or a file where a folder is), its
        folder does not exist (files) or is not a folder, no file can be created in it (tried
        with a temporary file, removed at once), or an existing output folder holds other files
        (``outputs``) or cannot be written.
    """
    path = Path(path)
    if folder:
        if path.exists() and not path.is_dir():
            raise ValueError(f"cannot write {path}: it exists and is not a folder")
        parent = path.parent  # where the temporary folder goes
        while not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.is_dir():
            raise ValueError(f"cannot write {path}: {parent} is not a folder")
        if path.is_dir():  # replaced as a whole: its old files are removed, so it must be writable
            _check_replaceable(path, outputs)
            _probe(path / "out", path)
    else:
        target = path.resolve() if path.is_symlink() else path
        if target.is_dir():
            raise ValueError(f"cannot write {path}: it is a folder")
        if _is_special(target):
            return path
        parent = target.parent
        while parents and not parent.exists() and parent != parent.parent:
            parent = parent.parent
        if not parent.exists():
            raise ValueError(f"cannot write {path}: folder does not exist: {parent}")
        if not parent.is_dir():
            raise ValueError(f"cannot write {path}: {parent} is not a folder")
    _probe(parent / (path.name or "out"), path)
    return path


def _probe(near: Path, path: Path) -> None:
    """ValueError (naming ``path``) unless a file can be created next to ``near`` (removed at once)."""
    probe = _temp_name(near, "probe")
    try:
        with open(probe, "wb"):
            pass
    except OSError as exc:
        raise ValueError(f"cannot write {path}: {_reason(exc)}") from None
    finally:
        _remove(probe)


@contextlib.contextmanager
def atomic_file(path, mode: str = "wb", **open_kwargs):
    """Open a temporary file next to ``path`` for writing; on a clean exit it replaces ``path``.

    Use as ``with atomic_file(path) as fh: np.savez(fh, ...)``. On any exception inside the block
    (or while renaming) the temporary file is removed, ``path`` keeps its old content (or stays
    absent), and an ``OSError`` becomes :class:`OutputError` naming ``path``; other exceptions
    (``KeyboardInterrupt`` included) pass through unchanged. A symbolic link is followed (the file
    it points to is replaced); a destination that is a device or a pipe is written in place.

    Parameters
    ----------
    path : str or Path
        The destination; its folder must exist.
    mode : "wb" or "w"
    open_kwargs : passed to ``open`` (``newline=""``, ``encoding=...``)

    Yields
    ------
    fh : the open temporary file
    """
    path = Path(path)
    target = path.resolve() if path.is_symlink() else path
    if _is_special(target):
        try:
            with open(target, mode, **open_kwargs) as fh:
                yield fh
        except OSError as exc:
            if isinstance(exc, OutputError):
                raise
            raise OutputError(path, _reason(exc), exc.errno) from exc
        return
    tmp = _temp_name(target, "tmp")
    try:
        with open(tmp, mode, **open_kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, target)
    except OSError as exc:
        _remove(tmp)
        if isinstance(exc, OutputError):
            raise
        raise OutputError(path, _reason(exc), exc.errno) from exc
    except BaseException:
        _remove(tmp)
        raise


@contextlib.contextmanager
def atomic_folder(path, outputs=None):
    """A temporary folder next to ``path`` to write files into; on a clean exit it takes ``path``'s place.

    When ``path`` does not exist the temporary folder is renamed to it (one step). When it is an
    existing folder, it is renamed aside, the new folder renamed to ``path`` and the old one removed:
    the result holds exactly the new files, never a mix of old and new (renames within one file
    system need no space). On any exception inside the block the temporary folder is removed and
    ``path`` is left as it was; an ``OSError`` becomes :class:`OutputError` naming ``path``.

    Parameters
    ----------
    path : str or Path
        The destination folder; missing parent folders are created.
    outputs : sequence of str, optional
        What an existing folder may hold (see :func:`check_writable`); a folder holding anything
        else raises ValueError before anything is written, so that no other file is removed.

    Yields
    ------
    tmp : Path
        The temporary folder (write the files into it under their final names).
    """
    path = Path(path)
    tmp = aside = None
    try:
        if path.exists() and not path.is_dir():
            raise NotADirectoryError(f"cannot write {path}: it exists and is not a folder")
        _check_replaceable(path, outputs)
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = _temp_name(path, "tmp")
        tmp.mkdir()
        yield tmp
        if path.exists():
            aside = _temp_name(path, "old")
            os.rename(path, aside)
            try:
                os.rename(tmp, path)
            except BaseException:
                os.rename(aside, path)
                aside = None
                raise
        else:
            os.rename(tmp, path)
        tmp = None
    except OSError as exc:
        if isinstance(exc, OutputError) and tmp is not None and tmp in exc.path.parents:
            # a file written inside the temporary folder: name it where it was going
            raise OutputError(path / exc.path.relative_to(tmp), exc.reason, exc.errno) from exc
        if isinstance(exc, (OutputError, NotADirectoryError, IsADirectoryError)):
            raise
        raise OutputError(path, _reason(exc), exc.errno) from exc
    finally:
        for leftover in (tmp, aside):
            if leftover is not None:
                _remove(leftover)
