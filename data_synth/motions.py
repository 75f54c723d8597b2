"""Motions of the humanoid: smooth frame sequences of joint rotations and root translation.

Every motion is a function ``motion(phase, rng) -> Pose`` of ``phase : (n_frames,) float64`` in
[0, 1) (one pass of the sequence) and a ``numpy.random.Generator`` that jitters amplitudes and
timing a little (so seeds differ). Angles are radians; rotation conventions are those of
:mod:`data_synth.skeleton` (x: the character's left, y: up, z: forward), wrapped in a few helpers
that name the movement (``arm``, ``leg``, ``trunk``) so motions read like choreography.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from data_synth import constants as C
from data_synth.humanoid import NAMES, _base_points, body_skeleton
from data_synth.skeleton import axis_rotation, forward_kinematics

__all__ = ["Pose", "MOTIONS", "motion_sequence", "random_poses", "smooth_signals", "limb_clearance"]

_X, _Y, _Z = np.eye(3)


@dataclass
class Pose:
    """A batch of poses: ``local (n_frames, n_joints, 3, 3)``, ``root (n_frames, 3)`` float64.

    ``plant`` names joints whose mean rest position is kept fixed in y (feet on the ground, for
    squats) by adjusting the root translation after forward kinematics; empty for none.
    """

    local: np.ndarray
    root: np.ndarray
    plant: tuple = ()

    @classmethod
    def identity(cls, n: int) -> "Pose":
        local = np.broadcast_to(np.eye(3), (n, len(NAMES), 3, 3)).copy()
        return cls(local, np.zeros((n, 3)))

    def rotate(self, joint: str, axis, angle) -> "Pose":
        """Apply a rotation about ``axis`` by ``angle (n,)`` after the joint's current one."""
        j = NAMES.index(joint)
        angle = np.broadcast_to(np.asarray(angle, float), (len(self.local),))
        self.local[:, j] = axis_rotation(axis, angle) @ self.local[:, j]
        return self

    # --- named movements ---------------------------------------------------------------------
    def arm(self, side: str, lower=0.0, forward=0.0, twist=0.0, elbow=0.0, shrug=0.0) -> "Pose":
        """``lower``: towards the body from the A-pose (negative raises the arm sideways, about
        -2.3 points it up); ``forward``: swing forward; ``twist``: about the upper arm;
        ``elbow``: flexion; ``shrug``: lifts the shoulder."""
        sgn = 1.0 if side == "l" else -1.0
        a = np.deg2rad(C.ARM_REST_ANGLE_DEG)
        direction = np.array([sgn * np.cos(a), -np.sin(a), 0.0])
        self.rotate(f"{side}_clavicle", _Z, sgn * np.asarray(shrug))
        self.rotate(f"{side}_upperarm", direction, sgn * np.asarray(twist))
        self.rotate(f"{side}_upperarm", _Z, -sgn * np.asarray(lower))
        self.rotate(f"{side}_upperarm", _X, -np.asarray(forward))
        self.rotate(f"{side}_forearm", np.array([np.cos(a), sgn * np.sin(a), 0.0]),
                    -np.asarray(elbow))
        return self

    def leg(self, side: str, hip=0.0, knee=0.0, ankle=0.0, spread=0.0) -> "Pose":
        """``hip``: thigh forward; ``knee``: flexion; ``ankle``: toes down; ``spread``: outwards."""
        sgn = 1.0 if side == "l" else -1.0
        self.rotate(f"{side}_thigh", _Z, sgn * np.asarray(spread))
        self.rotate(f"{side}_thigh", _X, -np.asarray(hip))
        self.rotate(f"{side}_shin", _X, np.asarray(knee))
        self.rotate(f"{side}_foot", _X, np.asarray(ankle))
        return self

    def trunk(self, bend=0.0, twist=0.0, side=0.0, head_nod=0.0, head_turn=0.0) -> "Pose":
        """Forward ``bend``, ``twist`` to the left and ``side`` bend, spread over spine and chest."""
        for joint in ("spine", "chest"):
            self.rotate(joint, _Y, 0.5 * np.asarray(twist))
            self.rotate(joint, _Z, -0.5 * np.asarray(side))
            self.rotate(joint, _X, 0.5 * np.asarray(bend))
        self.rotate("neck", _X, 0.4 * np.asarray(head_nod))
        self.rotate("head", _X, 0.6 * np.asarray(head_nod))
        self.rotate("head", _Y, np.asarray(head_turn))
        return self

    def vary(self, signals: np.ndarray, scale: float = 1.0) -> "Pose":
        """Add a performer's variation: every joint of :data:`constants.PERFORMANCE_RANGE` turns
        about x, y and z by its range x ``scale`` x a column of ``signals (n_frames, 3 n_joints)``
        (three columns per joint in ``NAMES`` order; :func:`smooth_signals`)."""
        for j, name in enumerate(NAMES):
            part = name[2:] if name[1] == "_" else name
            amount = scale * C.PERFORMANCE_RANGE.get(part, 0.0)
            if amount:
                for a, axis in enumerate((_X, _Y, _Z)):
                    angle = amount * signals[:, 3 * j + a]
                    if part in ("upperarm", "clavicle", "thigh") and a == 2:  # only away from the body
                        angle = (1.0 if name[0] == "l" else -1.0) * np.abs(angle)
                    self.rotate(name, axis, angle)
        return self

    def root_turn(self, yaw=0.0, pitch=0.0) -> "Pose":
        self.rotate("pelvis", _X, pitch)
        self.rotate("pelvis", _Y, yaw)
        return self


