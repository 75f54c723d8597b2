"""The seams: a network architecture and an inference method are each added as one module plus one
registry line (the feature-kind case is in test_features_baselines.py), and the estimator, the
trainer, the checkpoint and the evaluation take them by name."""

from __future__ import annotations

import sys

import numpy as np
import pytest
import torch

from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.model import inference, networks
from meshvae_lib.model.evaluation import evaluate_model
from meshvae_lib.model.meshvae_model import MeshVAEModel, load_model
from meshvae_lib.model.train_config import TrainConfig

torch.set_num_threads(1)

TOY_NETWORK = '''
from dataclasses import dataclass, field

import torch
from torch import nn

from meshvae_lib.model.network_base import Network


@dataclass(frozen=True)
class ToyOptions:
    floor: float = field(default=1e-3, metadata={"flag": "--toy-floor", "help": "the softplus deviation's floor"})


class LinearVAE(Network):
    """A toy architecture: one linear map each way, softplus deviations."""

    architecture = "toy-linear"
    description = "a toy: one linear map each way"
    Options = ToyOptions
    conditional = True

    def __init__(self, n_features, latent_dim, n_conditions=0, floor=1e-3):
        super().__init__()
        self.n_features, self.latent_dim, self.n_conditions, self.floor = n_features, latent_dim, n_conditions, floor
        self.enc = nn.Linear(n_features + n_conditions, 2 * latent_dim)
        self.dec = nn.Linear(latent_dim + n_conditions, n_features)

    @classmethod
    def start(cls, x, n_conditions, config, mesh):
        return cls(x.shape[1], config.latent_dim, n_conditions, cls.options(config).floor)

    def config(self):
        return {"n_features": self.n_features, "latent_dim": self.latent_dim, "n_conditions": self.n_conditions,
                "floor": self.floor}

    def encode(self, x, c=None):
        out = self.enc(self.with_condition(x, c, self.n_features, "features"))
        return out[:, :self.latent_dim], nn.functional.softplus(out[:, self.latent_dim:]) + self.floor

    def decode(self, z, c=None):
        return torch.tanh(self.dec(self.with_condition(z, c, self.latent_dim, "latent vectors")))
'''

TOY_INFERENCE = '''
import numpy as np
from meshvae_lib.model.inference.base import InferenceStrategy


class PriorMean(InferenceStrategy):
    """A toy inference: every mesh gets the prior's mean, shrunk towards it from the encoder's by ``weight``."""

    name = "toy-shrink"
    options = ("weight",)

    def __init__(self, weight=0.0):
        self.weight = float(weight)

    def infer(self, model, vertices, conditions):
        mu, _ = model.encode_rows(model.features_of(vertices), conditions)
        return self.weight * mu
'''


def _strips(n=16, nx=6, ny=3, seed=0):
    rng = np.random.default_rng(seed)
    F = [[i * ny + j, (i + 1) * ny + j, i * ny + j + 1] for i in range(nx - 1) for j in range(ny - 1)]
    F += [[(i + 1) * ny + j, (i + 1) * ny + j + 1, i * ny + j + 1] for i in range(nx - 1) for j in range(ny - 1)]
    V0 = np.array([[i, j, 0.0] for i in range(nx) for j in range(ny)])
    Vs = [V0 + np.c_[np.zeros((len(V0), 2)), rng.uniform(0.2, 1.0) * np.sin(V0[:, :1])] for _ in range(n)]
    return MeshCollection(np.array(Vs), np.array(F))


@pytest.fixture
def plug_in(tmp_path, monkeypatch):
    """Write a module to a folder on sys.path; the test then adds its registry line."""
    monkeypatch.syspath_prepend(str(tmp_path))
    written = []

    def write(name, source):
        (tmp_path / f"{name}.py").write_text(source)
        written.append(name)

    yield write
    for name in written:
        sys.modules.pop(name, None)


