"""One matplotlib figure per experiment (``ExperimentTable.plot()``), each axis saying what it shows.

The bar and line plots read the table's rows, so they also draw a table read back by
:func:`~meshvae_lib.paper.tables.read_results`; the loss curves and the embeddings need the
table's ``data`` (a live run).
"""

from __future__ import annotations

import textwrap

import numpy as np

__all__ = ["plot_table", "plot_validation_curves", "PLOTS"]

#: the y label of the error plots: the tables' numbers, the mean vertex distance after alignment.
ERROR_LABEL = "held-out per-vertex error (mesh units)"


def _figure(w=6.4, h=4.0):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(w, h), dpi=100)
    fig.set_layout_engine("constrained")
    return fig


def _bars(ax, table, columns, ylabel: str, labels=None, log: bool = False, ticks=None) -> None:
    """Grouped bars on ``ax``: one group per row (tick: ``ticks`` or the row's first cell), one bar
    per column (legend: ``labels`` or the column names); missing cells leave a gap."""
    x = np.arange(len(table.rows))
    w = 0.8 / max(len(columns), 1)
    for i, col in enumerate(columns):
        values = [np.nan if v is None else float(v) for v in table.column(col)]
        ax.bar(x + i * w, values, w, label=labels[i] if labels else col)
    ax.set_xticks(x + 0.4 - w / 2)
    ax.set_xticklabels(ticks or [str(r[0]) for r in table.rows], rotation=20, ha="right", fontsize=8)
    if log:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel, fontsize=8)
    ax.legend(fontsize=7)


def _bar_panels(table, panels, width=6.4, height=4.0, ticks=None):
    """A figure of bar panels side by side; ``panels``: (columns, y label, options of :func:`_bars`)."""
    fig = _figure(width, height)
    for i, (columns, ylabel, options) in enumerate(panels):
        _bars(fig.add_subplot(1, len(panels), i + 1), table, columns, ylabel, ticks=ticks, **options)
    fig.suptitle(table.title, fontsize=9)
    return fig


def _row_ticks(table) -> list[str]:
    """Each row's first cell, with "(linear data)" under it where the row is not informative."""
    rows = table.as_dicts()
    return [str(r[table.columns[0]]) + ("\n(linear data)" if r.get("informative", "yes") != "yes" else "")
            for r in rows]


def plot_latent_size(table):
    """Table 1: the held-out error (as the table prints it) against the latent size, one line per
    collection, and its linear floor (PCA on coordinates) as a dashed line of the same colour."""
    fig = _figure()
    ax = fig.add_subplot(111)
    cols = [c for c in table.columns if c.startswith("ours D=")]
    dims = [int(c.split("=")[1]) for c in cols]
    for row, tick in zip(table.as_dicts(), _row_ticks(table)):
        name = tick.replace("\n", " ")
        line, = ax.plot(dims, [row[c] for c in cols], "o-", label=f"{name} (ours)")
        if row.get("PCA coords") is not None:
            ax.axhline(row["PCA coords"], color=line.get_color(), ls="--", lw=1,
                       label=f"{name}: PCA on coordinates (linear floor)")
    ax.set_xscale("log", base=2)
    ax.set_xticks(dims)
    ax.set_xticklabels([str(d) for d in dims])
    ax.set_yscale("log")
    ax.set_xlabel("latent dimension")
    ax.set_ylabel(ERROR_LABEL)
    ax.legend(fontsize=7)
    ax.set_title(table.title, fontsize=9)
    return fig


def plot_features(table):
    """Table 2: our held-out error per collection and input feature, beside the linear floor (PCA on
    coordinates and on aligned coordinates); rows on linear data say so under their name."""
    cols = [c for c in table.columns if c.startswith("ours ")]
    floors = [c for c in ("PCA coords", "PCA aligned") if c in table.columns]
    labels = [c[5:] for c in cols] + [f"{c} (linear floor)" for c in floors]
    fig = _bar_panels(table, [(cols + floors, ERROR_LABEL, {"labels": labels, "log": True})], width=9.5,
                      ticks=_row_ticks(table))
    fig.axes[0].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))  # beside the bars, not over them
    return fig


