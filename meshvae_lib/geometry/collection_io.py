"""Reading and writing mesh collections: a folder of mesh files (+ ``labels.csv``) or one ``.npz``.

A *collection* is a set of meshes with one shared connectivity
(:class:`~meshvae_lib.geometry.collection.MeshCollection`, see ``docs/ARCHITECTURE.md``):

- an ``.npz`` with ``vertices (N, V, 3)``, ``faces (F, 3)``, optional ``names (N,)`` and one array
  ``label_<column> (N,)`` per label column; or
- a folder of mesh files (``.obj``, ``.ply``, ``.off``, read by
  :func:`~meshvae_lib.geometry.mesh_files.read_mesh`) in natural order (``2.obj`` before
  ``10.obj``), with an optional ``labels.csv`` whose first column is ``name`` (the file name
  without extension) followed by one column per label.

Every mesh is checked by :func:`~meshvae_lib.geometry.mesh_checks.validate_mesh`; a mesh whose
connectivity differs from the first is refused with a ``ValueError`` saying what differs.
"""

from __future__ import annotations

import csv
import logging
import re
from pathlib import Path

import numpy as np

from meshvae_lib.atomic import atomic_file, atomic_folder
from meshvae_lib.defaults import FILE_NAME_CHARS
from meshvae_lib.geometry.collection import MeshCollection, default_names
from meshvae_lib.geometry.mesh_checks import validate_mesh
from meshvae_lib.geometry.mesh_files import MESH_SUFFIXES, read_mesh, write_mesh
from meshvae_lib.geometry.npz_files import npz_array, npz_names, open_npz
from meshvae_lib.progress import progress as progress_bar
from meshvae_lib.input_checks import check_numeric, short_name

__all__ = ["read_collection", "write_collection", "natural_key", "FOLDER_OUTPUTS"]

logger = logging.getLogger(__name__)

#: what a collection folder that :func:`write_collection` replaces may hold: mesh files and
#: ``labels.csv`` (``meshvae_lib.atomic.check_writable``'s ``outputs``); a folder holding anything
#: else is refused rather than replaced.
FOLDER_OUTPUTS = (*MESH_SUFFIXES, "labels.csv")


def natural_key(name: str) -> list:
    """Sort key that orders embedded numbers by value: ``'2.obj' < '10.obj'``."""
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", str(name))]


def _parse_label_column(values: list[str]) -> np.ndarray:
    try:
        nums = np.array([float(v) for v in values])
    except ValueError:
        return np.array(values)
    if np.all(np.isfinite(nums)) and np.all(nums == np.round(nums)) and all(
        re.fullmatch(r"[+-]?\d+", v.strip()) for v in values
    ):
        return nums.astype(np.int64)
    return nums


def _names(names) -> str:
    """A few names for a message, each cut to a readable length."""
    return "[" + ", ".join(short_name(repr(n)) for n in names) + "]"


