"""The convergence figure of notebook 09: one panel per model kind, one line per row, dots at the chosen epochs."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from meshvae_lib.viewing.convergence_curves import convergence_figure, epochs_past_best  # noqa: E402


def _curve(best_at, last, scale):
    epochs = list(range(0, last + 1, 10))
    val = [scale * (1 + 5 * max(0, best_at - e) / best_at + (0.05 if e > best_at else 0)) for e in epochs]
    return {"epochs": epochs, "val_mse": val, "chosen": best_at}


@pytest.fixture
def curves():
    return {"a": {"coords": _curve(100, 300, 1e-3), "rimd": _curve(200, 400, 5.0)},
            "b": {"coords": _curve(50, 250, 2.0), "rimd": _curve(300, 500, 1e-6)}}


def test_one_panel_per_kind_one_line_per_row_each_ending_at_its_best(curves):
    fig = convergence_figure(curves, titles={"coords": "raw coordinates"})
    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["raw coordinates", "rimd"]
    for ax in axes:
        lines = [ln for ln in ax.get_lines() if ln.get_label() in ("a", "b")]
        assert [ln.get_label() for ln in lines] == ["a", "b"]
        for ln in lines:   # divided by its best value: the minimum is 1, whatever the units
            assert np.isclose(np.min(ln.get_ydata()), 1.0)
        dots = [ln for ln in ax.get_lines() if ln.get_marker() == "o"]
        assert len(dots) == 2 and all(np.isclose(d.get_ydata()[0], 1.0) for d in dots)
        assert ax.get_yscale() == "log" and ax.get_ylim()[1] == 10.0
        assert ax.title.get_fontsize() >= 10 and ax.xaxis.label.get_fontsize() >= 10
    assert axes[-1].get_legend() is not None and axes[0].get_ylabel() == "validation MSE / its best"
    plt.close(fig)


def test_rows_chosen_and_ordered_and_epochs_past_best(curves):
    fig = convergence_figure(curves, rows=["b"])
    assert [ln.get_label() for ln in fig.axes[0].get_lines() if ln.get_label() in ("a", "b")] == ["b"]
    plt.close(fig)
    assert epochs_past_best(curves) == {("a", "coords"): 200, ("a", "rimd"): 200, ("b", "coords"): 200, ("b", "rimd"): 200}
    with pytest.raises(ValueError):
        convergence_figure(curves, rows=[])