def plot_robustness(table):
    """Table 3: our held-out error per reference mesh and density, beside the linear floor (PCA on
    coordinates) and the paper's (Dyna)."""
    ticks = [f"{r['base mesh']}, {r['points']} pts" for r in table.as_dicts()]
    floors = [c for c in ("PCA coords",) if c in table.columns]
    return _bar_panels(table, [(["error", *floors, "paper error"], ERROR_LABEL,
                                {"labels": ["ours", *(f"{c} (linear floor)" for c in floors),
                                            "paper (Dyna chicken wings)"], "log": True})], ticks=ticks)


def plot_generation(table):
    """Sec. 5.2: nearest-neighbour distances, novelty and label match per model."""
    return _bar_panels(table, [
        (["median NN distance", "min NN distance", "training median NN distance"],
         "nearest-neighbour distance (RIMD features)", {}),
        (["median novelty"], "median novelty (NN distance / training median)", {}),
        (["label match"], "share whose nearest mesh has the asked label", {}),
    ], width=11.0)


def plot_interpolation(table):
    """Sec. 5.3: self-intersections and edge distortion per interpolation method."""
    return _bar_panels(table, [
        (["max self-intersections", "mean self-intersections"], "crossing triangle pairs per mesh",
         {"labels": ["max over the steps", "mean over the steps"]}),
        (["max edge distortion", "mean edge distortion"], "relative edge-length change vs nearest training mesh",
         {"labels": ["max over the steps", "mean over the steps"]}),
    ], width=9.0)


def plot_exploration(table):
    """Sec. 5.5: per latent dimension, the correlation of each measurement with the swept value."""
    cols = [c for c in table.columns if c.startswith("corr ")]
    ticks = [f"dim {d}" for d in table.column("dim")]
    return _bar_panels(table, [(cols, "correlation with the swept latent value", {"labels": [c[5:] for c in cols]})],
                       ticks=ticks)


def plot_loss(table):
    """Sec. 5.1: the training MSE per epoch of the MSE and the cross-entropy model."""
    fig = _figure()
    ax = fig.add_subplot(111)
    for key, label in (("mse_history", "MSE model"), ("bce_history", "BCE model")):
        ax.semilogy(np.arange(1, len(table.data[key]) + 1), table.data[key], label=label)
    ax.set_xlabel("epoch")
    ax.set_ylabel("training MSE per feature (Eq. 3 units)")
    ax.legend(fontsize=8)
    ax.set_title(table.title, fontsize=9)
    return fig


def plot_embedding(table):
    """Sec. 5.4: the 2D embeddings coloured by each label, and the retrieval precision-recall curves."""
    Y = table.data["embeddings"]
    labels = table.data["labels"]
    n = len(Y)
    fig = _figure(2.3 * max(n, 4), 2.3 * len(labels) + 3.4)  # constrained: the legend gets a cell beside the curves
    grid = fig.add_gridspec(len(labels) + 1, n, height_ratios=[1] * len(labels) + [1.5])
    for r, (col, lab) in enumerate(labels.items()):
        cats, codes = np.unique(lab, return_inverse=True)
        for i, (m, y) in enumerate(Y.items()):
            ax = fig.add_subplot(grid[r, i])
            ax.scatter(y[:, 0], y[:, 1], c=codes, cmap="tab10", vmin=0, vmax=9, s=6)
            name = "\n".join(textwrap.wrap(m, 24))
            ax.set_title(f"{name}\ncolour: {col}" if r == 0 else f"colour: {col}", fontsize=8)
            ax.set_xticks([])
            ax.set_yticks([])
    split = max(n - 2, 1)
    ax = fig.add_subplot(grid[-1, :split])
    for m, res in table.data["curves"].items():
        ax.plot(res.recall, res.precision["mean"], label=f"{m} (AUC {res.auc['mean']:.3f})")
    ax.set_xlabel("recall")
    ax.set_ylabel("precision (mean over the labels)")
    key = fig.add_subplot(grid[-1, split:])
    key.axis("off")
    key.legend(*ax.get_legend_handles_labels(), fontsize=7, loc="center left")
    ax.set_title("retrieval precision-recall (labels: " + ", ".join(labels) + ")", fontsize=9)
    return fig


