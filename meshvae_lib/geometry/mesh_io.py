"""Reading and writing meshes and mesh collections.

A *collection* is a set of meshes with one shared connectivity (see ``docs/ARCHITECTURE.md``):

- an ``.npz`` with ``vertices (N, V, 3)``, ``faces (F, 3)``, optional ``names (N,)`` and one array
  ``label_<column> (N,)`` per label column; or
- a folder of mesh files (``.obj``, ``.ply``, ``.off``) read in natural order (``2.obj`` before
  ``10.obj``), with an optional ``labels.csv`` whose first column is ``name`` (the file name without
  extension) followed by one column per label.

Single meshes are read with trimesh without any processing (``process=False``,
``maintain_order=True``): vertices are never merged, reordered or dropped, so vertex ``k`` of every
file is the same point of the shape.

Bad input is refused with a ``ValueError`` naming the file and the problem: non-finite coordinates,
faces that are not triangles (polygons in OBJ/OFF files, unless ``triangulate=True``), face indices
out of range, faces that repeat a vertex, vertices that no face uses, zero-area faces (unless
``allow_degenerate=True``), and meshes of a collection whose connectivity differs from the first.
:func:`remove_unreferenced_vertices` is the fix for unused vertices.
"""

from __future__ import annotations

import csv
import logging
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from meshvae_lib import tolerances as tol

__all__ = [
    "MESH_SUFFIXES",
    "MeshCollection",
    "validate_mesh",
    "remove_unreferenced_vertices",
    "read_mesh",
    "write_mesh",
    "read_collection",
    "write_collection",
    "natural_key",
]

logger = logging.getLogger(__name__)

#: file suffixes read as meshes in a collection folder.
MESH_SUFFIXES = (".obj", ".ply", ".off")


@dataclass
class MeshCollection:
    """Meshes sharing one connectivity.

    Attributes
    ----------
    vertices : (n_meshes, n_vertices, 3) float64
    faces : (n_faces, 3) int64
    names : list of str, length n_meshes
    labels : dict str -> (n_meshes,) array (numbers or str)
    """

    vertices: np.ndarray
    faces: np.ndarray
    names: list[str] = field(default_factory=list)
    labels: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self):
        self.vertices = np.asarray(self.vertices, dtype=np.float64)
        self.faces = np.asarray(self.faces, dtype=np.int64)
        if self.vertices.ndim != 3 or self.vertices.shape[-1] != 3:
            raise ValueError(
                f"vertices must have shape (n_meshes, n_vertices, 3), got {self.vertices.shape}"
            )
        if self.faces.ndim != 2 or self.faces.shape[1] != 3:
            raise ValueError(f"faces must have shape (n_faces, 3), got {self.faces.shape}")
        n = self.vertices.shape[0]
        if not self.names:
            self.names = _default_names(n)
        self.names = [str(s) for s in self.names]
        if len(self.names) != n:
            raise ValueError(f"{len(self.names)} names for {n} meshes")
        labels = {}
        for key, val in dict(self.labels).items():
            val = np.asarray(val)
            if val.shape != (n,):
                raise ValueError(f"label {key!r} must have shape ({n},), got {val.shape}")
            labels[str(key)] = val
        self.labels = labels

    def __len__(self) -> int:
        return self.vertices.shape[0]

    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[1]

    def subset(self, indices) -> "MeshCollection":
        """The meshes at ``indices`` (int array-like, or a boolean mask of length ``len(self)``), in
        that order, with their names and labels; the faces are shared. Indices may repeat."""
        idx = np.asarray(indices)
        if idx.dtype == bool:
            if idx.shape != (len(self),):
                raise ValueError(f"a boolean mask must have shape ({len(self)},), got {idx.shape}")
            idx = np.flatnonzero(idx)
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            raise ValueError(f"indices must be a 1-D array of integers, got dtype {idx.dtype} shape {idx.shape}")
        if idx.size == 0:
            raise ValueError("a collection needs at least one mesh, got no indices")
        if idx.min() < -len(self) or idx.max() >= len(self):
            raise ValueError(f"indices must lie in [0, {len(self) - 1}], got range [{idx.min()}, {idx.max()}]")
        return MeshCollection(self.vertices[idx], self.faces, [self.names[i] for i in idx],
                              {k: v[idx] for k, v in self.labels.items()})


