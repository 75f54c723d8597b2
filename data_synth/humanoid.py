"""The procedural humanoid: skeleton, implicit body, template mesh, body shapes and posing.

The template is built once per resolution (and cached): a smooth union of ellipsoids and tapered
capsules laid along the skeleton of an average body (1.75 m, A-pose with the arms 45 degrees
below horizontal), polygonised and relaxed (:mod:`data_synth.meshing`). Every body shape of a
collection moves the *same* template vertices, so all meshes share one connectivity:

1. smooth offsets along the rest normals (belly for a heavier body, breasts for the female body
   type), then
2. a linear blend of one affine map per bone that scales the bone's length (height, arm and
   leg proportions) and its girth (width and depth), each map fixing the bone's head joint so
   neighbouring bones agree at the joints.

Poses are then applied with dual-quaternion skinning on the shaped rest mesh and the shaped
skeleton (:func:`pose_body`).

Coordinates: metres, y up, z forward (the face looks along +z), x the character's left.
"""

from __future__ import annotations

import functools
from dataclasses import asdict, dataclass

import numpy as np

from data_synth import constants as C
from data_synth.collection import resolve_resolution
from data_synth.meshing import Capsule, Ellipsoid, ImplicitModel, polygonize, vertex_normals
from data_synth.skeleton import Skeleton, forward_kinematics
from data_synth.skinning import dual_quaternion_blend, linear_blend, skinning_weights

__all__ = [
    "JOINTS",
    "BodyShape",
    "BodyTemplate",
    "body_skeleton",
    "body_template",
    "shape_body",
    "pose_body",
    "clear_template_cache",
]

#: joint names and parents (the bone of a joint runs from it to its ``BONE_END``).
JOINTS = (
    ("pelvis", None), ("spine", "pelvis"), ("chest", "spine"), ("neck", "chest"),
    ("head", "neck"),
    ("l_clavicle", "chest"), ("l_upperarm", "l_clavicle"), ("l_forearm", "l_upperarm"),
    ("l_hand", "l_forearm"),
    ("r_clavicle", "chest"), ("r_upperarm", "r_clavicle"), ("r_forearm", "r_upperarm"),
    ("r_hand", "r_forearm"),
    ("l_thigh", "pelvis"), ("l_shin", "l_thigh"), ("l_foot", "l_shin"),
    ("r_thigh", "pelvis"), ("r_shin", "r_thigh"), ("r_foot", "r_shin"),
)
NAMES = tuple(name for name, _ in JOINTS)


def _arm_direction(side: float) -> np.ndarray:
    a = np.deg2rad(C.ARM_REST_ANGLE_DEG)
    return np.array([side * np.cos(a), -np.sin(a), 0.0])


def _base_points() -> dict:
    """Rest positions (metres) of the joints and bone ends of the average body."""
    pts = {
        "pelvis": (0.0, 0.96, -0.01), "spine": (0.0, 1.08, -0.01), "chest": (0.0, 1.24, -0.015),
        "neck": (0.0, 1.47, -0.02), "head": (0.0, 1.57, -0.01), "head_end": (0.0, 1.75, 0.0),
    }
    for s, side in (("l", 1.0), ("r", -1.0)):
        d = _arm_direction(side)
        shoulder = np.array([side * 0.175, 1.415, -0.02])
        pts[f"{s}_clavicle"] = (side * 0.03, 1.42, -0.02)
        pts[f"{s}_upperarm"] = tuple(shoulder)
        pts[f"{s}_forearm"] = tuple(shoulder + 0.285 * d)
        pts[f"{s}_hand"] = tuple(shoulder + 0.535 * d)
        pts[f"{s}_hand_end"] = tuple(shoulder + 0.72 * d)
        pts[f"{s}_thigh"] = (side * 0.1, 0.91, -0.01)
        pts[f"{s}_shin"] = (side * 0.105, 0.50, 0.0)
        pts[f"{s}_foot"] = (side * 0.115, 0.085, -0.025)
        pts[f"{s}_foot_end"] = (side * 0.125, 0.03, 0.16)
    return {k: np.asarray(v, dtype=np.float64) for k, v in pts.items()}