def test_a_new_network_is_one_module_and_one_registry_line(plug_in, monkeypatch, tmp_path, capsys):
    """A fourth network: one module (written here) and one registry line, nothing else edited. It
    trains, saves, loads, runs Gauss-Newton, evaluate, generate and interpolate, and ``meshvae train``
    offers its options as flags."""
    from meshvae_lib.applications.interpolation import LatentPath
    from meshvae_lib.cli import main
    from meshvae_lib.geometry.collection_io import write_collection

    plug_in("toy_network", TOY_NETWORK)
    monkeypatch.setitem(networks.ARCHITECTURES, "toy-linear", "toy_network:LinearVAE")   # the one line
    coll = _strips()
    cfg = TrainConfig(architecture="toy-linear", init="random", epochs=3, latent_dim=2, batch_size=4, progress=False,
                      network_options={"floor": 0.01})
    model = MeshVAEModel("coords", cfg, holdout_every=4).fit(coll)
    assert type(model.network).__name__ == "LinearVAE" and isinstance(model.network, networks.Network)
    assert model.latent_dim == 2 and model.network.floor == 0.01 and "architecture='toy-linear'" in repr(model)
    assert model.train_config_.latent_dim == 2 and model.train_config_.a == 0.9     # resolved once, recorded
    loaded = load_model(model.save(tmp_path / "toy.pt"), coll)
    assert type(loaded.network).__name__ == "LinearVAE" and loaded.network.floor == 0.01
    z = model.sample_latent(3, seed=1)
    np.testing.assert_array_equal(loaded.decode_latent(z), model.decode_latent(z))
    np.testing.assert_array_equal(loaded.generate(2, seed=3), model.generate(2, seed=3))
    saved = torch.load(tmp_path / "toy.pt", weights_only=True)
    assert saved["architecture"] == "toy-linear" and saved["train_config"]["network_options"] == {"floor": 0.01}
    assert (saved["train_config"]["latent_dim"], saved["train_config"]["a"]) == (2, 0.9)      # the resolved config
    fitted = evaluate_model(loaded, coll, held_out_only=True, inference="finite-difference")  # any inference works on it
    assert fitted["fit_iterations"] == 4      # the finite-difference default (GAUSS_NEWTON_ITERATIONS)
    # the default inference too: the decoder's Jacobian comes from autograd, nothing written for it
    encoder = evaluate_model(loaded, coll, held_out_only=True, inference="encoder")
    default = evaluate_model(loaded, coll, held_out_only=True, inference="gauss-newton")
    assert default["mean_vertex_error"] <= encoder["mean_vertex_error"] * (1 + 1e-9)
    assert default["mean_vertex_error"] < 0.9 * encoder["mean_vertex_error"]      # and it does something
    assert loaded.last_inference_.final_error.shape == (4,)                   # the strategy's declared report
    codes = loaded.encode_meshes(coll.vertices[[0, 5]])
    _, meshes = LatentPath(loaded.decode_latent, codes[0], codes[1]).steps(4)
    assert meshes.shape == (4, 18, 3) and np.allclose(meshes[0], loaded.decode_latent(codes[0]), atol=1e-6)
    # its options are flags of `meshvae train`, and the flag reaches the network
    with pytest.raises(SystemExit):
        main(["train", "--help"])
    text = capsys.readouterr().out
    assert "toy-linear: a toy: one linear map each way" in " ".join(text.split())
    assert "--toy-floor" in text and "toy-linear: the softplus deviation's floor (default 0.001)" in " ".join(text.split())
    path = write_collection(tmp_path / "s.npz", coll)
    assert main(["train", str(path), "-o", str(tmp_path / "cli.pt"), "--architecture", "toy-linear", "--features",
                 "coords", "--toy-floor", "0.05", "--latent", "2", "--epochs", "2", "--no-progress"]) == 0
    assert load_model(tmp_path / "cli.pt", coll).network.floor == 0.05
    assert main(["train", str(path), "-o", str(tmp_path / "x.pt"), "--toy-floor", "0.05"]) == 2
    assert "--toy-floor is the toy-linear network's, not mesh-vae's" in capsys.readouterr().err
    rows, J = networks.decoder_linearization(loaded.network, z[0])
    h = 1e-3
    fd = np.stack([(loaded.network.decode(torch.tensor(z[:1] + h * e, dtype=torch.float32))[0].detach().double().numpy()
                    - loaded.network.decode(torch.tensor(z[:1] - h * e, dtype=torch.float32))[0].detach().double().numpy()) / (2 * h)
                   for e in np.eye(2)], axis=1)
    assert J.shape == (coll.vertices.shape[1] * 3, 2) and np.allclose(J, fd, atol=1e-3 * np.abs(fd).max())
    with pytest.raises(ValueError, match="architecture"):
        TrainConfig(architecture="no-such-net")


