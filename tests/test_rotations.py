"""Polar decomposition, SO(3) log and exp."""

import numpy as np
import pytest
from geometry_fixtures import random_rotation

from meshvae_lib.geometry.polar import polar_decomposition, project_to_so3
from meshvae_lib.geometry.rotations import hat, rotation_angle, so3_exp, so3_log, vee


def _rodrigues_reference(axis, angle):
    """Textbook Rodrigues formula, no series, for comparison."""
    K = hat(axis)
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _svd_polar(T):
    U, s, Vt = np.linalg.svd(T)
    d = np.sign(np.linalg.det(U @ Vt))
    U[..., :, 2] *= d[..., None]
    s[..., 2] *= d
    return U @ Vt, (np.swapaxes(Vt, -1, -2) * s[..., None, :]) @ Vt


@pytest.mark.parametrize("angle", [0.0, 1e-8, 1.0, np.pi - 1e-6, np.pi])
def test_log_exp_round_trip(angle):
    rng = np.random.default_rng(3)
    for _ in range(5):
        axis = rng.standard_normal(3)
        axis /= np.linalg.norm(axis)
        w = angle * axis
        R = _rodrigues_reference(axis, angle)
        np.testing.assert_allclose(so3_exp(w), R, atol=4e-16 * 4)
        w_back = so3_log(R)
        if angle < np.pi:
            np.testing.assert_allclose(w_back, w, atol=1e-15 + 2e-16 / max(np.pi - angle, 1e-16) * 2)
        else:  # at pi the sign of the axis is arbitrary
            assert min(np.abs(w_back - w).max(), np.abs(w_back + w).max()) < 1e-14
        np.testing.assert_allclose(so3_exp(w_back), R, atol=1e-14)
        assert abs(rotation_angle(R) - angle) < 1e-14 + 1e-9 * (angle > 3)


def test_log_near_pi_has_axis_sign_of_antisymmetric_part():
    axis = np.array([0.0, 0.6, 0.8])
    w = (np.pi - 1e-3) * axis
    np.testing.assert_allclose(so3_log(so3_exp(w)), w, atol=1e-13)
    np.testing.assert_allclose(so3_log(so3_exp(-w)), -w, atol=1e-13)


def test_log_exp_vectorised_against_loop_and_batch_shapes():
    rng = np.random.default_rng(0)
    w = rng.uniform(-1, 1, (4, 50, 3)) * 1.2
    R = so3_exp(w)
    assert R.shape == (4, 50, 3, 3)
    loop = np.array([[_rodrigues_reference(x / np.linalg.norm(x), np.linalg.norm(x)) for x in row]
                     for row in w])
    np.testing.assert_allclose(R, loop, atol=1e-15 * 10)
    np.testing.assert_allclose(so3_log(R), w, atol=1e-14)
    np.testing.assert_allclose(np.swapaxes(R, -1, -2) @ R, np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-15 * 10)


def test_hat_vee():
    w = np.array([0.3, -1.0, 2.0])
    x = np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(hat(w) @ x, np.cross(w, x))
    np.testing.assert_allclose(vee(hat(w)), w)


def test_polar_matches_svd_and_keeps_rotation():
    rng = np.random.default_rng(1)
    T = np.concatenate([rng.standard_normal((300, 3, 3)),
                        np.eye(3) + 0.2 * rng.standard_normal((300, 3, 3))])
    R, S = polar_decomposition(T)
    R_ref, S_ref = _svd_polar(T)
    np.testing.assert_allclose(R, R_ref, atol=1e-10)
    np.testing.assert_allclose(S, S_ref, atol=1e-10)
    np.testing.assert_allclose(R @ S, T, atol=1e-13)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-13)
    np.testing.assert_array_equal(S, np.swapaxes(S, -1, -2))


def test_polar_of_reflection_keeps_rotation_and_moves_reflection_into_S():
    Rot = random_rotation(2)
    Refl = np.diag([1.0, 1.0, -1.0])
    T = Rot @ np.diag([1.5, 1.2, 0.7]) @ Refl
    R, S = polar_decomposition(T)
    assert abs(np.linalg.det(R) - 1) < 1e-14
    np.testing.assert_allclose(R @ S, T, atol=1e-14)
    np.testing.assert_allclose(S, S.T, atol=0)
    ev = np.linalg.eigvalsh(S)
    np.testing.assert_allclose(sorted(ev, key=abs), [-0.7, 1.2, 1.5], atol=1e-13)


def test_polar_singular_and_rotation_inputs():
    Rot = random_rotation(5)
    R, S = polar_decomposition(Rot)
    np.testing.assert_allclose(R, Rot, atol=1e-15 * 4)
    np.testing.assert_allclose(S, np.eye(3), atol=1e-15 * 4)
    T = np.diag([2.0, 1.0, 0.0]) @ Rot  # rank 2: SVD fallback
    R, S = polar_decomposition(T)
    assert abs(np.linalg.det(R) - 1) < 1e-12
    np.testing.assert_allclose(R @ S, T, atol=1e-12)
    R, S = polar_decomposition(np.zeros((3, 3)))
    assert abs(np.linalg.det(R) - 1) < 1e-12 and np.all(S == 0)


def test_project_to_so3_is_closest_rotation():
    rng = np.random.default_rng(7)
    M = random_rotation(8) + 0.05 * rng.standard_normal((3, 3))
    R = project_to_so3(M)
    best = np.linalg.norm(R - M)
    for k in range(50):
        Q = so3_exp(0.01 * rng.standard_normal(3)) @ R
        assert np.linalg.norm(Q - M) >= best - 1e-15


def test_bad_shapes():
    with pytest.raises(ValueError, match=r"\(\.\.\., 3, 3\)"):
        polar_decomposition(np.zeros((4, 2, 3)))
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        so3_exp(np.zeros((2, 4)))
    with pytest.raises(ValueError, match="NaN"):
        polar_decomposition(np.full((3, 3), np.nan))


def test_quaternion_relative_log_matches_matrix_log():
    from meshvae_lib.geometry.rotations import quat_from_soa, relative_log_quat, to_soa

    rng = np.random.default_rng(4)
    w = rng.standard_normal((500, 3))
    w *= (rng.uniform(0, np.pi, 500) / np.linalg.norm(w, axis=1))[:, None]
    w[:4] = [[0, 0, 0], [1e-9, 0, 0], [0, np.pi - 1e-6, 0], [0, 0, 1.0]]
    Ri, Rj = so3_exp(rng.standard_normal((500, 3))), None
    Rj = Ri @ so3_exp(w)  # so R_i^T R_j = exp(w)
    got = relative_log_quat(quat_from_soa(to_soa(Ri)), quat_from_soa(to_soa(Rj))).T
    np.testing.assert_allclose(got, w, atol=1e-14 * 20)
    np.testing.assert_allclose(got, so3_log(np.swapaxes(Ri, 1, 2) @ Rj), atol=1e-13)
