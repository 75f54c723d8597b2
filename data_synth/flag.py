"""A flag waving on a pole: a rectangular sheet (one boundary loop) in turbulent, gusty wind.

The sheet is ``FLAG_ASPECT`` wide and 1 high, attached to a vertical pole along its edge
``x = 0``. Each horizontal row of the sheet is an *inextensible curve*: its tangent turns by a
yaw angle and droops by a pitch angle, and positions are integrated along the row, so rows are
never stretched (the vertical edges change length, within the bounds the tests check). The yaw is
turbulence: ``FLAG_WIND_MODES`` travelling waves of random wavelength, speed and slant (diagonal
waves fold the cloth), each swelling and fading with its own slow envelope, all growing towards the
free end and scaled by a gust envelope. Frames are ``1 / FLAG_FPS`` seconds apart: far enough for
the wind to change the folds between frames, so that the collection is not a linear family
(benchmarks/bench_synth_floor.py).
"""

from __future__ import annotations

import numpy as np

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import grid_sheet, grid_tube

__all__ = ["make_flag", "flag_frames"]


def _grid_size(resolution: int) -> tuple[int, int]:
    resolution = resolve_resolution(resolution)
    n_u = int(round(np.sqrt(resolution * C.FLAG_ASPECT)))
    n_v = int(round(resolution / n_u))
    return n_u, n_v


def flag_frames(uv: np.ndarray, n_u: int, n_v: int, times: np.ndarray, rng: np.random.Generator):
    """Positions of the flag at ``times : (n_frames,) float64`` (seconds).

    Parameters
    ----------
    uv : (n_u * n_v, 2) float64, rest coordinates (vertex ``i * n_v + j``: column i, row j).

    Returns
    -------
    V : (n_frames, n_u * n_v, 3) float64
    strength : (n_frames,) float64, the wind's gust envelope in [0, 1].
    """
    width = C.FLAG_ASPECT
    u = uv[:, 0].reshape(n_u, n_v)[:, 0]  # (n_u,)
    v = uv[:, 1].reshape(n_u, n_v)[0]  # (n_v,)
    t = times[:, None, None]
    gust_f = rng.uniform(0.05, 0.12)
    strength = 0.5 + 0.5 * np.sin(2 * np.pi * gust_f * times + rng.uniform(0, 2 * np.pi))  # (n_frames,)
    s = strength[:, None, None]
    uu = (u / width)[None, :, None]
    vv = v[None, None, :]
    yaw = np.zeros((len(times), n_u, n_v))
    for _ in range(C.FLAG_WIND_MODES):  # tens of modes, each vectorised over frames and vertices
        wavelength = rng.uniform(C.FLAG_MIN_WAVELENGTH, 1.1)
        k, omega, slant = 2.0 * np.pi / wavelength, 2.0 * np.pi * rng.uniform(0.6, 2.0), rng.uniform(-2.5, 2.5)
        amp = C.FLAG_WAVE_AMPLITUDE / np.sqrt(C.FLAG_WIND_MODES) * np.sqrt(wavelength / 1.1)  # short waves are weaker
        swell = 0.5 + 0.5 * np.sin(2 * np.pi * rng.uniform(0.05, 0.3) * t + rng.uniform(0, 2 * np.pi))
        yaw += amp * swell * np.sin(k * u[None, :, None] - omega * t + slant * vv + rng.uniform(0, 2 * np.pi))
    yaw *= (0.6 + 0.6 * s) * uu**0.7  # grows towards the free end and with the gust
    pitch = np.broadcast_to((0.5 - 0.3 * s) * uu * (0.7 + 0.3 * vv), yaw.shape)  # droops more when the wind drops
    tangent = np.stack([np.cos(pitch) * np.cos(yaw), -np.sin(pitch),
                        np.cos(pitch) * np.sin(yaw)], axis=-1)  # (n_frames, n_u, n_v, 3)
    du = np.diff(u)[None, :, None, None]
    steps = 0.5 * (tangent[:, 1:] + tangent[:, :-1]) * du
    # renormalise each step to the rest length: rows stay inextensible
    steps *= du / np.linalg.norm(steps, axis=-1, keepdims=True)
    pos = np.concatenate([np.zeros_like(steps[:, :1]), np.cumsum(steps, axis=1)], axis=1)
    pos[..., 1] += v[None, None, :]
    return pos.reshape(len(times), n_u * n_v, 3), strength


def flag_pole() -> tuple[np.ndarray, np.ndarray]:
    """The pole the flag hangs on, as scenery (not part of the collection): an open cylinder along
    ``y`` through the sheet's attached edge ``x = 0``, from below the sheet to just above it.

    Returns ``V (n, 3) float64, F (m, 3) int64``.
    """
    r, bottom, top = C.FLAG_POLE_RADIUS, C.FLAG_POLE_BOTTOM, C.FLAG_POLE_TOP
    V, F = grid_tube(12, 24, top - bottom, r)
    V = V[:, [1, 0, 2]]                       # along y
    V[:, 1] += bottom
    V[:, 0] -= r                              # the sheet's edge touches the pole's surface
    return V, F[:, [0, 2, 1]]                 # swapping two axes flipped the orientation


def make_flag(seed: int = 0, resolution: int | None = None,
              n_frames: int = C.FLAG_N_FRAMES) -> SynthCollection:
    """A flag in turbulent wind: ``n_frames`` frames, ``1 / FLAG_FPS`` s apart; labels ``frame`` and ``wind``."""
    resolution = C.FLAG_DEFAULT_RESOLUTION if resolution is None else int(resolution)
    n_u, n_v = _grid_size(resolution)
    V0, F, uv = grid_sheet(n_u, n_v, C.FLAG_ASPECT, 1.0)
    rng = np.random.default_rng(seed)
    times = np.arange(n_frames) / C.FLAG_FPS
    V, strength = flag_frames(uv, n_u, n_v, times, rng)
    pole = flag_pole()
    wind = np.where(strength < 1 / 3, "calm", np.where(strength < 2 / 3, "breeze", "gust"))
    return SynthCollection(
        vertices=V, faces=F, names=[f"frame_{i:03d}" for i in range(n_frames)],
        labels={"frame": np.arange(n_frames, dtype=np.int64), "wind": wind},
        description="a flag on a pole in turbulent, gusty wind (one boundary loop)",
        extras={"rest": V0, "grid_shape": (n_u, n_v), "wind_strength": strength,
                "props": [(pole[0], pole[1], C.FLAG_POLE_COLOR)]},  # scenery for renderings
    )
