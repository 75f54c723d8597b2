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
import numpy as np
import torch
from torch import nn


class LinearVAE(nn.Module):
    """A toy architecture: one linear map each way, softplus deviations."""

    architecture = "toy-linear"
    output = "tanh"

    def __init__(self, n_features, latent_dim, n_conditions=0):
        super().__init__()
        self.n_features, self.latent_dim, self.n_conditions = n_features, latent_dim, n_conditions
        self.enc = nn.Linear(n_features + n_conditions, 2 * latent_dim)
        self.dec = nn.Linear(latent_dim + n_conditions, n_features)

    @classmethod
    def from_config(cls, config):
        return cls(**config)

    @classmethod
    def start(cls, x, n_conditions, config):
        return cls(x.shape[1], config.latent_dim, n_conditions)

    def config(self):
        return {"n_features": self.n_features, "latent_dim": self.latent_dim, "n_conditions": self.n_conditions}

    def used_latent_dims(self):
        return np.arange(self.latent_dim)

    def _with(self, x, c):
        return x if c is None else torch.cat([x, c], 1)

    def encode(self, x, c=None):
        out = self.enc(self._with(x, c))
        return out[:, :self.latent_dim], nn.functional.softplus(out[:, self.latent_dim:]) + 1e-3

    def reparameterize(self, mu, sigma, generator=None):
        return mu + sigma * torch.randn(mu.shape, generator=generator)

    def decode(self, z, c=None):
        return torch.tanh(self.dec(self._with(z, c)))

    def forward(self, x, c=None, generator=None):
        mu, sigma = self.encode(x, c)
        return self.decode(self.reparameterize(mu, sigma, generator), c), mu, sigma
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


def test_a_new_network_is_one_module_and_one_registry_line(plug_in, monkeypatch, tmp_path):
    plug_in("toy_network", TOY_NETWORK)
    monkeypatch.setitem(networks.ARCHITECTURES, "toy-linear", "toy_network:LinearVAE")   # the one line
    coll = _strips()
    cfg = TrainConfig(architecture="toy-linear", init="random", epochs=3, latent_dim=2, batch_size=4, progress=False)
    model = MeshVAEModel("coords", cfg, holdout_every=4).fit(coll)
    assert type(model.network).__name__ == "LinearVAE" and isinstance(model.network, networks.Network)
    assert model.latent_dim == 2 and "architecture='toy-linear'" in repr(model)
    loaded = load_model(model.save(tmp_path / "toy.pt"), coll)
    assert type(loaded.network).__name__ == "LinearVAE"
    z = model.sample_latent(3, seed=1)
    np.testing.assert_array_equal(loaded.decode_latent(z), model.decode_latent(z))
    assert torch.load(tmp_path / "toy.pt", weights_only=True)["architecture"] == "toy-linear"
    fitted = evaluate_model(loaded, coll, held_out_only=True, inference="finite-difference")  # any inference works on it
    assert fitted["fit_iterations"] == 4      # the finite-difference default (GAUSS_NEWTON_ITERATIONS)
    # the default inference too: the decoder's Jacobian comes from autograd, nothing written for it
    encoder = evaluate_model(loaded, coll, held_out_only=True, inference="encoder")
    default = evaluate_model(loaded, coll, held_out_only=True, inference="gauss-newton")
    assert default["mean_vertex_error"] <= encoder["mean_vertex_error"] * (1 + 1e-9)
    assert default["mean_vertex_error"] < 0.9 * encoder["mean_vertex_error"]      # and it does something
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
