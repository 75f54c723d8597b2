"""The floor figures of notebook 09: per-mesh errors sorted by the floor's, and ratios to the floor as bars."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from meshvae_lib.viewing.floor_figures import floor_ratio_figure, per_mesh_error_figure  # noqa: E402


@pytest.fixture
def errors():
    floor = np.array([3.0, 1.0, 2.0, 5.0])
    return {"PCA": floor, "tracks": 1.01 * floor, "below": np.array([0.1, 0.2, 0.3, 0.4])}


def test_per_mesh_lines_follow_the_floors_order(errors):
    fig = per_mesh_error_figure(errors, floor="PCA", names=["a", "b", "c", "d"])
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    order = [1, 2, 0, 3]   # increasing floor error
    assert np.array_equal(lines["PCA"].get_ydata(), errors["PCA"][order])
    assert np.all(np.diff(lines["PCA"].get_ydata()) >= 0), "the floor rises from left to right"
    assert np.allclose(lines["tracks"].get_ydata(), 1.01 * lines["PCA"].get_ydata()), "a column keeps its pairing with the floor"
    assert np.array_equal(lines["below"].get_ydata(), errors["below"][order])
    assert [t.get_text() for t in ax.get_xticklabels()] == ["b", "c", "a", "d"]
    assert lines["PCA"].get_linestyle() == "--" and lines["below"].get_marker() not in (None, "None", "")
    assert ax.get_yscale() == "log"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["PCA", "tracks", "below"]
    assert min(t.get_fontsize() for t in ax.get_xticklabels() + ax.get_yticklabels()) >= 10


def test_per_mesh_rejects_what_it_cannot_draw(errors):
    with pytest.raises(ValueError, match="floor"):
        per_mesh_error_figure(errors, floor="nope")
    with pytest.raises(ValueError, match="positive finite"):
        per_mesh_error_figure({**errors, "short": [1.0, 2.0]}, floor="PCA")
    with pytest.raises(ValueError, match="positive finite"):
        per_mesh_error_figure({**errors, "zero": [0.0, 1.0, 1.0, 1.0]}, floor="PCA")
    with pytest.raises(ValueError, match="names"):
        per_mesh_error_figure(errors, floor="PCA", names=["a"])


def test_ratio_bars_have_the_ratios_heights_and_a_line_at_one():
    ratios = {"scape": {"encoder": 2.6, "Gauss-Newton": 0.23}, "hand": {"encoder": 7.5, "Gauss-Newton": 0.69},
              "bar": {"encoder": 24.9}}
    fig = floor_ratio_figure(ratios, title="t")
    ax = fig.axes[0]
    heights = [p.get_height() for p in ax.patches]
    assert np.allclose(heights[:3], [2.6, 7.5, 24.9]), "the encoder's bars, one per row, in the rows' order"
    assert np.allclose(heights[3:5], [0.23, 0.69]) and np.isnan(heights[5]), "a missing cell leaves a gap"
    ones = [ln for ln in ax.get_lines() if np.allclose(ln.get_ydata(), 1.0)]
    assert len(ones) == 1 and ones[0].get_linestyle() == "--", "the floor: one dashed line at 1"
    assert ax.get_yscale() == "log" and ax.get_ylim()[0] < 0.23 and ax.get_ylim()[1] > 24.9
    assert [t.get_text() for t in ax.get_xticklabels()] == ["scape", "hand", "bar"]
    texts = {t.get_text() for t in ax.texts}
    assert {"2.6", "0.23", "25", "0.69"} <= texts, "each bar's value written above it"
    assert [t.get_text() for t in ax.get_legend().get_texts()][:2] == ["encoder", "Gauss-Newton"]


def test_ratio_bars_reject_non_positive_ratios():
    with pytest.raises(ValueError):
        floor_ratio_figure({})
    with pytest.raises(ValueError, match="positive"):
        floor_ratio_figure({"a": {"x": 0.0}})
    with pytest.raises(ValueError, match="positive"):
        floor_ratio_figure({"a": {"x": float("inf")}})
