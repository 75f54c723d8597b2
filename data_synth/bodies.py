"""Collections of the humanoid: SCAPE-like, Dyna-like and a Jumping-like sequence."""

from __future__ import annotations

import numpy as np

from data_synth import constants as C
from data_synth.collection import SynthCollection
from data_synth.humanoid import NAMES, BodyShape, body_template, pose_body, shape_body
from data_synth.motions import MOTIONS, Pose, limb_clearance, motion_sequence, random_poses
from data_synth.skeleton import forward_kinematics

__all__ = ["make_scape", "make_dyna", "make_jumping", "make_poses", "poses_dof", "DYNA_SHAPES", "pose_shape", "checked_sequence"]

#: the Dyna-like collection's body shapes (jittered a little per seed).
DYNA_SHAPES = {
    "male_average": BodyShape(height=1.78, girth=1.0, body_type="male"),
    "male_heavy": BodyShape(height=1.72, girth=1.3, arm_length=0.97, body_type="male"),
    "female_slim": BodyShape(height=1.66, girth=0.88, leg_length=1.04, body_type="female"),
    "female_heavy": BodyShape(height=1.62, girth=1.22, shoulder_width=0.95, body_type="female"),
    "male_tall_slim": BodyShape(height=1.92, girth=0.86, leg_length=1.06, arm_length=1.04,
                                body_type="male"),
}


def pose_shape(template, shape: BodyShape, pose: Pose) -> np.ndarray:
    """Meshes ``(n_frames, n_vertices, 3) float64`` of body ``shape`` in every frame of ``pose``.

    Joints listed in ``pose.plant`` keep their rest height (the lowest one) and their mean
    horizontal position, so feet stay on the ground.
    """
    V_rest, joints = shape_body(template, shape)
    root = pose.root.copy()
    if pose.plant:
        idx = [NAMES.index(n) for n in pose.plant]
        _, p = forward_kinematics(template.skeleton, pose.local, np.zeros_like(root), rest=joints)
        root[:, 1] = joints[idx, 1].min() - p[:, idx, 1].min(axis=1) + pose.root[:, 1]
        root[:, [0, 2]] = joints[idx][:, [0, 2]].mean(0) - p[:, idx][:, :, [0, 2]].mean(1)
    return pose_body(V_rest, joints, template, pose.local, root)


def checked_sequence(name: str, n_frames: int, rng: np.random.Generator, **options) -> Pose:
    """:func:`~data_synth.motions.motion_sequence` drawn again (at most :data:`constants.POSE_DRAWS`
    times) until every frame passes the skeleton check (:func:`~data_synth.motions.limb_clearance`:
    no arm through the other arm or the head)."""
    for _ in range(C.POSE_DRAWS):
        pose = motion_sequence(name, n_frames, rng, **options)
        if (limb_clearance(pose) >= 0.0).all():
            return pose
    raise RuntimeError(f"no draw of motion {name!r} in {C.POSE_DRAWS} passed the skeleton check")


def _jitter(shape: BodyShape, rng: np.random.Generator) -> BodyShape:
    j = lambda v: float(v * rng.uniform(0.98, 1.02))  # noqa: E731
    return BodyShape(height=j(shape.height), girth=j(shape.girth), arm_length=j(shape.arm_length),
                     leg_length=j(shape.leg_length), shoulder_width=j(shape.shoulder_width),
                     body_type=shape.body_type)


def make_scape(seed: int = 0, resolution: int | None = None,
               n_poses: int = C.SCAPE_N_POSES, diversity: float = 1.0) -> SynthCollection:
    """One body in ``n_poses`` distinct poses (the paper's SCAPE has 71), rest pose first: random
    frames of random motions with every joint moved independently, each passing the skeleton check
    (:func:`~data_synth.motions.random_poses`). ``diversity`` in [0, 2] scales the independent joint
    draws (0: frames of the motions alone; notebook 09's lesson on when RIMD wins turns it)."""
    if not 0.0 <= diversity <= 2.0:
        raise ValueError(f"diversity must lie in [0, 2], got {diversity!r}")
    rng = np.random.default_rng(seed)
    template = body_template(resolution)
    shape = _jitter(BodyShape(), rng)
    pose, sources = random_poses(n_poses - 1, rng, diversity)
    rest = Pose.identity(1)
    pose = Pose(np.concatenate([rest.local, pose.local]), np.concatenate([rest.root, pose.root]),
                plant=pose.plant)
    V = pose_shape(template, shape, pose)
    return SynthCollection(
        vertices=V, faces=template.F.copy(),
        names=[f"pose_{i:03d}" for i in range(n_poses)],
        labels={"source_motion": np.array(["rest"] + sources)},
        description="SCAPE-like: one body in many distinct poses",
        extras={"rest": V[0].copy(), "shape_params": shape.as_dict()},
    )


