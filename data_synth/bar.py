"""A bar (an open tube, two boundary loops) that twists and bends far past 180 degrees.

The tube lies along x, length ``BAR_LENGTH``, with a rounded-square cross section of half-width
``BAR_RADIUS`` (a superellipse, so that a twist is visible). A deformation is a *rod*: every cross
section keeps its shape and is carried by a frame that turns along the centre line at a rate that
varies along the bar -- a twist rate about the tangent and curvatures in the two normal planes, each
a smooth profile of three modes (constant, linear and quadratic in arc length) --; the centre line
is the integral of the frames' tangents, so the bar never stretches. Every mesh draws its own nine
profile coefficients (``BAR_PROFILE_DEG``), so the collection holds S-bends, spirals and twists
that are not a few-parameter family (benchmarks/bench_synth_floor.py). Three motions weight the
draws: ``twist`` (twist only), ``bend`` (bending in both planes) and ``twist_bend`` (both).
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import grid_tube

__all__ = ["make_bar", "rod_deform", "BAR_MOTIONS"]

#: motion -> (twist, bend) scale of its draws: the fraction of ``BAR_PROFILE_DEG`` it uses.
BAR_MOTIONS = {"twist": (1.0, 0.0), "bend": (0.0, 1.0), "twist_bend": (0.8, 0.8)}


def _tube_size(resolution: int) -> tuple[int, int]:
    resolution = resolve_resolution(resolution)
    # ring spacing = segment length * sqrt(3)/2 gives near-equilateral triangles
    ratio = C.BAR_LENGTH / (2 * np.pi * C.BAR_RADIUS * np.sqrt(3) / 2)
    n_around = max(8, int(round(np.sqrt(resolution / ratio))))
    n_along = max(3, int(round(resolution / n_around)))
    return n_around, n_along


def _profiles(s: np.ndarray, coef: np.ndarray) -> np.ndarray:
    """Rates along the bar: ``coef (n, 3)`` radians of the constant, linear and quadratic modes of
    ``t = 2 s / L - 1`` (each integrates to its coefficient times L over the bar for the constant
    mode) -> ``(n, len(s))`` radians per unit length."""
    t = 2.0 * s / C.BAR_LENGTH - 1.0
    modes = np.stack([np.ones_like(t), t, 1.5 * t**2 - 0.5])
    return coef @ modes / C.BAR_LENGTH


def rod_deform(V0: np.ndarray, twist: np.ndarray, bend_y: np.ndarray, bend_z: np.ndarray):
    """Carry the rest tube's cross sections along turning frames (a rod that does not stretch).

    Parameters
    ----------
    V0 : (n_vertices, 3) float64, the rest tube along x from 0 to ``BAR_LENGTH`` (vertices on rings
        of equal x).
    twist, bend_y, bend_z : (n, 3) float64, radians: the three modes of the twist rate (about the
        tangent) and of the curvatures (about the frame's z and y axes).

    Returns
    -------
    V : (n, n_vertices, 3) float64, centred on the rest tube's centre;
    turn : (n,) float64, the rotation accumulated from ring to ring along the bar, radians.
    """
    s_rings, ring = np.unique(V0[:, 0], return_inverse=True)
    n = len(twist)
    rates = np.stack([_profiles(s_rings, np.asarray(c, float)) for c in (twist, bend_z, bend_y)], axis=-1)
    rates = rates[..., [0, 2, 1]]  # (n, rings, 3): about the frame's x (twist), y and z
    ds = np.diff(s_rings)
    omega = 0.5 * (rates[:, 1:] + rates[:, :-1]) * ds[None, :, None]  # (n, rings - 1, 3)
    steps = Rotation.from_rotvec(omega.reshape(-1, 3)).as_matrix().reshape(n, -1, 3, 3)
    R = np.empty((n, len(s_rings), 3, 3))
    R[:, 0] = np.eye(3)
    for i in range(1, len(s_rings)):  # along the rings (tens), vectorised over meshes
        R[:, i] = R[:, i - 1] @ steps[:, i - 1]
    tangent = R[..., 0]
    seg = 0.5 * (tangent[:, 1:] + tangent[:, :-1]) * ds[None, :, None]
    centre = np.concatenate([np.zeros((n, 1, 3)), np.cumsum(seg, axis=1)], axis=1)
    section = np.column_stack([np.zeros(len(V0)), V0[:, 1], V0[:, 2]])
    V = centre[:, ring] + np.einsum("nvij,vj->nvi", R[:, ring], section)
    turn = np.linalg.norm(omega, axis=-1).sum(axis=1)
    return V - V.mean(axis=1, keepdims=True) + V0.mean(axis=0), turn


def _rest_tube(resolution: int):
    n_around, n_along = _tube_size(resolution)
    V0, F = grid_tube(n_around, n_along, C.BAR_LENGTH, C.BAR_RADIUS)
    # a rounded-square cross section (superellipse), so that twisting shows in the geometry
    theta = np.arctan2(V0[:, 2], V0[:, 1])
    p = C.BAR_SQUARENESS
    factor = (np.abs(np.cos(theta)) ** p + np.abs(np.sin(theta)) ** p) ** (-1.0 / p)
    V0[:, 1:] *= factor[:, None]
    return V0, F, (n_along, n_around)


def make_bar(seed: int = 0, resolution: int | None = None,
             n_variants: int = C.BAR_VARIANTS) -> SynthCollection:
    """Bar collection: 3 motions x ``n_variants`` independent draws; labels ``motion``, ``variant``,
    ``twist_deg`` (the end rings' twist about the bar) and ``bend_deg`` (the bending accumulated
    along it); ``extras["turn_deg"]`` (n,) int64: all rotation accumulated from ring to ring."""
    resolution = C.BAR_DEFAULT_RESOLUTION if resolution is None else int(resolution)
    V0, F, tube_shape = _rest_tube(resolution)
    rng = np.random.default_rng(seed)
    scale = np.deg2rad(np.asarray(C.BAR_PROFILE_DEG, float))  # (2, 3): twist modes, bend modes
    s_rings = np.unique(V0[:, 0])
    chunks, names, motion, variant, tw, bd, turns = [], [], [], [], [], [], []
    for m, (w_twist, w_bend) in BAR_MOTIONS.items():
        n = n_variants
        draw = lambda: np.clip(rng.normal(size=(n, 3)), -C.BAR_PROFILE_CLIP, C.BAR_PROFILE_CLIP)  # noqa: E731
        twist = draw() * scale[0] * w_twist
        bend_y, bend_z = (draw() * scale[1] * w_bend for _ in range(2))
        V, turn = rod_deform(V0, twist, bend_y, bend_z)
        chunks.append(V)
        bend_rate = np.hypot(_profiles(s_rings, bend_y), _profiles(s_rings, bend_z))
        for i in range(n):
            names.append(f"{m}_{i:02d}")
            motion.append(m)
            variant.append(i)
            tw.append(int(round(np.rad2deg(twist[i, 0]))))  # the other modes integrate to zero
            bd.append(int(round(np.rad2deg(np.trapezoid(bend_rate[i], s_rings)))))
            turns.append(int(round(np.rad2deg(turn[i]))))
    return SynthCollection(
        vertices=np.concatenate(chunks), faces=F, names=names,
        labels={"motion": np.array(motion), "variant": np.array(variant, dtype=np.int64),
                "twist_deg": np.array(tw, dtype=np.int64), "bend_deg": np.array(bd, dtype=np.int64)},
        description="an open tube (two boundary loops) bent and twisted along its length, past 180 degrees",
        extras={"rest": V0, "tube_shape": tube_shape, "turn_deg": np.array(turns, dtype=np.int64)},
    )