def _default_names(n: int) -> list[str]:
    width = max(4, len(str(max(n - 1, 0))))
    return [f"{k:0{width}d}" for k in range(n)]


def natural_key(name: str) -> list:
    """Sort key that orders embedded numbers by value: ``'2.obj' < '10.obj'``."""
    return [int(t) if t.isdigit() else t.lower() for t in re.split(r"(\d+)", str(name))]


# ---------------------------------------------------------------------------------------------
# validation


def validate_mesh(V, F, *, name: str = "mesh", allow_degenerate: bool = False) -> None:
    """Check that ``(V, F)`` is a usable triangle mesh; raise ``ValueError`` otherwise.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int
    name : str
        Used in error messages (a file name, say).
    allow_degenerate : bool
        Accept zero-area faces (area below ``DEGENERATE_AREA_RTOL`` times the squared mean edge
        length). The geometry core copes with them (their cotangent weights fall back to 1, see
        :mod:`meshvae_lib.geometry.cotangent`), but they usually signal a broken file.

    Raises
    ------
    ValueError
        Wrong shapes, non-finite coordinates, indices out of range, faces repeating a vertex,
        unreferenced vertices, or (unless allowed) zero-area faces. The message names the first
        offending vertex or face.
    """
    V = np.asarray(V)
    F = np.asarray(F)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{name}: vertices must have shape (n_vertices, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(
            f"{name}: faces must be triangles with shape (n_faces, 3), got {F.shape}"
        )
    if len(F) == 0:
        raise ValueError(f"{name}: has no faces")
    if not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"{name}: faces must be integers, got dtype {F.dtype}")
    bad = ~np.isfinite(V).all(axis=1)
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(
            f"{name}: {int(bad.sum())} vertices have NaN or infinite coordinates "
            f"(first: vertex {k} = {V[k].tolist()})"
        )
    n = len(V)
    if F.min() < 0 or F.max() >= n:
        raise ValueError(
            f"{name}: face indices must lie in [0, {n - 1}], found range [{F.min()}, {F.max()}]"
        )
    rep = (F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2]) | (F[:, 2] == F[:, 0])
    if rep.any():
        k = int(np.flatnonzero(rep)[0])
        raise ValueError(
            f"{name}: {int(rep.sum())} faces repeat a vertex (first: face {k} = {F[k].tolist()})"
        )
    used = np.zeros(n, bool)
    used[F.reshape(-1)] = True
    if not used.all():
        k = np.flatnonzero(~used)
        raise ValueError(
            f"{name}: {len(k)} unreferenced vertices (no face uses them; first: {k[:5].tolist()}); "
            "remove them with meshvae_lib.geometry.mesh_io.remove_unreferenced_vertices"
        )
    if not allow_degenerate:
        Vf = V.astype(np.float64)
        c = np.cross(Vf[F[:, 1]] - Vf[F[:, 0]], Vf[F[:, 2]] - Vf[F[:, 0]])
        area = 0.5 * np.linalg.norm(c, axis=1)
        e = np.linalg.norm(Vf[F] - Vf[np.roll(F, -1, axis=1)], axis=2)
        scale = np.mean(e) ** 2
        zero = area <= tol.DEGENERATE_AREA_RTOL * scale
        if zero.any():
            k = int(np.flatnonzero(zero)[0])
            raise ValueError(
                f"{name}: {int(zero.sum())} zero-area faces (first: face {k} = {F[k].tolist()}, "
                f"area {area[k]:.3g}); pass allow_degenerate=True (meshvae: --allow-degenerate) to accept them"
            )