def make_dyna(seed: int = 0, resolution: int | None = None, shapes=None, motions=None,
              frames_per_motion: int = C.DYNA_FRAMES_PER_MOTION) -> SynthCollection:
    """Several body shapes x several motions (Dyna-like), labelled ``shape``, ``motion``, ``frame``.

    Each (shape, motion) is its own performance: the frames start at a random point of the motion's
    first frame interval and carry a performer's variation (:meth:`~data_synth.motions.Pose.vary`),
    so no two meshes repeat (the rest pose is never a frame).

    ``extras['shape_params']`` maps each shape name to its parameters; ``extras['shape_matrix']``
    is ``(n_shapes, 5) float64`` (height, girth, arm_length, leg_length, shoulder_width) in the
    order of ``extras['shape_names']``, ``extras['body_type']`` gives male/female per shape and
    ``extras['shape_rest']`` is ``(n_shapes, n_vertices, 3) float64``, each shape in the rest pose.
    """
    rng = np.random.default_rng(seed)
    template = body_template(resolution)
    shapes = list(DYNA_SHAPES) if shapes is None else list(shapes)
    motions = list(MOTIONS) if motions is None else list(motions)
    for s in shapes:
        if s not in DYNA_SHAPES:
            raise ValueError(f"unknown body shape {s!r}; shapes are {sorted(DYNA_SHAPES)}")
    chunks, names, lab_shape, lab_motion, lab_frame = [], [], [], [], []
    params, shape_rest = {}, []
    for s in shapes:  # a few shapes x a few motions; each block is vectorised
        shape = _jitter(DYNA_SHAPES[s], rng)
        params[s] = shape.as_dict()
        shape_rest.append(shape_body(template, shape)[0])
        for m in motions:
            pose = checked_sequence(m, frames_per_motion, rng, offset=rng.uniform(), vary=C.DYNA_VARY)
            chunks.append(pose_shape(template, shape, pose))
            for f in range(frames_per_motion):
                names.append(f"{s}_{m}_{f:02d}")
                lab_shape.append(s)
                lab_motion.append(m)
                lab_frame.append(f)
    keys = ("height", "girth", "arm_length", "leg_length", "shoulder_width")
    return SynthCollection(
        vertices=np.concatenate(chunks), faces=template.F.copy(), names=names,
        labels={"shape": np.array(lab_shape), "motion": np.array(lab_motion),
                "frame": np.array(lab_frame, dtype=np.int64)},
        description=f"Dyna-like: {len(shapes)} body shapes x {len(motions)} motions",
        extras={"rest": template.V.copy(), "shape_params": params, "shape_names": shapes,
                "shape_rest": np.stack(shape_rest),
                "shape_param_names": list(keys),
                "shape_matrix": np.array([[params[s][k] for k in keys] for s in shapes]),
                "body_type": [params[s]["body_type"] for s in shapes]},
    )


def make_jumping(seed: int = 0, resolution: int | None = None,
                 n_frames: int = C.JUMPING_N_FRAMES) -> SynthCollection:
    """One body doing :data:`constants.JUMPING_REPS` jumping jacks in ``n_frames`` frames (like
    Vlasic et al.'s 'Jumping'), each jack its own height and width, with a performer's variation
    (:meth:`~data_synth.motions.Pose.vary`)."""
    rng = np.random.default_rng(seed)
    template = body_template(resolution)
    shape = _jitter(BodyShape(height=1.70, girth=0.95), rng)
    pose = checked_sequence("jumping_jacks", n_frames, rng, vary=C.JUMPING_VARY, cycles=C.JUMPING_CYCLES,
                           reps=C.JUMPING_REPS)
    V = pose_shape(template, shape, pose)
    return SynthCollection(
        vertices=V, faces=template.F.copy(), names=[f"frame_{i:03d}" for i in range(n_frames)],
        labels={"frame": np.arange(n_frames, dtype=np.int64)},
        description="Jumping-like: one body doing jumping jacks, 10 frames a jack",
        extras={"rest": shape_body(template, shape)[0], "shape_params": shape.as_dict()},
    )


