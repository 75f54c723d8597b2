"""Small procedural meshes and deformations for the geometry tests and benchmarks (numpy only).

Nothing here reads files: tests never need ../shared.
"""

from __future__ import annotations

import numpy as np


def icosphere(subdivisions: int = 1, radius: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Subdivided icosahedron: closed genus-0 mesh, ``10 * 4**s + 2`` vertices."""
    t = (1.0 + 5**0.5) / 2.0
    V = np.array(
        [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
         [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    F = np.array(
        [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], np.int64)
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(subdivisions):
        he = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
        key = np.sort(he, axis=1)
        uniq, inv = np.unique(key, axis=0, return_inverse=True)
        inv = inv.reshape(-1)
        mid = V[uniq[:, 0]] + V[uniq[:, 1]]
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = len(F)
        a, b, c = (inv[:m] + len(V), inv[m:2 * m] + len(V), inv[2 * m:] + len(V))
        V = np.concatenate([V, mid])
        F = np.concatenate([
            np.stack([F[:, 0], a, c], 1), np.stack([F[:, 1], b, a], 1),
            np.stack([F[:, 2], c, b], 1), np.stack([a, b, c], 1)])
    return radius * V, F


def tube(n_around: int = 16, n_along: int = 20, radius: float = 0.5, height: float = 4.0,
         capped: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Cylinder along z from 0 to ``height``; closed with fan caps when ``capped``.

    Vertices: ``n_around * (n_along + 1)`` ring vertices, plus 2 cap centres when capped. Rings are
    staggered by half a step so that the triangles are close to equilateral.
    """
    k = np.arange(n_along + 1)
    j = np.arange(n_around)
    phi = 2 * np.pi * (j[None, :] + 0.5 * (k[:, None] % 2)) / n_around
    z = np.repeat((height * k / n_along)[:, None], n_around, axis=1)
    V = np.stack([radius * np.cos(phi), radius * np.sin(phi), z], -1).reshape(-1, 3)
    idx = (k[:-1, None] * n_around + j[None, :])  # (n_along, n_around)
    nxt = k[:-1, None] * n_around + (j[None, :] + 1) % n_around
    up = idx + n_around
    up_nxt = nxt + n_around
    even = (k[:-1] % 2 == 0)[:, None]
    # staggered rings: choose the diagonal that keeps triangles well shaped
    f1 = np.where(even[..., None], np.stack([idx, nxt, up], -1), np.stack([idx, nxt, up_nxt], -1))
    f2 = np.where(even[..., None], np.stack([nxt, up_nxt, up], -1), np.stack([idx, up_nxt, up], -1))
    F = np.concatenate([f1.reshape(-1, 3), f2.reshape(-1, 3)])
    if capped:
        nb = len(V)
        V = np.concatenate([V, [[0, 0, 0], [0, 0, height]]])
        bottom = np.stack([np.full(n_around, nb), (j + 1) % n_around, j], 1)
        top_ring = n_along * n_around
        top = np.stack([np.full(n_around, nb + 1), top_ring + j, top_ring + (j + 1) % n_around], 1)
        F = np.concatenate([F, bottom, top])
    return V, F.astype(np.int64)


def grid(nx: int = 4, ny: int = 3, size: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Flat triangulated square in the z = 0 plane, ``(nx + 1) * (ny + 1)`` vertices, boundary."""
    x, y = np.meshgrid(np.linspace(0, size, nx + 1), np.linspace(0, size, ny + 1))
    V = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], 1)
    i, j = np.meshgrid(np.arange(nx), np.arange(ny))
    a = (j * (nx + 1) + i).ravel()
    F = np.concatenate([np.stack([a, a + 1, a + nx + 2], 1), np.stack([a, a + nx + 2, a + nx + 1], 1)])
    return V, F.astype(np.int64)


def strip(nx: int = 13, ny: int = 4, length: float = 3.0, width: float = 0.6) -> tuple[np.ndarray, np.ndarray]:
    """Flat strip ``length x width`` in the z = 0 plane, ``nx * ny`` vertices ordered along x first
    (``indexing="ij"``), each quad split along the same diagonal."""
    x, y = np.meshgrid(np.linspace(0, length, nx), np.linspace(0, width, ny), indexing="ij")
    P = np.stack([x.ravel(), y.ravel(), np.zeros(nx * ny)], 1)
    a = (np.arange(nx - 1)[:, None] * ny + np.arange(ny - 1)[None, :]).ravel()
    F = np.stack([np.stack([a, a + ny, a + 1], 1), np.stack([a + ny, a + ny + 1, a + 1], 1)], 1).reshape(-1, 3)
    return P, F.astype(np.int64)


def bumpy(V: np.ndarray, amount: float = 0.05, seed: int = 0) -> np.ndarray:
    """Reference mesh with small random bumps (so no one-ring is exactly symmetric)."""
    rng = np.random.default_rng(seed)
    return V + amount * rng.standard_normal(V.shape) * np.ptp(V, axis=0).max() / 20


def twist_bend(V: np.ndarray, twist_deg: float = 300.0, bend_deg: float = 120.0) -> np.ndarray:
    """Large non-rigid deformation of a shape along z: twist about z, then bend in the x-z plane.

    The twist angle grows linearly from 0 to ``twist_deg`` along z; the bend maps the z axis onto
    an arc of ``bend_deg``.
    """
    z = V[:, 2]
    z0, z1 = z.min(), z.max()
    s = (z - z0) / (z1 - z0)
    a = np.deg2rad(twist_deg) * s
    x = V[:, 0] * np.cos(a) - V[:, 1] * np.sin(a)
    y = V[:, 0] * np.sin(a) + V[:, 1] * np.cos(a)
    L = z1 - z0
    b = np.deg2rad(bend_deg)
    Rb = L / b
    th = b * s
    xb = (Rb - x) * np.cos(th) - Rb
    zb = (Rb - x) * np.sin(th) + z0
    return np.stack([-xb - 0.0, y, zb], 1)


def random_rotation(seed: int = 0) -> np.ndarray:
    """Uniformly random rotation matrix ``(3, 3)``."""
    rng = np.random.default_rng(seed)
    q = rng.standard_normal(4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])
