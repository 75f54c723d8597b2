"""The one-ring drawing of notebook 01: the edge, its two opposite angles and the normal edge."""

import matplotlib
import numpy as np
import pytest

from meshvae_lib.geometry.cotangent import cotangent_weights
from meshvae_lib.geometry.topology import edge_index, edges
from meshvae_lib.viewing.one_ring_figure import one_ring_figure, opposite_apexes

matplotlib.use("Agg")


def _hexagon_cap(height=0.1):
    """A vertex 0 at height ``height`` above a regular hexagon of unit radius: six triangles."""
    ang = np.arange(6) * np.pi / 3
    V = np.vstack([[0.0, 0.0, height], np.stack([np.cos(ang), np.sin(ang), np.zeros(6)], axis=1)])
    F = np.array([[0, 1 + k, 1 + (k + 1) % 6] for k in range(6)])
    return V, F


def test_the_apexes_opposite_an_edge():
    V, F = _hexagon_cap()
    a, b = opposite_apexes(F, 0, 1)
    assert {a, b} == {2, 6}
    with pytest.raises(ValueError, match="two triangles"):
        opposite_apexes(F, 1, 2)   # a boundary edge of the cap


def test_the_figure_marks_both_angles_the_edge_and_the_normal_edge():
    V, F = _hexagon_cap()
    fig = one_ring_figure(V, F, 0, 1)
    left, right = fig.axes
    gids = {p.get_gid() for p in left.patches} | {line.get_gid() for line in left.lines}
    assert {"alpha", "beta", "edge-ij"} <= gids
    assert "normal-edge" in {p.get_gid() for p in right.patches}
    # the title quotes the library's cotangent weight of the edge, to two decimals
    c = float(cotangent_weights(V, F, clamp=False)[edge_index(edges(F), 0, 1)])
    assert f"= {c:.2f}" in left.get_title()
    labels = " ".join(t.get_text() for t in left.texts)
    assert "60°" in labels or "61°" in labels or "59°" in labels   # near-equilateral triangles
    assert min(t.get_fontsize() for ax in fig.axes for t in ax.texts) >= 9
    with pytest.raises(ValueError, match="not a neighbour"):
        one_ring_figure(V, F, 1, 4)
