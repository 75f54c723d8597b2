"""A head (closed surface) with blendshape-style expressions.

The neutral head is an implicit model (cranium, jaw, cheeks, nose, brow ridge, lips, chin, ears
and a neck stump; a mouth groove and eye sockets carved out), polygonised once. Each *blendshape*
is a smooth displacement field of the neutral vertices (Gaussian-weighted moves of the mouth
corners, brows, lips and cheeks, and a jaw rotation weighted below the mouth); an *expression* is a
weighted sum of blendshapes with the jaw turned about its hinge (a rotation, not a scaled
displacement); every mesh draws its own intensity and weights, so no two meshes are the same.

Coordinates (metres): the head's centre near the origin, y up, the face looking along +z.
"""

from __future__ import annotations

import functools

import numpy as np
from scipy.spatial.transform import Rotation

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import Capsule, Ellipsoid, ImplicitModel, polygonize

__all__ = ["make_face", "face_template", "blendshapes", "EXPRESSIONS"]

#: expression -> blendshape weights at its peak ("jaw_open": the jaw's rotation, as a fraction of
#: ``FACE_JAW_ANGLE``, not a blendshape)
EXPRESSIONS = {
    "smile": {"smile": 1.0, "cheek_raise": 0.8},
    "laugh": {"smile": 1.0, "cheek_raise": 1.0, "jaw_open": 0.6},
    "surprise": {"jaw_open": 0.9, "brow_raise": 1.0},
    "angry": {"brow_lower": 1.0, "mouth_corners_down": 0.5, "lip_press": 0.6},
    "sad": {"mouth_corners_down": 1.0, "brow_inner_up": 1.0},
    "kiss": {"pucker": 1.0},
    "puff": {"cheek_puff": 1.0},
    "shout": {"jaw_open": 1.0, "brow_lower": 0.6, "mouth_stretch": 0.6},
}


def _face_model() -> ImplicitModel:
    prims = [
        Ellipsoid((0.0, 0.03, -0.01), (0.075, 0.098, 0.095), 0),
        Ellipsoid((0.0, -0.035, 0.025), (0.058, 0.06, 0.07), 0),
        Ellipsoid((0.0, -0.09, 0.06), (0.026, 0.02, 0.022), 0),  # chin
        Ellipsoid((0.038, -0.005, 0.06), (0.027, 0.026, 0.03), 0),
        Ellipsoid((-0.038, -0.005, 0.06), (0.027, 0.026, 0.03), 0),
        Capsule((0.0, 0.02, 0.088), (0.0, -0.013, 0.112), 0.007, 0.013, 0),  # nose
        Capsule((-0.042, 0.043, 0.078), (0.042, 0.043, 0.078), 0.011, 0.011, 0),  # brow ridge
        Ellipsoid((0.0, -0.036, 0.092), (0.025, 0.0075, 0.012), 0),  # upper lip
        Ellipsoid((0.0, -0.052, 0.088), (0.023, 0.0085, 0.012), 0),  # lower lip
        Ellipsoid((0.078, 0.005, -0.015), (0.012, 0.03, 0.02), 0),  # ears
        Ellipsoid((-0.078, 0.005, -0.015), (0.012, 0.03, 0.02), 0),
        Capsule((0.0, -0.06, -0.025), (0.0, -0.17, -0.03), 0.05, 0.052, 0),  # neck
    ]
    carve = [
        Ellipsoid((0.0, -0.044, 0.104), (0.026, 0.0035, 0.016), 0),  # mouth line
        Ellipsoid((0.032, 0.02, 0.096), (0.016, 0.009, 0.012), 0),  # eye sockets
        Ellipsoid((-0.032, 0.02, 0.096), (0.016, 0.009, 0.012), 0),
    ]
    return ImplicitModel(prims, blend=C.FACE_BLEND_RADIUS, subtract=carve, subtract_blend=0.008)


