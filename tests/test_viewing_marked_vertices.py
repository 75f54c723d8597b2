"""Marked vertices (notebook 01's "where are the bad T_i"): circled where they are, counted."""

import matplotlib
import numpy as np
import pytest

from meshvae_lib.viewing.marked_vertices import marked_vertices_figure
from meshvae_lib.viewing.render import view_basis

matplotlib.use("Agg")


def _tetra():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return V, F


def test_each_panel_circles_its_own_vertices_and_counts_them():
    V, F = _tetra()
    fig = marked_vertices_figure(np.stack([V, V + 1]), F, [np.array([True, False, False, True]), [2]],
                                 titles=["a", "b"], legend="marked")
    axes = fig.axes[:2]
    assert axes[0].get_title() == "a\n2 vertices marked" and axes[1].get_title() == "b\n1 vertex marked"
    R = view_basis((10, 0))
    for ax, expected in zip(axes, [V[[0, 3]], (V + 1)[[2]]]):
        marks = [c for c in ax.collections if c.get_gid() == "marks"]
        assert len(marks) == 1
        np.testing.assert_allclose(marks[0].get_offsets(), (expected @ R.T)[:, :2])
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["marked"]


def test_the_marks_must_match_the_meshes():
    V, F = _tetra()
    with pytest.raises(ValueError, match="2 sets of marks for 1 meshes"):
        marked_vertices_figure(V, F, [[0], [1]])
    with pytest.raises(ValueError, match="must be 4 booleans"):
        marked_vertices_figure(V, F, [np.ones(3, dtype=bool)])