def _read_labels_csv(path: Path, names: list[str]) -> dict[str, np.ndarray]:
    """The label columns of a folder's ``labels.csv``: one row per mesh, in ``names``' order.

    The file is UTF-8, with or without a byte-order mark. Raises ``ValueError`` naming the file and
    the line for a header without ``name`` first, an
    empty row (blank lines at the end are allowed), a row with another number of fields, an empty
    mesh name or label value, a mesh named twice, and rows missing or naming no mesh.
    """
    try:
        with open(path, newline="", encoding="utf-8-sig") as fh:  # a byte-order mark (Excel's UTF-8 CSV) is skipped
            rows = list(enumerate(csv.reader(fh), start=1))
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ValueError(f"{path}: is not a readable CSV file ({short_name(exc, 120)})") from None
    while rows and not any(c.strip() for c in rows[-1][1]):  # blank lines at the end
        rows.pop()
    if not rows:
        return {}
    header = [h.strip() for h in rows[0][1]]
    if not header or header[0] != "name":
        raise ValueError(f"{path}: the first column must be 'name', got header {_names(header[:5])}")
    empty = [h for h in header[1:] if not h]
    if empty or len(set(header)) != len(header):
        raise ValueError(f"{path}: line {rows[0][0]}: the header needs distinct, non-empty column names,"
                         f" got {_names(header[:8])}")
    table: dict[str, list[str]] = {}
    first_line: dict[str, int] = {}
    for k, row in rows[1:]:
        if not any(c.strip() for c in row):
            raise ValueError(f"{path}: line {k} is empty; every row names a mesh and its labels")
        if len(row) != len(header):
            raise ValueError(
                f"{path}: line {k} has {len(row)} fields, the header has {len(header)}"
            )
        cells = [c.strip() for c in row]
        if not cells[0]:
            raise ValueError(f"{path}: line {k} has an empty mesh name")
        blank = [header[c] for c, v in enumerate(cells) if not v]
        if blank:
            raise ValueError(f"{path}: line {k} ({short_name(repr(cells[0]))}) has an empty value in column"
                             f" {short_name(repr(blank[0]))}")
        if cells[0] in table:
            raise ValueError(f"{path}: line {k} names mesh {short_name(repr(cells[0]))} again (first on line"
                             f" {first_line[cells[0]]}); give one row per mesh")
        table[cells[0]] = cells[1:]
        first_line[cells[0]] = k
    missing = [n for n in names if n not in table]
    if missing:
        raise ValueError(f"{path}: no row for mesh(es) {_names(missing[:5])}")
    unknown = sorted(set(table) - set(names))
    if unknown:
        raise ValueError(f"{path}: rows name meshes that are not in the folder: {_names(unknown[:5])}")
    return {
        col: _parse_label_column([table[n][c] for n in names])
        for c, col in enumerate(header[1:])
    }


def _check_same_connectivity(F_ref, F, name: str, ref_name: str, n_ref: int, n: int) -> None:
    if n != n_ref:
        raise ValueError(
            f"{name}: has {n} vertices but {ref_name} has {n_ref}; a collection must share one "
            "connectivity"
        )
    if F.shape != F_ref.shape:
        raise ValueError(
            f"{name}: has {len(F)} faces but {ref_name} has {len(F_ref)}; a collection must share "
            "one connectivity"
        )
    diff = np.flatnonzero((F != F_ref).any(axis=1))
    if len(diff):
        k = int(diff[0])
        raise ValueError(
            f"{name}: its faces differ from those of {ref_name} ({len(diff)} faces differ; first: "
            f"face {k} is {F[k].tolist()} vs {F_ref[k].tolist()})"
        )


def _validate_collection(vertices: np.ndarray, faces: np.ndarray, names, src: str,
                         allow_degenerate: bool) -> None:
    bad = ~np.isfinite(vertices).all(axis=(1, 2))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{src}: mesh {names[k]!r} (index {k}) has NaN or infinite coordinates"
        )
    for k in range(len(vertices)):
        validate_mesh(vertices[k], faces, name=f"{src}: mesh {names[k]!r}",
                      allow_degenerate=allow_degenerate)


