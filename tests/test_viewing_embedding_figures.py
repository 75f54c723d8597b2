"""Notebook 07's figures draw what they say: the embedding maps and the latent cost of one dimension."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest

from meshvae_lib.viewing.embedding_maps import embedding_maps_figure
from meshvae_lib.course.prior_costs import one_dimension_cost, prior_cost_figure


def _maps(n=30):
    rng = np.random.default_rng(0)
    return {"wide": rng.normal(size=(n, 2)), "collapsed": 0.01 * rng.normal(size=(n, 2))}


def test_the_maps_have_one_column_per_map_and_one_row_per_label():
    labels = {"shape": np.repeat(["a", "b", "c"], 10), "motion": np.tile(["x", "y"], 15)}
    fig = embedding_maps_figure(_maps(), labels)
    assert len(fig.axes) == 4
    assert [ax.get_title() for ax in fig.axes[:2]] == ["wide", "collapsed"]
    assert [fig.axes[0].get_ylabel(), fig.axes[2].get_ylabel()] == ["coloured by shape", "coloured by motion"]
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    assert [[t.get_text() for t in lg.get_texts()] for lg in legends] == [["a", "b", "c"], ["x", "y"]]
    assert all(len(ax.collections[0].get_offsets()) == 30 for ax in fig.axes), "every mesh is a dot"


def test_shared_axes_show_a_collapsed_map_as_a_spot():
    fig = embedding_maps_figure(_maps(), {"shape": np.repeat(["a", "b", "c"], 10)}, share_axes=True)
    wide, collapsed = fig.axes
    assert wide.get_xlim() == collapsed.get_xlim() and wide.get_ylim() == collapsed.get_ylim()
    with pytest.raises(ValueError):
        embedding_maps_figure({"bad": np.zeros((30, 3))}, {"shape": np.zeros(30)})
    with pytest.raises(ValueError):
        embedding_maps_figure(_maps(), {"too many": np.arange(30)})


def test_one_dimension_cost_is_the_closed_form():
    mu = np.array([0.0, 0.5, 1.0, 2.0])
    s = 0.1
    assert np.allclose(one_dimension_cost(mu, s, s, "exact"), 0.5 * mu**2 / s**2)
    assert np.allclose(one_dimension_cost(mu, s, s, "sibling"), 0.5 * mu**2)
    sig = np.array([0.05, 0.1, 1.0])
    r = (sig / s) ** 2
    assert np.allclose(one_dimension_cost(0.0, sig, s, "sibling"), 0.5 * (r - np.log(r) - 1))
    assert np.allclose(one_dimension_cost(0.0, sig, s, "exact"), one_dimension_cost(0.0, sig, s, "sibling"))


def test_the_cost_figure_draws_both_forms_and_both_widths():
    fig = prior_cost_figure(0.1)
    left, right = fig.axes
    assert left.get_title() == "cost of a mean (σ = s)"
    assert right.get_title() == "cost of a width (μ = 0), both forms"
    assert [t.get_text() for t in left.get_legend().get_texts()][0] == "exact KL, s = 0.1"
    assert [t.get_text() for t in right.get_legend().get_texts()] == ["s = 0.1", "s = 1"]
    exact, sibling = (line.get_ydata() for line in left.get_lines()[:2])
    assert exact.max() > 10 * sibling.max(), "the exact mean cost is 1/s^2 = 100 times steeper"
    for line, s in zip(right.get_lines()[::2], (0.1, 1.0)):
        x, y = line.get_xdata(), line.get_ydata()
        assert abs(np.log(x[np.argmin(y)] / s)) < 0.05, "each width cost is zero at sigma = s"
    with pytest.raises(ValueError):
        prior_cost_figure(1.5)
