"""Latent-space exploration (paper Sec. 5.5, Fig. 9): grids, humanoid measurements, dimension effects."""

from __future__ import annotations

import numpy as np
import pytest

from meshvae_lib.applications import exploration as ex


def _stick_body():
    """A point-sampled humanoid in A-pose (y up, x left, z forward), 1.75 tall."""
    pts = []
    g = np.linspace(0, 1, 7)
    # legs and feet
    for sx in (-1, 1):
        for t in g:
            for u in g:
                pts.append([sx * (0.06 + 0.08 * u), 0.9 * t, 0.05 * (u - 0.5)])
    # torso
    for t in g:
        for u in g:
            for w in (-0.1, 0.1):
                pts.append([0.3 * (u - 0.5), 0.9 + 0.6 * t, w])
    # head
    for t in g:
        pts.append([0.05 * (t - 0.5), 1.5 + 0.25 * t, 0.0])
    # arms, 45 degrees down, ending at the hands
    for sx in (-1, 1):
        for t in g:
            pts.append([sx * (0.2 + 0.4 * t), 1.45 - 0.4 * t, 0.0])
    return np.array(pts)


def _yaw(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])


def test_sigma_object_and_grid():
    from meshvae_lib.defaults import EXPLORATION_SIGMA_OBJECT
    from meshvae_lib.model.train_config import pad_sigma_object

    np.testing.assert_array_equal(pad_sigma_object(EXPLORATION_SIGMA_OBJECT, 6), [0.1, 0.1, 0.5, 0.5, 1, 1])
    with pytest.raises(ValueError):
        pad_sigma_object(EXPLORATION_SIGMA_OBJECT, 3)
    base = np.arange(5.0)
    Z = ex.latent_grid(base, dims=(2, 3), n=3)
    assert Z.shape == (3, 3, 5)
    np.testing.assert_array_equal(Z[:, :, 2], [[-2] * 3, [0] * 3, [2] * 3])
    np.testing.assert_array_equal(Z[:, :, 3], [[-2, 0, 2]] * 3)
    np.testing.assert_array_equal(Z[:, :, [0, 1, 4]], np.broadcast_to(base[[0, 1, 4]], (3, 3, 3)))
    with pytest.raises(ValueError, match="distinct"):
        ex.latent_grid(base, dims=(1, 1))


def test_regions_on_the_stick_body():
    V = _stick_body()
    r = ex.humanoid_regions(V)
    assert np.all(V[r["left_foot"], 0] > 0) and np.all(V[r["right_foot"], 0] < 0)
    assert np.all(V[r["left_foot"], 1] <= 0.06 * 1.75 + 1e-12)
    assert V[:, 0].argmax() in r["left_hand"] and V[:, 0].argmin() in r["right_hand"]
    assert np.all(np.abs(V[r["torso"], 0]) < 0.175)
    with pytest.raises(ValueError, match="distinct"):
        ex.humanoid_regions(V, up=1, left=1)


def test_measurements_hand_computed():
    V = _stick_body()
    r = ex.humanoid_regions(V)
    m = ex.measure_humanoid(V, r)
    assert m["height"] == pytest.approx(1.75, abs=1e-12)
    assert m["support"] == pytest.approx(0.0, abs=1e-12)
    assert m["facing"] == pytest.approx(0.0, abs=1e-9)
    # turning 30 degrees about the up axis (towards the character's left, +x)
    t = ex.measure_humanoid(V @ _yaw(30).T + [1.0, 2.0, 3.0], r)
    assert t["facing"] == pytest.approx(30.0, abs=1e-9)
    assert t["height"] == pytest.approx(1.75, abs=1e-12)
    # lifting the right foot by 0.1: the left leg supports, support = 0.1 / height
    W = V.copy()
    W[r["right_foot"], 1] += 0.1
    assert ex.measure_humanoid(W, r)["support"] == pytest.approx(0.1 / 1.75, abs=1e-12)
    # raising both hands by 0.2
    W = V.copy()
    hands = np.concatenate([r["left_hand"], r["right_hand"]])
    W[hands, 1] += 0.2
    assert ex.measure_humanoid(W, r)["arm_height"] == pytest.approx(m["arm_height"] + 0.2 / 1.75, abs=1e-12)
    # batches give the same numbers
    B = ex.measure_humanoid(np.stack([V, V @ _yaw(30).T]), r)
    np.testing.assert_allclose(B["facing"], [0.0, 30.0], atol=1e-9)