def read_collection(path, *, allow_degenerate: bool = False, progress: bool = False
                    ) -> MeshCollection:
    """Read a collection: an ``.npz``, a folder of meshes (+ ``labels.csv``), or one mesh file.

    Parameters
    ----------
    path : str or Path
    allow_degenerate : bool
        Accept zero-area faces (see :func:`validate_mesh`).
    progress : bool
        Show a progress bar (stderr) while reading a folder.

    Returns
    -------
    MeshCollection
        ``vertices (N, V, 3) float64``, ``faces (F, 3) int64``, ``names``, ``labels``. Names of a
        folder's meshes are the file names without extension.

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        Bad content: see :func:`validate_mesh`; meshes whose connectivity differs from the first
        are named with what differs.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such collection (folder, .npz or mesh file): {path}")
    if path.is_dir():
        return _read_folder(path, allow_degenerate, progress)
    if path.suffix.lower() == ".npz":
        return _read_npz(path, allow_degenerate)
    V, F = read_mesh(path, allow_degenerate=allow_degenerate)
    return MeshCollection(V[None], F, [path.stem], {})


def _read_npz(path: Path, allow_degenerate: bool) -> MeshCollection:
    data = open_npz(path)
    src = short_name(path.name)
    with data:
        for key in ("vertices", "faces"):
            if key not in data.files:
                raise ValueError(f"{src}: has no {key!r} array (found {_names(data.files[:10])})")
        vertices = np.asarray(check_numeric(npz_array(data, "vertices", path), f"{src}: 'vertices'"),
                              dtype=np.float64)
        faces = check_numeric(npz_array(data, "faces", path), f"{src}: 'faces'")
        if vertices.ndim == 2:
            vertices = vertices[None]
        if vertices.ndim != 3 or vertices.shape[-1] != 3:
            raise ValueError(
                f"{src}: 'vertices' must have shape (N, V, 3), got {vertices.shape}"
            )
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(
                f"{src}: 'faces' must be triangles with shape (F, 3), got {faces.shape}"
            )
        n = len(vertices)
        if n == 0:
            raise ValueError(f"{src}: holds no meshes ('vertices' has shape {vertices.shape})")
        names = (npz_names(data, "names", path) if "names" in data.files else default_names(n))
        if len(names) != n:
            raise ValueError(f"{src}: {len(names)} names for {n} meshes")
        _check_distinct_names(names, src)
        labels = {}
        for key in data.files:
            if key.startswith("label_"):
                val = npz_array(data, key, path)
                if val.dtype.kind not in "biufUS":
                    raise ValueError(f"{src}: {short_name(repr(key))} must hold numbers or text, got dtype {val.dtype}")
                if val.shape != (n,):
                    raise ValueError(
                        f"{src}: {short_name(repr(key))} must have shape ({n},), got {val.shape}"
                    )
                labels[key[len("label_"):]] = val
    _validate_collection(vertices, faces, names, src, allow_degenerate)
    return MeshCollection(vertices, faces.astype(np.int64), names, labels)


def _check_distinct_names(names: list[str], src: str) -> None:
    """ValueError naming the first mesh name that ``names`` holds twice (a name must pick one mesh)."""
    first: dict[str, int] = {}
    for k, name in enumerate(names):
        if name in first:
            raise ValueError(f"{src}: mesh name {short_name(repr(name))} is given twice (meshes {first[name]} and {k});"
                             " every mesh needs its own name")
        first[name] = k


def _read_folder(path: Path, allow_degenerate: bool, progress: bool) -> MeshCollection:
    files = sorted(
        (p for p in path.iterdir() if p.is_file() and p.suffix.lower() in MESH_SUFFIXES),
        key=lambda p: natural_key(p.name),
    )
    if not files:
        raise ValueError(f"{path}: holds no mesh files ({', '.join(MESH_SUFFIXES)})")
    stems = [p.stem for p in files]
    if len(set(stems)) != len(stems):
        dup = sorted({s for s in stems if stems.count(s) > 1})
        raise ValueError(f"{path}: several files share the name(s) {dup[:5]} (different suffixes)")
    it = files
    if progress and len(files) > 20:
        it = progress_bar(files, desc="reading meshes", unit="mesh")
    V_ref = F_ref = None
    verts = []
    for k, p in enumerate(it):
        V, F = read_mesh(p, allow_degenerate=allow_degenerate)
        if k == 0:
            V_ref, F_ref = V, F
        else:
            _check_same_connectivity(F_ref, F, p.name, files[0].name, len(V_ref), len(V))
        verts.append(V)
    logger.info("read %d meshes from %s", len(files), path)
    labels = {}
    csv_path = path / "labels.csv"
    if csv_path.is_file():
        labels = _read_labels_csv(csv_path, stems)
    return MeshCollection(np.stack(verts), F_ref, stems, labels)


def write_collection(path, vertices, faces=None, names=None, labels=None) -> Path:
    """Write a collection to an ``.npz`` (when ``path`` ends in ``.npz``) or to a folder.

    A folder gets one OBJ file per mesh, named after the mesh when the names are usable as file
    names and keep their order under natural sort (else numbered ``0000_<name>.obj``, the name cut
    to ``FILE_NAME_CHARS`` characters), plus ``labels.csv`` when there are labels. Positions keep full
    float64 precision in both formats.

    Writing is atomic (:mod:`meshvae_lib.atomic`): the ``.npz`` through a temporary file, the folder
    through a temporary folder that replaces an existing folder as a whole (so it holds exactly the
    new meshes; a folder holding files other than :data:`FOLDER_OUTPUTS` raises ValueError and is
    left alone). A failed write leaves the old output as it was and raises
    :class:`~meshvae_lib.atomic.OutputError` (``cannot write FILE: reason``).

    Parameters
    ----------
    path : str or Path
    vertices : (n_meshes, n_vertices, 3) float, or a :class:`MeshCollection`
        (then ``faces``, ``names`` and ``labels`` default to the collection's).
    faces : (n_faces, 3) int
    names : list of str, optional
    labels : dict str -> (n_meshes,) array, optional

    Returns
    -------
    path : Path
    """
    if isinstance(vertices, MeshCollection):
        col = vertices
        faces = col.faces if faces is None else faces
        names = col.names if names is None else names
        labels = col.labels if labels is None else labels
        vertices = col.vertices
    if faces is None:
        raise ValueError("faces are required")
    col = MeshCollection(vertices, faces, list(names) if names is not None else [],
                         dict(labels or {}))
    path = Path(path)
    if path.suffix.lower() == ".npz":
        if not path.parent.is_dir():
            raise FileNotFoundError(f"folder does not exist: {path.parent}")
        arrays = {"vertices": col.vertices, "faces": col.faces, "names": np.array(col.names)}
        for key, val in col.labels.items():
            arrays[f"label_{key}"] = val
        with atomic_file(path) as fh:
            np.savez_compressed(fh, **arrays)
        return path
    stems = list(col.names)
    safe = (all(_FILE_NAME.fullmatch(s) and len(s.encode()) <= FILE_NAME_CHARS for s in stems)
            and len(set(stems)) == len(stems))
    if not safe or sorted(stems, key=natural_key) != stems:
        width = max(4, len(str(len(stems) - 1)))
        stems = [f"{k:0{width}d}_{_file_name_part(s)}" for k, s in enumerate(stems)]
    with atomic_folder(path, outputs=FOLDER_OUTPUTS) as tmp:
        for V, stem in zip(col.vertices, stems):
            write_mesh(tmp / f"{stem}.obj", V, col.faces)
        if col.labels:
            with open(tmp / "labels.csv", "w", newline="") as fh:
                w = csv.writer(fh)
                keys = list(col.labels)
                w.writerow(["name", *keys])
                for k, stem in enumerate(stems):
                    w.writerow([stem, *[_fmt_label(col.labels[c][k]) for c in keys]])
    return path


#: a mesh name usable as a file name as it is: letters and digits of any script, ``_ . + -``.
_FILE_NAME = re.compile(r"[\w.+-]+")


def _file_name_part(name: str) -> str:
    """``name`` made usable in a file name: runs of other characters (spaces, slashes, control
    characters) become ``_``, letters of any script are kept, cut to ``FILE_NAME_CHARS`` bytes of
    UTF-8 (file systems count bytes)."""
    text = re.sub(r"[^\w.+-]+", "_", name).encode()[:FILE_NAME_CHARS]
    return text.decode(errors="ignore")


def _fmt_label(v) -> str:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return str(v)
