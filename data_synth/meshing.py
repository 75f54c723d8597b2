"""Template construction: implicit surfaces made of primitives, polygonised and relaxed.

A closed template (body, hand, head) is the zero level set of an *implicit function* ``f`` that is
negative inside. ``f`` is a smooth union of simple primitives (tapered capsules and ellipsoids),
each tied to a *part* (a bone, for skinning). :func:`polygonize` samples ``f`` on a grid, runs
marching cubes (``skimage.measure.marching_cubes``), keeps the largest connected component and
relaxes the triangles tangentially while pulling every vertex back onto the surface, which
removes the slivers marching cubes leaves.

Parametric meshes (the flag's sheet and the bar's tube) are built by :func:`grid_sheet` and
:func:`grid_tube`.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from data_synth import constants as C

logger = logging.getLogger(__name__)

__all__ = [
    "Capsule",
    "Ellipsoid",
    "ImplicitModel",
    "polygonize",
    "relax",
    "grid_sheet",
    "grid_tube",
    "vertex_adjacency",
    "vertex_normals",
]


@dataclass(frozen=True)
class Capsule:
    """Tapered capsule from ``a`` (radius ``ra``) to ``b`` (radius ``rb``), tied to ``part``."""

    a: tuple
    b: tuple
    ra: float
    rb: float
    part: int

    def evaluate(self, P: np.ndarray) -> np.ndarray:
        """Approximate signed distance of points ``P : (n, 3) float64`` -> ``(n,) float64``."""
        a = np.asarray(self.a, float)
        ab = np.asarray(self.b, float) - a
        t = np.clip((P - a) @ ab / (ab @ ab), 0.0, 1.0)
        d = np.linalg.norm(P - (a + t[:, None] * ab), axis=1)
        return d - (self.ra + t * (self.rb - self.ra))


@dataclass(frozen=True)
class Ellipsoid:
    """Ellipsoid at ``center`` with semi-axes ``radii`` along the columns of ``axes``."""

    center: tuple
    radii: tuple
    part: int
    axes: tuple = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))

    def evaluate(self, P: np.ndarray) -> np.ndarray:
        """Approximate signed distance of points ``P : (n, 3) float64`` -> ``(n,) float64``."""
        q = (P - np.asarray(self.center, float)) @ np.asarray(self.axes, float).T
        r = np.asarray(self.radii, float)
        k0 = np.linalg.norm(q / r, axis=1)
        k1 = np.linalg.norm(q / r**2, axis=1)
        k1 = np.maximum(k1, 1e-12)
        # Inigo Quilez's bound, corrected inside so the gradient never vanishes at the centre.
        outside = k0 * (k0 - 1.0) / k1
        inside = (k0 - 1.0) * r.min()
        return np.where(k0 >= 1.0, outside, inside)


def _smooth_min(a: np.ndarray, b: np.ndarray, k: float) -> np.ndarray:
    """Polynomial smooth minimum with blend radius ``k`` (equals ``min`` where |a-b| >= k)."""
    h = np.maximum(k - np.abs(a - b), 0.0) / k
    return np.minimum(a, b) - h * h * k * 0.25


@dataclass
class ImplicitModel:
    """Smooth union of primitives; ``parts[i]`` names the part of primitive ``i``.

    ``subtract`` primitives are carved out (smooth difference) after the union.
    """

    primitives: list
    blend: float
    subtract: list = field(default_factory=list)
    subtract_blend: float = 0.0

    def evaluate(self, P: np.ndarray) -> np.ndarray:
        """Implicit value at points ``P : (n, 3) float64`` (negative inside) -> ``(n,)``."""
        P = np.asarray(P, dtype=np.float64)
        f = self.primitives[0].evaluate(P)
        for prim in self.primitives[1:]:
            f = _smooth_min(f, prim.evaluate(P), self.blend)
        for prim in self.subtract:
            g = -prim.evaluate(P)
            k = max(self.subtract_blend, 1e-9)
            h = np.maximum(k - np.abs(f - g), 0.0) / k
            f = np.maximum(f, g) + h * h * k * 0.25
        return f

    def part_of(self, P: np.ndarray) -> np.ndarray:
        """Part of the nearest primitive at points ``P : (n, 3)`` -> ``(n,) int64``."""
        P = np.asarray(P, dtype=np.float64)
        values = np.stack([prim.evaluate(P) for prim in self.primitives], axis=1)
        parts = np.array([prim.part for prim in self.primitives], dtype=np.int64)
        return parts[np.argmin(values, axis=1)]

    def value_and_gradient(self, P: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
        """Value ``(n,)`` and forward-difference gradient ``(n, 3)`` at ``P : (n, 3)``, step ``h``."""
        n = len(P)
        offsets = np.vstack([np.zeros(3), np.eye(3) * h])
        values = self.evaluate((P[:, None, :] + offsets[None]).reshape(-1, 3)).reshape(n, 4)
        return values[:, 0], (values[:, 1:] - values[:, :1]) / h

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Loose axis-aligned bounding box of the union, ``(lo (3,), hi (3,))``."""
        lo, hi = [], []
        for prim in self.primitives:
            if isinstance(prim, Capsule):
                r = max(prim.ra, prim.rb)
                pts = np.array([prim.a, prim.b], float)
                lo.append(pts.min(0) - r)
                hi.append(pts.max(0) + r)
            else:
                r = max(prim.radii)
                c = np.asarray(prim.center, float)
                lo.append(c - r)
                hi.append(c + r)
        return np.min(lo, axis=0), np.max(hi, axis=0)


