"""Printing numbers in a lesson so that its stored outputs are the same on every machine.

Round-off (an error of 1e-15 on one CPU, 3e-16 on another) is printed as a bound, not as its
digits; everything above the bound is printed as usual. A choice among values that tie up to
round-off (two frames of a periodic motion) is made by a stated rule, not by the last bits.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import DEFAULT_ARCHITECTURE
from meshvae_lib.tolerances import TIE_RTOL

__all__ = ["roundoff", "first_argmax", "real_inference_table", "real_feature_table", "span_ceiling_table",
           "spiral_table", "spiral_figure", "local_parts_table", "local_parts_figure",
           "local_parts_stretch_table", "describe_model", "model_summary"]

#: the columns of :func:`spiral_table` and :func:`spiral_figure`: (record key, inference, label).
_SPIRAL_COLUMNS = (("pca", None, "PCA coords"), ("spiral", "encoder", "spiral enc"),
                   ("spiral", "gauss_newton", "spiral GN"), ("rimd_equal", "encoder", "RIMD enc"),
                   ("rimd_equal", "gauss_newton", "RIMD GN"), ("rimd_default", "gauss_newton", "RIMD default"))


def roundoff(x: float, below: float = 1e-10) -> str:
    """``"< 1e-10"`` when ``|x| < below``, else ``x`` in the ``.1e`` format (``"3.2e-04"``).

    x : a real number (an error, a residual); below : float > 0, the bound under which the digits
    are round-off and differ between machines and library versions.
    """
    if not below > 0:
        raise ValueError(f"below must be > 0, got {below}")
    x = float(x)
    return f"< {below:.0e}" if abs(x) < below else f"{x:.1e}"


def first_argmax(values, rtol: float = TIE_RTOL) -> int:
    """The index of the largest value, ties broken by the earliest index: the first ``i`` with
    ``values[i] >= max - rtol * |max|``.

    values : (n,) finite reals, n >= 1; rtol : float >= 0, how close to the largest value (relative)
    counts as a tie. ``np.argmax`` also returns the first of equal values, but two frames of a
    periodic motion that tie mathematically differ in their last bits, and which one is larger
    then depends on the CPU and its BLAS kernels (notebook 00: frames 30 and 90 of the jumping
    jacks, 8e-16 apart). Returns an int.
    """
    x = np.asarray(values, dtype=np.float64)
    if x.ndim != 1 or len(x) == 0:
        raise ValueError(f"values must be a non-empty 1-D array, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("values must be finite")
    if not rtol >= 0:
        raise ValueError(f"rtol must be >= 0, got {rtol}")
    top = x.max()
    return int(np.flatnonzero(x >= top - rtol * abs(top))[0])


def real_inference_table(rows) -> str:
    """The recorded real-mesh comparison (``docs/results/inference_real.json``'s ``rows``: dicts with
    ``collection``, ``paper_path`` (or None), ``encoder``, ``default``, ``pca_coords``,
    ``pca_aligned``) as a fixed-width table: held-out errors of the paper's path, the encoder, the
    default inference and PCA on coordinates and on aligned coordinates, then the first three
    divided by PCA on coordinates and the default divided by PCA on aligned coordinates. Recorded
    numbers, the same on every machine."""
    lines = [f"{'collection':10s} {'paper path':>10s} {'encoder':>9s} {'default':>9s} {'PCA coords':>10s}"
             f" {'PCA align':>9s} | / PCA coords: paper path, encoder, default | default / PCA aligned"]
    for r in rows:
        paper = r.get("paper_path")
        paper_path = "-" if paper is None else f"{paper:.2e}"
        paper_ratio = "-" if paper is None else f"{paper / r['pca_coords']:.2f}"
        lines.append(f"{r['collection']:10s} {paper_path:>10s} {r['encoder']:9.2e} {r['default']:9.2e}"
                     f" {r['pca_coords']:10.2e} {r['pca_aligned']:9.2e} | {paper_ratio:>15s}"
                     f" {r['encoder'] / r['pca_coords']:8.2f} {r['default'] / r['pca_coords']:8.2f}"
                     f" | {r['default'] / r['pca_aligned']:8.2f}")
    return "\n".join(lines)


def real_feature_table(rows) -> str:
    """Table 2 on real meshes, recorded (``docs/results/inference_real.json``'s ``rows``: dicts with
    ``collection``, ``coords_default``, ``aligned_default``, ``default`` (RIMD), ``paper_path`` (RIMD
    the paper's way, or None), ``pca_coords``, ``pca_aligned``, ``floor_relative`` and ``informative``)
    as a fixed-width table: the three input kinds with the library's default training and inference,
    RIMD the paper's way, the linear floor, the floor over the diagonal, RIMD (default) over PCA on
    coordinates, and "yes" or "linear data: not informative". Recorded numbers, the same on every
    machine."""
    from meshvae_lib.paper.linear_floor import NOT_INFORMATIVE

    lines = [f"{'collection':10s} {'coords':>9s} {'aligned':>9s} {'RIMD':>9s} {'RIMD paper':>10s} {'PCA coords':>10s}"
             f" {'PCA align':>9s} {'floor/diag':>10s} {'RIMD/PCA':>8s}  informative"]
    for r in rows:
        paper = "-" if r.get("paper_path") is None else f"{r['paper_path']:.2e}"
        lines.append(f"{r['collection']:10s} {r['coords_default']:9.2e} {r['aligned_default']:9.2e} {r['default']:9.2e}"
                     f" {paper:>10s} {r['pca_coords']:10.2e} {r['pca_aligned']:9.2e} {r['floor_relative']:10.1e}"
                     f" {r['default'] / r['pca_coords']:8.2f}  {'yes' if r['informative'] else NOT_INFORMATIVE}")
    return "\n".join(lines)


def span_ceiling_table(rows) -> str:
    """How good a decoder of the default form can be on real meshes, recorded
    (``docs/results/inference_real.json``'s ``span_ceiling.rows``: dicts with ``collection``,
    ``n_meshes``, ``pca_coords``, ``feature_projection``, ``vertex_optimal``, ``default`` (mean
    held-out errors on the same meshes) and ``vertex_optimal_below_pca`` (how many of the meshes)),
    written by ``benchmarks/inference_span_oracle.py``: PCA on coordinates, the held-out feature
    projected onto the span of the training features, the span's point closest to the mesh in vertex
    error, and the default model, each also divided by PCA. Recorded numbers, the same on every
    machine."""
    lines = [f"{'collection':10s} {'meshes':>6s} {'PCA coords':>10s} {'projection':>10s} {'best in span':>12s}"
             f" {'default':>9s} | / PCA: projection, best in span, default | best below PCA"]
    for r in rows:
        pca = r["pca_coords"]
        lines.append(f"{r['collection']:10s} {r['n_meshes']:6d} {pca:10.2e} {r['feature_projection']:10.2e}"
                     f" {r['vertex_optimal']:12.2e} {r['default']:9.2e} | {r['feature_projection'] / pca:10.2f}"
                     f" {r['vertex_optimal'] / pca:6.2f} {r['default'] / pca:6.2f}"
                     f" | {r['vertex_optimal_below_pca']} of {r['n_meshes']}")
    return "\n".join(lines)


def _spiral_cell(r: dict, key: str, how) -> float:
    return float(r[key]) if how is None else float(r[key][how]["error"])


def spiral_table(records) -> str:
    """The spiral network beside the paper's network and PCA at one latent size, recorded
    (``docs/results/spiral_real.json``, written by ``benchmarks/spiral_comparison.py``: one dict per
    collection with ``collection``, ``source``, ``vertices``, ``latent`` D, ``pca`` (PCA on
    coordinates with D directions), ``pca_all`` (with every direction), and ``spiral``, ``rimd_equal``
    (RIMD at latent D), ``rimd_default`` (RIMD, latent resolved: more than D used dimensions), each
    with ``used``, ``train_seconds`` and the ``encoder`` and ``gauss_newton`` errors and
    ``n_meshes``) as a fixed-width table ("held": the held-out meshes measured); the default's column says how many dimensions it used. Recorded numbers, the
    same on every machine."""
    head = f"{'collection':22s} {'verts':>6s} {'held':>4s} {'D':>3s} " + " ".join(f"{label:>12s}" for _, _, label in _SPIRAL_COLUMNS)
    lines = [head + "  (dims of the default) | spiral GN / PCA, RIMD GN / PCA"]
    for r in records:
        cells = [_spiral_cell(r, k, h) for k, h, _ in _SPIRAL_COLUMNS]
        name = f"{r['collection']} ({'real' if r['source'] == 'real' else 'stand-in'})"
        held = r["spiral"]["gauss_newton"]["n_meshes"]
        lines.append(f"{name:22s} {r['vertices']:6d} {held:4d} {r['latent']:3d} " + " ".join(f"{c:12.2e}" for c in cells)
                     + f"  ({r['rimd_default']['used']:3d})             | {cells[2] / cells[0]:6.2f}, {cells[4] / cells[0]:6.2f}")
    return "\n".join(lines)


def spiral_figure(records):
    """Grouped bars of :func:`spiral_table` (log scale, one group per collection); the default's bar
    is hatched: it has more latent dimensions than the others. Returns the matplotlib figure."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.5, 3.6))
    width = 0.8 / len(_SPIRAL_COLUMNS)
    for j, (key, how, label) in enumerate(_SPIRAL_COLUMNS):
        values = [_spiral_cell(r, key, how) for r in records]
        ax.bar(np.arange(len(records)) + (j - (len(_SPIRAL_COLUMNS) - 1) / 2) * width, values, width, label=label,
               color=f"C{j}", hatch="//" if key == "rimd_default" else None, edgecolor="white" if key == "rimd_default" else None)
    ax.set_yscale("log")
    every = [_spiral_cell(r, k, h) for r in records for k, h, _ in _SPIRAL_COLUMNS]
    ax.set_ylim(min(every) / 2, max(every) * 6)  # room for the legend above the bars
    ax.set_xticks(np.arange(len(records)), [f"{r['collection']}\n{r['vertices']:,} vertices" for r in records])
    ax.set_ylabel("held-out mean vertex error")
    ax.set_title(f"latent size D = {records[0]['latent']} (the hatched default uses more)")
    ax.legend(ncol=3, fontsize=8, frameon=False)
    fig.tight_layout()
    return fig


#: the columns of :func:`local_parts_table` and :func:`local_parts_figure`: (label, value of a record and variant).
_LOCAL_COLUMNS = (("local parts", lambda r, v: v["error"]), ("regional PCA", lambda r, v: v["regional_pca"]),
                  ("global RIMD", lambda r, v: r.get("default_equal", r["default"])["error"]),
                  ("global PCA", lambda r, v: r["pca"]))


def local_parts_table(records, variant: str) -> str:
    """The local-parts network beside its linear floors and the global default, recorded
    (``docs/results/local_parts.json``, written by ``benchmarks/local_parts_comparison.py``: one dict
    per collection with ``collection``, ``source``, ``vertices``, ``n_evaluated``, ``latent``,
    ``pca`` (PCA on coordinates with ``pca_directions``), ``default`` (the global RIMD default:
    ``error``, ``used``), ``default_equal`` (the same network at ``latent``, present where the
    default has more dimensions) and ``variants``: ``"R:rule"`` -> ``error`` and ``regional_pca`` (PCA
    on coordinates with the same regions and directions)) for one ``variant``, as a fixed-width table
    of held-out mean vertex errors (the global RIMD column at equal capacity: ``default_equal`` where
    present, else the default) with the local model's ratios to each other column. Recorded numbers,
    the same on every machine."""
    head = f"{'collection':22s} {'verts':>6s} {'held':>4s} " + " ".join(f"{label:>14s}" for label, _ in _LOCAL_COLUMNS)
    lines = [head + "   local / regional PCA, / global RIMD, / global PCA"]
    for r in records:
        v = r["variants"][variant]
        cells = [f(r, v) for _, f in _LOCAL_COLUMNS]
        name = f"{r['collection']} ({'real' if r['source'] == 'real' else 'stand-in'})"
        dims = [str(v["used"]), str(v["regional_pca_directions"]), str(r.get("default_equal", r["default"])["used"]),
                str(r["pca_directions"])]
        lines.append(f"{name:22s} {r['vertices']:6d} {r['n_evaluated']:4d} "
                     + " ".join(f"{c:9.2e} ({d:>3s})" for c, d in zip(cells, dims))
                     + "   " + ", ".join(f"{cells[0] / c:5.2f}" for c in cells[1:]))
    return "\n".join(lines) + "\n(in brackets: latent dimensions or principal directions used)"


def local_parts_figure(records, variant: str):
    """Grouped bars of :func:`local_parts_table` (log scale, one group per collection). Returns the
    matplotlib figure."""
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.5, 3.4))
    width = 0.8 / len(_LOCAL_COLUMNS)
    every = []
    for j, (label, f) in enumerate(_LOCAL_COLUMNS):
        values = [f(r, r["variants"][variant]) for r in records]
        every += values
        ax.bar(np.arange(len(records)) + (j - (len(_LOCAL_COLUMNS) - 1) / 2) * width, values, width, label=label,
               color=f"C{j}")
    ax.set_yscale("log")
    ax.set_ylim(min(every) / 2, max(every) * 6)  # room for the legend above the bars
    ax.set_xticks(np.arange(len(records)), [f"{r['collection']}{'' if r['source'] == 'real' else ' (stand-in)'}"
                                            f"\n{r['vertices']:,} vertices" for r in records])
    ax.set_ylabel("held-out mean vertex error")
    ax.set_title(f"latent size {records[0]['latent']}: {variant.replace(':', ' regions, ')}")
    ax.legend(ncol=4, fontsize=8, frameon=False)
    fig.tight_layout()
    return fig


