"""The network diagram of notebook 04: the stages of a mesh VAE with their sizes, drawn left to right."""

import matplotlib

matplotlib.use("Agg")

import pytest

from meshvae_lib.model.vae import MeshVAE
from meshvae_lib.viewing.network_diagram import network_diagram, network_layers


def test_layers_of_the_default_network_without_internal_layers():
    stages = network_layers(MeshVAE(100, 8))
    assert [s["kind"] for s in stages] == ["data", "latent", "latent", "output"]
    assert [s["size"] for s in stages] == [100, 8, 8, 100]
    # one linear map each way: K -> 2D for the two heads, D -> K for the decoder (weights and biases)
    assert [s["weights"] for s in stages] == [0, 100 * 16 + 16, 0, 8 * 100 + 100]
    assert "tanh" in stages[-1]["label"]


def test_layers_with_a_pca_projection_and_internal_layers():
    stages = network_layers(MeshVAE(100, 8, input_rank=5))
    assert [s["kind"] for s in stages] == ["data", "fixed", "latent", "latent", "output"]
    assert stages[1]["size"] == 5 and stages[2]["weights"] == 5 * 16 + 16
    net = MeshVAE(100, 8, hidden=(20,))
    stages = network_layers(net)
    assert [s["size"] for s in stages] == [100, 20, 8, 8, 20, 100]
    trained = sum(p.numel() for p in net.parameters())
    assert sum(s["weights"] for s in stages) == trained, "every trained weight is on one arrow"


def test_the_diagram_draws_one_row_per_network_with_sizes_titles_and_spans():
    nets = [MeshVAE(16428, 32), MeshVAE(16428, 32, hidden=(1024,))]
    fig = network_diagram(nets, titles=["default", "one internal layer"])
    assert len(fig.axes) == 2
    texts = [[t.get_text() for t in ax.texts] for ax in fig.axes]
    assert texts[0].count("K = 16428") == 2 and texts[0].count("D = 32") == 2
    assert "1024" in texts[1] and "16.8M" in texts[1], "the internal layer's size and its K x 1024 weights"
    assert all({"encoder", "decoder"} <= set(t) for t in texts)
    assert [ax.get_title(loc="left") for ax in fig.axes] == ["default", "one internal layer"]
    assert len(fig.axes[1].patches) > len(fig.axes[0].patches), "more boxes and arrows with internal layers"
    assert min(t.get_fontsize() for ax in fig.axes for t in ax.texts) >= 9


def test_bad_arguments():
    with pytest.raises(TypeError, match="MeshVAE"):
        network_layers(object())
    with pytest.raises(ValueError, match="one title per network"):
        network_diagram([MeshVAE(10, 2)], titles=["a", "b"])
    with pytest.raises(ValueError, match="at least one network"):
        network_diagram([])