@functools.lru_cache(maxsize=4)
def _cached(resolution: int):
    V, F = polygonize(_face_model(), resolution, area_estimate=0.09)
    V.setflags(write=False)
    F.setflags(write=False)
    return V, F


def face_template(resolution: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Neutral head ``(V (n, 3) float64, F (m, 3) int64)``, cached and read-only."""
    resolution = resolve_resolution(resolution, C.FACE_DEFAULT_RESOLUTION)
    return _cached(resolution)


def _gauss(V, center, sigma):
    return np.exp(-0.5 * np.sum(((V - np.asarray(center)) / np.asarray(sigma)) ** 2, axis=1))


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def _jaw_weights(V: np.ndarray):
    """The jaw's hinge ``(3,)`` near the ears and each vertex's jaw weight ``(n,)``: everything below
    the mouth, fading into the neck and towards the back of the head."""
    front = _smoothstep((V[:, 2] - 0.03) / 0.04)
    below = _smoothstep((-0.044 - V[:, 1]) / 0.03 + 0.35)
    not_neck = _smoothstep((V[:, 2] - 0.0) / 0.05)
    return np.array([0.0, -0.01, -0.02]), below * not_neck * front


def blendshapes(V: np.ndarray) -> dict[str, np.ndarray]:
    """Displacement field ``(n_vertices, 3) float64`` of every blendshape at weight 1 (the jaw is not
    one: it turns about its hinge, :func:`_jaw_rotation`)."""
    x = V[:, 0]
    sx = np.tanh(x / 0.012)  # a smooth 'which side' (a sign would tear the midline)
    out = {}
    corner = sum(_gauss(V, (s * 0.026, -0.044, 0.092), (0.014, 0.012, 0.02)) for s in (1, -1))
    out["smile"] = np.stack([0.006 * sx, 0.007 * np.ones_like(x), -0.004 * np.ones_like(x)], 1) * corner[:, None]
    out["mouth_corners_down"] = np.stack([0.001 * sx, -0.006 * np.ones_like(x), np.zeros_like(x)], 1) * corner[:, None]
    out["mouth_stretch"] = np.stack([0.006 * sx, -0.002 * np.ones_like(x), np.zeros_like(x)], 1) * corner[:, None]
    cheek = sum(_gauss(V, (s * 0.04, -0.005, 0.07), (0.02, 0.018, 0.02)) for s in (1, -1))
    out["cheek_raise"] = np.array([0.0, 0.004, 0.003]) * cheek[:, None]
    brow = sum(_gauss(V, (s * 0.03, 0.047, 0.085), (0.025, 0.014, 0.03)) for s in (1, -1))
    out["brow_raise"] = np.array([0.0, 0.008, 0.001]) * brow[:, None]
    out["brow_lower"] = np.stack([-0.003 * sx, -0.005 * np.ones_like(x), 0.002 * np.ones_like(x)], 1) * brow[:, None]
    inner = _gauss(V, (0.0, 0.045, 0.085), (0.018, 0.014, 0.03))
    out["brow_inner_up"] = np.array([0.0, 0.006, 0.0]) * inner[:, None]
    lips = _gauss(V, (0.0, -0.044, 0.095), (0.02, 0.014, 0.02))
    # lips press together: the upper lip moves down, the lower up (a smooth step across the
    # mouth line, never a jump between neighbouring vertices)
    across = np.tanh((V[:, 1] + 0.044) / 0.006)
    out["lip_press"] = np.stack([np.zeros_like(x), -0.002 * across,
                                 -0.002 * np.ones_like(x)], 1) * lips[:, None]
    puff = sum(_gauss(V, (s * 0.045, -0.035, 0.055), (0.018, 0.02, 0.025)) for s in (1, -1))
    normals_out = V - np.array([0.0, -0.03, 0.0])
    normals_out /= np.linalg.norm(normals_out, axis=1, keepdims=True)
    out["cheek_puff"] = 0.01 * puff[:, None] * normals_out
    out = {k: C.FACE_BLENDSHAPE_SCALE * d for k, d in out.items()}
    # pucker: the lips push forward (scaled like the others) and draw together sideways (not
    # scaled: more would crush the edges across the mouth)
    out["pucker"] = np.stack([-0.3 * x, np.zeros_like(x), C.FACE_BLENDSHAPE_SCALE * 0.009 * np.ones_like(x)], 1) * lips[:, None]
    return out


def _identity(V: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A per-seed person: head proportions scaled by up to 6% per axis, a longer or shorter
    chin and a larger or smaller nose (smooth moves of the neutral vertices, same mesh)."""
    scale = 1.0 + rng.uniform(-0.06, 0.06, size=3)
    V = V * scale
    chin = _gauss(V, (0.0, -0.09, 0.06), (0.03, 0.025, 0.03))
    V[:, 1] += rng.uniform(-0.008, 0.008) * chin
    nose = _gauss(V, (0.0, -0.005, 0.11), (0.012, 0.02, 0.015))
    V[:, 2] += rng.uniform(-0.006, 0.006) * nose
    return V


def _jaw_rotation(V: np.ndarray, angle: float) -> np.ndarray:
    """Open the jaw: every vertex turned about the hinge (near the ears) by ``angle`` times its jaw
    weight (1 on the chin, fading to 0 above the mouth and into the neck): a rotation, not a
    displacement scaled with the angle. V (n, 3) float64 -> (n, 3) float64."""
    pivot, w = _jaw_weights(V)
    rotvec = np.zeros((len(V), 3))
    rotvec[:, 0] = angle * w
    return Rotation.from_rotvec(rotvec).apply(V - pivot) + pivot


def make_face(seed: int = 0, resolution: int | None = None,
              variants_per_expression: int = C.FACE_VARIANTS) -> SynthCollection:
    """Every expression ``variants_per_expression`` times, each an independent draw: its intensity
    (``FACE_MIN_INTENSITY`` to 1), every blendshape weight jittered by up to ``FACE_WEIGHT_JITTER``,
    and the jaw opened by the expression's angle plus up to ``FACE_SPEECH_JAW`` radians (speech),
    at most ``FACE_JAW_ANGLE``. Labels ``expression``, ``variant``, ``intensity_pct``."""
    V0, F = face_template(resolution)
    rng = np.random.default_rng(seed)
    V0 = _identity(np.array(V0), rng)
    shapes = blendshapes(V0)
    chunks, names, expr, variant, inten = [], [], [], [], []
    for e, weights in EXPRESSIONS.items():
        for i in range(variants_per_expression):
            intensity = rng.uniform(C.FACE_MIN_INTENSITY, 1.0)
            field = np.zeros_like(V0)
            jaw = rng.uniform(0.0, C.FACE_SPEECH_JAW)
            for b, w in weights.items():
                k = w * intensity * (1.0 + rng.uniform(-1, 1) * C.FACE_WEIGHT_JITTER)
                if b == "jaw_open":
                    jaw += k * C.FACE_JAW_ANGLE
                else:
                    field += k * shapes[b]
            chunks.append(_jaw_rotation(V0 + field, min(jaw, C.FACE_JAW_ANGLE)))
            names.append(f"{e}_{i:02d}")
            expr.append(e)
            variant.append(i)
            inten.append(int(round(100 * intensity)))
    return SynthCollection(
        vertices=np.stack(chunks), faces=np.array(F), names=names,
        labels={"expression": np.array(expr), "variant": np.array(variant, dtype=np.int64),
                "intensity_pct": np.array(inten, dtype=np.int64)},
        description="a head with expressions (blendshapes and a rotating jaw), every mesh its own intensity",
        extras={"rest": V0, "blendshape_names": sorted(shapes)},  # rest: this seed's neutral
    )
