"""The registry: every collection builds, is deterministic for a seed, differs across seeds,
and its names and labels are complete and consistent with the named groups."""

from __future__ import annotations

import numpy as np
import pytest

import data_synth
from data_synth import constants as C
from data_synth import COLLECTIONS, list_collections, make_collection
from data_synth.bar import BAR_MOTIONS
from data_synth.bodies import DYNA_SHAPES
from data_synth.face import EXPRESSIONS
from data_synth.hand import GESTURES
from data_synth.motions import MOTIONS
from test_synth_geometry import built  # pytest puts tests/ on sys.path

NAMES = [n for n, _ in list_collections()]
#: small templates keep these tests fast; geometry tests use the default sizes
SMALL = 600


def test_public_names():
    assert data_synth.make_collection is make_collection
    assert set(NAMES) >= {"scape", "dyna", "jumping", "flag", "bar", "hand", "face"}
    assert all(isinstance(d, str) and d for _, d in list_collections())
    assert list(COLLECTIONS) == NAMES


@pytest.mark.parametrize("name", NAMES)
def test_deterministic_for_a_seed_and_different_across_seeds(name):
    a = make_collection(name, seed=3, resolution=SMALL)
    b = make_collection(name, seed=3, resolution=SMALL)
    c = make_collection(name, seed=4, resolution=SMALL)
    np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.faces, b.faces)
    assert a.names == b.names
    for key in a.labels:
        np.testing.assert_array_equal(a.labels[key], b.labels[key])
    assert a.vertices.shape == c.vertices.shape
    np.testing.assert_array_equal(a.faces, c.faces)  # seeds change motion, not connectivity
    diff = np.abs(a.vertices - c.vertices).max()
    size = np.ptp(a.vertices[0], axis=0).max()
    assert diff > 0.01 * size, f"{name}: seeds 3 and 4 differ by only {diff:.2e}"


@pytest.mark.parametrize("name", NAMES)
def test_default_sizes_and_types(name):
    col = built(name)  # the default collection, shared with the geometry tests
    N, V, _ = col.vertices.shape
    assert 500 <= V <= 3000, f"{name}: {V} vertices"
    assert 20 <= N <= (C.POSES_N if name == "poses" else 250), f"{name}: {N} meshes"
    assert col.vertices.dtype == np.float64 and col.faces.dtype == np.int64
    assert len(col.names) == N and len(set(col.names)) == N
    assert col.description
    for key, value in col.labels.items():
        assert value.shape == (N,), key
        assert value.dtype.kind in "iU", f"{name}.{key}: dtype {value.dtype}"
    assert col.extras["rest"].shape == (V, 3)


def test_resolution_controls_vertex_count():
    for name, target in (("flag", 2000), ("bar", 2000), ("face", 1000)):
        V = make_collection(name, resolution=target).vertices.shape[1]
        assert abs(V - target) < 0.1 * target, f"{name}: asked {target}, got {V}"


def test_body_scan_resolution_works():
    col = make_collection("jumping", resolution=7000)
    assert abs(col.vertices.shape[1] - 7000) < 700
    assert np.isfinite(col.vertices).all()


def test_dyna_labels_form_a_full_grid():
    col = make_collection("dyna", resolution=SMALL)
    shapes, motions, frames = col.labels["shape"], col.labels["motion"], col.labels["frame"]
    assert set(shapes) == set(DYNA_SHAPES) and len(DYNA_SHAPES) >= 4
    assert set(motions) == set(MOTIONS) and len(MOTIONS) >= 4
    assert {"walk", "run", "jumping_jacks", "punch", "squat", "wave", "turn"} <= set(MOTIONS)
    n_frames = frames.max() + 1
    assert len(col.names) == len(DYNA_SHAPES) * len(MOTIONS) * n_frames
    keys = set(zip(shapes, motions, frames.tolist()))
    assert len(keys) == len(col.names)  # every (shape, motion, frame) exactly once
    for name, s, m, f in zip(col.names, shapes, motions, frames):
        assert name == f"{s}_{m}_{f:02d}"
    # shape numbers in extras, one row per shape, consistent with the per-shape dicts
    M = col.extras["shape_matrix"]
    assert M.shape == (len(DYNA_SHAPES), len(col.extras["shape_param_names"]))
    for row, s in zip(M, col.extras["shape_names"]):
        p = col.extras["shape_params"][s]
        np.testing.assert_allclose(row, [p[k] for k in col.extras["shape_param_names"]])
    assert set(col.extras["body_type"]) == {"male", "female"}
    # body shapes really differ: the rest bodies' statures are the height parameter, and the
    # heavier bodies are wider at the waist
    rest = col.extras["shape_rest"]
    np.testing.assert_allclose(np.ptp(rest[:, :, 1], axis=1), M[:, 0], rtol=1e-9)
    # the belly: a band at 60% of the stature, near the midline (the hands are further out)
    belly = (np.abs(rest[:, :, 1] / M[:, :1] - 0.6) < 0.03) & (np.abs(rest[:, :, 0]) < 0.1)
    depths = np.array([np.ptp(r[b, 2]) / h for r, b, h in zip(rest, belly, M[:, 0])])
    girth = M[:, 1]
    assert np.corrcoef(girth, depths)[0, 1] > 0.8, (girth, depths)
    # meshes of one shape and one motion change from frame to frame
    block = col.vertices[(shapes == "male_average") & (motions == "walk")]
    assert np.abs(np.diff(block, axis=0)).max() > 0.02


