"""FeatureExtractor (RIMD and the coordinate baselines of Table 2) and ConditionEncoder."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.features import ConditionEncoder, FeatureExtractor
from meshvae_lib.geometry.rimd import RIMDLayout
from meshvae_lib.geometry.topology import edges
from meshvae_lib.model.train_config import default_hidden
from meshvae_lib.defaults import HIDDEN_COORDS


def grid_collection(n=6, seed=0, nx=6, ny=4):
    """A wavy sheet deformed differently per mesh, each under a random rigid motion."""
    rng = np.random.default_rng(seed)
    x, y = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 0.7, ny), indexing="ij")
    P = np.stack([x.ravel(), y.ravel(), 0.05 * np.sin(3 * x.ravel() + y.ravel())], 1)
    F = []
    for i in range(nx - 1):
        for j in range(ny - 1):
            a = i * ny + j
            F += [[a, a + ny, a + 1], [a + ny, a + ny + 1, a + 1]]
    Vs = [P]
    for _ in range(n - 1):
        V = P.copy()
        V[:, 2] += rng.uniform(-0.3, 0.3) * V[:, 0] ** 2 + rng.uniform(-0.2, 0.2) * V[:, 1] * V[:, 0]
        R = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
        Vs.append(V @ R.T + rng.normal(size=3))
    return np.array(Vs), np.array(F)


@pytest.mark.parametrize("kind", ["rimd", "aligned", "coords"])
def test_round_trip_meshes_to_rows_to_meshes(kind):
    V, F = grid_collection()
    ext = FeatureExtractor(kind).fit(V, F)
    X = ext.transform(V)
    assert X.shape == (len(V), ext.n_features_) and X.dtype == np.float64
    back = ext.inverse_transform(X)
    assert back.shape == V.shape
    diag = np.linalg.norm(np.ptp(V[0], axis=0))
    if kind == "coords":
        np.testing.assert_array_equal(back, V)
    elif kind == "aligned":
        np.testing.assert_allclose(back, rigid_align(V, V[0]), atol=1e-12)
    else:  # RIMD has no pose: compare after aligning to the true meshes
        np.testing.assert_allclose(rigid_align(back, V), V, atol=1e-6 * diag)
    assert ext.inverse_transform(X[1]).shape == V.shape[1:]


def test_feature_lengths():
    V, F = grid_collection(n=2)
    nv, ne = V.shape[1], len(edges(F))
    assert FeatureExtractor("coords").fit(V, F).n_features_ == 3 * nv
    assert FeatureExtractor("aligned").fit(V, F).n_features_ == 3 * nv
    assert FeatureExtractor("rimd").fit(V, F).n_features_ == 6 * nv + 6 * ne == RIMDLayout(F, nv).K


def test_invariance_to_rigid_motion():
    V, F = grid_collection(n=3)
    R = Rotation.from_euler("xyz", [0.7, -1.2, 2.0]).as_matrix()
    moved = V @ R.T + np.array([3.0, -1.0, 0.5])
    for kind, invariant in (("rimd", True), ("aligned", True), ("coords", False)):
        ext = FeatureExtractor(kind).fit(V, F)
        diff = np.abs(ext.transform(moved[1:]) - ext.transform(V[1:])).max()
        assert (diff < 1e-8) == invariant, (kind, diff)


def test_compatibility_checks_and_bad_input():
    V, F = grid_collection(n=2)
    ext = FeatureExtractor("aligned").fit(V, F)
    with pytest.raises(ValueError, match="24 vertices, got 20"):
        ext.transform(V[:, :20])
    with pytest.raises(ValueError, match="connectivity"):
        ext.check_compatible(V, F[:, ::-1])
    with pytest.raises(ValueError, match=r"\(N, 72\)"):
        ext.inverse_transform(np.zeros((1, 5)))
    with pytest.raises(ValueError, match="kind must be one of"):
        FeatureExtractor("voxels").fit(V, F)
    with pytest.raises(ValueError, match="not fitted"):
        FeatureExtractor().transform(V)
    with pytest.raises(ValueError, match="reference_index"):
        FeatureExtractor("coords", reference_index=5).fit(V, F)


@pytest.mark.parametrize("kind", ["rimd", "aligned", "coords"])
def test_state_dict_round_trip(kind):
    V, F = grid_collection(n=3)
    ext = FeatureExtractor(kind).fit(V, F)
    copy = FeatureExtractor.from_state_dict(ext.state_dict())
    np.testing.assert_array_equal(copy.transform(V), ext.transform(V))
    np.testing.assert_array_equal(copy.inverse_transform(ext.transform(V)), ext.inverse_transform(ext.transform(V)))


def test_default_hidden_layers():
    assert default_hidden("rimd") == ()
    assert default_hidden("coords", "random") == tuple(HIDDEN_COORDS) == default_hidden("aligned", "random") == (256,)
    assert default_hidden("coords") == () == default_hidden("rimd", "pca") == default_hidden("rimd", "random")
    with pytest.raises(ValueError):
        default_hidden("nope")


def test_condition_encoder_one_hot_and_numeric():
    labels = {"motion": np.array(["run", "jump", "run", "walk"]), "bmi": np.array([20.0, 30.0, 25.0, 20.0]),
              "subject": np.array([50022, 50002, 50022, 50002])}
    enc = ConditionEncoder(["motion", "bmi", "subject"]).fit(labels)
    assert enc.categories_["motion"] == ["jump", "run", "walk"]
    assert enc.kinds_ == {"motion": "onehot", "bmi": "numeric", "subject": "onehot"}
    C = enc.transform(labels)
    assert C.shape == (4, 3 + 1 + 2) and C.dtype == np.float32
    np.testing.assert_array_equal(C[:, :3], [[0, 1, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    np.testing.assert_allclose(C[:, 3], [-1, 1, 0, -1])
    np.testing.assert_array_equal(C[:, 4:], [[0, 1], [1, 0], [0, 1], [1, 0]])
    np.testing.assert_array_equal(enc.encode_values({"motion": "walk", "bmi": 30.0, "subject": "50002"}),
                                  [0, 0, 1, 1, 1, 0])
    copy = ConditionEncoder.from_state_dict(enc.state_dict())
    np.testing.assert_array_equal(copy.transform(labels), C)
    with pytest.raises(ValueError, match="no value 'swim'"):
        enc.encode_values({"motion": "swim", "bmi": 1.0, "subject": 50002})
    with pytest.raises(ValueError, match=r"missing condition values for \['bmi'\]"):
        enc.encode_values({"motion": "run", "subject": 50002})
    with pytest.raises(ValueError, match="no label column 'age'"):
        ConditionEncoder(["age"]).fit(labels)
