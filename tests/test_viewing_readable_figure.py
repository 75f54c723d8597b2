"""readable_figure: every text of a finished figure at least the asked size, legends moved aside on request."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from meshvae_lib.viewing.readable_figure import readable_figure  # noqa: E402


def _small_figure():
    fig = Figure(figsize=(4, 3))
    ax = fig.add_subplot(111)
    ax.plot([1, 2, 3], [1, 4, 9], label="squares")
    ax.set_xticks([1, 2, 3], ["one", "two", "three"], fontsize=6)
    ax.tick_params(axis="y", labelsize=5)
    ax.set_ylabel("value", fontsize=7)
    ax.set_title("title", fontsize=8)
    ax.legend(fontsize=6)
    fig.suptitle("big one", fontsize=14)
    return fig, ax


def test_every_text_reaches_the_minimum_and_larger_ones_stay():
    fig, ax = _small_figure()
    out = readable_figure(fig, min_fontsize=10)
    assert out is fig
    sizes = [t.get_fontsize() for t in fig.findobj(Text) if t.get_text()]
    assert min(sizes) >= 10
    assert fig._suptitle.get_fontsize() == 14, "a larger text keeps its size"
    assert all(t.get_fontsize() >= 10 for t in ax.yaxis.get_ticklabels())
    assert ax.get_legend().get_texts()[0].get_text() == "squares"


def test_resize_and_legend_outside():
    fig, ax = _small_figure()
    readable_figure(fig, min_fontsize=9, size=(8, 3), legend_outside=True)
    assert tuple(fig.get_size_inches()) == (8, 3)
    legend = ax.get_legend()
    assert legend is not None and legend._loc == 2   # "upper left" of its anchor
    assert tuple(legend.get_bbox_to_anchor()._bbox.bounds[:2]) == (1.0, 1.0)
    with pytest.raises(ValueError):
        readable_figure(fig, min_fontsize=0)
