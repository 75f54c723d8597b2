"""meshvae_lib.course.display.first_argmax: a choice among near-ties made by a stated rule."""

import numpy as np
import pytest

from meshvae_lib.course.display import first_argmax
from meshvae_lib.tolerances import TIE_RTOL


def test_the_earliest_of_values_tied_to_the_last_bits():
    # frames 30 and 90 of notebook 00's jumping jacks: which is larger depends on the BLAS kernels
    a, b = 0.1402245850396264, 0.1402245850396265
    x = np.zeros(120)
    x[30], x[90] = a, b
    assert np.argmax(x) == 90 and first_argmax(x) == 30
    x[30], x[90] = b, a
    assert np.argmax(x) == 30 and first_argmax(x) == 30


def test_a_clear_maximum_wins_wherever_it_is():
    assert first_argmax([1.0, 3.0, 2.0]) == 1
    assert first_argmax([3.0, 3.0 * (1 - 10 * TIE_RTOL)]) == 0
    assert first_argmax([3.0 * (1 - 10 * TIE_RTOL), 3.0]) == 1      # 1e-8 apart: not a tie
    assert first_argmax([1.0, 1.0 + 1e-12], rtol=0) == 1            # rtol 0: np.argmax
    assert first_argmax([-2.0, -1.0 - 1e-12, -1.0]) == 1            # negative values: |max|
    assert first_argmax([0.0, 0.0]) == 0


def test_bad_input_says_what_is_wrong():
    with pytest.raises(ValueError, match=r"non-empty 1-D array, got shape \(0,\)"):
        first_argmax([])
    with pytest.raises(ValueError, match=r"got shape \(2, 2\)"):
        first_argmax(np.zeros((2, 2)))
    with pytest.raises(ValueError, match="finite"):
        first_argmax([1.0, np.nan])
    with pytest.raises(ValueError, match="rtol must be >= 0, got -1"):
        first_argmax([1.0], rtol=-1)


def test_real_inference_table_prints_the_recorded_rows_and_their_ratio():
    from meshvae_lib.course.display import real_inference_table

    rows = [{"collection": "a/3", "paper_path": 0.5, "encoder": 0.25, "default": 0.01, "pca_coords": 0.04,
             "pca_aligned": 0.02},
            {"collection": "b", "paper_path": None, "encoder": 1.0, "default": 3.0, "pca_coords": 1.5, "pca_aligned": 4.0}]
    lines = real_inference_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:2] == ["collection", "paper"]
    assert lines[1].split() == ["a/3", "5.00e-01", "2.50e-01", "1.00e-02", "4.00e-02", "2.00e-02", "|", "12.50", "6.25",
                                "0.25", "|", "0.50"]
    assert lines[2].split() == ["b", "-", "1.00e+00", "3.00e+00", "1.50e+00", "4.00e+00", "|", "-", "0.67", "2.00",
                                "|", "0.75"]


def test_real_feature_table_prints_the_recorded_kinds_the_floor_and_the_verdict():
    from meshvae_lib.course.display import real_feature_table

    rows = [{"collection": "a/3", "coords_default": 0.03, "aligned_default": 0.02, "default": 0.01, "paper_path": 0.5,
             "pca_coords": 0.04, "pca_aligned": 0.02, "floor_relative": 5e-3, "informative": True},
            {"collection": "b", "coords_default": 2e-5, "aligned_default": 1.6e-5, "default": 7.5e-5, "paper_path": None,
             "pca_coords": 1.5e-5, "pca_aligned": 1.2e-5, "floor_relative": 5.2e-6, "informative": False}]
    lines = real_feature_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:4] == ["collection", "coords", "aligned", "RIMD"]
    assert lines[1].split() == ["a/3", "3.00e-02", "2.00e-02", "1.00e-02", "5.00e-01", "4.00e-02", "2.00e-02", "5.0e-03",
                                "0.25", "yes"]
    assert lines[2].split() == ["b", "2.00e-05", "1.60e-05", "7.50e-05", "-", "1.50e-05", "1.20e-05", "5.2e-06", "5.00",
                                "linear", "data:", "not", "informative"]


