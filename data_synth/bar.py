"""A bar (an open tube, two boundary loops) that twists and bends far past 180 degrees.

The tube lies along x, length ``BAR_LENGTH``, with a rounded-square cross section of half-width
``BAR_RADIUS`` (a superellipse, so that a twist is visible). A deformation bends its
centre line into a circular arc of total angle ``bend`` (in the xy plane) and turns its cross
sections about the centre line by an angle growing linearly from 0 at one end to ``twist`` at
the other, so the two end rings end up rotated by ``twist`` (and ``bend``) relative to each other.
Three motions ramp these from zero: ``twist`` (to 300 degrees), ``bend`` (to 240 degrees) and
``twist_bend`` (270 and 180 degrees together).
"""

from __future__ import annotations

import numpy as np

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import grid_tube

__all__ = ["make_bar", "bend_and_twist", "BAR_MOTIONS"]

#: motion -> (final twist, final bend) in degrees
BAR_MOTIONS = {"twist": (300.0, 0.0), "bend": (0.0, 240.0), "twist_bend": (270.0, 180.0)}


def _tube_size(resolution: int) -> tuple[int, int]:
    resolution = resolve_resolution(resolution)
    # ring spacing = segment length * sqrt(3)/2 gives near-equilateral triangles
    ratio = C.BAR_LENGTH / (2 * np.pi * C.BAR_RADIUS * np.sqrt(3) / 2)
    n_around = max(8, int(round(np.sqrt(resolution / ratio))))
    n_along = max(3, int(round(resolution / n_around)))
    return n_around, n_along


def bend_and_twist(V0: np.ndarray, twist: np.ndarray, bend: np.ndarray) -> np.ndarray:
    """Bend and twist the rest tube.

    Parameters
    ----------
    V0 : (n_vertices, 3) float64, the rest tube along x from 0 to ``BAR_LENGTH``.
    twist, bend : (n_frames,) float64, radians.

    Returns
    -------
    (n_frames, n_vertices, 3) float64
    """
    L = C.BAR_LENGTH
    s = V0[:, 0]  # arc length along the centre line
    theta = twist[:, None] * (s / L)[None]  # (n_frames, n_vertices)
    y, z = V0[:, 1], V0[:, 2]
    ty = np.cos(theta) * y - np.sin(theta) * z  # twisted cross section
    tz = np.sin(theta) * y + np.cos(theta) * z
    kappa = bend[:, None] / L
    phi = kappa * s[None]
    small = np.abs(kappa) < 1e-9
    safe = np.where(small, 1.0, kappa)
    cx = np.where(small, s[None], np.sin(phi) / safe)
    cy = np.where(small, 0.0, (1.0 - np.cos(phi)) / safe)
    # the cross section's y axis turns with the tangent (cos phi, sin phi) -> (-sin phi, cos phi)
    x = cx - np.sin(phi) * ty
    yy = cy + np.cos(phi) * ty
    # centre the bar on its middle so the deformation is symmetric about the origin
    out = np.stack([x, yy, tz], axis=-1)
    return out - out.mean(axis=1, keepdims=True) + V0.mean(axis=0)


def make_bar(seed: int = 0, resolution: int | None = None,
             n_frames: int = C.BAR_N_FRAMES_PER_MOTION) -> SynthCollection:
    """Bar collection: 3 motions x ``n_frames``; labels ``motion``, ``frame``, ``twist_deg``,
    ``bend_deg``."""
    resolution = C.BAR_DEFAULT_RESOLUTION if resolution is None else int(resolution)
    n_around, n_along = _tube_size(resolution)
    V0, F = grid_tube(n_around, n_along, C.BAR_LENGTH, C.BAR_RADIUS)
    # a rounded-square cross section (superellipse), so that twisting shows in the geometry
    theta = np.arctan2(V0[:, 2], V0[:, 1])
    p = C.BAR_SQUARENESS
    factor = (np.abs(np.cos(theta)) ** p + np.abs(np.sin(theta)) ** p) ** (-1.0 / p)
    V0[:, 1:] *= factor[:, None]
    rng = np.random.default_rng(seed)
    chunks, names, motion, frame, tw, bd = [], [], [], [], [], []
    for m, (twist_max, bend_max) in BAR_MOTIONS.items():
        scale = rng.uniform(0.95, 1.05)
        sign = 1.0 if rng.random() < 0.5 else -1.0
        ramp = np.linspace(0.0, 1.0, n_frames)
        ramp = ramp * ramp * (3 - 2 * ramp)
        twist = np.deg2rad(sign * scale * twist_max) * ramp
        bend = np.deg2rad(scale * bend_max) * ramp
        chunks.append(bend_and_twist(V0, twist, bend))
        for f in range(n_frames):
            names.append(f"{m}_{f:02d}")
            motion.append(m)
            frame.append(f)
            tw.append(int(round(np.rad2deg(twist[f]))))
            bd.append(int(round(np.rad2deg(bend[f]))))
    return SynthCollection(
        vertices=np.concatenate(chunks), faces=F, names=names,
        labels={"motion": np.array(motion), "frame": np.array(frame, dtype=np.int64),
                "twist_deg": np.array(tw, dtype=np.int64), "bend_deg": np.array(bd, dtype=np.int64)},
        description="an open tube (two boundary loops) twisting and bending past 180 degrees",
        extras={"rest": V0, "tube_shape": (n_along, n_around)},
    )