def plot_validation_curves(table):
    """A converged table's validation curves (``data["validation_curves"]``: collection -> kind -> ``epochs``,
    ``val_mse``, ``chosen``): one panel per collection, one line per input kind, the chosen epoch
    marked; a curve that ends flat stopped by patience, not by the epoch limit."""
    curves = table.data["validation_curves"]
    fig = _figure(2.6 * len(curves), 2.8)
    for i, (name, kinds) in enumerate(curves.items()):
        ax = fig.add_subplot(1, len(curves), i + 1)
        for kind, c in kinds.items():
            line, = ax.semilogy(c["epochs"], c["val_mse"], label=kind, lw=1)
            best = int(np.argmin(c["val_mse"]))
            ax.plot(c["epochs"][best], c["val_mse"][best], "o", color=line.get_color(), ms=3)
        ax.set_title(name, fontsize=8)
        ax.set_xlabel("epoch", fontsize=7)
        ax.tick_params(labelsize=6)
        if i == 0:
            ax.set_ylabel("validation MSE (Eq. 3 units)", fontsize=7)
            ax.legend(fontsize=6)
    fig.suptitle(table.title + ": validation curves (dot: the chosen epoch)", fontsize=8)
    return fig


def plot_noise_diversity(table):
    """When RIMD wins: each model's held-out error over PCA on coordinates against capture noise, one
    line per pose diversity and one panel per model; the dashed line is PCA (below it, the model wins)."""
    rows = table.as_dicts()
    levels = sorted({r["noise"] for r in rows})
    panels = (("coords / PCA", "coordinates (encoder)"), ("rimd / PCA", "RIMD (the paper's encoder)"),
              ("rimd, Gauss-Newton / PCA", "RIMD (default inference)"))
    fig = _figure(10.0, 3.4)
    for i, (col, title) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1, sharey=fig.axes[0] if i else None)
        for d in sorted({r["diversity"] for r in rows}):
            ys = [next(float(r[col]) for r in rows if r["diversity"] == d and r["noise"] == n) for n in levels]
            ax.plot(range(len(levels)), ys, "o-", label=f"pose diversity {d:g}")
        ax.axhline(1.0, color="k", ls="--", lw=1, label="PCA on coordinates")
        ax.set_yscale("log")
        ax.set_xticks(range(len(levels)))
        ax.set_xticklabels([f"{n:g}" for n in levels], fontsize=8)
        ax.set_xlabel("capture noise (fraction of the diagonal)", fontsize=8)
        ax.set_title(title, fontsize=9)
        if i == 0:
            ax.set_ylabel("held-out error / PCA's", fontsize=8)
    fig.axes[-1].legend(fontsize=7)
    fig.suptitle(table.title, fontsize=9)
    return fig


#: experiment (table name) -> its plot.
PLOTS = {
    "table1_latent_size": plot_latent_size,
    "table2_features": plot_features,
    "table2_features_converged": plot_features,
    "table3_robustness": plot_robustness,
    "loss_mse_vs_bce": plot_loss,
    "embedding_auc": plot_embedding,
    "generation": plot_generation,
    "interpolation": plot_interpolation,
    "exploration": plot_exploration,
    "noise_diversity": plot_noise_diversity,
    "noise_diversity_converged": plot_noise_diversity,
    "table1_latent_size_converged": plot_latent_size,
    "table3_robustness_converged": plot_robustness,
}


def plot_table(table):
    """The figure of ``table`` (its ``name`` picks the plot); ValueError for a table without one."""
    if table.name not in PLOTS:
        raise ValueError(f"no plot for experiment {table.name!r}; plots exist for {sorted(PLOTS)}")
    return PLOTS[table.name](table)