#: where each joint's bone ends (a child joint or an end point).
BONE_END = {
    "pelvis": "spine", "spine": "chest", "chest": "neck", "neck": "head", "head": "head_end",
    **{f"{s}_{a}": f"{s}_{b}" for s in "lr" for a, b in (
        ("clavicle", "upperarm"), ("upperarm", "forearm"), ("forearm", "hand"),
        ("hand", "hand_end"), ("thigh", "shin"), ("shin", "foot"), ("foot", "foot_end"))},
}


def body_skeleton() -> Skeleton:
    """The average body's skeleton (19 joints, :data:`JOINTS`)."""
    pts = _base_points()
    parents = np.array([-1 if p is None else NAMES.index(p) for _, p in JOINTS], dtype=np.int64)
    return Skeleton(NAMES, parents, np.array([pts[n] for n in NAMES]))


def _body_model() -> ImplicitModel:
    """Implicit surface of the average body; each primitive is tied to a joint index."""
    P = _base_points()
    j = NAMES.index
    prims = [
        Ellipsoid((0.0, 0.935, -0.01), (0.165, 0.13, 0.115), j("pelvis")),
        Ellipsoid((0.0, 1.10, 0.0), (0.14, 0.13, 0.10), j("spine")),
        Ellipsoid((0.0, 1.30, -0.01), (0.165, 0.16, 0.11), j("chest")),
        # fillers between the torso ellipsoids keep the flanks smooth (no rings at the waist)
        Ellipsoid((0.0, 1.02, -0.005), (0.152, 0.10, 0.105), j("pelvis")),
        Ellipsoid((0.0, 1.19, -0.005), (0.148, 0.12, 0.102), j("spine")),
        Capsule((0.0, 1.44, -0.025), (0.0, 1.60, -0.01), 0.052, 0.048, j("neck")),
        Ellipsoid((0.0, 1.665, 0.005), (0.078, 0.105, 0.095), j("head")),
        Ellipsoid((0.0, 1.605, 0.035), (0.058, 0.06, 0.068), j("head")),
        Ellipsoid((0.0, 1.655, 0.098), (0.014, 0.024, 0.02), j("head")),
    ]
    for s, side in (("l", 1.0), ("r", -1.0)):
        d = _arm_direction(side)
        perp = np.array([-d[1], d[0], 0.0]) * side  # in the body plane, across the arm
        prims += [
            Capsule(tuple(P[f"{s}_clavicle"] + [0, 0.0, -0.005]),
                    tuple(P[f"{s}_upperarm"] + [-side * 0.01, 0.005, 0]), 0.062, 0.055,
                    j(f"{s}_clavicle")),
            Capsule(tuple(P[f"{s}_upperarm"]), tuple(P[f"{s}_forearm"]), 0.052, 0.04,
                    j(f"{s}_upperarm")),
            Capsule(tuple(P[f"{s}_forearm"]), tuple(P[f"{s}_hand"]), 0.038, 0.027,
                    j(f"{s}_forearm")),
            Ellipsoid(tuple(P[f"{s}_hand"] + 0.085 * d), (0.085, 0.028, 0.046), j(f"{s}_hand"),
                      axes=(tuple(d), tuple(perp), (0.0, 0.0, 1.0))),
            Ellipsoid((side * 0.075, 0.90, -0.055), (0.085, 0.09, 0.07), j("pelvis")),
            Capsule(tuple(P[f"{s}_thigh"]), tuple(P[f"{s}_shin"]), 0.076, 0.052,
                    j(f"{s}_thigh")),
            Capsule(tuple(P[f"{s}_shin"]), tuple(P[f"{s}_foot"] + [0, 0.02, 0]), 0.05, 0.032,
                    j(f"{s}_shin")),
            Ellipsoid(tuple(P[f"{s}_shin"] + [0, -0.14, -0.025]), (0.046, 0.11, 0.048),
                      j(f"{s}_shin")),
            Capsule(tuple(P[f"{s}_foot"] + [0, -0.035, -0.04]),
                    tuple(P[f"{s}_foot_end"] + [0, 0.0, -0.02]), 0.036, 0.028,
                    j(f"{s}_foot")),
        ]
    return ImplicitModel(prims, blend=C.BODY_BLEND_RADIUS)