def test_a_new_inference_method_is_one_module_and_one_registry_line(plug_in, monkeypatch, tmp_path):
    plug_in("toy_inference", TOY_INFERENCE)
    monkeypatch.setitem(inference.METHODS, "toy-shrink", "toy_inference:PriorMean")   # the one line
    coll = _strips()
    model = MeshVAEModel("coords", TrainConfig(epochs=3, latent_dim=2, progress=False), holdout_every=4,
                         inference="toy-shrink").fit(coll)
    np.testing.assert_array_equal(model.encode_meshes(coll), np.zeros((len(coll), 2)))
    np.testing.assert_array_equal(model.reconstruct(coll.vertices[:2]), model.decode_latent(np.zeros((2, 2))))
    half = inference.make_inference("toy-shrink", weight=0.5)
    np.testing.assert_allclose(model.encode_meshes(coll, inference=half),
                               0.5 * model.encode_meshes(coll, inference="encoder"), rtol=0, atol=0)
    loaded = load_model(model.save(tmp_path / "m.pt"), coll)
    assert loaded.inference == "toy-shrink"
    res = evaluate_model(loaded, coll, inference=half)
    assert res["n_meshes"] == len(coll) and res["fit_iterations"] == 0
    keep = MeshVAEModel("coords", TrainConfig(epochs=2, latent_dim=2, progress=False), inference=half).fit(coll)
    again = load_model(keep.save(tmp_path / "k.pt"), coll)
    assert type(again.inference).__name__ == "PriorMean" and again.inference.weight == 0.5


def _bent_sheets(n=20, nx=30, ny=12, seed=0):
    """A sheet bent along x and twisted by random amounts: a nonlinear family on 360 vertices."""
    from geometry_fixtures import strip

    rng = np.random.default_rng(seed)
    P, F = strip(nx, ny, length=3.0, width=1.0)
    Vs = []
    for _ in range(n):
        bend, twist = rng.uniform(-1.2, 1.2), rng.uniform(-0.8, 0.8)
        theta = bend * P[:, 0] / 3.0
        r = 3.0 / max(abs(bend), 1e-3) * np.sign(bend or 1.0)
        x, z = r * np.sin(theta), r * (1 - np.cos(theta))
        y = P[:, 1] * np.cos(twist * P[:, 0]) - 0.5
        Vs.append(np.c_[x, y, z + P[:, 1] * np.sin(twist * P[:, 0])])
    return MeshCollection(np.array(Vs), F)


SMALL_SPIRAL = {"channels": (8, 8), "spiral_length": 7, "factors": (2, 2)}


