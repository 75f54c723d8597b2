"""The RIMD diagrams of notebook 02 and the normalisation margins of notebook 03 draw what they say."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from meshvae_lib.geometry.rimd import RIMDEncoder
from meshvae_lib.geometry.topology import edges
from meshvae_lib.viewing.normalization_margins import normalization_margin_figure
from meshvae_lib.viewing.rimd_diagrams import feature_layout_figure, polar_decomposition_figure

from geometry_fixtures import icosphere


def _texts(fig):
    return [t.get_text() for ax in fig.axes for t in (*ax.texts, ax.title)]


def test_the_polar_figure_names_the_stretches_and_the_turn():
    th = np.radians(40)
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    fig = polar_decomposition_figure(R @ np.diag([1.5, 0.7]))
    titles = [ax.get_title() for ax in fig.axes]
    assert titles == ["reference one-ring", "S: stretch by 1.50 and 0.70", "R S = T: then turn by 40°"]
    assert len(fig.axes[1].patches) + len(fig.axes[1].texts) >= 2, "the eigenvectors of S are drawn as arrows"
    with pytest.raises(ValueError):
        polar_decomposition_figure(np.diag([1.0, -1.0]))


def test_the_layout_figure_marks_both_directions_and_the_vertex():
    V, F = icosphere(1)
    lay = RIMDEncoder(V, F).layout
    i, j = (int(k) for k in edges(F)[3])
    texts = " ".join(_texts(feature_layout_figure(lay, (i, j))))
    assert f"log dR_{i},{j} at f[{int(lay.edge_feature_index(i, j)[0])}]" in texts
    assert f"log dR_{j},{i} at f[{int(lay.edge_feature_index(j, i)[0])}]" in texts
    assert f"S_{i} at f[{int(lay.vertex_feature_index(i)[0])}]" in texts
    assert f"{lay.scaling_slice.stop - lay.scaling_slice.start} numbers" in texts


def test_the_margin_figure_shows_where_outputs_of_one_decode():
    values = np.array([0.0, 0.2, 0.5, 1.0])
    fig = normalization_margin_figure(values, a=0.9)
    texts = " ".join(_texts(fig))
    top = 1.0 + 0.1 / 1.8                       # (1 - a) / (2a) of the range beyond the maximum
    assert f"output +1 decodes to {top:.3g}" in texts and f"output -1 decodes to {-0.1 / 1.8:.3g}" in texts
    assert "[-0.9, 0.9]" in texts
    assert len(fig.axes[0].patches) == 3 and len(fig.axes[1].patches) == 3, "two margins and the data span per line"
    with pytest.raises(ValueError):
        normalization_margin_figure(np.ones(3))