def remove_unreferenced_vertices(V, F) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Drop vertices that no face uses, renumbering the faces.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    V_kept : (n_kept, 3) float64
    F_new : (n_faces, 3) int64
    kept : (n_kept,) int64
        Old ids of the kept vertices (``V_kept = V[kept]``).
    """
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    used = np.zeros(len(V), bool)
    used[F.reshape(-1)] = True
    kept = np.flatnonzero(used)
    new_id = np.full(len(V), -1, np.int64)
    new_id[kept] = np.arange(len(kept))
    return V[kept], new_id[F], kept


# ---------------------------------------------------------------------------------------------
# single meshes


def _polygon_corners_in_text(path: Path) -> int:
    """Largest number of corners of a face in an OBJ or ASCII OFF file (3 for triangle meshes)."""
    suffix = path.suffix.lower()
    try:
        text = path.read_text(errors="replace")
    except UnicodeDecodeError:  # pragma: no cover - binary file
        return 3
    most = 3
    if suffix == ".obj":
        for line in text.splitlines():
            if line.startswith("f ") or line.startswith("f\t"):
                most = max(most, len(line.split()) - 1)
    elif suffix == ".off":
        lines = [ln.split("#")[0].split() for ln in text.splitlines()]
        lines = [ln for ln in lines if ln]
        if not lines:
            return 3
        head = lines[0]
        start = 1
        if head[0].upper().endswith("OFF") and len(head) == 1:
            counts = lines[1]
            start = 2
        else:
            counts = head[1:] if head[0].upper().endswith("OFF") else head
        try:
            nv, nf = int(counts[0]), int(counts[1])
        except (ValueError, IndexError):
            return 3
        for ln in lines[start + nv : start + nv + nf]:
            try:
                most = max(most, int(ln[0]))
            except ValueError:
                pass
    return most


def read_mesh(
    path, *, validate: bool = True, triangulate: bool = False, allow_degenerate: bool = False
) -> tuple[np.ndarray, np.ndarray]:
    """Read one triangle mesh (OBJ, PLY, OFF, or anything trimesh reads) without reordering it.

    Parameters
    ----------
    path : str or Path
    validate : bool
        Run :func:`validate_mesh` (default). Turn off only to inspect a broken file.
    triangulate : bool
        Accept polygon faces, split into triangles by trimesh (fan triangulation). Off by default:
        polygons raise an error, because splitting them changes the connectivity.
    allow_degenerate : bool
        Accept zero-area faces (see :func:`validate_mesh`).

    Returns
    -------
    V : (n_vertices, 3) float64
    F : (n_faces, 3) int64

    Raises
    ------
    FileNotFoundError
        If ``path`` does not exist.
    ValueError
        If the file is not a readable triangle mesh or fails validation.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such mesh file: {path}")
    if not triangulate and path.suffix.lower() in (".obj", ".off"):
        corners = _polygon_corners_in_text(path)
        if corners > 3:
            raise ValueError(
                f"{path.name}: has faces with {corners} corners; only triangle meshes are "
                "supported (triangulate it, or read it with triangulate=True)"
            )
    try:
        mesh = trimesh.load(path, process=False, maintain_order=True, force="mesh")
    except Exception as exc:  # trimesh raises many kinds of errors for unreadable files
        raise ValueError(f"{path.name}: cannot be read as a mesh ({exc})") from exc
    V = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    F = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if F.size == 0:
        raise ValueError(f"{path.name}: holds no triangles")
    if validate:
        validate_mesh(V, F, name=path.name, allow_degenerate=allow_degenerate)
    return V, F


