"""RIMD feature (Eq. 2): layout, invariances, agreement with a direct computation."""

import numpy as np
import pytest
from geometry_fixtures import bumpy, random_rotation, tube, twist_bend

from meshvae_lib.geometry.deformation_gradient import deformation_gradients
from meshvae_lib.geometry.rimd import S_ENTRIES, RIMDEncoder, RIMDLayout, rimd_features
from meshvae_lib.geometry.rimd_files import load_features, save_features
from meshvae_lib.geometry.polar import polar_decomposition
from meshvae_lib.geometry.rotations import so3_log
from meshvae_lib.geometry.topology import edges


@pytest.fixture(scope="module")
def mesh():
    V0, F = tube(12, 10)
    V0 = bumpy(V0, seed=4)
    return V0, F, twist_bend(V0, 280, 100)


def test_paper_dimension_60012():
    # a closed genus-0 mesh with 2502 vertices has 7500 edges, as in the paper's Fig. 2
    V, F = tube(50, 49)
    assert len(V) == 2502 and len(edges(F)) == 7500
    assert RIMDLayout(F, len(V)).K == 60012
    assert RIMDLayout(F, len(V), "compact").K == 6 * 2502 + 3 * 7500


def test_layout_indices_point_at_the_right_numbers(mesh):
    V0, F, V = mesh
    enc = RIMDEncoder(V0, F)
    f = enc.transform(V)
    R, S = polar_decomposition(deformation_gradients(V0, V, F))
    lay = enc.layout
    D = lay.rotation_edges
    for i, j in [D[0], D[0][::-1], D[40], D[40][::-1], D[-1]]:
        np.testing.assert_allclose(f[lay.edge_feature_index(i, j)], so3_log(R[i].T @ R[j]),
                                   atol=1e-13)
    for i in (0, 7, len(V0) - 1):
        idx = lay.vertex_feature_index(i)
        np.testing.assert_allclose(f[idx], [S[i][a, b] for a, b in S_ENTRIES], atol=1e-13)
        np.testing.assert_allclose(lay.scaling_part(f, i), S[i], atol=1e-13)
    # one-ring contiguity: the rotation block of vertex i is its one-ring, in order
    assert np.all(np.diff(D[:, 0]) >= 0)


def test_directed_edges_are_antisymmetric_and_compact_agrees(mesh):
    V0, F, V = mesh
    fp = rimd_features(V0, V, F)
    fc = rimd_features(V0, V, F, layout="compact")
    lp, lc = RIMDLayout(F, len(V0)), RIMDLayout(F, len(V0), "compact")
    for i, j in edges(F)[::7]:
        np.testing.assert_allclose(fp[lp.edge_feature_index(j, i)],
                                   -fp[lp.edge_feature_index(i, j)], atol=1e-15)
        np.testing.assert_allclose(fc[lc.edge_feature_index(i, j)],
                                   fp[lp.edge_feature_index(i, j)], atol=1e-15)
        np.testing.assert_allclose(lc.rotation_part(fc, j, i), -fc[lc.edge_feature_index(i, j)])
    np.testing.assert_allclose(fc[lc.scaling_slice], fp[lp.scaling_slice])
    with pytest.raises(ValueError, match="stores edge"):
        lc.edge_feature_index(5, 0)


def test_rigid_motion_leaves_features_unchanged(mesh):
    V0, F, V = mesh
    enc = RIMDEncoder(V0, F)
    f = enc.transform(V)
    moved = V @ random_rotation(11).T + np.array([3.0, -1.0, 7.0])
    np.testing.assert_allclose(enc.transform(moved), f, atol=1e-12)


def test_uniform_scale_changes_only_S_by_that_factor(mesh):
    V0, F, V = mesh
    enc = RIMDEncoder(V0, F)
    f, fs = enc.transform(np.stack([V, 1.7 * V]))
    lay = enc.layout
    np.testing.assert_allclose(fs[lay.rotation_slice], f[lay.rotation_slice], atol=1e-12)
    np.testing.assert_allclose(fs[lay.scaling_slice], 1.7 * f[lay.scaling_slice], atol=1e-12)


def test_reference_has_zero_rotation_and_identity_S(mesh):
    V0, F, _ = mesh
    f = rimd_features(V0, V0, F)
    lay = RIMDLayout(F, len(V0))
    assert np.abs(f[lay.rotation_slice]).max() < 1e-14
    S6 = f[lay.scaling_slice].reshape(-1, 6)
    np.testing.assert_allclose(S6, np.tile([1, 0, 0, 1, 0, 1.0], (len(V0), 1)), atol=1e-13)


def test_batch_matches_single_and_pack_unpack(mesh):
    V0, F, V = mesh
    enc = RIMDEncoder(V0, F)
    batch = np.stack([V, V0, 0.9 * V])
    fb = enc.transform(batch, batch_size=2)
    assert fb.shape == (3, enc.K) and fb.dtype == np.float64
    for k in range(3):
        np.testing.assert_allclose(fb[k], enc.transform(batch[k]), atol=1e-15)
    log_dR, S = enc.layout.unpack(fb)
    S6 = np.stack([S[..., a, b] for a, b in S_ENTRIES], -1)
    np.testing.assert_allclose(enc.layout.pack(log_dR, S6), fb, atol=1e-15)


def test_bad_input(mesh):
    V0, F, V = mesh
    with pytest.raises(ValueError, match="layout"):
        RIMDLayout(F, len(V0), "dense")
    with pytest.raises(ValueError, match=r"got \(5, 3\)"):
        rimd_features(V0, V[:5], F)
    lay = RIMDLayout(F, len(V0))
    with pytest.raises(ValueError, match="features must have shape"):
        lay.unpack(np.zeros(10))
    with pytest.raises(ValueError, match="not an edge"):
        lay.edge_feature_index(0, len(V0) - 1)
    with pytest.raises(ValueError, match="out of range"):
        lay.vertex_feature_index(len(V0))


def test_feature_file_round_trip(mesh, tmp_path):
    V0, F, V = mesh
    f = rimd_features(V0, np.stack([V, V0]), F, layout="compact")
    save_features(tmp_path / "f.npz", f, V0, F, ["a", "b"], {"k": np.array([3, 4])}, layout="compact")
    d = load_features(tmp_path / "f.npz")
    np.testing.assert_array_equal(d["features"], f)
    np.testing.assert_array_equal(d["reference"], V0)
    assert d["names"] == ["a", "b"] and d["layout"] == "compact" and d["labels"]["k"].tolist() == [3, 4]
    with pytest.raises(ValueError, match="layout of this mesh has K"):
        save_features(tmp_path / "g.npz", f, V0, F)  # compact rows, paper layout
    with pytest.raises(ValueError, match=r"features must have shape \(n_meshes, k\)"):
        save_features(tmp_path / "g.npz", f[0], V0, F, layout="compact")
    with pytest.raises(ValueError, match="must end in .npz"):
        save_features(tmp_path / "g.txt", f, V0, F, layout="compact")
