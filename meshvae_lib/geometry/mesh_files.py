"""Reading and writing single triangle meshes: OBJ, PLY and OFF.

Meshes are read with trimesh without any processing (``process=False``, ``maintain_order=True``):
vertices are never merged, reordered or dropped, so vertex ``k`` of every file is the same point of
the shape. Polygon faces in OBJ/OFF files are refused unless ``triangulate=True``, and every mesh
read is checked by :func:`~meshvae_lib.geometry.mesh_checks.validate_mesh`. Writing keeps float64
positions exactly (OBJ and OFF with 17 significant digits, PLY binary float64).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshvae_lib.atomic import atomic_file
from meshvae_lib.geometry.mesh_checks import validate_mesh
from meshvae_lib.input_checks import short_name
from meshvae_lib.validation import check_mesh

__all__ = ["MESH_SUFFIXES", "read_mesh", "write_mesh"]

#: file suffixes read as meshes (in a collection folder) and written by :func:`write_mesh`.
MESH_SUFFIXES = (".obj", ".ply", ".off")


def _polygon_corners_in_text(path: Path) -> int:
    """Largest number of corners of a face in an OBJ or ASCII OFF file (3 for triangle meshes).

    Also checks what trimesh would pass over silently or report without a line: a face with fewer
    than three corners, and a face index that names no vertex (OBJ counts from 1, or from the end
    with negative indices, so 0 is never valid; OFF counts from 0). Raises ``ValueError`` naming
    the file and the line.
    """
    suffix = path.suffix.lower()
    try:
        text = path.read_text(errors="replace")
    except UnicodeDecodeError:  # pragma: no cover - binary file
        return 3
    name = short_name(path.name)
    if suffix == ".obj":
        return _check_obj_faces(text, name)
    if suffix == ".off":
        return _check_off_faces(text, name)
    return 3


def _face_line(faces: list, counts: np.ndarray, k: int) -> int:
    """The line number of corner ``k`` of the flattened face corners."""
    return faces[int(np.searchsorted(np.cumsum(counts), k, side="right"))][0]


def _check_obj_faces(text: str, name: str) -> int:
    """:func:`_polygon_corners_in_text` for an OBJ file's text (vectorised over the corners)."""
    most = 3
    faces = []  # (line number, corner tokens, vertices defined before the line)
    n_vertices = 0
    for lineno, line in enumerate(text.splitlines(), start=1):
        if line.startswith("v ") or line.startswith("v\t"):
            n_vertices += 1
        elif line.startswith("f ") or line.startswith("f\t"):
            faces.append((lineno, line.split("#")[0].split()[1:], n_vertices))
    if not faces:
        return most
    counts = np.array([len(c) for _, c, _ in faces])
    if counts.min() < 3:
        lineno, corners, _ = faces[int(np.argmin(counts))]
        raise ValueError(f"{name}: line {lineno}: a face with {len(corners)} corner(s); a face needs at"
                         " least three")
    most = int(counts.max())
    tokens = np.char.partition(np.array([c for _, cs, _ in faces for c in cs]), "/")[:, 0]
    try:
        idx = tokens.astype(np.int64)
    except ValueError:
        k = next(i for i, t in enumerate(tokens.tolist()) if not t.lstrip("+-").isdigit())
        lineno = _face_line(faces, counts, k)
        raise ValueError(f"{name}: line {lineno}: face corner {short_name(repr(str(tokens[k])))} is not a"
                         " vertex index") from None
    before = np.repeat(np.array([n for _, _, n in faces]), counts)
    # OBJ counts from 1 (any vertex of the file), or back from the last vertex defined (negative)
    bad = (idx == 0) | (idx > n_vertices) | ((idx < 0) & (-idx > before))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        lineno = _face_line(faces, counts, k)
        raise ValueError(f"{name}: line {lineno}: face index {int(idx[k])} names no vertex (OBJ counts from"
                         f" 1; the file has {n_vertices} vertices)")
    return most


def _check_off_faces(text: str, name: str) -> int:
    """:func:`_polygon_corners_in_text` for an ASCII OFF file's text."""
    most = 3
    lines = [(k, ln.split("#")[0].split()) for k, ln in enumerate(text.splitlines(), start=1)]
    lines = [(k, ln) for k, ln in lines if ln]
    if not lines:
        return 3
    head = lines[0][1]
    start = 1
    if head[0].upper().endswith("OFF") and len(head) == 1:
        if len(lines) < 2:
            return 3
        counts = lines[1][1]
        start = 2
    else:
        counts = head[1:] if head[0].upper().endswith("OFF") else head
    try:
        nv, nf = int(counts[0]), int(counts[1])
    except (ValueError, IndexError):
        return 3
    if nv < 0 or nf < 0 or len(lines) - start < nv + nf:
        raise ValueError(f"{name}: its header (line {lines[start - 1][0]}) says {nv:,} vertices and {nf:,} faces,"
                         f" but {len(lines) - start:,} lines follow it: the file is cut short or its header is wrong")
    for lineno, ln in lines[start + nv : start + nv + nf]:
        try:
            n = int(ln[0])
            idx = [int(v) for v in ln[1 : 1 + n]]
        except ValueError:
            raise ValueError(f"{name}: line {lineno}: a face line must be whole numbers, got"
                             f" {short_name(' '.join(ln))!r}") from None
        if n < 3 or len(idx) < n:
            raise ValueError(f"{name}: line {lineno}: a face with {min(n, len(idx))} corner(s); a face"
                             " needs at least three")
        bad = [v for v in idx if not 0 <= v < nv]
        if bad:
            raise ValueError(f"{name}: line {lineno}: face index {bad[0]} names no vertex (OFF counts"
                             f" from 0; the file has {nv} vertices)")
        most = max(most, n)
    return most