def test_correlation_against_numpy(rng):
    Z = rng.normal(size=(40, 3))
    M = {"a": Z[:, 0] * 2 + 0.1 * rng.normal(size=40), "b": rng.normal(size=40), "c": np.ones(40)}
    C, names = ex.latent_measurement_correlation(Z, M)
    assert names == ["a", "b", "c"] and C.shape == (3, 3)
    for i in range(3):
        for j, k in enumerate(["a", "b"]):
            assert C[i, j] == pytest.approx(np.corrcoef(Z[:, i], M[k])[0, 1], abs=1e-12)
    np.testing.assert_array_equal(C[:, 2], 0.0)


class _FakeModel:
    """decode: dim 0 stretches the body vertically, dim 1 turns it by 20 degrees per unit."""

    latent_dim = 4

    def __init__(self):
        self.V = _stick_body()

    def decode_latent(self, Z):
        Z = np.atleast_2d(Z)
        out = []
        for z in Z:
            W = self.V * [1.0, 1.0 + 0.1 * z[0], 1.0]
            out.append(W @ _yaw(20 * z[1]).T)
        return np.array(out)


def test_explore_and_dimension_effects_find_the_controls():
    model = _FakeModel()
    grid = ex.explore(model, dims=(0, 1), n=3)
    assert grid.vertices.shape == (3, 3, len(model.V), 3) and grid.latents.shape == (3, 3, 4)
    np.testing.assert_array_equal(grid.values_a, [-2, 0, 2])
    np.testing.assert_allclose(grid.vertices[1, 1], model.V, atol=1e-12)
    r = ex.humanoid_regions(model.V)
    eff = ex.dimension_effects(model, lambda V: ex.measure_humanoid(V, r), dims=(0, 1, 2), n_values=5)
    rows = eff.rows()
    assert rows[0]["controls"] == "height" and rows[0]["correlation"] == pytest.approx(1.0, abs=1e-9)
    assert rows[1]["controls"] == "facing" and rows[1]["correlation"] == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(eff.measurements["facing"][1], 20 * np.linspace(-2, 2, 5), atol=1e-9)
    np.testing.assert_allclose(eff.effect[2], 0.0, atol=1e-9)  # dim 3 does nothing
    assert "| 1 | height |" in eff.to_markdown()
    # for a monotone response the span is the absolute end-to-end change
    for i, name in ((0, "height"), (1, "facing")):
        j = eff.names.index(name)
        assert eff.span[i, j] == pytest.approx(abs(eff.effect[i, j]), rel=1e-12)
    assert np.all(eff.span >= np.abs(eff.effect) - 1e-12)
    np.testing.assert_allclose(eff.span[2], 0.0, atol=1e-9)


class _BendModel(_FakeModel):
    """dim 0 turns the body by 20 |z| degrees: a V-shaped response, zero end-to-end change."""

    def decode_latent(self, Z):
        Z = np.atleast_2d(Z)
        return np.array([self.V @ _yaw(20 * abs(z[0])).T for z in Z])


def test_span_sees_responses_that_peak_inside_the_range():
    model = _BendModel()
    r = ex.humanoid_regions(model.V)
    eff = ex.dimension_effects(model, lambda V: ex.measure_humanoid(V, r), dims=(0,), n_values=5)
    j = eff.names.index("facing")
    facing = eff.measurements["facing"][0]
    np.testing.assert_allclose(facing, 20 * np.abs(np.linspace(-2, 2, 5)), atol=1e-9)
    assert abs(eff.effect[0, j]) < 1e-9  # the ends agree ...
    std = np.std(facing)  # no reference meshes: the sweep's own spread is the unit
    assert eff.span[0, j] == pytest.approx((facing.max() - facing.min()) / std, rel=1e-12)  # ... the span does not
    assert eff.span[0, j] > 2.0


def test_dimension_displacement_hand_computed_and_blind_to_rigid_motion():
    model = _FakeModel()
    d = ex.dimension_displacement(model)
    assert d.shape == (4,)
    y = model.V[:, 1]
    # dim 0 scales y by 0.8 at -2 and 1.2 at +2; the best rigid fit of one onto the other is a pure
    # translation (the centroid), leaving 0.4 |y - mean(y)| per vertex (up to a rotation of ~1e-8 that
    # the body's small y-z covariance allows)
    assert d[0] == pytest.approx(np.mean(0.4 * np.abs(y - y.mean())), rel=1e-6)
    np.testing.assert_allclose(d[1:], 0.0, atol=1e-9)  # a rotation, and two dimensions that do nothing
    R = np.stack([model.V, model.V * [1.0, 1.1, 1.0]])
    spread = np.linalg.norm(R - R.mean(axis=0), axis=-1).mean()
    np.testing.assert_allclose(ex.dimension_displacement(model, dims=(0,), reference_vertices=R), d[0] / spread, rtol=1e-12)
    with pytest.raises(ValueError, match="dims"):
        ex.dimension_displacement(model, dims=(4,))
