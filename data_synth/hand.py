"""A hand (closed surface) with a palm, five fingers of three bending joints and a wrist.

Coordinates (metres): the wrist at the origin, fingers pointing along +y, the palm facing +z,
the thumb on the +x side. Built like the body: an implicit model (ellipsoid palm, tapered-capsule
phalanges and a forearm stump), polygonised, skinned to a 17-joint skeleton and posed with
dual-quaternion skinning. Gestures curl the fingers (flexion about each joint's axis) and bend
the wrist.
"""

from __future__ import annotations

import functools

import numpy as np

from data_synth import constants as C
from data_synth.collection import SynthCollection, resolve_resolution
from data_synth.meshing import Capsule, Ellipsoid, ImplicitModel, polygonize
from data_synth.skeleton import Skeleton, axis_rotation, forward_kinematics
from data_synth.skinning import dual_quaternion_blend, skinning_weights

__all__ = ["make_hand", "hand_template", "GESTURES", "FINGERS"]

FINGERS = ("thumb", "index", "middle", "ring", "little")
_X, _Y, _Z = np.eye(3)

#: gesture -> curl per finger (0 straight, 1 fully curled), thumb first; then spread, wrist flex
GESTURES = {
    "fist": ((1.0, 1.0, 1.0, 1.0, 1.0), 0.0, 0.2),
    "point": ((0.9, 0.0, 1.0, 1.0, 1.0), 0.0, 0.0),
    "peace": ((0.9, 0.0, 0.0, 1.0, 1.0), 0.6, 0.0),
    "thumbs_up": ((0.0, 1.0, 1.0, 1.0, 1.0), 0.0, -0.3),
    "grab": ((0.5, 0.55, 0.55, 0.55, 0.55), 0.3, 0.3),
    "spread": ((0.0, 0.0, 0.0, 0.0, 0.0), 1.0, -0.4),
    "ok": ((0.65, 0.7, 0.1, 0.15, 0.2), 0.3, 0.0),
    "wave_down": ((0.1, 0.1, 0.1, 0.1, 0.1), 0.2, 1.1),
}


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


def _gesture_rotations(skeleton, dirs, curls, spread, wrist, amount) -> np.ndarray:
    """Local rotations ``(n_frames, 17, 3, 3)`` blending from open (0) to the gesture (1)."""
    n = len(amount)
    local = np.broadcast_to(np.eye(3), (n, skeleton.n_joints, 3, 3)).copy()
    local[:, 1] = axis_rotation(_X, wrist * amount)
    flex = (1.25, 1.45, 0.95)  # maximum flexion of the three joints, radians
    spread_angle = {"index": 0.12, "middle": 0.0, "ring": -0.1, "little": -0.22, "thumb": 0.3}
    thumb_target = np.array([-0.7, 0.0, 1.0])
    for f, finger in enumerate(FINGERS):
        for k in range(3):
            j = skeleton.index(f"{finger}_{k}")
            if finger == "thumb":
                axis = np.cross(dirs[j], thumb_target)
                angle = curls[f] * amount * (0.7, 0.8, 0.9)[k]
            else:
                axis = _X
                angle = curls[f] * amount * flex[k]
            R = axis_rotation(axis, angle)
            if k == 0:
                R = R @ axis_rotation(_Z, -spread * spread_angle[finger] * amount)
            local[:, j] = R
    return local


def make_hand(seed: int = 0, resolution: int | None = None,
              frames_per_gesture: int = 10) -> SynthCollection:
    """Each gesture from the open hand to its peak; labels ``gesture``, ``frame``."""
    V0, F, W, skeleton, dirs = hand_template(resolution)
    rng = np.random.default_rng(seed)
    chunks, names, gesture, frame = [], [], [], []
    ramp = np.linspace(0.0, 1.0, frames_per_gesture)
    ramp = ramp * ramp * (3 - 2 * ramp)
    for g, (curls, spread, wrist) in GESTURES.items():
        curls = np.clip(np.array(curls) + rng.uniform(-0.08, 0.08, size=5), 0.0, 1.0)
        local = _gesture_rotations(skeleton, dirs, curls, spread * rng.uniform(0.8, 1.1),
                                   wrist + rng.uniform(-0.15, 0.15), ramp)
        R, p = forward_kinematics(skeleton, local, np.zeros((len(ramp), 3)))
        t = p - np.einsum("njab,jb->nja", R, skeleton.rest)
        chunks.append(dual_quaternion_blend(np.asarray(V0), W, R, t, parents=skeleton.parents))
        for f in range(frames_per_gesture):
            names.append(f"{g}_{f:02d}")
            gesture.append(g)
            frame.append(f)
    return SynthCollection(
        vertices=np.concatenate(chunks), faces=np.array(F), names=names,
        labels={"gesture": np.array(gesture), "frame": np.array(frame, dtype=np.int64)},
        description="a hand making gestures from the open pose (fingers bend at three joints)",
        extras={"rest": np.array(V0)},
    )
