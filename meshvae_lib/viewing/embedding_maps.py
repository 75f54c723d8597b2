"""2D embeddings of a labelled collection side by side (notebook 07, the paper's Fig. 7).

:func:`embedding_maps_figure` draws one column per map (the σ_object VAE's dimensions 1-2, PCA,
NPE, t-SNE, ...) and one row per label (body shape, motion): every mesh is a dot at its 2D
position, coloured by its value of the row's label, with one legend per row. With
``share_axes=True`` every panel has the same axis limits, so a map whose points have collapsed to
a spot looks like one.
"""

from __future__ import annotations

import numpy as np

__all__ = ["embedding_maps_figure"]


def embedding_maps_figure(maps: dict, labels: dict, share_axes: bool = False, panel_inches: float = 3.0,
                          fontsize: float = 10.0, point_size: float = 14.0):
    """Scatter plots of 2D embeddings, one column per map and one row per label.

    Parameters
    ----------
    maps : dict name -> (N, 2) float
        The embeddings, in column order.
    labels : dict label name -> (N,) values
        One row per label; the points are coloured by the label's value (at most 10 values).
    share_axes : bool
        Give every panel the same x and y limits (the union of all maps), so the maps' sizes
        compare; otherwise each panel is scaled to its own points.
    panel_inches, fontsize, point_size
        Size of one panel, of every text, of the dots.

    Returns
    -------
    matplotlib.figure.Figure
        ``len(labels) x len(maps)`` axes; the top row titled with the map names, the first column's
        y label "coloured by <label>", and one legend per row listing the label's values.

    Raises
    ------
    ValueError
        If a map is not (N, 2), a label does not have N values, or has more than 10 values.
    """
    import matplotlib.pyplot as plt

    if not maps or not labels:
        raise ValueError("need at least one map and one label")
    Y = {name: np.asarray(y, dtype=float) for name, y in maps.items()}
    n = len(next(iter(Y.values())))
    for name, y in Y.items():
        if y.shape != (n, 2):
            raise ValueError(f"map {name!r} must have shape ({n}, 2), got {y.shape}")
    rows = {}
    for label, values in labels.items():
        values = np.asarray(values)
        if values.shape != (n,):
            raise ValueError(f"label {label!r} must have {n} values, got shape {values.shape}")
        cats, codes = np.unique(values, return_inverse=True)
        if len(cats) > 10:
            raise ValueError(f"label {label!r} has {len(cats)} values; at most 10 can be told apart by colour")
        rows[label] = (cats, codes)
    fig, axes = plt.subplots(len(rows), len(Y), figsize=(panel_inches * len(Y) + 2.2, panel_inches * len(rows)),
                             squeeze=False)
    if share_axes:
        allpts = np.concatenate(list(Y.values()))
        lo, hi = allpts.min(axis=0), allpts.max(axis=0)
        pad = 0.05 * np.maximum(hi - lo, 1e-12)
        lims = [(lo[k] - pad[k], hi[k] + pad[k]) for k in range(2)]
    cmap = plt.get_cmap("tab10")
    for r, (label, (cats, codes)) in enumerate(rows.items()):
        for c, (name, y) in enumerate(Y.items()):
            ax = axes[r, c]
            ax.scatter(y[:, 0], y[:, 1], c=[cmap(k) for k in codes], s=point_size, linewidths=0)
            ax.set_xticks([])
            ax.set_yticks([])
            if share_axes:
                ax.set_xlim(*lims[0])
                ax.set_ylim(*lims[1])
            if r == 0:
                ax.set_title(name, fontsize=fontsize + 1)
            if c == 0:
                ax.set_ylabel(f"coloured by {label}", fontsize=fontsize)
        handles = [plt.Line2D([], [], marker="o", ls="", color=cmap(k), label=str(v)) for k, v in enumerate(cats)]
        axes[r, -1].legend(handles=handles, fontsize=fontsize - 1, loc="center left", bbox_to_anchor=(1.02, 0.5),
                           title=label, title_fontsize=fontsize)
    fig.tight_layout()
    return fig