@pytest.mark.parametrize("name,column,groups", [
    ("hand", "gesture", set(GESTURES)),
    ("face", "expression", set(EXPRESSIONS)),
    ("bar", "motion", set(BAR_MOTIONS)),
])
def test_group_labels_are_complete(name, column, groups):
    col = make_collection(name, resolution=SMALL)
    assert set(col.labels[column]) == groups
    counts = {g: int(np.sum(col.labels[column] == g)) for g in groups}
    assert len(set(counts.values())) == 1, counts  # the same number of meshes per group
    index = "frame" if "frame" in col.labels else "variant"
    for n, g, f in zip(col.names, col.labels[column], col.labels[index]):
        assert n == f"{g}_{f:02d}"


def test_face_intensity_scales_the_expression(monkeypatch):
    """Every mesh moves (no neutral copies); with the jitter, the speech and mood motions, the
    asymmetry and the head's turn switched off, an expression without rotations (no jaw, no lip roll)
    is its blendshape field times the intensity label, exactly."""
    col = make_collection("face", resolution=SMALL)
    disp = np.linalg.norm(col.vertices - col.extras["rest"], axis=-1).max(axis=1)
    assert disp.min() > 0.0015 and disp.max() > 0.003
    from data_synth import constants as C

    for knob in ("FACE_WEIGHT_JITTER", "FACE_SPEECH_JAW", "FACE_SPEECH_WEIGHT", "FACE_ASYMMETRY", "FACE_JAW_SIDE"):
        monkeypatch.setattr(C, knob, 0.0)
    monkeypatch.setattr(C, "FACE_HEAD_TURN", (0.0, 0.0, 0.0, 0.0))
    col = make_collection("face", resolution=SMALL)
    move = col.vertices - col.extras["rest"]
    for e in ("smile", "puff"):
        k = np.flatnonzero(col.labels["expression"] == e)
        ratio = move[k] / np.maximum(col.labels["intensity_pct"][k], 1)[:, None, None]
        # equal up to the label's rounding to a whole percent (0.5 / 60 of the field each, so 2% between two)
        np.testing.assert_allclose(ratio, np.broadcast_to(ratio[:1], ratio.shape), atol=0.02 * np.abs(ratio).max())
        assert np.abs(move[k]).max() > 1e-3, e


def test_face_head_turns_on_a_fixed_neck():
    """The head turns by its yaw label (measured by a rigid fit of the cranium to the neutral head,
    to a degree after rounding and the other small motions) while the bottom of the neck stays put;
    the yaws span both sides."""
    from meshvae_lib.geometry.alignment import rigid_transform

    col = make_collection("face", resolution=SMALL)
    rest = col.extras["rest"]
    crown = rest[:, 1] > 0.06  # the top of the skull: no expression moves it
    neck = rest[:, 1] + 0.5 * rest[:, 2] < -0.2
    assert crown.sum() > 10 and neck.sum() > 10
    yaw = col.labels["head_yaw_deg"]
    assert yaw.min() < -20 and yaw.max() > 20
    for V, label in zip(col.vertices, yaw):
        R, _ = rigid_transform(rest[crown], V[crown])
        measured = np.degrees(np.arctan2(R[0, 2], R[2, 2]))
        assert abs(measured - label) < 3.0, (measured, label)
        assert np.abs(V[neck] - rest[neck]).max() < 1e-3


