"""A mesh named on the command line: an index into a collection, a mesh name of it, or a mesh file.

:func:`resolve_mesh` is the one resolver every command uses (``features --reference``,
``interpolate A B``); it returns a :class:`ChosenMesh`. Not a sub-command: ``meshvae_lib.cli``
re-exports both.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from . import UsageError


@dataclass(frozen=True)
class ChosenMesh:
    """A mesh picked by :func:`resolve_mesh`: its vertices (n, 3), its name, and either its index
    into the collection or the file it was read from."""

    vertices: object
    name: str
    index: int | None = None
    file: str | None = None

    def describe(self) -> str:
        from meshvae_lib.input_checks import short_name

        return (f"file {self.file}" if self.file is not None
                else f"mesh {short_name(repr(self.name))} (index {self.index})")


def resolve_mesh(spec: str, collection, option: str, *, faces=None, n_vertices: int | None = None,
                 owner: str = "the collection's", allow_degenerate: bool = False,
                 hint: str = "") -> ChosenMesh:
    """The mesh that ``spec`` names: an index into ``collection`` (negative counts from the end), a
    mesh name of ``collection``, or else a mesh file (OBJ/PLY/OFF). Without a collection only a
    file.

    option : what the command line calls it (``--reference``, ``A``), for the messages.
    faces, n_vertices : the connectivity a mesh file must have (default: the collection's);
        ``owner`` says whose it is in the message ("the collection's", "the model's").
    hint : appended to the message when ``spec`` names nothing.

    Raises :class:`UsageError` for an index out of range, a ``spec`` that names nothing, or a file
    with another connectivity.
    """
    from meshvae_lib.input_checks import short_name

    if collection is not None:
        n = len(collection)
        try:
            k = int(spec)
        except ValueError:
            k = collection.names.index(spec) if spec in collection.names else None
        if k is not None:
            if not -n <= k < n:
                raise UsageError(f"{option} {k} is out of range for {n} meshes (0..{n - 1}, or -{n}..-1"
                                 " from the end)")
            k %= n
            return ChosenMesh(collection.vertices[k], collection.names[k], index=k)
        if faces is None:
            faces, n_vertices = collection.faces, collection.n_vertices
    from pathlib import Path

    path = Path(spec)
    try:
        is_file = path.is_file()
    except (OSError, ValueError):  # a name too long for the file system, a NUL byte
        is_file = False
    if not is_file:
        shown = short_name(repr(spec))
        if _is_dir(path):
            raise UsageError(f"{option} {shown} is a folder, not a mesh file{hint}")
        if path.suffix or os.sep in spec:  # meant as a file: say it is not there
            where = "; nor is it a mesh name of the collection" if collection is not None else ""
            raise UsageError(f"{option} {shown}: no such mesh file{where}{hint}")
        what = "neither an index, a mesh name of the collection, nor" if collection is not None else "not"
        raise UsageError(f"{option} {shown} is {what} a mesh file{hint}")
    import numpy as np

    from meshvae_lib.geometry.mesh_files import read_mesh

    V, F = read_mesh(path, allow_degenerate=allow_degenerate)
    if faces is not None:
        faces = np.asarray(faces)
        if len(V) != n_vertices or F.shape != faces.shape or np.any(F != faces):
            raise UsageError(f"{option} {short_name(path.name)}: its connectivity ({len(V)} vertices, {len(F)} faces)"
                             f" differs from {owner} ({n_vertices} vertices, {len(faces)} faces)")
    return ChosenMesh(V, path.stem, file=short_name(path.name))


def _is_dir(path) -> bool:
    try:
        return path.is_dir()
    except (OSError, ValueError):
        return False
