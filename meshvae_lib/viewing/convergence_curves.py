"""Validation curves of models trained until they stop improving, drawn so that their ends can be read
(the recorded converged tables of ``docs/results``).

:func:`convergence_figure` draws a recorded experiment's validation curves (``results.json``:
``tables[name]["validation_curves"]``, row -> model -> ``epochs``, ``val_mse``, ``chosen``) as one
panel per model kind (an input feature, a latent size), one coloured line per row (a collection).
Each curve is divided by its own best value, so every curve reaches 1 at its chosen epoch (a dot)
whatever its units, and a curve that stopped by patience ends flat, a run of epochs to the right of
its dot without going below 1. The y axis is logarithmic and cut at ``ymax`` times the best value:
the start of training lies above it, the end, which the figure is about, fills the panel.
"""

from __future__ import annotations

import numpy as np

__all__ = ["convergence_figure", "epochs_past_best"]


def epochs_past_best(curves, rows=None) -> dict:
    """How many epochs each curve ran after its chosen (best) epoch: ``{(row, kind): epochs}``."""
    rows = list(curves) if rows is None else list(rows)
    return {(r, k): int(c["epochs"][-1]) - int(c["chosen"]) for r in rows for k, c in curves[r].items()}


def convergence_figure(curves, rows=None, titles=None, ymax: float = 10.0, figsize=(11.0, 3.9)):
    """Validation curves over their best value: one panel per model kind, one line per row.

    Parameters
    ----------
    curves : dict
        row -> kind -> ``{"epochs": [...], "val_mse": [...], "chosen": int}`` (as recorded by
        ``meshvae_lib.paper.protocol.validation_curve``).
    rows : list of str, optional
        The rows to draw, in this order (default: all).
    titles : dict, optional
        kind -> panel title (default: the kind itself).
    ymax : float
        The top of the y axis, in multiples of each curve's best value.

    Returns
    -------
    matplotlib.figure.Figure
        One axis per kind, titled; on each, one line per row (labelled with the row's name, the
        same colour in every panel), a dot at the chosen epoch, a dashed line at 1 (each curve's
        best); the legend on the last axis. Fonts of at least 10 pt.
    """
    import matplotlib.pyplot as plt

    rows = list(curves) if rows is None else list(rows)
    if not rows:
        raise ValueError("no rows to draw")
    kinds = list(curves[rows[0]])
    titles = titles or {}
    colors = plt.get_cmap("tab10").colors
    fig, axes = plt.subplots(1, len(kinds), figsize=figsize, sharey=True, squeeze=False, layout="constrained")
    for ax, kind in zip(axes[0], kinds):
        for i, row in enumerate(rows):
            c = curves[row][kind]
            epochs, val = np.asarray(c["epochs"], dtype=float), np.asarray(c["val_mse"], dtype=float)
            rel = val / val.min()
            ax.plot(epochs, rel, color=colors[i % len(colors)], lw=1.6, label=row)
            at = int(np.argmin(np.abs(epochs - c["chosen"])))
            ax.plot(epochs[at], rel[at], "o", color=colors[i % len(colors)], ms=7, mec="k", mew=0.6)
        ax.axhline(1.0, color="0.4", ls="--", lw=1)
        ax.set_yscale("log")
        ax.set_ylim(0.9, ymax)
        ticks = [t for t in (1, 1.5, 2, 3, 5, 10, 20, 50, 100) if t <= ymax]
        ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
        ax.yaxis.set_minor_locator(plt.NullLocator())
        ax.set_title(titles.get(kind, kind), fontsize=12)
        ax.set_xlabel("epoch", fontsize=11)
        ax.tick_params(labelsize=10)
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("validation MSE / its best", fontsize=11)
    axes[0][-1].legend(fontsize=10, loc="upper right", title="dot: chosen epoch", title_fontsize=10)
    return fig