@pytest.mark.parametrize("features", ["coords", "aligned"])
def test_the_spiral_network_goes_through_every_path(features, tmp_path):
    from meshvae_lib.applications.exploration import explore
    from meshvae_lib.applications.interpolation import LatentPath
    from meshvae_lib.model.evaluation import pca_baseline

    coll = _bent_sheets()
    cfg = TrainConfig(architecture="spiral", latent_dim=3, epochs=400, batch_size=8, progress=False,
                      network_options=SMALL_SPIRAL)
    assert (cfg.output, cfg.loss) == ("linear", "l1")          # the architecture's own defaults
    model = MeshVAEModel(features, cfg, holdout_every=5).fit(coll)
    assert type(model.network).__name__ == "SpiralVAE" and isinstance(model.network, networks.Network)
    assert model.latent_dim == 3 and model.train_epochs_ == 400 and model.network.level_sizes[0] == 360
    from meshvae_lib.course.display import model_summary

    assert "network:  spiral, spiral convolutions 8 -> 8 (spirals of 7) on 360 -> " in model_summary(model)
    encoder = evaluate_model(model, coll, held_out_only=True, inference="encoder")
    default = evaluate_model(model, coll, held_out_only=True)                  # Gauss-Newton through autograd
    assert default["inference"] == "gauss-newton"
    assert default["mean_vertex_error"] <= encoder["mean_vertex_error"] * (1 + 1e-9)
    # it learned the two-parameter family: a quarter of the data's own spread and below PCA with two
    # directions (measured: 0.065 against 0.093; PCA with its three directions 0.064, a tie)
    V = coll.vertices
    spread = np.mean(np.linalg.norm(V - V.mean(0), axis=-1))
    assert default["mean_vertex_error"] < 0.25 * spread
    pca2 = pca_baseline(V[~model.holdout_mask_], V[model.holdout_mask_], n_components=2)
    assert default["mean_vertex_error"] < pca2["mean_vertex_error"]
    loaded = load_model(model.save(tmp_path / "spiral.pt"), coll)
    z = model.sample_latent(4, seed=2)
    np.testing.assert_array_equal(loaded.decode_latent(z), model.decode_latent(z))
    np.testing.assert_array_equal(loaded.generate(2, seed=3), model.generate(2, seed=3))
    np.testing.assert_allclose(loaded.encode_meshes(coll.vertices[:3]), model.encode_meshes(coll.vertices[:3]),
                               rtol=1e-6, atol=1e-6)
    codes = model.encode_meshes(coll.vertices[[0, 7]])
    _, meshes = LatentPath(model.decode_latent, codes[0], codes[1]).steps(5)
    assert meshes.shape == (5, 360, 3) and np.all(np.isfinite(meshes))
    grid = explore(model, dims=(0, 1), n=3)
    assert np.all(np.isfinite(grid.vertices))
    assert torch.load(tmp_path / "spiral.pt", weights_only=True)["architecture"] == "spiral"


def test_the_spiral_networks_decoder_jacobian_is_its_derivative():
    coll = _bent_sheets(n=8)
    cfg = TrainConfig(architecture="spiral", latent_dim=3, epochs=2, batch_size=4, progress=False,
                      network_options=SMALL_SPIRAL)
    net = MeshVAEModel("coords", cfg).fit(coll).network
    z = np.array([0.3, -0.2, 0.5])
    rows, J = networks.decoder_linearization(net, z)
    h = 1e-2
    dec = lambda v: net.decode(torch.tensor(v[None], dtype=torch.float32))[0].detach().double().numpy()  # noqa: E731
    fd = np.stack([(dec(z + h * e) - dec(z - h * e)) / (2 * h) for e in np.eye(3)], axis=1)
    np.testing.assert_allclose(rows, dec(z), rtol=0, atol=1e-6)
    assert J.shape == (3 * 360, 3) and np.allclose(J, fd, atol=2e-3 * np.abs(fd).max())


def test_the_spiral_network_refuses_what_it_cannot_read():
    coll = _bent_sheets(n=8)
    with pytest.raises(ValueError, match="positions"):
        MeshVAEModel("rimd", TrainConfig(architecture="spiral", epochs=1, progress=False,
                                         network_options=SMALL_SPIRAL)).fit(coll)
    with pytest.raises(ValueError, match="output"):
        TrainConfig(architecture="spiral", output="tanh")
    with pytest.raises(ValueError, match="channels"):
        TrainConfig(architecture="spiral", network_options={"width": 3})
    with pytest.raises(ValueError, match="takes none"):
        TrainConfig(network_options={"channels": (8,)})
    with pytest.raises(ValueError, match="360 vertices"):
        MeshVAEModel("coords", TrainConfig(architecture="spiral", epochs=1, progress=False)).fit(coll)  # 4 levels of 4
    spiral = TrainConfig(architecture="spiral")
    assert (spiral.epochs, spiral.output, spiral.loss, spiral.resolved_latent_dim(100)) == (300, "linear", "l1", 16)
    assert not spiral.uses_pca_init() and not spiral.resolved_early_stopping()
    paper = TrainConfig()
    assert (paper.epochs, paper.output, paper.loss, paper.resolved_latent_dim(100)) == (1000, "tanh", "mse", 128)