def test_span_ceiling_table_prints_the_recorded_errors_and_their_ratios_to_pca():
    from meshvae_lib.course.display import span_ceiling_table

    rows = [{"collection": "a", "n_meshes": 40, "pca_coords": 0.002, "feature_projection": 0.03, "vertex_optimal": 0.004,
             "default": 0.005, "vertex_optimal_below_pca": 9},
            {"collection": "b/3", "n_meshes": 12, "pca_coords": 0.02, "feature_projection": 0.07, "vertex_optimal": 0.015,
             "default": 0.014, "vertex_optimal_below_pca": 10}]
    lines = span_ceiling_table(rows).splitlines()
    assert len(lines) == 3 and lines[0].split()[:3] == ["collection", "meshes", "PCA"]
    assert lines[1].split() == ["a", "40", "2.00e-03", "3.00e-02", "4.00e-03", "5.00e-03", "|", "15.00", "2.00", "2.50",
                                "|", "9", "of", "40"]
    assert lines[2].split() == ["b/3", "12", "2.00e-02", "7.00e-02", "1.50e-02", "1.40e-02", "|", "3.50", "0.75", "0.70",
                                "|", "10", "of", "12"]



def _spiral_record(name, source, pca, spiral, rimd, default, used):
    net = lambda enc, gn, u=16: {"used": u, "train_seconds": 1.0, "encoder": {"error": enc},  # noqa: E731
                                 "gauss_newton": {"error": gn, "n_meshes": 14}}
    return {"collection": name, "source": source, "vertices": 2514, "latent": 16, "pca": pca, "pca_all": pca / 3,
            "spiral": net(*spiral), "rimd_equal": net(*rimd), "rimd_default": net(default, default, used)}


def test_spiral_table_and_figure_show_each_network_beside_pca_at_one_latent_size():
    import matplotlib

    matplotlib.use("Agg")
    from meshvae_lib.course.display import spiral_figure, spiral_table

    records = [_spiral_record("scape", "synthetic stand-in", 0.04, (0.06, 0.05), (0.045, 0.02), 0.002, 56),
               _spiral_record("pcow/3", "real", 0.07, (0.15, 0.1), (0.1, 0.035), 0.014, 54)]
    lines = spiral_table(records).splitlines()
    assert len(lines) == 3 and lines[0].split()[:4] == ["collection", "verts", "held", "D"]
    assert lines[1].split() == ["scape", "(stand-in)", "2514", "14", "16", "4.00e-02", "6.00e-02", "5.00e-02", "4.50e-02",
                                "2.00e-02", "2.00e-03", "(", "56)", "|", "1.25,", "0.50"]
    assert lines[2].split()[:2] == ["pcow/3", "(real)"] and lines[2].split()[-2:] == ["1.43,", "0.50"]
    fig = spiral_figure(records)
    ax = fig.axes[0]
    assert len(ax.containers) == 6 and ax.get_yscale() == "log"
    heights = [[bar.get_height() for bar in c] for c in ax.containers]
    assert heights[0] == [0.04, 0.07] and heights[2] == [0.05, 0.1] and heights[5] == [0.002, 0.014]
    assert [bar.get_hatch() for bar in ax.containers[5]] == ["//", "//"]     # the default: more dimensions
    import matplotlib.pyplot as plt

    plt.close(fig)


def _strips(n=12, seed=0):
    """A strip of 6 x 3 vertices bent by a random amount: a tiny collection to fit models on."""
    from meshvae_lib.geometry.collection import MeshCollection

    rng = np.random.default_rng(seed)
    nx, ny = 6, 3
    F = [[i * ny + j, (i + 1) * ny + j, i * ny + j + 1] for i in range(nx - 1) for j in range(ny - 1)]
    F += [[(i + 1) * ny + j, (i + 1) * ny + j + 1, i * ny + j + 1] for i in range(nx - 1) for j in range(ny - 1)]
    V0 = np.array([[i, j, 0.0] for i in range(nx) for j in range(ny)])
    Vs = [V0 + np.c_[np.zeros((len(V0), 2)), rng.uniform(0.2, 1.0) * np.sin(V0[:, :1])] for _ in range(n)]
    return MeshCollection(np.array(Vs), np.array(F))