def test_sequences_are_sampled_sparsely_but_continuously():
    """The jumping sequence and the flag are captured at a few frames per second (about 8: at 30
    any smooth sequence is linear data, issue 24): consecutive frames still move less than the whole
    motion spans, and nearer frames are nearer each other than frames far apart."""
    for name, far in (("jumping", 5), ("flag", 20)):  # jumping: half a jack apart (10 frames a jack)
        V = make_collection(name, resolution=SMALL).vertices
        gap = lambda lag: np.linalg.norm(V[lag:] - V[:-lag], axis=-1).mean()  # noqa: E731
        span = np.linalg.norm(V - V.mean(axis=0), axis=-1).mean()
        assert gap(1) < 0.7 * gap(far), (name, gap(1), gap(far))
        assert gap(1) < 1.5 * span, (name, gap(1), span)


def test_scape_poses_are_distinct():
    col = make_collection("scape", resolution=SMALL)
    X = col.vertices.reshape(len(col.vertices), -1)
    X = X - X.mean(axis=1, keepdims=True)
    d = np.sqrt(((X[:, None] - X[None]) ** 2).mean(-1))
    np.fill_diagonal(d, np.inf)
    assert d.min() > 0.01  # every pair of poses differs by more than 1 cm RMS
    assert col.labels["source_motion"][0] == "rest"


def test_jumping_is_jumping_jacks():
    """Arms go from below the shoulders to above the head and the feet leave the ground."""
    col = make_collection("jumping", resolution=SMALL)
    V = col.vertices
    top = V[:, :, 1].max(axis=1)
    head_top = V[0, :, 1].max()
    assert (top > head_top + 0.1).any()  # hands above the head in some frames
    assert np.isclose(top[0], head_top, atol=0.02) or top[0] < head_top + 0.02
    low = V[:, :, 1].min(axis=1)
    assert low.max() - low.min() > 0.05  # it jumps


@pytest.mark.parametrize("bad", [
    dict(name="nope"), dict(name="scape", seed=-1), dict(name="scape", resolution=10),
    dict(name="flag", resolution=10**7), dict(name="bar", resolution=2.5),
])
def test_bad_input_raises_value_error_showing_the_value(bad):
    name = bad.pop("name")
    with pytest.raises(ValueError) as exc:
        make_collection(name, **bad)
    shown = str(list(bad.values())[0]) if bad else name
    assert shown in str(exc.value)


def test_poses_have_sixteen_known_angles_within_their_ranges():
    col = built("poses")
    assert len(col) == C.POSES_N >= 1000
    dof = col.extras["dof"]
    assert dof.shape == (len(col), 16) and col.extras["dof_names"] == list(C.POSES_DOF)
    low, high = np.array(list(C.POSES_DOF.values())).T
    assert (dof >= low).all() and (dof <= high).all()
    # every angle is drawn over its whole range, independently of the others
    assert (dof.min(0) < low + 0.05 * (high - low)).all() and (dof.max(0) > high - 0.05 * (high - low)).all()
    assert np.abs(np.corrcoef(dof.T) - np.eye(16)).max() < 0.15


def test_poses_are_rebuilt_from_their_angles():
    from data_synth.bodies import poses_dof

    rng = np.random.default_rng(0)
    pose, angles = poses_dof(40, rng)
    assert angles.shape == (40, 16) and pose.local.shape[0] == 40
    straight = np.flatnonzero(angles[:, list(C.POSES_DOF).index("l_elbow")] < 0.1)
    bent = np.flatnonzero(angles[:, list(C.POSES_DOF).index("l_elbow")] > 1.2)
    from data_synth.humanoid import NAMES

    j = NAMES.index("l_forearm")
    turn = np.degrees(np.arccos(np.clip((np.trace(pose.local[:, j], axis1=1, axis2=2) - 1) / 2, -1, 1)))
    assert turn[straight].max() < turn[bent].min()
    with pytest.raises(ValueError, match="n must be at least 1, got 0"):
        poses_dof(0, rng)
    with pytest.raises(ValueError, match="n_poses must be an integer >= 2, got 1"):
        COLLECTIONS["poses"].build(seed=0, n_poses=1)


def test_poses_whose_ranges_reject_every_pose_fail_after_a_bounded_number_of_draws(monkeypatch):
    """Ranges that put every arm through the body would make the redraw loop endless: after
    POSES_MAX_DRAWS batches it raises, saying how many poses passed."""
    import data_synth.bodies as bodies

    monkeypatch.setattr(bodies, "limb_clearance", lambda pose: np.full(len(pose.local), -1.0))
    with pytest.raises(RuntimeError, match=rf"only 0 of {C.POSES_MAX_DRAWS * 7} poses .* 7 were asked for"):
        bodies.poses_dof(7, np.random.default_rng(0))