def local_parts_stretch_table(records, variant: str, limit: float = 1.5) -> str:
    """The recorded edge stretch of meshes that mix parts (``variants[variant]["stretch"]`` of
    ``docs/results/local_parts.json``, see :func:`local_parts_table`: ``held_out``, the mean relative
    edge-length change of held-out meshes against their nearest training mesh, and each kind of
    generated mesh's ratio to it: ``mixed_ratio``, every region's source among all training meshes;
    ``mixed_ratio_5``, among a base mesh's 5 nearest; ``prior_ratio``, prior samples). One line per
    collection that records them, ratios with 2 decimals; ``*`` marks a ratio over ``limit``.
    Recorded numbers, the same on every machine."""
    head = f"{'collection':22s} {'held out':>9s} {'any sources':>12s} {'5 nearest':>10s} {'prior':>7s}"
    lines = [head + f"   (ratios to the held-out stretch; * over {limit}x)"]
    for r in records:
        s = r["variants"][variant].get("stretch")
        if s is None:
            continue
        name = f"{r['collection']} ({'real' if r['source'] == 'real' else 'stand-in'})"
        marks = [f"{s[k]:.2f}{'*' if s[k] > limit else ' '}" for k in ("mixed_ratio", "mixed_ratio_5", "prior_ratio")]
        lines.append(f"{name:22s} {s['held_out']:9.3f} {marks[0]:>12s} {marks[1]:>10s} {marks[2]:>7s}".rstrip())
    return "\n".join(lines)


