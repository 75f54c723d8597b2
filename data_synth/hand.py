"""A hand (closed surface) with a palm, five fingers of three bending joints and a wrist.

Coordinates (metres): the wrist at the origin, fingers pointing along +y, the palm facing +z,
the thumb on the +x side. Built like the body: an implicit model (ellipsoid palm, tapered-capsule
phalanges and a forearm stump), polygonised, skinned to a 17-joint skeleton and posed with
dual-quaternion skinning. Gestures curl the fingers (flexion about each joint's axis) and bend
the wrist; every mesh draws its own angles for every joint around its gesture's, so that no two
meshes share a pose and the collection is not a linear family (benchmarks/bench_synth_floor.py).
"""

from __future__ import annotations

import functools

import numpy as np

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import Capsule, Ellipsoid, ImplicitModel, polygonize
from data_synth.skeleton import Skeleton, axis_rotation, forward_kinematics
from data_synth.skinning import dual_quaternion_blend, skinning_weights

__all__ = ["make_hand", "hand_template", "GESTURES", "FINGERS", "STEADY_FINGERS", "clear_template_cache"]

FINGERS = ("thumb", "index", "middle", "ring", "little")
_X, _Y, _Z = np.eye(3)

#: gesture -> curl per finger (0 straight, 1 fully curled), thumb first; then spread; then the
#: wrist's flexion, deviation and pronation (radians; thumbs up turns the fist on its side)
GESTURES = {
    "fist": ((1.0, 1.0, 1.0, 1.0, 1.0), 0.0, (0.2, 0.0, 0.0)),
    "point": ((0.9, 0.0, 1.0, 1.0, 1.0), 0.0, (0.0, 0.0, 0.0)),
    "peace": ((0.9, 0.0, 0.0, 1.0, 1.0), 0.6, (0.0, 0.0, 0.0)),
    "thumbs_up": ((0.0, 1.0, 1.0, 1.0, 1.0), 0.0, (0.0, 0.75, 0.0)),
    "grab": ((0.5, 0.55, 0.55, 0.55, 0.55), 0.3, (0.3, 0.0, 0.0)),
    "spread": ((0.0, 0.0, 0.0, 0.0, 0.0), 1.0, (-0.4, 0.0, 0.0)),
    "ok": ((0.4, 0.75, 0.1, 0.15, 0.2), 0.3, (0.0, 0.0, 0.0)),
    "wave_down": ((0.1, 0.1, 0.1, 0.1, 0.1), 0.2, (0.75, 0.0, 0.0)),
}
#: gesture -> fingers that hold their pose exactly (no per-mesh jitter): the ring of "ok", whose
#: thumb and index tips nearly touch (1.8 cm apart centre to centre, about 4 mm of skin between)
STEADY_FINGERS = {"ok": ("thumb", "index")}


def _layout():
    """Joint names, parents, rest positions and bone directions of the hand."""
    names, parents, rest, dirs = ["forearm", "palm"], [-1, 0], [(0, -0.06, 0), (0, 0, 0)], [_Y, _Y]
    bases = {"index": (0.033, 0.092, 0.0), "middle": (0.011, 0.097, 0.0),
             "ring": (-0.011, 0.093, 0.0), "little": (-0.033, 0.083, 0.0)}
    lengths = {"index": (0.043, 0.026, 0.021), "middle": (0.047, 0.029, 0.022),
               "ring": (0.044, 0.028, 0.021), "little": (0.035, 0.021, 0.019)}
    splay = {"index": 0.12, "middle": 0.0, "ring": -0.1, "little": -0.22}
    tips = {}
    thumb_dir = np.array([0.62, 0.72, 0.3])
    thumb_dir /= np.linalg.norm(thumb_dir)
    for finger in FINGERS:
        if finger == "thumb":
            start, d, segs = np.array([0.022, 0.02, 0.008]), thumb_dir, (0.045, 0.033, 0.027)
        else:
            start = np.array(bases[finger])
            d = axis_rotation(_Z, -splay[finger]) @ _Y
            segs = lengths[finger]
        p = start
        parent = 1
        for k, seg in enumerate(segs):
            names.append(f"{finger}_{k}")
            parents.append(parent)
            rest.append(tuple(p))
            dirs.append(d)
            parent = len(names) - 1
            p = p + seg * d
        tips[finger] = p
    return names, np.array(parents), np.array(rest, float), np.array(dirs), tips


def _hand_model(names, rest, dirs, tips) -> ImplicitModel:
    prims = [
        Capsule((0.0, -0.07, 0.0), (0.0, 0.0, 0.0), 0.022, 0.024, 0),
        Ellipsoid((0.0, 0.048, 0.0), (0.045, 0.055, 0.0155), 1),
        Ellipsoid((0.018, 0.03, 0.006), (0.02, 0.03, 0.014), 1),  # thenar eminence
    ]
    radius = {"thumb": (0.0115, 0.0095, 0.0085), "index": (0.0086, 0.0078, 0.007),
              "middle": (0.0088, 0.008, 0.0072), "ring": (0.0084, 0.0076, 0.0068),
              "little": (0.008, 0.007, 0.0062)}
    for j, name in enumerate(names):
        if "_" not in name:
            continue
        finger, k = name.split("_")
        k = int(k)
        r = radius[finger]
        end = rest[j + 1] if k < 2 else tips[finger]
        prims.append(Capsule(tuple(rest[j]), tuple(end), r[k], r[k] if k < 2 else r[k] * 0.9, j))
    return ImplicitModel(prims, blend=C.HAND_BLEND_RADIUS)