def test_model_summary_says_the_start_the_epochs_and_what_training_changed():
    from meshvae_lib.course.display import describe_model, model_summary
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.model.train_config import TrainConfig

    coll = _strips()
    start = MeshVAEModel("coords", TrainConfig(epochs=5, early_stopping=False, progress=False)).fit(coll)
    d = describe_model(start)
    assert (d["start"], d["hidden"], d["epochs"], d["epoch_budget"], d["early_stopping"]) == ("PCA", (), 5, 5, False)
    assert d["features"] == "coords" and d["n_features"] == 54 and d["used_dims"] <= d["latent_dim"]
    assert len(start.history_) == 5 and d["mse_first"] == start.history_[0]["mse"] and d["mse_last"] == start.history_[-1]["mse"]
    text = model_summary(start)
    assert "the PCA of the training features" in text and "5 of 5 epochs (a fixed budget)" in text
    assert "no internal layer" in text and "K = 54" in text

    rand = MeshVAEModel("coords", TrainConfig(epochs=3, init="random", hidden=(8,), latent_dim=2,
                                               early_stopping=False, progress=False)).fit(coll)
    d = describe_model(rand)
    assert (d["start"], d["hidden"], d["latent_dim"]) == ("random", (8,), 2)
    assert "internal layers 8" in model_summary(rand) and "random weights" in model_summary(rand)

    # latent 8 below the 29 training rows' rank: the PCA start can move, early stopping searches
    chosen = MeshVAEModel("rimd", TrainConfig(progress=False, latent_dim=8), holdout_every=4).fit(_strips(40))
    d = describe_model(chosen)
    assert d["early_stopping"] and not d["search_skipped"]
    assert d["epochs"] == len(chosen.history_) - (d["epochs"] == 0) == chosen.train_epochs_
    if d["epochs"] == 0:
        assert d["mse_first"] == d["mse_last"] and "(chosen by early stopping): the model is its start" in model_summary(chosen)
    else:
        assert f"{d['epochs']} of 1000 epochs (chosen by early stopping)" in model_summary(chosen)
    portable = model_summary(chosen, portable=True)
    assert "early stopping ended it within the budget of 1000 epochs" in portable and f"{d['epochs']} of 1000" not in portable
    assert f"{d['mse_last']:.2g} after the last" in portable and len(portable.splitlines()) == 4
    # a fixed budget is no choice: portable keeps its count
    assert "5 of 5 epochs (a fixed budget)" in model_summary(start, portable=True)
    # the default latent size holds every training row: the start is kept without a search
    kept = MeshVAEModel("rimd", TrainConfig(progress=False), holdout_every=4).fit(_strips(40))
    d = describe_model(kept)
    assert d["search_skipped"] and not d["early_stopping"] and d["epochs"] == 0 and d["mse_first"] == d["mse_last"]
    assert "0 of 1000 epochs (no epoch search: the start's span holds every training row): the model is its start" \
        in model_summary(kept)


def test_model_summary_refuses_an_unfitted_model():
    from meshvae_lib.course.display import model_summary
    from meshvae_lib.model.meshvae_model import MeshVAEModel
    from meshvae_lib.validation import NotFittedError

    with pytest.raises(NotFittedError):
        model_summary(MeshVAEModel())


def test_local_parts_stretch_table_marks_the_ratios_over_the_limit_and_skips_unrecorded_collections():
    from meshvae_lib.course.display import local_parts_stretch_table

    stretch = {"held_out": 0.02, "mixed_ratio": 1.62, "mixed_ratio_5": 1.01, "prior_ratio": 1.5}
    records = [{"collection": "pdance/3", "source": "real", "variants": {"4:spectral": {"stretch": stretch}}},
               {"collection": "scape", "source": "synthetic", "variants": {"4:spectral": {}}}]
    lines = local_parts_stretch_table(records, "4:spectral").splitlines()
    assert len(lines) == 2 and lines[0].split()[:4] == ["collection", "held", "out", "any"]
    assert lines[1].split() == ["pdance/3", "(real)", "0.020", "1.62*", "1.01", "1.50"]   # 1.5 is not over 1.5
    assert local_parts_stretch_table(records, "4:spectral", limit=1.0).splitlines()[1].split()[3:] == ["1.62*", "1.01*", "1.50*"]