def describe_model(model) -> dict:
    """What a fitted :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` is, as plain values.

    Returns a dict: ``architecture`` (the network's registry name), ``network`` (what it is, in a few
    words: the network's ``describe()`` where it has one), ``features`` (the feature kind), ``n_features`` (K), ``latent_dim`` (D),
    ``used_dims`` (dimensions the decoder uses), ``hidden`` (internal layer sizes, outermost first;
    empty: one linear map each way), ``conditions`` (number of condition inputs), ``sigma_object``
    (True when a sigma_object prior was trained), ``start`` ("PCA" or "random"), ``epoch_budget``
    (the configured epochs), ``epochs`` (epochs the network was trained for), ``early_stopping``
    (True when early stopping chose them), ``search_skipped`` (True when the start was kept
    without a search, ``meshvae_lib.model.training.start_is_optimum``), ``mse_first`` and ``mse_last`` (the training
    reconstruction MSE of the first and the last history record; equal when not trained).
    """
    from meshvae_lib.validation import check_is_fitted

    check_is_fitted(model, ("network_", "train_config_", "history_"), "call fit(collection) or load_model(path) first")
    config = model.train_config_
    n_cond = int(model.n_conditions)
    history = model.history_
    net = model.network
    return {
        "architecture": str(config.architecture),
        "network": net.describe(),
        "features": str(model.features),
        "n_features": int(model.n_features),
        "latent_dim": int(model.latent_dim),
        "used_dims": int(len(model.used_latent_dims)),
        "hidden": tuple(int(h) for h in config.hidden),
        "conditions": n_cond,
        "sigma_object": config.sigma_object is not None,
        "start": "PCA" if config.uses_pca_init(n_cond) else "random",
        "epoch_budget": int(config.epochs),
        "epochs": int(model.train_epochs_),
        "early_stopping": model.selection_ is not None and "skipped" not in model.selection_,
        "search_skipped": model.selection_ is not None and "skipped" in model.selection_,
        "mse_first": float(history[0]["mse"]),
        "mse_last": float(history[-1]["mse"]),
    }