def vertex_adjacency(F: np.ndarray, n_vertices: int) -> sp.csr_matrix:
    """Symmetric 0/1 vertex adjacency ``(n_vertices, n_vertices)`` of triangles ``F``."""
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    A = sp.coo_matrix((np.ones(len(i)), (i, j)), shape=(n_vertices, n_vertices)).tocsr()
    A = ((A + A.T) > 0).astype(np.float64)
    return A.tocsr()


def _largest_component(V: np.ndarray, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    A = vertex_adjacency(F, len(V))
    _, comp = connected_components(A, directed=False)
    keep_label = np.bincount(comp[F[:, 0]]).argmax()
    keep_v = comp == keep_label
    new_index = -np.ones(len(V), dtype=np.int64)
    new_index[keep_v] = np.arange(keep_v.sum())
    F = new_index[F[comp[F[:, 0]] == keep_label]]
    return V[keep_v], F


def _face_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return n


def vertex_normals(V: np.ndarray, F: np.ndarray) -> np.ndarray:
    """Area-weighted unit vertex normals of a template or rest mesh.

    The one implementation in ``data_synth``, which does not depend on ``meshvae_lib`` (the
    library's own is ``meshvae_lib.geometry.topology.vertex_normals``; the two agree to rounding).

    Parameters
    ----------
    V : (n_vertices, 3) float64
    F : (n_faces, 3) int64

    Returns
    -------
    N : (n_vertices, 3) float64
        Unit vectors (a vertex without faces gets the zero vector).
    """
    fn = _face_normals(V, F)
    vn = np.zeros_like(V)
    for k in range(3):
        np.add.at(vn, F[:, k], fn)
    return vn / np.maximum(np.linalg.norm(vn, axis=1, keepdims=True), 1e-300)


def relax(V: np.ndarray, F: np.ndarray, model: ImplicitModel | None, iterations: int,
          step: float, grad_h: float) -> np.ndarray:
    """Tangential Laplacian relaxation, each round followed by reprojection onto ``model``.

    Parameters
    ----------
    V : (n_vertices, 3) float64
    F : (n_faces, 3) int64
    model : implicit surface to project onto, or None to only relax.

    Returns
    -------
    V : (n_vertices, 3) float64, the relaxed positions.
    """
    A = vertex_adjacency(F, len(V))
    deg = np.asarray(A.sum(axis=1)).ravel()
    V = V.copy()
    for _ in range(iterations):
        n = vertex_normals(V, F)
        move = (A @ V) / deg[:, None] - V
        move -= np.sum(move * n, axis=1, keepdims=True) * n
        V += step * move
        if model is not None:
            V = _project(V, model, grad_h, 1)
    if model is not None:
        V = _project(V, model, grad_h, C.REPROJECT_STEPS)
    return V


def _project(V: np.ndarray, model: ImplicitModel, grad_h: float, steps: int) -> np.ndarray:
    """Newton steps ``x -= f(x) grad f / |grad f|^2`` towards the zero set of ``model``."""
    for _ in range(steps):
        f, g = model.value_and_gradient(V, grad_h)
        V = V - (f / np.maximum(np.sum(g * g, axis=1), 1e-12))[:, None] * g
    return V


def _sample_narrow_band(model: ImplicitModel, axes: list, spacing: float) -> np.ndarray:
    """Implicit values on the grid ``axes`` (three 1-D coordinate arrays), exact near the surface.

    The model is first sampled on every second grid point; fine points farther from the surface
    than ``NARROW_BAND_CELLS`` coarse cells keep their nearest coarse value (only their sign
    matters to marching cubes), the others are evaluated exactly.
    """
    shape = tuple(len(a) for a in axes)
    coarse_axes = [a[::2] for a in axes]
    coarse = model.evaluate(
        np.stack(np.meshgrid(*coarse_axes, indexing="ij"), axis=-1).reshape(-1, 3)
    ).reshape(tuple(len(a) for a in coarse_axes))
    values = coarse
    for k in range(3):
        values = np.repeat(values, 2, axis=k)
    values = values[: shape[0], : shape[1], : shape[2]]
    near = np.abs(values) < C.NARROW_BAND_CELLS * 2.0 * spacing
    idx = np.nonzero(near)
    points = np.stack([axes[k][idx[k]] for k in range(3)], axis=1)
    values = values.copy()
    values[idx] = model.evaluate(points)
    return values


def polygonize(model: ImplicitModel, n_vertices: int, area_estimate: float,
               relax_iterations: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Closed triangle mesh of the zero set of ``model`` with about ``n_vertices`` vertices.

    Parameters
    ----------
    model : ImplicitModel
    n_vertices : int, the target vertex count (the result is within a few percent of it).
    area_estimate : float, the surface area, used to choose the grid spacing.

    Returns
    -------
    V : (n_vertices, 3) float64
    F : (n_faces, 3) int64, counter-clockwise seen from outside.
    """
    from skimage.measure import marching_cubes

    spacing = np.sqrt(C.MC_VERTEX_DENSITY * area_estimate / n_vertices)
    lo, hi = model.bounds()
    for _attempt in range(3):
        pad = C.MC_PADDING_CELLS * spacing
        axes = [np.arange(lo[k] - pad, hi[k] + pad + spacing, spacing) for k in range(3)]
        values = _sample_narrow_band(model, axes, spacing)
        verts, faces, _, _ = marching_cubes(values, level=0.0, spacing=(spacing,) * 3,
                                            method="lewiner", allow_degenerate=False)
        V = verts.astype(np.float64) + np.array([a[0] for a in axes])
        F = faces.astype(np.int64)
        V, F = _largest_component(V, F)
        ratio = len(V) / n_vertices
        logger.debug("marching cubes: spacing %.4g gave %d vertices (target %d)", spacing,
                     len(V), n_vertices)
        if abs(ratio - 1.0) < 0.08:
            break
        spacing *= np.sqrt(ratio)
    # marching cubes orients faces by the gradient; make them counter-clockwise from outside.
    centroid_sign = np.sum(_face_normals(V, F) * (V[F].mean(axis=1) - V.mean(axis=0)))
    if centroid_sign < 0:
        F = F[:, ::-1].copy()
    iterations = C.RELAX_ITERATIONS if relax_iterations is None else relax_iterations
    V = relax(V, F, model, iterations, C.RELAX_STEP, C.GRADIENT_STEP * spacing)
    return V, F


def grid_sheet(n_u: int, n_v: int, width: float, height: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rectangular sheet in the plane z = 0, ``x`` in [0, width], ``y`` in [0, height].

    Triangles alternate their diagonal so the sheet has no preferred shear direction.

    Returns
    -------
    V : (n_u * n_v, 3) float64; vertex ``i * n_v + j`` sits at column ``i``, row ``j``.
    F : (2 (n_u - 1)(n_v - 1), 3) int64, counter-clockwise seen from +z.
    uv : (n_u * n_v, 2) float64, the (x, y) rest coordinates.
    """
    u = np.linspace(0.0, width, n_u)
    v = np.linspace(0.0, height, n_v)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    V = np.stack([uu.ravel(), vv.ravel(), np.zeros(uu.size)], axis=1)
    i, j = np.meshgrid(np.arange(n_u - 1), np.arange(n_v - 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    a = i * n_v + j
    b = (i + 1) * n_v + j
    c = (i + 1) * n_v + j + 1
    d = i * n_v + j + 1
    flip = (i + j) % 2 == 1
    t1 = np.where(flip[:, None], np.stack([a, b, d], 1), np.stack([a, b, c], 1))
    t2 = np.where(flip[:, None], np.stack([b, c, d], 1), np.stack([a, c, d], 1))
    F = np.vstack([t1, t2]).astype(np.int64)
    return V, F, V[:, :2].copy()


def grid_tube(n_around: int, n_along: int, length: float, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Open cylinder along ``x`` from 0 to ``length``: two boundary loops, one at each end.

    Rings are staggered by half a segment every other row, so the triangles are nearly
    equilateral when the ring spacing matches the segment length.

    Returns
    -------
    V : (n_along * n_around, 3) float64; vertex ``r * n_around + k`` is point ``k`` of ring ``r``.
    F : (2 n_around (n_along - 1), 3) int64, counter-clockwise seen from outside.
    """
    r = np.arange(n_along)
    k = np.arange(n_around)
    rr, kk = np.meshgrid(r, k, indexing="ij")
    theta = 2.0 * np.pi * (kk + 0.5 * (rr % 2)) / n_around
    x = rr * length / (n_along - 1)
    V = np.stack([x, radius * np.cos(theta), radius * np.sin(theta)], axis=-1).reshape(-1, 3)
    ri, ki = np.meshgrid(np.arange(n_along - 1), k, indexing="ij")
    ri, ki = ri.ravel(), ki.ravel()
    kn = (ki + 1) % n_around
    a = ri * n_around + ki
    b = ri * n_around + kn
    c = (ri + 1) * n_around + ki
    d = (ri + 1) * n_around + kn
    even = ri % 2 == 0
    # even rows: the upper ring is shifted forward by half a segment
    t1 = np.where(even[:, None], np.stack([a, b, c], 1), np.stack([a, d, c], 1))
    t2 = np.where(even[:, None], np.stack([b, d, c], 1), np.stack([a, b, d], 1))
    F = np.vstack([t1, t2]).astype(np.int64)
    return V, F