def smooth_signals(phase, rng: np.random.Generator, n_channels: int, cycles: int) -> np.ndarray:
    """Smooth random signals ``(n_frames, n_channels) float64`` over one pass of ``phase (n_frames,)``:
    random Fourier series with 1 .. ``cycles`` cycles per pass, amplitudes falling as 1/k and random
    phases, scaled to unit RMS over a whole pass (exactly: by the coefficients, not by the frames)."""
    k = np.arange(1, cycles + 1, dtype=np.float64)
    amp = rng.normal(size=(n_channels, cycles)) / k
    shift = rng.uniform(0.0, 2.0 * np.pi, size=(n_channels, cycles))
    waves = np.sin(2.0 * np.pi * k * np.asarray(phase, np.float64)[:, None, None] + shift)
    return (amp * waves).sum(axis=2) / np.sqrt(0.5 * (amp**2).sum(axis=1))


def _smooth_pulse(x):
    """0 at x <= 0, 1 at x >= 1, C1 smooth in between."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def walk(phase, rng, run=False):
    n = len(phase)
    amp = rng.uniform(0.9, 1.1)
    phi = 2.0 * np.pi * 2.0 * phase + rng.uniform(0, 2 * np.pi)  # two strides
    p = Pose.identity(n)
    if run:
        hip_a, knee_a, arm_a, elbow, lean, bob = 0.75, 1.5, 0.6, 1.5, 0.22, 0.05
    else:
        hip_a, knee_a, arm_a, elbow, lean, bob = 0.42, 0.75, 0.35, 0.3, 0.04, 0.02
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        s = np.sin(phi + (0 if sgn > 0 else np.pi))
        c = np.cos(phi + (0 if sgn > 0 else np.pi))
        swing = (0.5 + 0.5 * c) ** 2  # knee bends while the thigh swings forward
        p.leg(side, hip=amp * hip_a * s + (0.25 if run else 0.0), knee=0.08 + amp * knee_a * swing,
              ankle=0.15 * np.maximum(-s, 0) - 0.1 * swing)
        p.arm(side, lower=C.ARM_DOWN, forward=-amp * arm_a * s, elbow=elbow + 0.2 * (0.5 + 0.5 * s))
    p.trunk(bend=lean, twist=0.12 * np.sin(phi), head_nod=-lean)
    p.root_turn(yaw=-0.08 * np.sin(phi), pitch=0.5 * lean)
    speed = 1.4 if not run else 2.6
    p.root[:, 2] = speed * phase * 2.0 * (0.9 if run else 0.7)
    p.root[:, 1] = -bob * (0.5 + 0.5 * np.cos(2 * phi))
    return p


def run(phase, rng):
    return walk(phase, rng, run=True)


def jumping_jacks(phase, rng, reps=2.0):
    """``reps`` jumping jacks per pass; each repetition reaches its own height and width (a
    performer never repeats exactly)."""
    n = len(phase)
    phi = 2.0 * np.pi * reps * phase + rng.uniform(-0.2, 0.2)
    s = _smooth_pulse(0.5 - 0.5 * np.cos(phi))  # 0: arms down, legs together; 1: arms up, legs apart
    cycles = max(2, int(np.ceil(reps)))
    vary = smooth_signals(phase, rng, 3, cycles)
    up = rng.uniform(0.95, 1.05) + 0.04 * np.clip(vary[:, 0], -1.0, 1.0)
    wide = 1.0 + 0.15 * vary[:, 1]
    p = Pose.identity(n)
    for k, side in enumerate(("l", "r")):
        lag = 0.05 * vary[:, 2] * (1 if k else -1)  # one arm a little ahead of the other
        p.arm(side, lower=C.ARM_DOWN - up * C.JACKS_ARM_RAISE * np.clip(s + lag, 0, 1), shrug=0.5 * s,
              elbow=0.15 + 0.1 * s, forward=0.1 * (1 - s))
        p.leg(side, spread=0.06 + 0.24 * wide * s, knee=0.3 * (1 - np.abs(np.sin(phi))),
              hip=0.15 * (1 - np.abs(np.sin(phi))), ankle=0.35 * np.abs(np.sin(phi)))
    p.trunk(head_nod=-0.1 * s)
    p.root[:, 1] = 0.12 * np.abs(np.sin(phi)) - 0.05 * (1 - np.abs(np.sin(phi)))
    return p


def punch(phase, rng):
    n = len(phase)
    p = Pose.identity(n)
    # four punches, alternating left and right, each a quick extension and slower return
    k = 4
    local = (phase * k) % 1.0
    which = np.floor(phase * k).astype(int) % 2
    ext = _smooth_pulse(local / 0.35) * (1 - _smooth_pulse((local - 0.45) / 0.55))
    ext *= rng.uniform(0.9, 1.0)
    for side, idx in (("l", 0), ("r", 1)):
        e = np.where(which == idx, ext, 0.0)
        p.arm(side, lower=C.ARM_DOWN - 0.05 * e, forward=0.9 + 0.6 * e, twist=0.0, shrug=0.15,
              elbow=1.9 * (1 - e) + 0.1)
    twist = 0.35 * np.where(which == 0, -ext, ext)
    p.trunk(twist=twist, bend=0.1)
    p.leg("l", hip=0.35, knee=0.35, ankle=-0.1)
    p.leg("r", hip=-0.2, knee=0.25, ankle=0.1)
    p.root_turn(yaw=0.5 * twist)
    p.root[:, 1] = -0.04
    return p


def squat(phase, rng):
    n = len(phase)
    depth = rng.uniform(0.9, 1.05)
    s = depth * (0.5 - 0.5 * np.cos(2.0 * np.pi * 1.5 * phase))
    p = Pose.identity(n)
    pitch = 0.35 * s
    for side in ("l", "r"):
        # thigh 60 degrees forward, shin 30 degrees back, foot flat: hip, knee, ankle follow
        p.leg(side, hip=1.05 * s + pitch, knee=1.55 * s, ankle=-0.5 * s, spread=0.12 * s)
        p.arm(side, lower=C.ARM_DOWN - 0.05 * s, forward=1.35 * s, elbow=0.2 * s, shrug=0.15 * s)
    p.trunk(bend=0.2 * s, head_nod=-0.5 * s)
    p.root_turn(pitch=pitch)
    p.plant = ("l_foot", "r_foot")
    return p


def wave(phase, rng):
    n = len(phase)
    p = Pose.identity(n)
    raise_ = _smooth_pulse(phase / 0.25) * (1 - _smooth_pulse((phase - 0.8) / 0.2))
    freq = rng.uniform(2.5, 3.5)
    osc = np.sin(2 * np.pi * freq * phase) * raise_
    p.arm("r", lower=C.ARM_DOWN - 1.35 * raise_, twist=-1.4 * raise_, elbow=(1.2 + 0.45 * osc) * raise_
          + 0.15, shrug=0.15 * raise_)
    p.arm("l", lower=C.ARM_DOWN, forward=0.05, elbow=0.15)
    p.trunk(side=-0.08 * raise_, head_turn=-0.2 * raise_)
    return p


def turn(phase, rng):
    n = len(phase)
    p = Pose.identity(n)
    direction = 1.0 if rng.random() < 0.5 else -1.0
    yaw = direction * 2.0 * np.pi * phase * (1.0 - 1e-9)
    step = np.sin(2 * np.pi * 4 * phase)
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        lift = np.maximum(sgn * step, 0.0)
        p.leg(side, hip=0.45 * lift, knee=0.8 * lift, ankle=-0.2 * lift)
        p.arm(side, lower=C.ARM_DOWN, forward=0.1 * sgn * step, elbow=0.35)
    p.trunk(twist=-0.15 * direction, head_turn=0.3 * direction)
    p.root_turn(yaw=yaw)
    return p


#: name -> (function, one-line description)
MOTIONS = {
    "walk": (walk, "walking forward, two strides"),
    "run": (run, "running forward, two strides"),
    "jumping_jacks": (jumping_jacks, "two jumping jacks, arms from the sides to overhead"),
    "punch": (punch, "boxing: four alternating punches from a guard"),
    "squat": (squat, "deep squats with arms forward, feet on the ground"),
    "wave": (wave, "raises the right arm and waves"),
    "turn": (turn, "turns once on the spot, stepping"),
}


def motion_sequence(name: str, n_frames: int, rng: np.random.Generator, offset: float = 0.0,
                    vary: float = 0.0, cycles: int = C.PERFORMANCE_CYCLES, **options) -> Pose:
    """Frames ``0 .. n_frames - 1`` of motion ``name``, evenly spaced over one pass and started
    ``offset`` (in [0, 1): a fraction of the spacing) after its beginning; ``vary`` scales the
    performer's variation (:meth:`Pose.vary`, 0: none), whose signals have up to ``cycles`` cycles
    per pass; ``options`` go to the motion."""
    if name not in MOTIONS:
        raise ValueError(f"unknown motion {name!r}; motions are {sorted(MOTIONS)}")
    if n_frames < 1:
        raise ValueError(f"n_frames must be at least 1, got {n_frames}")
    if not 0.0 <= offset < 1.0:
        raise ValueError(f"offset must lie in [0, 1), got {offset}")
    phase = (np.arange(n_frames) + offset) / n_frames
    pose = MOTIONS[name][0](phase, rng, **options)
    if vary:
        pose.vary(smooth_signals(phase, rng, 3 * len(NAMES), cycles), vary)
    return pose


def limb_clearance(pose: Pose) -> np.ndarray:
    """The skeleton check of a batch of poses, on the average body's skeleton: the least margin
    (metres) by which the pose keeps the two arms (points along shoulder, elbow, wrist and
    fingertips) :data:`constants.ARM_ARM_CLEARANCE` apart, and either arm from the middle of its
    upper arm on :data:`constants.ARM_HEAD_CLEARANCE` (hands: ``HAND_HEAD_CLEARANCE``) from the
    centre of the head. ``(n,) float64``; a pose passes when it is >= 0."""
    skeleton = body_skeleton()
    rest = _base_points()
    R, p = forward_kinematics(skeleton, pose.local, pose.root)
    t = np.linspace(0.0, 1.0, 5)[:-1]
    arms = []
    for s in "lr":
        up, fore, hand = (NAMES.index(f"{s}_{b}") for b in ("upperarm", "forearm", "hand"))
        tip = p[:, hand] + np.einsum("nab,b->na", R[:, hand], rest[f"{s}_hand_end"] - rest[f"{s}_hand"])
        chain = [p[:, up], p[:, fore], p[:, hand], tip]
        pts = [a[:, None] + t[None, :, None] * (b - a)[:, None] for a, b in zip(chain[:-1], chain[1:])]
        arms.append(np.concatenate(pts + [tip[:, None]], axis=1))  # (n, 13, 3): 8 .. 12 the hand
    arm_arm = np.linalg.norm(arms[0][:, :, None] - arms[1][:, None], axis=3).min(axis=(1, 2))
    head = NAMES.index("head")
    centre = p[:, head] + np.einsum("nab,b->na", R[:, head], C.HEAD_CENTRE_OFFSET)
    need = np.where(np.arange(2, 13) >= 8, C.HAND_HEAD_CLEARANCE, C.ARM_HEAD_CLEARANCE)
    margin = [np.linalg.norm(a[:, 2:] - centre[:, None], axis=2) - need for a in arms]
    return np.minimum(arm_arm - C.ARM_ARM_CLEARANCE, np.min(np.concatenate(margin, axis=1), axis=1))


def _draw_poses(n: int, rng: np.random.Generator, diversity: float) -> tuple[Pose, list]:
    names = sorted(MOTIONS)
    chosen = [names[k] for k in rng.integers(0, len(names), size=n)]
    local = np.empty((n, len(NAMES), 3, 3))
    root = np.zeros((n, 3))
    for i, name in enumerate(chosen):  # n is small (tens); each is one vectorised pose
        pose = MOTIONS[name][0](np.array([rng.random()]), rng)
        local[i], root[i] = pose.local[0], pose.root[0]
        root[i, [0, 2]] = 0.0
    pose = Pose(local, root, plant=("l_foot", "r_foot"))
    # random offsets: spine and neck, and limbs within comfortable ranges
    d = diversity
    u = lambda a: rng.uniform(-d * a, d * a, size=n)  # noqa: E731
    for side in ("l", "r"):
        # arms mostly move away from the torso (pressing them into it would interpenetrate)
        pose.arm(side, lower=u(0.12) - np.abs(u(0.5)), forward=u(0.5), twist=u(0.4),
                 elbow=np.abs(u(0.6)))
        pose.leg(side, hip=u(0.25), knee=np.abs(u(0.3)), spread=np.abs(u(0.1)))
    # bending and nodding mostly forward (backwards pinches the back of the neck)
    pose.trunk(bend=d * rng.uniform(-0.1, 0.3, size=n), twist=u(0.4), side=u(0.2),
               head_nod=d * rng.uniform(-0.12, 0.3, size=n), head_turn=u(0.5))
    # and every joint a little more, independently (wrists and ankles most)
    pose.vary(rng.normal(size=(n, 3 * len(NAMES))), d * C.SCAPE_VARY)
    return pose, chosen


def random_poses(n: int, rng: np.random.Generator, diversity: float = 1.0) -> tuple[Pose, list]:
    """``n`` distinct poses: a random frame of a random motion plus random joint offsets scaled by
    ``diversity`` (0: the motions' frames alone; 1: the SCAPE-like default), drawn until ``n`` pass
    the skeleton check (:func:`limb_clearance`: no arm through the other or through the head).

    Returns the poses and, for each, the motion it started from.
    """
    local, root, names = [], [], []
    while sum(len(x) for x in local) < n:
        pose, chosen = _draw_poses(n, rng, diversity)
        keep = np.flatnonzero(limb_clearance(pose) >= 0.0)
        local.append(pose.local[keep])
        root.append(pose.root[keep])
        names += [chosen[k] for k in keep]
    return Pose(np.concatenate(local)[:n], np.concatenate(root)[:n], plant=("l_foot", "r_foot")), names[:n]