def _write_obj(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    with open(path, "w") as fh:
        fh.write(f"# {len(V)} vertices, {len(F)} faces\n")
        np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
        np.savetxt(fh, F + 1, fmt="f %d %d %d")


def _write_off(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    with open(path, "w") as fh:
        fh.write(f"OFF\n{len(V)} {len(F)} 0\n")
        np.savetxt(fh, V, fmt="%.17g %.17g %.17g")
        np.savetxt(fh, F, fmt="3 %d %d %d")


def _write_ply(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    """Binary little-endian PLY with float64 vertices (trimesh's exporter writes float32)."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(V)}\nproperty double x\nproperty double y\nproperty double z\n"
        f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.zeros(len(F), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"] = 3
    faces["v"] = F
    with open(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        fh.write(faces.tobytes())


def write_mesh(path, V, F) -> Path:
    """Write one triangle mesh; the suffix picks the format (``.obj``, ``.off``, ``.ply``).

    OBJ and OFF are written as text with 17 significant digits and PLY as binary float64, so
    positions survive a round trip exactly.

    Parameters
    ----------
    path : str or Path
    V : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    path : Path
    """
    path = Path(path)
    V = np.asarray(V, dtype=np.float64)
    F = np.asarray(F, dtype=np.int64)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n_vertices, 3), got {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"faces must have shape (n_faces, 3), got {F.shape}")
    suffix = path.suffix.lower()
    if not path.parent.is_dir():
        raise FileNotFoundError(f"folder does not exist: {path.parent}")
    if suffix == ".obj":
        _write_obj(path, V, F)
    elif suffix == ".off":
        _write_off(path, V, F)
    elif suffix == ".ply":
        _write_ply(path, V, F)
    else:
        raise ValueError(f"unknown mesh format {suffix!r} for {path}; use .obj, .off or .ply")
    return path


# ---------------------------------------------------------------------------------------------
# collections


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


def _read_labels_csv(path: Path, names: list[str]) -> dict[str, np.ndarray]:
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    rows = [r for r in rows if any(c.strip() for c in r)]
    if not rows:
        return {}
    header = [h.strip() for h in rows[0]]
    if not header or header[0] != "name":
        raise ValueError(f"{path}: the first column must be 'name', got header {header}")
    table = {}
    for k, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise ValueError(
                f"{path}: line {k} has {len(row)} fields, the header has {len(header)}"
            )
        table[row[0].strip()] = [c.strip() for c in row[1:]]
    missing = [n for n in names if n not in table]
    if missing:
        raise ValueError(f"{path}: no row for mesh(es) {missing[:5]}")
    unknown = sorted(set(table) - set(names))
    if unknown:
        raise ValueError(f"{path}: rows name meshes that are not in the folder: {unknown[:5]}")
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
    try:
        data = np.load(path, allow_pickle=False)
    except Exception as exc:
        raise ValueError(f"{path.name}: cannot be read as .npz ({exc})") from exc
    with data:
        for key in ("vertices", "faces"):
            if key not in data.files:
                raise ValueError(f"{path.name}: has no {key!r} array (found {data.files})")
        vertices = np.asarray(data["vertices"], dtype=np.float64)
        faces = np.asarray(data["faces"])
        if vertices.ndim == 2:
            vertices = vertices[None]
        if vertices.ndim != 3 or vertices.shape[-1] != 3:
            raise ValueError(
                f"{path.name}: 'vertices' must have shape (N, V, 3), got {vertices.shape}"
            )
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(
                f"{path.name}: 'faces' must be triangles with shape (F, 3), got {faces.shape}"
            )
        n = len(vertices)
        names = [str(s) for s in data["names"]] if "names" in data.files else _default_names(n)
        if len(names) != n:
            raise ValueError(f"{path.name}: {len(names)} names for {n} meshes")
        labels = {}
        for key in data.files:
            if key.startswith("label_"):
                val = np.asarray(data[key])
                if val.shape != (n,):
                    raise ValueError(
                        f"{path.name}: {key!r} must have shape ({n},), got {val.shape}"
                    )
                labels[key[len("label_"):]] = val
    _validate_collection(vertices, faces, names, path.name, allow_degenerate)
    return MeshCollection(vertices, faces.astype(np.int64), names, labels)


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
        from tqdm.auto import tqdm

        it = tqdm(files, desc="reading meshes", unit="mesh")
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
    names and keep their order under natural sort (else numbered ``0000_<name>.obj``), plus
    ``labels.csv`` when there are labels. Positions keep full float64 precision in both formats.

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
        np.savez_compressed(path, **arrays)
        return path
    path.mkdir(parents=True, exist_ok=True)
    stems = list(col.names)
    safe = all(re.fullmatch(r"[\w.+-]+", s) for s in stems) and len(set(stems)) == len(stems)
    if not safe or sorted(stems, key=natural_key) != stems:
        width = max(4, len(str(len(stems) - 1)))
        stems = [
            f"{k:0{width}d}_{re.sub(r'[^0-9A-Za-z.+-]+', '_', s)}" for k, s in enumerate(stems)
        ]
    for V, stem in zip(col.vertices, stems):
        _write_obj(path / f"{stem}.obj", V, col.faces)
    if col.labels:
        with open(path / "labels.csv", "w", newline="") as fh:
            w = csv.writer(fh)
            keys = list(col.labels)
            w.writerow(["name", *keys])
            for k, stem in enumerate(stems):
                w.writerow([stem, *[_fmt_label(col.labels[c][k]) for c in keys]])
    return path


def _fmt_label(v) -> str:
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return str(v)
