"""Learned errors drawn beside the linear floor (notebook 09).

:func:`per_mesh_error_figure` draws the held-out error of several columns (PCA on coordinates, a
model through its encoder, the same model through Gauss-Newton inference, ...) mesh by mesh, the
meshes sorted by the floor's error, so that a column that tracks the floor, one that scatters
around it and one far below it are told apart at a glance. :func:`floor_ratio_figure` draws
recorded errors divided by their floor as grouped bars on a logarithmic axis with a line at 1:
below the line a column beats PCA on coordinates at equal capacity.
"""

from __future__ import annotations

import numpy as np

__all__ = ["per_mesh_error_figure", "floor_ratio_figure"]

#: markers of the columns, in order (the floor is drawn as a dashed black line instead).
_MARKERS = ("s", "^", "v", "D", "o", "P", "X")


def per_mesh_error_figure(errors, floor: str, names=None, ylabel: str = "held-out error (mesh units)",
                          title: str | None = None, size=(9.5, 4.0)):
    """Each column's error on each held-out mesh, the meshes sorted by the floor's error.

    Parameters
    ----------
    errors : dict
        column label -> (M,) float, the error of that column on each of the same M meshes (e.g.
        ``evaluate_model(...)["per_mesh"]``); every value positive and finite.
    floor : str
        The label in ``errors`` of the linear floor; drawn as a dashed black line, the other
        columns as markers joined by thin lines, in the order of ``errors``.
    names : sequence of M str, optional
        Tick labels of the meshes (default: their positions 0 .. M-1).
    ylabel, title : str
    size : (width, height) in inches

    Returns
    -------
    matplotlib.figure.Figure
        One axis, logarithmic y; x runs over the meshes in the order of increasing floor error
        (ties keep their order), each line's y data is its column's errors in that order; the
        legend lists the columns in the order of ``errors``. Fonts of at least 10 pt. Not
        registered with pyplot.
    """
    from matplotlib.figure import Figure

    cols = {str(k): np.asarray(v, dtype=np.float64).ravel() for k, v in errors.items()}
    if floor not in cols:
        raise ValueError(f"the floor {floor!r} is not one of the columns {list(cols)}")
    m = len(cols[floor])
    bad = [k for k, v in cols.items() if len(v) != m or not np.all(np.isfinite(v)) or np.any(v <= 0)]
    if m == 0 or bad:
        raise ValueError(f"every column needs {m} positive finite errors, one per mesh; not so for {bad}")
    labels = [str(i) for i in range(m)] if names is None else [str(n) for n in names]
    if len(labels) != m:
        raise ValueError(f"{len(labels)} names for {m} meshes")
    order = np.argsort(cols[floor], kind="stable")
    fig = Figure(figsize=size, dpi=100, layout="constrained")
    ax = fig.add_subplot(111)
    x = np.arange(m)
    markers = iter(_MARKERS * (1 + len(cols) // len(_MARKERS)))
    for label, values in cols.items():
        if label == floor:
            ax.plot(x, values[order], "k--", lw=2, label=label, zorder=3)
        else:
            ax.plot(x, values[order], marker=next(markers), ms=7, lw=0.8, label=label)
    ax.set_yscale("log")
    ax.set_xticks(x, [labels[i] for i in order], rotation=45, ha="right", fontsize=10)
    ax.set_xlabel("held-out mesh (sorted by the floor's error)", fontsize=11)
    ax.set_ylabel(ylabel, fontsize=11)
    ax.tick_params(axis="y", labelsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=10, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        ax.set_title(title, fontsize=12)
    return fig


def floor_ratio_figure(ratios, title: str | None = None, ylabel: str = "error / PCA on coordinates",
                       floor_label: str = "linear floor (PCA on coordinates)", size=(9.5, 4.0)):
    """Errors over their linear floor as grouped bars, with the floor as a line at 1.

    Parameters
    ----------
    ratios : dict
        row label (a collection) -> column label -> float, the column's error divided by the row's
        floor (positive and finite; a missing column or None leaves a gap). Every row's columns
        are drawn in the order of first appearance over the rows.
    title, ylabel, floor_label : str
    size : (width, height) in inches

    Returns
    -------
    matplotlib.figure.Figure
        One axis, logarithmic y: one group of bars per row (ticks: the row labels), one bar per
        column (the legend lists the columns, then the floor), each bar's height the ratio; a
        dashed black line at 1 and the value written above each bar (2 significant digits).
        Fonts of at least 10 pt. Not registered with pyplot.
    """
    from matplotlib.figure import Figure

    rows = {str(r): dict(c) for r, c in ratios.items()}
    if not rows:
        raise ValueError("no rows to draw")
    columns = list(dict.fromkeys(str(c) for cells in rows.values() for c in cells))
    values = np.array([[np.nan if rows[r].get(c) is None else float(rows[r][c]) for c in columns] for r in rows])
    given = values[np.isfinite(values)]
    if given.size == 0 or np.any(given <= 0) or np.isinf(values).any():
        raise ValueError("every ratio must be positive and finite")
    fig = Figure(figsize=size, dpi=100, layout="constrained")
    ax = fig.add_subplot(111)
    x = np.arange(len(rows))
    width = 0.8 / len(columns)
    for j, column in enumerate(columns):
        bars = ax.bar(x + (j - (len(columns) - 1) / 2) * width, values[:, j], width, label=column)
        for bar, v in zip(bars, values[:, j]):
            if np.isfinite(v):
                ax.annotate(f"{v:.2g}", (bar.get_x() + bar.get_width() / 2, v), ha="center", va="bottom", fontsize=10)
    line = ax.axhline(1.0, color="k", ls="--", lw=1.5, label=floor_label)
    ax.set_yscale("log")
    lo, hi = float(given.min()), float(given.max())
    ax.set_ylim(min(lo, 1.0) / 1.6, max(hi, 1.0) * 2.0)
    ax.set_xticks(x, list(rows), fontsize=10)
    ax.set_ylabel(ylabel, fontsize=11)
    ax.tick_params(axis="y", labelsize=10)
    ax.grid(alpha=0.3, axis="y", which="both")
    handles = [c for c in ax.containers] + [line]   # the columns first, then the floor
    ax.legend(handles, [h.get_label() for h in handles], fontsize=10, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    if title:
        ax.set_title(title, fontsize=12)
    return fig