@dataclass(frozen=True)
class BodyShape:
    """Body-shape parameters.

    height : stature in metres (1.75 average), feet to the top of the head in the rest pose.
    girth : BMI-like bulk factor, 1.0 average (0.85 slim, 1.3 heavy); body mass index is
        roughly ``22 * girth**2``.
    arm_length, leg_length, shoulder_width : proportions, 1.0 average.
    body_type : "male" or "female" (female: wider hips, narrower waist and shoulders, breasts).
    """

    height: float = 1.75
    girth: float = 1.0
    arm_length: float = 1.0
    leg_length: float = 1.0
    shoulder_width: float = 1.0
    body_type: str = "male"

    def __post_init__(self):
        if self.body_type not in ("male", "female"):
            raise ValueError(f"body_type must be 'male' or 'female', got {self.body_type!r}")
        for name in ("height", "girth", "arm_length", "leg_length", "shoulder_width"):
            value = getattr(self, name)
            low, high = (1.2, 2.2) if name == "height" else (0.6, 1.6)
            if not low <= value <= high:
                raise ValueError(f"{name} must lie in [{low}, {high}], got {value}")

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class BodyTemplate:
    """The average body's template mesh with its skeleton and skinning weights.

    V : (n_vertices, 3) float64, rest pose; F : (n_faces, 3) int64;
    W : (n_vertices, n_joints) float64; parts : (n_vertices,) int64; skeleton : Skeleton.
    """

    V: np.ndarray
    F: np.ndarray
    W: np.ndarray
    parts: np.ndarray
    skeleton: Skeleton


@functools.lru_cache(maxsize=4)
def _cached_template(resolution: int) -> BodyTemplate:
    model = _body_model()
    V, F = polygonize(model, resolution, area_estimate=1.85)
    parts = model.part_of(V)
    skeleton = body_skeleton()
    # left bones act on the left, right bones on the right. Leg bones fade out across the
    # midline (half at x = 0, so the crotch follows both thighs equally); arm bones (clavicles
    # and below) fade to zero at the midline, so two shrugging clavicles never pull the same
    # skin at the back of the neck in opposite directions.
    side = np.array([1.0 if n.startswith("l_") else -1.0 if n.startswith("r_") else 0.0
                     for n in NAMES])
    leg = np.array([n[2:] in ("thigh", "shin", "foot") for n in NAMES])
    u = V[:, :1] * side[None] / C.SKIN_MIDLINE_WIDTH
    x = np.clip(np.where(leg[None], 0.5 + 0.5 * u, u), 0.0, 1.0)
    mask = np.where(side[None] == 0.0, 1.0, x * x * (3.0 - 2.0 * x))
    W = skinning_weights(V, F, parts, skeleton, C.SKIN_BLEND_WIDTH, relatives_depth=None,
                         mask=mask)
    for a in (V, F, W, parts):
        a.setflags(write=False)
    return BodyTemplate(V, F, W, parts, skeleton)


def body_template(resolution: int | None = None) -> BodyTemplate:
    """Template of the average body with about ``resolution`` vertices (cached, read-only)."""
    resolution = resolve_resolution(resolution, C.HUMANOID_DEFAULT_RESOLUTION)
    return _cached_template(resolution)


def _bump(V, center, sigma):
    d2 = np.sum(((V - np.asarray(center)) / np.asarray(sigma)) ** 2, axis=1)
    return np.exp(-0.5 * d2)