#: bytes of each PLY property type.
_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2, "uint16": 2,
              "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4, "double": 8, "float64": 8}


def _ply_counts(path: Path, name: str) -> dict[str, int]:
    """The element counts a PLY file's header states (``{"vertex": n, "face": m, ...}``), checked
    against the data that follows: an ASCII file needs a line per element, a binary file at least the
    bytes of its fixed-size properties (and of a triangle per face). Raises ``ValueError`` naming the
    file for a header that claims more than the file holds (cut short, or a wrong header), so that no
    reader allocates for counts that are not there. Returns {} when the header cannot be parsed (the
    reader then reports it)."""
    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    end = head.find(b"end_header")
    if not head.startswith(b"ply") or end < 0:
        return {}
    body_start = head.find(b"\n", end) + 1
    fmt, elements = "", []  # (name, count, [(kind, sizes)])
    for line in head[:end].decode("ascii", errors="replace").splitlines():
        words = line.split()
        if not words:
            continue
        try:
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                elements.append((words[1], int(words[2]), []))
            elif words[0] == "property" and elements:
                if words[1] == "list":
                    elements[-1][2].append(("list", _PLY_SIZES.get(words[2], 1), _PLY_SIZES.get(words[3], 1)))
                else:
                    elements[-1][2].append(("scalar", _PLY_SIZES.get(words[1], 1), 0))
        except (IndexError, ValueError):
            return {}
    size = path.stat().st_size - body_start
    if fmt == "ascii":
        with open(path, "rb") as fh:
            fh.seek(body_start)
            available = sum(1 for ln in fh if ln.strip())
        needed = sum(count for _, count, _ in elements)
        unit = "lines"
    else:
        needed = 0
        for element, count, props in elements:
            per = sum(a + (3 * b if element == "face" else 0) for _, a, b in props)
            needed += count * per
        available, unit = size, "bytes"
    if any(count < 0 for _, count, _ in elements) or available < needed:
        stated = ", ".join(f"{element} {count:,}" for element, count, _ in elements)
        raise ValueError(f"{name}: its header says {stated} (elements), which need at least {needed:,} {unit}, but the file"
                         f" holds {available:,}: it is cut short or its header is wrong")
    return {element: count for element, count, _ in elements}


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
    if path.suffix.lower() in (".obj", ".off"):
        corners = _polygon_corners_in_text(path)
        if corners > 3 and not triangulate:
            raise ValueError(
                f"{short_name(path.name)}: has faces with {corners} corners; only triangle meshes are "
                "supported (triangulate it, or read it with triangulate=True)"
            )
    stated = _ply_counts(path, short_name(path.name)) if path.suffix.lower() == ".ply" else {}
    try:
        mesh = trimesh.load(path, process=False, maintain_order=True, force="mesh")
    except Exception as exc:  # trimesh raises many kinds of errors for unreadable files
        raise ValueError(f"{short_name(path.name)}: cannot be read as a mesh ({short_name(exc, 200)})") from exc
    V = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64)
    F = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    if F.size == 0:
        raise ValueError(f"{short_name(path.name)}: holds no triangles")
    for what, got in (("vertex", len(V)), ("face", len(F))):
        if what in stated and stated[what] != got:
            raise ValueError(f"{short_name(path.name)}: its header says {stated[what]:,} {what} elements, {got:,} were"
                             " read: the file is damaged or its header is wrong")
    if validate:
        validate_mesh(V, F, name=short_name(path.name), allow_degenerate=allow_degenerate)
    return V, F


def _write_obj(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    with atomic_file(path, "w") as fh:
        fh.write(f"# {len(V)} vertices, {len(F)} faces\n")
        np.savetxt(fh, V, fmt="v %.17g %.17g %.17g")
        np.savetxt(fh, F + 1, fmt="f %d %d %d")


def _write_off(path: Path, V: np.ndarray, F: np.ndarray) -> None:
    with atomic_file(path, "w") as fh:
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
    with atomic_file(path, "wb") as fh:
        fh.write(header.encode("ascii"))
        fh.write(np.ascontiguousarray(V, dtype="<f8").tobytes())
        fh.write(faces.tobytes())


def write_mesh(path, V, F) -> Path:
    """Write one triangle mesh; the suffix picks the format (``.obj``, ``.off``, ``.ply``).

    OBJ and OFF are written as text with 17 significant digits and PLY as binary float64, so
    positions survive a round trip exactly. The file is written atomically
    (:func:`~meshvae_lib.atomic.atomic_file`): a failed write leaves an older file as it was and
    raises :class:`~meshvae_lib.atomic.OutputError` (``cannot write FILE: reason``).

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
    V, F = check_mesh(V, F, batch=False)
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
