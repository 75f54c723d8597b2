"""Interpolation paths and implausibility measures (paper Sec. 5.3, Fig. 6); the self-intersection
count itself is tested in test_intersections.py."""

from __future__ import annotations

import numpy as np
import pytest
from geometry_fixtures import grid

from meshvae_lib.applications import interpolation as itp
from meshvae_lib.geometry.topology import edges


# ---------------------------------------------------------------------------------------------
# paths
# ---------------------------------------------------------------------------------------------


def test_linear_steps_ends_and_midpoint(rng):
    a, b = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    P = itp.linear_steps(a, b, 5)
    assert P.shape == (5, 4, 3) and P.dtype == np.float64
    np.testing.assert_allclose(P[0], a, atol=0)
    np.testing.assert_allclose(P[-1], b, atol=1e-15)
    np.testing.assert_allclose(P[2], 0.5 * (a + b), atol=1e-15)
    with pytest.raises(ValueError, match="n_steps"):
        itp.linear_steps(a, b, 1)
    with pytest.raises(ValueError, match=r"\(4, 3\) and \(3,\)"):
        itp.linear_steps(a, b[0], 3)


def test_coordinates_aligns_b_first(rng):
    V = rng.normal(size=(20, 3))
    R = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])  # 90 degrees about z
    seq = itp.interpolate_coordinates(V, V @ R.T + 3.0, 4)
    # B is a rigid copy of A: after alignment every step is A (no shrinking through the middle)
    np.testing.assert_allclose(seq, np.broadcast_to(V, seq.shape), atol=1e-10)
    raw = itp.interpolate_coordinates(V, V @ R.T, 3, align=False)
    np.testing.assert_allclose(raw[1], 0.5 * (V + V @ R.T), atol=1e-15)


def test_feature_and_latent_interpolation_use_the_callables(rng):
    f_a, f_b = rng.normal(size=6), rng.normal(size=6)
    seq = itp.interpolate_features(f_a, f_b, 3, lambda f: f.reshape(-1, 2, 3))
    np.testing.assert_allclose(seq[1].ravel(), 0.5 * (f_a + f_b), atol=1e-15)

    W = rng.normal(size=(6, 2))
    encode = lambda X: (X @ W, None)  # noqa: E731  linear "encoder" on (2, 6) inputs
    decode = lambda Z: (Z @ W.T).reshape(-1, 2, 3)  # noqa: E731
    mu, _ = encode(np.stack([f_a, f_b]))
    z, V = itp.LatentPath(decode, mu[0], mu[1]).steps(5)
    assert z.shape == (5, 2) and V.shape == (5, 2, 3)
    np.testing.assert_allclose(z[0], f_a @ W, atol=1e-12)
    np.testing.assert_allclose(z[-1], f_b @ W, atol=1e-12)
    np.testing.assert_allclose(np.diff(z, axis=0), np.diff(z, axis=0)[:1].repeat(4, 0), atol=1e-12)


# ---------------------------------------------------------------------------------------------
# edge-length distortion
# ---------------------------------------------------------------------------------------------


def test_edge_length_distortion_against_brute_force(rng):
    V, F = grid(3, 3)
    data = V[None] + 0.05 * rng.normal(size=(7, 16, 3))
    query = V[None] + 0.05 * rng.normal(size=(3, 16, 3))
    d, nn = itp.edge_length_distortion(query, F, data)
    E = edges(F)
    for q in range(3):
        best, arg = np.inf, -1
        for m in range(7):
            lq = [np.linalg.norm(query[q, i] - query[q, j]) for i, j in E]
            lm = [np.linalg.norm(data[m, i] - data[m, j]) for i, j in E]
            val = np.mean([abs(x - y) / y for x, y in zip(lq, lm)])
            if val < best:
                best, arg = val, m
        assert d[q] == pytest.approx(best, rel=1e-12)
        assert nn[q] == arg


def test_edge_length_distortion_rigid_invariance_and_scale(rng):
    V, F = grid(3, 3)
    data = np.stack([V, 2.0 * V])
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    d, nn = itp.edge_length_distortion(V @ Q.T + 1.0, F, data)
    assert d == pytest.approx(0.0, abs=1e-12) and nn == 0
    d, nn = itp.edge_length_distortion(1.5 * V, F, data)  # every edge 50% longer than V's
    assert d == pytest.approx(0.25, abs=1e-12) and nn == 1  # 25% shorter than 2V's
    with pytest.raises(ValueError, match="dataset"):
        itp.edge_length_distortion(V, F, V)


def test_vertex_edge_stretch_against_a_loop_and_in_closed_form(rng):
    V, F = grid(3, 4)
    Vd = V[None] + 0.1 * rng.normal(size=(2, len(V), 3))
    got = itp.vertex_edge_stretch(Vd, V, F)
    E = edges(F)
    for k in range(2):
        for v in range(len(V)):                      # the definition, one vertex at a time
            at = [e for e in range(len(E)) if v in E[e]]
            ref = np.mean([abs(np.linalg.norm(Vd[k, E[e, 0]] - Vd[k, E[e, 1]]) / np.linalg.norm(V[E[e, 0]] - V[E[e, 1]]) - 1)
                           for e in at])
            assert got[k, v] == pytest.approx(ref, rel=1e-12)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    assert np.abs(itp.vertex_edge_stretch(V @ Q.T + 2.0, V, F)).max() < 1e-12       # rigid: zero
    assert np.allclose(itp.vertex_edge_stretch(0.7 * V, V, F), 0.3, atol=1e-12)     # scale c: |c - 1|
    assert itp.vertex_edge_stretch(Vd[0], V, F).shape == (len(V),)
    with pytest.raises(ValueError, match="V_ref"):
        itp.vertex_edge_stretch(Vd, Vd, F)


def test_batch_and_implausibility_table(rng):
    V, F = grid(3, 3)
    seq = {"a": np.stack([V, V * 1.1]), "b": np.stack([V, V])}
    table = itp.implausibility(seq, F, V[None])
    np.testing.assert_array_equal(table.self_intersections["a"], [0, 0])
    np.testing.assert_allclose(table.edge_distortion["a"], [0.0, 0.1], atol=1e-12)
    rows = table.rows()
    assert rows[0]["method"] == "a" and rows[0]["max edge distortion"] == pytest.approx(0.1)
    md = table.to_markdown()
    assert md.count("\n") == 3 and "| a |" in md


def test_latent_path_decodes_the_straight_blend():
    from meshvae_lib.applications.interpolation import LatentPath

    seen = []
    path = LatentPath(lambda z: (seen.append(z), np.tile(z[:1], (4, 3)))[1], np.array([0.0, 2.0]), np.array([1.0, 0.0]))
    np.testing.assert_allclose(path.latent(0.25), [0.25, 1.5], atol=1e-15)
    V = path(0.5)
    assert V.shape == (4, 3) and np.allclose(V, 0.5) and np.allclose(seen[-1], [0.5, 1.0])
    np.testing.assert_array_equal(path.latent(0.0), [0.0, 2.0])
    np.testing.assert_array_equal(path.latent(1.0), [1.0, 0.0])
    with pytest.raises(ValueError, match="one size"):
        LatentPath(lambda z: z, np.zeros(2), np.zeros(3))
