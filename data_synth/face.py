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

__all__ = ["make_face", "face_template", "blendshapes", "EXPRESSIONS", "clear_template_cache"]

#: expression -> blendshape weights at its peak ("jaw_open" and "lip_roll" are rotations, as fractions
#: of ``FACE_JAW_ANGLE`` and ``FACE_LIP_ROLL``, not blendshapes)
EXPRESSIONS = {
    "smile": {"smile": 1.0, "cheek_raise": 0.8, "squint": 0.4},
    "laugh": {"smile": 1.0, "cheek_raise": 1.0, "squint": 0.9, "jaw_open": 0.7},
    "surprise": {"jaw_open": 1.0, "brow_raise": 1.0, "eyes_wide": 1.0},
    "angry": {"brow_lower": 1.0, "squint": 0.6, "mouth_corners_down": 0.4, "lip_press": 0.6},
    "sad": {"mouth_corners_down": 1.0, "brow_inner_up": 1.0, "lip_roll": 0.4},
    "kiss": {"pucker": 1.0, "lip_roll": 1.0},
    "puff": {"cheek_puff": 1.0, "lip_press": 0.5},
    "shout": {"jaw_open": 1.0, "brow_lower": 0.7, "mouth_stretch": 1.0},
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


def _side(V: np.ndarray) -> np.ndarray:
    """A smooth 'which side' of every vertex ``(n,)``: +1 left, -1 right, through 0 on the midline
    (a sign would tear the midline)."""
    return np.tanh(V[:, 0] / 0.012)


def _rig(V0: np.ndarray) -> dict:
    """What every mesh of one neutral head ``V0 (n, 3)`` shares, computed once: ``side (n, 1)``
    (:func:`_side`), the jaw's ``hinge (3,)`` and weights ``jaw (n,)`` and the head's weights
    ``head (n,)``."""
    hinge, w_jaw = _jaw_weights(V0)
    return {"side": _side(V0)[:, None], "hinge": hinge, "jaw": w_jaw, "head": _head_weights(V0)}


def blendshapes(V: np.ndarray) -> dict[str, np.ndarray]:
    """Displacement field ``(n_vertices, 3) float64`` of every blendshape at weight 1 (the jaw is not
    one: it turns about its hinge in :func:`_expression_mesh`)."""
    x = V[:, 0]
    sx = _side(V)
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
    # the eyelids: above each eye the skin moves down and below it up (squint), or the other way
    above = sum(_gauss(V, (s * 0.032, 0.032, 0.09), (0.016, 0.007, 0.02)) for s in (1, -1))
    below = sum(_gauss(V, (s * 0.032, 0.007, 0.09), (0.016, 0.007, 0.02)) for s in (1, -1))
    out["squint"] = np.array([0.0, -0.003, 0.0]) * above[:, None] + np.array([0.0, 0.002, 0.001]) * below[:, None]
    out["eyes_wide"] = np.array([0.0, 0.005, 0.001]) * above[:, None] + np.array([0.0, -0.002, 0.0]) * below[:, None]
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


def _rotate_weighted(V: np.ndarray, pivot, rotvec, w: np.ndarray) -> np.ndarray:
    """Every vertex turned about ``pivot (3,)`` by the rotation ``w_i * rotvec`` (a rotation vector
    ``(3,)``, radians): weight 1 turns rigidly, 0 stays, in between bends smoothly. V (n, 3) -> (n, 3)."""
    pivot = np.asarray(pivot, dtype=np.float64)
    return Rotation.from_rotvec(w[:, None] * np.asarray(rotvec, dtype=np.float64)).apply(V - pivot) + pivot


def _head_weights(V: np.ndarray) -> np.ndarray:
    """How far each vertex follows the head's turn ``(n,)``: 1 on the head (chin and jaw included),
    fading to 0 down the neck along a plane that tilts forward (the chin sits above the neck)."""
    return _smoothstep((V[:, 1] + 0.5 * V[:, 2] + 0.19) / 0.1)


def _lip_roll(V: np.ndarray, angle: float) -> np.ndarray:
    """Roll both lips about their roots: outward (``angle > 0``, the upper lip curls up, the lower
    down, as in a kiss) or inward (``angle < 0``, lips pressed thin). A rotation per lip, radians."""
    upper = _gauss(V, (0.0, -0.034, 0.094), (0.024, 0.008, 0.014))
    lower = _gauss(V, (0.0, -0.054, 0.09), (0.022, 0.009, 0.014))
    V = _rotate_weighted(V, (0.0, -0.036, 0.078), (-angle, 0.0, 0.0), upper)
    return _rotate_weighted(V, (0.0, -0.052, 0.076), (angle, 0.0, 0.0), lower)


def _expression_mesh(V0: np.ndarray, shapes: dict, rig: dict, weights: dict, intensity: float,
                     rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """One mesh ``(n, 3)`` of an expression and its head pose ``(yaw, pitch, roll)`` in radians
    (``rig``: :func:`_rig` of ``V0``).

    The expression's blendshapes at ``intensity`` (each weight jittered by ``FACE_WEIGHT_JITTER``)
    plus every other blendshape a little (speech and mood: up to ``FACE_SPEECH_WEIGHT``), then the
    rotations: the lips roll, the jaw opens and slides sideways about its hinge, and the head turns
    on the neck (yaw, pitch and roll drawn independently within ``FACE_HEAD_TURN``)."""
    field = np.zeros_like(V0)
    extra = {b: rng.uniform(0.0, C.FACE_SPEECH_WEIGHT) for b in sorted(shapes) if b not in weights}
    jaw = rng.uniform(0.0, C.FACE_SPEECH_JAW)
    roll = rng.uniform(-1.0, 1.0) * C.FACE_LIP_ROLL * C.FACE_SPEECH_WEIGHT
    for b, w in weights.items():
        k = w * intensity * (1.0 + rng.uniform(-1, 1) * C.FACE_WEIGHT_JITTER)
        if b == "jaw_open":
            jaw += k * C.FACE_JAW_ANGLE
        elif b == "lip_roll":
            roll += k * C.FACE_LIP_ROLL
        else:
            extra[b] = extra.get(b, 0.0) + k
    for b, k in extra.items():  # each side of the face a little its own (no face is symmetric)
        field += k * (1.0 + rng.uniform(-1.0, 1.0) * C.FACE_ASYMMETRY * rig["side"]) * shapes[b]
    V = _lip_roll(V0 + field, roll)
    slide = rng.uniform(-1.0, 1.0) * C.FACE_JAW_SIDE
    V = _rotate_weighted(V, rig["hinge"], (min(jaw, C.FACE_JAW_ANGLE), slide, 0.0), rig["jaw"])
    yaw_max, pitch_up, pitch_down, roll_max = C.FACE_HEAD_TURN
    pose = np.array([rng.uniform(-yaw_max, yaw_max), rng.uniform(-pitch_up, pitch_down),
                     rng.uniform(-roll_max, roll_max)])
    V = _rotate_weighted(V, C.FACE_NECK_PIVOT, pose[[1, 0, 2]], rig["head"])
    return V, pose


def make_face(seed: int = 0, resolution: int | None = None,
              variants_per_expression: int = C.FACE_VARIANTS) -> SynthCollection:
    """Every expression ``variants_per_expression`` times, each an independent draw: its intensity
    (``FACE_MIN_INTENSITY`` to 1), its blendshape weights, the rest of the face's small motions and
    the head's turn on the neck (:func:`_expression_mesh`), as a performer's face moves in a capture.
    Labels ``expression``, ``variant``, ``intensity_pct`` and ``head_yaw_deg``."""
    V0, F = face_template(resolution)
    rng = np.random.default_rng(seed)
    V0 = _identity(np.array(V0), rng)
    shapes, rig = blendshapes(V0), _rig(V0)
    chunks, names, expr, variant, inten, yaw = [], [], [], [], [], []
    for e, weights in EXPRESSIONS.items():
        for i in range(variants_per_expression):
            intensity = rng.uniform(C.FACE_MIN_INTENSITY, 1.0)
            V, pose = _expression_mesh(V0, shapes, rig, weights, intensity, rng)
            chunks.append(V)
            names.append(f"{e}_{i:02d}")
            expr.append(e)
            variant.append(i)
            inten.append(int(round(100 * intensity)))
            yaw.append(int(round(np.degrees(pose[0]))))
    return SynthCollection(
        vertices=np.stack(chunks), faces=np.array(F), names=names,
        labels={"expression": np.array(expr), "variant": np.array(variant, dtype=np.int64),
                "intensity_pct": np.array(inten, dtype=np.int64), "head_yaw_deg": np.array(yaw, dtype=np.int64)},
        description="a head with expressions (blendshapes, rolling lips and a rotating jaw) turning on its neck",
        extras={"rest": V0, "blendshape_names": sorted(shapes)},  # rest: this seed's neutral
    )


def clear_template_cache() -> None:
    """Forget the templates built so far, so that the next collection builds them again."""
    _cached.cache_clear()
