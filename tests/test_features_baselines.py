"""The feature kinds (RIMD and the coordinate baselines of Table 2), their registry, and ConditionEncoder."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.conditions import ConditionEncoder
from meshvae_lib.model.feature_kinds import FEATURE_KINDS, kind_class, kind_from_state, make_kind
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
    k = make_kind(kind, V[0], F)
    X = k.encode(V)
    assert X.shape == (len(V), k.n_features) and X.dtype == np.float64
    back = k.decode(X)
    assert back.shape == V.shape
    diag = np.linalg.norm(np.ptp(V[0], axis=0))
    if kind == "coords":
        np.testing.assert_array_equal(back, V)
    elif kind == "aligned":
        np.testing.assert_allclose(back, rigid_align(V, V[0]), atol=1e-12)
    else:  # RIMD has no pose: compare after aligning to the true meshes
        np.testing.assert_allclose(rigid_align(back, V), V, atol=1e-6 * diag)
    assert k.decode(X[1:2]).shape == (1,) + V.shape[1:]


def test_feature_lengths_and_the_registry():
    V, F = grid_collection(n=2)
    nv, ne = V.shape[1], len(edges(F))
    assert FEATURE_KINDS == ("coords", "aligned", "rimd")  # the order of Table 2, baseline first
    assert make_kind("coords", V[0], F).n_features == 3 * nv
    assert make_kind("aligned", V[0], F).n_features == 3 * nv
    assert make_kind("rimd", V[0], F).n_features == 6 * nv + 6 * ne == RIMDLayout(F, nv).K
    assert make_kind("rimd", V[0], F, layout="compact").n_features == 6 * nv + 3 * ne
    assert make_kind("coords", V[0], F, layout="compact").get_options() == {}  # options a kind lacks are left out
    for name in FEATURE_KINDS:
        assert kind_class(name).name == name


def test_invariance_to_rigid_motion():
    V, F = grid_collection(n=3)
    R = Rotation.from_euler("xyz", [0.7, -1.2, 2.0]).as_matrix()
    moved = V @ R.T + np.array([3.0, -1.0, 0.5])
    for kind, invariant in (("rimd", True), ("aligned", True), ("coords", False)):
        k = make_kind(kind, V[0], F)
        diff = np.abs(k.encode(moved[1:]) - k.encode(V[1:])).max()
        assert (diff < 1e-8) == invariant, (kind, diff)


def test_compatibility_checks_and_bad_input():
    V, F = grid_collection(n=2)
    k = make_kind("aligned", V[0], F)
    with pytest.raises(ValueError, match="24 vertices, got 20"):
        k.encode(V[:, :20])
    with pytest.raises(ValueError, match="connectivity"):
        k.check_compatible(V, F[:, ::-1])
    with pytest.raises(ValueError, match=r"\(n_meshes, 72\)"):
        k.decode(np.zeros((1, 5)))
    with pytest.raises(ValueError, match="kind must be one of"):
        make_kind("voxels", V[0], F)
    with pytest.raises(ValueError, match="reference must have shape"):
        make_kind("coords", V, F)
    with pytest.raises(ValueError, match="out of range"):
        make_kind("coords", V[0, :5], F)
    with pytest.raises(ValueError, match="read-only"):
        k.reference[0, 0] = 1.0


@pytest.mark.parametrize("kind", ["rimd", "aligned", "coords"])
def test_state_dict_round_trip(kind):
    V, F = grid_collection(n=3)
    k = make_kind(kind, V[0], F, layout="compact")
    copy = kind_from_state(k.state_dict())
    assert type(copy) is type(k) and copy.get_options() == k.get_options()
    np.testing.assert_array_equal(copy.encode(V), k.encode(V))
    np.testing.assert_array_equal(copy.decode(k.encode(V)), k.decode(k.encode(V)))


TOY_KIND = '''
import numpy as np
from meshvae_lib.model.feature_kinds.base import FeatureKind


class EdgeVectorsKind(FeatureKind):
    """A toy kind: each mesh's vertices relative to the first vertex (translation-free)."""

    name = "toy"
    options = ("scale",)

    def __init__(self, reference, faces, scale=1.0):
        super().__init__(reference, faces)
        self.scale = float(scale)

    @property
    def n_features(self):
        return 3 * self.n_vertices

    def _encode(self, V):
        return ((V - V[:, :1]) * self.scale).reshape(len(V), -1)

    def _decode(self, X):
        return X.reshape(len(X), -1, 3) / self.scale
'''


def test_a_new_feature_kind_is_one_module_and_one_registry_line(tmp_path, monkeypatch):
    """What a contributor does to add a kind: write the module, add its line to the registry. The
    model trains on it, saves and loads it by name, and the command line offers it."""
    import sys

    from meshvae_lib.geometry.collection import MeshCollection
    from meshvae_lib.model import feature_kinds
    from meshvae_lib.model.meshvae_model import MeshVAEModel, load_model
    from meshvae_lib.model.train_config import TrainConfig

    (tmp_path / "toy_kind.py").write_text(TOY_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(feature_kinds.KINDS, "toy", "toy_kind:EdgeVectorsKind")   # the one line
    V, F = grid_collection(n=12)
    coll = MeshCollection(V, F)
    model = MeshVAEModel("toy", TrainConfig(epochs=3, latent_dim=3, progress=False), holdout_every=4).fit(coll)
    assert model.feature_kind.name == "toy" and model.n_features == 3 * V.shape[1]
    loaded = load_model(model.save(tmp_path / "toy.pt"), coll)
    assert type(loaded.feature_kind).__name__ == "EdgeVectorsKind" and loaded.feature_kind.scale == 1.0
    np.testing.assert_array_equal(loaded.reconstruct(V[:2]), model.reconstruct(V[:2]))
    assert default_hidden("toy", "random") == ()
    sys.modules.pop("toy_kind", None)


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
