"""data_synth.motions and capture noise: the performer's variation, the skeleton check and the noise
level, each against a hand-computed expectation."""

from __future__ import annotations

import numpy as np
import pytest

from data_synth import constants as C
from data_synth import make_collection
from data_synth.bodies import checked_sequence
from data_synth.capture_noise import add_capture_noise
from data_synth.motions import Pose, limb_clearance, motion_sequence, smooth_signals
from data_synth.quality import bounding_box_diagonals


def test_smooth_signals_have_unit_rms_over_a_pass_and_are_periodic():
    rng = np.random.default_rng(0)
    phase = np.arange(4000) / 4000
    S = smooth_signals(phase, rng, 6, 10)
    # the RMS over a whole pass of a Fourier series is sqrt(sum a_k^2 / 2): exactly 1 after scaling
    np.testing.assert_allclose(np.sqrt((S**2).mean(axis=0)), 1.0, rtol=1e-9)
    np.testing.assert_allclose(smooth_signals(np.array([0.0, 1.0]), np.random.default_rng(1), 3, 4)[0],
                               smooth_signals(np.array([0.0, 1.0]), np.random.default_rng(1), 3, 4)[1], atol=1e-12)
    # no content above `cycles` per pass: the 11th harmonic and above carry nothing
    spectrum = np.abs(np.fft.rfft(S, axis=0))
    assert spectrum[11:].max() < 1e-9 * spectrum.max()


def test_vary_moves_arms_only_away_from_the_body():
    """The upper arm's variation about z (towards or away from the torso) is one-sided: every frame of
    a varied rest pose has the arms at least as far out as the rest pose has them."""
    rng = np.random.default_rng(3)
    pose = Pose.identity(200)
    pose.vary(rng.normal(size=(200, 3 * len(pose.local[0]))), 1.0)
    from data_synth.humanoid import NAMES, body_skeleton
    from data_synth.skeleton import forward_kinematics

    _, p = forward_kinematics(body_skeleton(), pose.local, pose.root)
    _, p0 = forward_kinematics(body_skeleton(), Pose.identity(1).local, np.zeros((1, 3)))
    for side, sgn in (("l", 1.0), ("r", -1.0)):
        up, fore = NAMES.index(f"{side}_upperarm"), NAMES.index(f"{side}_forearm")
        spread = lambda q: sgn * (q[:, fore, 0] - q[:, up, 0])  # noqa: E731  elbow's distance out from the shoulder
        assert (spread(p) >= spread(p0) - 1e-3).mean() > 0.8  # the other axes move it a little either way
        assert spread(p).mean() > spread(p0)[0]


def test_limb_clearance_by_hand():
    """Rest pose: the arms are ~0.6 m apart, far from the head (margin > 0). Both forearms folded across
    the chest: the hands meet (the arm-arm margin is negative). An arm raised straight through the
    head's side: negative too."""
    rest = Pose.identity(1)
    assert limb_clearance(rest)[0] > 0.2
    crossed = Pose.identity(1)
    for side in "lr":
        crossed.arm(side, forward=1.4, twist=1.0, elbow=2.3)  # forearms turned in, across the chest
    assert limb_clearance(crossed)[0] < 0
    through_head = Pose.identity(1).arm("l", lower=-2.9, shrug=0.6)
    assert limb_clearance(through_head)[0] < 0


def test_checked_sequences_pass_the_skeleton_check_and_bad_offsets_raise():
    rng = np.random.default_rng(0)
    pose = checked_sequence("jumping_jacks", 60, rng, vary=1.0, reps=6)
    assert (limb_clearance(pose) >= 0).all()
    with pytest.raises(ValueError, match="offset must lie in \\[0, 1\\), got 1.0"):
        motion_sequence("walk", 6, rng, offset=1.0)


def test_capture_noise_level_and_independence():
    """Per-coordinate standard deviation = level x diagonal, so the mean vertex displacement is
    sqrt(8/pi) x that (the mean of a 3D Gaussian's norm); the exact meshes under it are kept."""
    rng = np.random.default_rng(0)
    V = rng.normal(size=(3, 5000, 3))
    noisy = add_capture_noise(V, 1e-3, np.random.default_rng(1))
    d = np.linalg.norm(noisy - V, axis=2).mean(axis=1) / bounding_box_diagonals(V)
    np.testing.assert_allclose(d, np.sqrt(8 / np.pi) * 1e-3, rtol=0.02)
    np.testing.assert_array_equal(add_capture_noise(V, 0.0, rng), V)
    col = make_collection("bar", noise=1e-3)
    np.testing.assert_array_equal(col.extras["exact"], make_collection("bar").vertices)
    assert col.extras["noise"] == 1e-3 and make_collection("bar").extras["noise"] == 0.0
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="noise must be a finite number >= 0"):
            make_collection("bar", noise=bad)
    with pytest.raises(ValueError, match="level must be a finite number >= 0, got -0.5"):
        add_capture_noise(V, -0.5, rng)