def model_summary(model, portable: bool = False) -> str:
    """A few lines that say which model a lesson uses: its network, its start, how long it trained
    and what training changed (see :func:`describe_model`). Training digits differ between
    machines: print it in a ``# NBVAL_IGNORE_OUTPUT`` cell.

    portable : leave out what is a choice among near-ties on another CPU -- the epoch count that
        early stopping chose (the epoch of lowest validation error on a flat curve) -- and print the
        training MSEs with two significant digits. Returns a str of four lines either way.
    """
    d = describe_model(model)
    layers = "no internal layer (one linear map each way)" if not d["hidden"] else \
        "internal layers " + " -> ".join(str(h) for h in d["hidden"])
    if d["architecture"] != DEFAULT_ARCHITECTURE:
        layers = f"{d['architecture']}, {d['network']}"
    extras = [f"{d['conditions']} condition inputs"] * bool(d["conditions"]) + ["a sigma_object prior"] * d["sigma_object"]
    start = "the PCA of the training features" if d["start"] == "PCA" else "random weights (PyTorch's initialisation)"
    chosen = ("no epoch search: the start's span holds every training row" if d["search_skipped"] else
              "chosen by early stopping" if d["early_stopping"] else "a fixed budget")
    digits = ".2g" if portable else ".3g"
    epochs = (f"early stopping ended it within the budget of {d['epoch_budget']} epochs" if portable and d["early_stopping"]
              else f"{d['epochs']} of {d['epoch_budget']} epochs ({chosen})")
    if d["epochs"] == 0:
        trained = f"{epochs}: the model is its start"
    else:
        change = d["mse_last"] / d["mse_first"] - 1 if d["mse_first"] > 0 else 0.0
        trained = (f"{epochs}; training MSE {d['mse_first']:{digits}} "
                   f"after the first epoch, {d['mse_last']:{digits}} after the last ({change:+.0%})")
    return "\n".join([
        f"features: {d['features']} (K = {d['n_features']}), latent {d['latent_dim']} ({d['used_dims']} used)",
        f"network:  {layers}" + "".join(", " + e for e in extras),
        f"start:    {start}",
        f"training: {trained}",
    ])