def poses_dof(n: int, rng: np.random.Generator) -> tuple[Pose, np.ndarray]:
    """``n`` poses of the sixteen named joint angles of :data:`constants.POSES_DOF`, each drawn
    uniformly and independently in its range, redrawn until every pose passes the skeleton check
    (:func:`~data_synth.motions.limb_clearance`; at most ``POSES_MAX_DRAWS`` batches of n, then
    RuntimeError). Returns the poses (feet planted) and their angles
    ``(n, 16) float64`` in the order of ``POSES_DOF``."""
    if n < 1:
        raise ValueError(f"n must be at least 1, got {n}")
    names = list(C.POSES_DOF)
    low, high = np.array([C.POSES_DOF[k] for k in names]).T
    local, angles = [], []
    for _ in range(C.POSES_MAX_DRAWS):
        if sum(len(a) for a in angles) >= n:
            break
        a = rng.uniform(low, high, size=(n, len(names)))
        d = dict(zip(names, a.T))
        pose = Pose.identity(n)
        pose.plant = ("l_foot", "r_foot")
        for s in "lr":
            pose.arm(s, lower=d[f"{s}_arm_lower"], forward=d[f"{s}_arm_forward"], twist=d[f"{s}_arm_twist"],
                     elbow=d[f"{s}_elbow"])
            pose.leg(s, hip=d[f"{s}_hip"], knee=d[f"{s}_knee"])
        pose.trunk(bend=d["trunk_bend"], twist=d["trunk_twist"], head_nod=d["head_nod"], head_turn=d["head_turn"])
        keep = np.flatnonzero(limb_clearance(pose) >= 0.0)
        local.append(pose.local[keep])
        angles.append(a[keep])
    kept = sum(len(a) for a in angles)
    if kept < n:
        raise RuntimeError(f"only {kept} of {C.POSES_MAX_DRAWS * n} poses drawn in POSES_DOF's ranges pass the"
                           f" skeleton check, {n} were asked for: the ranges put limbs through the body")
    local = np.concatenate(local)[:n]
    return Pose(local, np.zeros((n, 3)), plant=("l_foot", "r_foot")), np.concatenate(angles)[:n]


def make_poses(seed: int = 0, resolution: int | None = None, n_poses: int = C.POSES_N) -> SynthCollection:
    """One body in ``n_poses`` (default 1,200) random poses of sixteen named joint angles (four per
    arm, two per leg, four of trunk and head; :data:`constants.POSES_DOF`), each drawn
    independently, so that the collection's degrees of freedom are known: the collection on which
    the course measures where a nonlinear decoder starts to pay (issue 47). The rest pose is not
    among them. ``extras['dof']`` is ``(n_poses, 16) float64``, the angles of each mesh, and
    ``extras['dof_names']`` their names."""
    if isinstance(n_poses, bool) or not isinstance(n_poses, (int, np.integer)) or n_poses < 2:
        raise ValueError(f"n_poses must be an integer >= 2, got {n_poses!r}")
    rng = np.random.default_rng(seed)
    template = body_template(resolution)
    shape = _jitter(BodyShape(), rng)
    pose, angles = poses_dof(int(n_poses), rng)
    V = pose_shape(template, shape, pose)
    return SynthCollection(
        vertices=V, faces=template.F.copy(), names=[f"pose_{i:04d}" for i in range(len(V))], labels={},
        description=f"one body in {len(V)} poses of 16 joint angles drawn independently",
        extras={"rest": shape_body(template, shape)[0], "shape_params": shape.as_dict(), "dof": angles,
                "dof_names": list(C.POSES_DOF)},
    )