def shape_body(template: BodyTemplate, shape: BodyShape) -> tuple[np.ndarray, np.ndarray]:
    """Rest mesh and rest skeleton of one body shape, same connectivity as the template.

    Returns
    -------
    V : (n_vertices, 3) float64, shaped rest pose (feet on y = 0, head top at y = height).
    joints : (n_joints, 3) float64, shaped rest joint positions.
    """
    V0, F, W = template.V, template.F, template.W
    g = shape.girth
    female = shape.body_type == "female"
    # 1. offsets along the normals
    normals = vertex_normals(V0, F)
    front = np.clip(normals[:, 2], 0.0, None)
    offset = 0.07 * (g - 1.0) * _bump(V0, (0.0, 1.06, 0.08), (0.12, 0.12, 0.1)) * front
    offset += 0.03 * (g - 1.0) * _bump(V0, (0.0, 0.92, -0.1), (0.12, 0.08, 0.08))
    if female:
        for side in (1.0, -1.0):
            offset += 0.032 * g * _bump(V0, (side * 0.085, 1.29, 0.09), (0.05, 0.045, 0.05)) * front
    V1 = V0 + offset[:, None] * normals
    # 2. per-bone affine maps
    pts = _base_points()
    scale = shape.height / 1.75
    seg = {name: 1.0 for name in list(BONE_END) + list(BONE_END.values())}
    for s in "lr":
        for n in ("forearm", "hand", "hand_end"):
            seg[f"{s}_{n}"] = shape.arm_length
        # shoulders and hips move out with the torso's girth, so arms and legs stay clear of it
        seg[f"{s}_upperarm"] = shape.shoulder_width * (0.92 if female else 1.0) * g**0.7
        for n in ("shin", "foot"):
            seg[f"{s}_{n}"] = shape.leg_length
        seg[f"{s}_thigh"] = (1.12 if female else 1.0) * g**0.5  # hip joints further apart
    new = {"pelvis": pts["pelvis"] * scale}
    parent_of = dict(JOINTS)
    parent_of.update({v: k for k, v in BONE_END.items() if v.endswith("_end")})
    order = [n for n, _ in JOINTS] + [v for v in BONE_END.values() if v.endswith("_end")]
    for name in order[1:]:
        p = parent_of[name]
        new[name] = new[p] + scale * seg[name] * (pts[name] - pts[p])
    width_torso = {"pelvis": 1.1 if female else 1.0, "spine": 0.9 if female else 1.0,
                   "chest": 0.93 if female else 1.0}
    J = len(NAMES)
    M = np.zeros((J, 3, 3))
    b = np.zeros((J, 3))
    for j, name in enumerate(NAMES):  # about 20 bones
        head, tail = pts[name], pts[BONE_END[name]]
        d = (tail - head) / np.linalg.norm(tail - head)
        s_len = np.linalg.norm(new[BONE_END[name]] - new[name]) / np.linalg.norm(tail - head)
        part = name[2:] if name[1] == "_" else name
        if part in ("pelvis", "spine", "chest"):
            G = np.diag([width_torso[part] * g, 1.0, g * (1.05 if part == "spine" else 1.0)])
        elif part in ("upperarm", "thigh"):
            G = np.eye(3) * g**0.8 * (0.94 if female and part == "upperarm" else 1.0)
        elif part in ("forearm", "shin", "neck", "clavicle"):
            G = np.eye(3) * g**0.5
        else:
            G = np.eye(3)
        P = np.eye(3) - np.outer(d, d)
        M[j] = s_len * np.outer(d, d) + scale * P @ G @ P
        b[j] = new[name] - M[j] @ head
    V2 = linear_blend(V1, W, M, b)
    joints = np.array([new[n] for n in NAMES])
    # feet on y = 0, and a uniform scale so the stature is exactly ``shape.height``
    floor = np.array([0.0, V2[:, 1].min(), 0.0])
    k = shape.height / np.ptp(V2[:, 1])
    return (V2 - floor) * k, (joints - floor) * k


def pose_body(V_rest: np.ndarray, joints_rest: np.ndarray, template: BodyTemplate,
              local: np.ndarray, root_translation: np.ndarray) -> np.ndarray:
    """Pose a shaped body with dual-quaternion skinning.

    Parameters
    ----------
    V_rest : (n_vertices, 3) float64 and joints_rest : (n_joints, 3) float64, from
        :func:`shape_body`.
    local : (n_frames, n_joints, 3, 3) float64, local joint rotations (see
        :mod:`data_synth.skeleton`).
    root_translation : (n_frames, 3) float64

    Returns
    -------
    (n_frames, n_vertices, 3) float64
    """
    R, p = forward_kinematics(template.skeleton, local, root_translation, rest=joints_rest)
    t = p - np.einsum("njab,jb->nja", R, joints_rest)
    return dual_quaternion_blend(V_rest, template.W, R, t, parents=template.skeleton.parents)


def clear_template_cache() -> None:
    """Forget the templates built so far, so that the next collection builds them again."""
    _cached_template.cache_clear()