@functools.lru_cache(maxsize=4)
def _cached(resolution: int):
    names, parents, rest, dirs, tips = _layout()
    model = _hand_model(names, rest, dirs, tips)
    V, F = polygonize(model, resolution, area_estimate=0.043)
    skeleton = Skeleton(tuple(names), parents, rest)
    parts = model.part_of(V)
    W = skinning_weights(V, F, parts, skeleton, C.HAND_SKIN_BLEND_WIDTH)
    for a in (V, F, W):
        a.setflags(write=False)
    return V, F, W, skeleton, dirs


def hand_template(resolution: int | None = None):
    """``(V (n,3) float64, F (m,3) int64, W (n, 17) float64, skeleton, bone_dirs (17,3))``."""
    resolution = resolve_resolution(resolution, C.HAND_DEFAULT_RESOLUTION)
    return _cached(resolution)


def _pose_rotations(skeleton, dirs, joint_curl, spread, wrist) -> np.ndarray:
    """Local rotations ``(n, 17, 3, 3)`` of ``n`` hand poses.

    joint_curl : (n, 5, 3) float, flexion of every finger joint (thumb first) as a fraction of its
        range (0 straight, 1 fully bent); spread : (n,) float, how far the fingers fan out (0: the
        rest splay, 1: spread); wrist : (n, 3) float, radians: flexion (about x), deviation (about z)
        and pronation (a twist about the forearm, y).
    """
    n = len(spread)
    local = np.broadcast_to(np.eye(3), (n, skeleton.n_joints, 3, 3)).copy()
    local[:, 1] = axis_rotation(_Y, wrist[:, 2]) @ axis_rotation(_Z, wrist[:, 1]) @ axis_rotation(_X, wrist[:, 0])
    flex = (1.25, 1.45, 0.95)  # maximum flexion of the three joints, radians
    spread_angle = {"index": 0.12, "middle": 0.0, "ring": -0.1, "little": -0.22, "thumb": 0.3}
    thumb_target = np.array([-0.7, 0.0, 1.0])
    for f, finger in enumerate(FINGERS):
        for k in range(3):
            j = skeleton.index(f"{finger}_{k}")
            if finger == "thumb":
                axis, angle = np.cross(dirs[j], thumb_target), joint_curl[:, f, k] * (0.7, 0.8, 0.9)[k]
            else:
                axis, angle = _X, joint_curl[:, f, k] * flex[k]
            R = axis_rotation(axis, angle)
            if k == 0:
                R = R @ axis_rotation(_Z, -spread * spread_angle[finger])
            local[:, j] = R
    return local


def _sample_poses(rng, curls, spread, wrist, n: int, steady=()):
    """``n`` independent variants of one gesture: every joint, the spread and all three wrist angles
    drawn around the gesture's (``constants.HAND_*``), so that no two meshes share a pose; the
    fingers named in ``steady`` keep the gesture's curls exactly."""
    amount = np.broadcast_to(rng.uniform(C.HAND_MIN_AMOUNT, 1.0, size=(n, 1, 1)), (n, 5, 1)).copy()
    jitter = rng.uniform(-1, 1, size=(n, 5, 3)) * C.HAND_JOINT_JITTER
    for finger in steady:
        amount[:, FINGERS.index(finger)] = 1.0
        jitter[:, FINGERS.index(finger)] = 0.0
    joint = np.asarray(curls, float)[None, :, None] * amount + jitter
    spread_jitter = 0.0 if steady else C.HAND_SPREAD_JITTER  # the spread moves the thumb and the index
    spread = np.clip(spread + rng.uniform(-1, 1, size=n) * spread_jitter, 0.0, 1.2)
    wrist = np.asarray(wrist, float)[None] + rng.uniform(-1, 1, size=(n, 3)) * np.asarray(C.HAND_WRIST_RANGE)
    return np.clip(joint, 0.0, 1.0), spread, wrist


def make_hand(seed: int = 0, resolution: int | None = None,
              variants_per_gesture: int = C.HAND_VARIANTS) -> SynthCollection:
    """Every gesture, ``variants_per_gesture`` times, each an independent pose near the gesture's peak
    (every finger joint, the spread and the wrist's three angles drawn per mesh); labels
    ``gesture``, ``variant``."""
    V0, F, W, skeleton, dirs = hand_template(resolution)
    rng = np.random.default_rng(seed)
    chunks, names, gesture, variant = [], [], [], []
    for g, (curls, spread, wrist) in GESTURES.items():
        local = _pose_rotations(skeleton, dirs, *_sample_poses(rng, curls, spread, wrist, variants_per_gesture,
                                                                       STEADY_FINGERS.get(g, ())))
        R, p = forward_kinematics(skeleton, local, np.zeros((variants_per_gesture, 3)))
        t = p - np.einsum("njab,jb->nja", R, skeleton.rest)
        chunks.append(dual_quaternion_blend(np.asarray(V0), W, R, t, parents=skeleton.parents))
        for v in range(variants_per_gesture):
            names.append(f"{g}_{v:02d}")
            gesture.append(g)
            variant.append(v)
    return SynthCollection(
        vertices=np.concatenate(chunks), faces=np.array(F), names=names,
        labels={"gesture": np.array(gesture), "variant": np.array(variant, dtype=np.int64)},
        description="a hand making gestures, every mesh its own pose of every finger joint and the wrist",
        extras={"rest": np.array(V0)},
    )


def clear_template_cache() -> None:
    """Forget the templates built so far, so that the next collection builds them again."""
    _cached.cache_clear()
