"""GPU-ready buffers from numpy meshes: float32 positions, normals and colours, uint32 indices.

These are plain numpy functions (no pythreejs): the viewer hands their output to three.js
``BufferAttribute`` objects, and the tests check them without a browser. Every output is a fresh,
C-contiguous ``numpy.ndarray`` (never a subclass such as trimesh's ``TrackedArray``, which makes
traittypes warn about dtype coercion).
"""

from __future__ import annotations

import math

import numpy as np

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.validation import check_faces, check_vertices

__all__ = [
    "position_buffer",
    "normal_buffer",
    "index_buffer",
    "color_buffer",
    "row_offsets",
    "fit_camera",
]


def position_buffer(V) -> np.ndarray:
    """Vertex positions as a three.js ``position`` attribute.

    Parameters
    ----------
    V : (n_vertices, 3) float

    Returns
    -------
    P : (n_vertices, 3) float32, C-contiguous
    """
    return np.array(check_vertices(V, "V", batch=False, finite=True), dtype=np.float32, order="C")


def normal_buffer(V, F) -> np.ndarray:
    """Area-weighted unit vertex normals (:func:`meshvae_lib.geometry.topology.vertex_normals`) as float32.

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int

    Returns
    -------
    N : (n_vertices, 3) float32, C-contiguous
        Unit vectors; a vertex without faces gets the zero vector.
    """
    return np.array(vertex_normals(check_vertices(V, "V", batch=False, finite=True), F), dtype=np.float32, order="C")


def index_buffer(F, n_vertices: int) -> np.ndarray:
    """Triangle indices as a flat three.js ``index`` attribute.

    Parameters
    ----------
    F : (n_faces, 3) int
        Triangles, 0-based, counter-clockwise seen from outside.
    n_vertices : int
        Number of vertices the indices refer to.

    Returns
    -------
    I : (3 * n_faces,) uint32
        ``F`` flattened row by row.
    """
    F = check_faces(F, n_vertices=n_vertices, name="F")
    if F.shape[0] == 0:
        raise ValueError(f"F must have shape (n_faces, 3) with n_faces > 0, got {F.shape}")
    return np.array(F.reshape(-1), dtype=np.uint32, order="C")


def color_buffer(colors, n_vertices: int) -> np.ndarray:
    """Per-vertex RGB colours as a three.js ``color`` attribute.

    Parameters
    ----------
    colors : str, (3,) float, (n_vertices, 3) float or (n_vertices, 4) float
        A matplotlib colour name or hex string (``"#b0b8c8"``), one RGB triple for every vertex,
        or one RGB(A) row per vertex, in [0, 1] (alpha is dropped).
    n_vertices : int

    Returns
    -------
    C : (n_vertices, 3) float32 in [0, 1]
    """
    if isinstance(colors, str):
        from matplotlib.colors import to_rgb

        try:
            rgb = to_rgb(colors)
        except ValueError as err:
            raise ValueError(f"unknown colour {colors!r}") from err
        C = np.broadcast_to(np.asarray(rgb, dtype=np.float64), (n_vertices, 3))
    else:
        C = np.asarray(colors, dtype=np.float64)
        if C.shape in ((3,), (4,)):
            C = np.broadcast_to(C[:3], (n_vertices, 3))
        elif C.ndim == 2 and C.shape[0] == n_vertices and C.shape[1] in (3, 4):
            C = C[:, :3]
        else:
            raise ValueError(
                f"colors must be a colour name, (3,), ({n_vertices}, 3) or ({n_vertices}, 4); "
                f"got shape {C.shape}"
            )
        if not np.all(np.isfinite(C)) or C.min() < 0.0 or C.max() > 1.0:
            raise ValueError(
                f"colors must be finite RGB values in [0, 1], got range [{np.nanmin(C)}, {np.nanmax(C)}]"
            )
    return np.array(C, dtype=np.float32, order="C")


def row_offsets(meshes, gap: float = 0.25) -> np.ndarray:
    """Translations that place several meshes side by side along x, centred on the origin.

    The meshes keep their relative pose (one common centre is subtracted, not one per mesh), so
    two methods' outputs for the same input stay comparable. Slots are as wide as the widest mesh.

    Parameters
    ----------
    meshes : sequence of k arrays (n_vertices, 3) float
    gap : float
        Space between slots as a fraction of the slot width.

    Returns
    -------
    offsets : (k, 3) float64
        Add ``offsets[i]`` to mesh ``i``.
    """
    meshes = [check_vertices(V, f"meshes[{i}]", batch=False, finite=True) for i, V in enumerate(meshes)]
    if not meshes:
        raise ValueError("row_offsets needs at least one mesh")
    if gap < 0:
        raise ValueError(f"gap must be >= 0, got {gap}")
    lo = np.min([V.min(axis=0) for V in meshes], axis=0)
    hi = np.max([V.max(axis=0) for V in meshes], axis=0)
    center = 0.5 * (lo + hi)
    width = max(float(np.max([np.ptp(V[:, 0]) for V in meshes])), float(np.max(hi - lo)) * 1e-3, 1e-12)
    slot = width * (1.0 + gap)
    k = len(meshes)
    offsets = np.zeros((k, 3))
    offsets[:, 0] = (np.arange(k) - (k - 1) / 2.0) * slot
    return offsets - center


def fit_camera(points, fov: float = 40.0, aspect: float = 1.6, direction=(0.35, 0.3, 1.0), margin: float = 1.1):
    """Where to put a perspective camera so that all points are in view.

    Parameters
    ----------
    points : (n_points, 3) float
        Everything that must be visible (e.g. all meshes after their row offsets).
    fov : float
        Vertical field of view in degrees.
    aspect : float
        Width / height of the view.
    direction : (3,) float
        Direction from the target to the camera (normalised here).
    margin : float
        Extra room around the points (1.0 = tight).

    Returns
    -------
    position : (3,) float64
    target : (3,) float64
        Centre of the points' bounding box.
    """
    P = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if len(P) == 0 or not np.all(np.isfinite(P)):
        raise ValueError(f"fit_camera needs finite points, got shape {P.shape}")
    d = np.asarray(direction, dtype=np.float64)
    if d.shape != (3,) or not np.linalg.norm(d) > 0:
        raise ValueError(f"direction must be a nonzero 3-vector, got {direction!r}")
    d = d / np.linalg.norm(d)
    lo, hi = P.min(axis=0), P.max(axis=0)
    target = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-9)
    half_v = math.radians(fov) / 2.0
    half_h = math.atan(math.tan(half_v) * aspect)
    # Fit the projected extent of the box: horizontal half size vs. vertical half size.
    half_w = 0.5 * float(np.hypot(hi[0] - lo[0], hi[2] - lo[2]))
    half_hgt = 0.5 * float(np.hypot(hi[1] - lo[1], hi[2] - lo[2]))
    dist = max(half_w / math.tan(half_h), half_hgt / math.tan(half_v), radius * 0.5) * margin + 0.5 * radius
    return target + dist * d, target
