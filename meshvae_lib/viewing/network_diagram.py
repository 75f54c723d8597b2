"""The mesh VAE as a diagram: its layers left to right, each with its size (notebook 04).

:func:`network_layers` lists the stages of a :class:`~meshvae_lib.model.vae.MeshVAE` (read from its
``config()``, so that this layer needs nothing of the model layer) as plain values;
:func:`network_diagram` draws them with matplotlib, one row per network, so that a network
without internal layers can be set beside one with them.
"""

from __future__ import annotations

import math

__all__ = ["network_layers", "network_diagram"]


#: what :func:`network_layers` reads of a mesh VAE's ``config()``.
_CONFIG_KEYS = ("n_features", "latent_dim", "hidden", "n_conditions", "input_rank", "output")


def _mesh_vae_config(net) -> dict:
    """A mesh VAE network's ``config()``; TypeError naming the type for anything else."""
    try:
        config = net.config()
    except AttributeError:            # not a network
        config = None
    if not isinstance(config, dict) or not set(_CONFIG_KEYS) <= set(config):
        raise TypeError(f"expected a MeshVAE network (its config() has {', '.join(_CONFIG_KEYS)}),"
                        f" got {type(net).__name__}")
    return config


def network_layers(net) -> list[dict]:
    """The stages of a mesh VAE network, input to output.

    net : a :class:`~meshvae_lib.model.vae.MeshVAE` (a fitted model's is ``model.network``).
    Returns a list of dicts ``{"label", "size", "kind", "weights"}``: ``kind`` is "data" (the
    feature vector in and out), "fixed" (the PCA start's input projection, not trained), "hidden"
    (``Linear -> BatchNorm -> LeakyReLU``), "latent" (the heads mu and sigma, and z) or "output"
    (the decoder's last linear map and its activation); ``weights`` is the number of trained
    weights of the linear map that produces the stage (0 for the input and for z, the fixed
    projection's numbers for "fixed"). The encoder's two heads are one stage (label mu, sigma in
    matplotlib's mathtext) of size D (each).
    """
    config = _mesh_vae_config(net)
    K, D, C = int(config["n_features"]), int(config["latent_dim"]), int(config["n_conditions"])
    r, hidden = int(config["input_rank"]), [int(h) for h in config["hidden"]]
    stages = [{"label": "RIMD feature\n(normalised)", "size": K, "kind": "data", "weights": 0}]
    width = K
    if r:
        stages.append({"label": "PCA projection\n(fixed)", "size": r, "kind": "fixed", "weights": r * K + K})
        width = r
    width += C
    for h in hidden:
        stages.append({"label": "Linear, BatchNorm,\nLeakyReLU", "size": int(h), "kind": "hidden",
                       "weights": width * int(h) + int(h) + 2 * int(h)})
        width = int(h)
    stages.append({"label": "$\\mu$, $\\sigma$\n(encoder heads)", "size": D, "kind": "latent",
                   "weights": width * 2 * D + 2 * D})
    stages.append({"label": "$z = \\mu + \\sigma \\odot \\varepsilon$", "size": D, "kind": "latent", "weights": 0})
    width = D + C
    for h in reversed(hidden):
        stages.append({"label": "Linear, BatchNorm,\nLeakyReLU", "size": int(h), "kind": "hidden",
                       "weights": width * int(h) + int(h) + 2 * int(h)})
        width = int(h)
    stages.append({"label": f"Linear, then\n{config['output']}", "size": K, "kind": "output", "weights": width * K + K})
    return stages


_COLORS = {"data": "#d9d9d9", "fixed": "#fdd0a2", "hidden": "#9ecae1", "latent": "#a1d99b", "output": "#fcbba1"}


def _count(n: int) -> str:
    if n >= 1e6:
        return f"{n / 1e6:.1f}M"
    if n >= 1e4:
        return f"{n / 1e3:.0f}k"
    return f"{n:,}"


def network_diagram(networks, titles=None, width: float = 10.0, row_height: float = 2.4):
    """Draw mesh VAE networks as boxes left to right, one row per network.

    networks : a ``MeshVAE`` network or a list of them; titles : one
    title per row or None. Each stage of :func:`network_layers` is a box whose height grows with
    the logarithm of its size, labelled with what it is and its size (``K = 16428``, ``D = 32``);
    the arrow into a box carries the number of trained weights of the linear map that produces it
    (the fixed PCA projection's arrow says "fixed"); a line above the boxes spans the encoder (input
    to the heads mu, sigma) and another the decoder (after z to the output). Latent stages are
    green, internal layers blue, the fixed projection orange, the feature vectors grey. Fonts are
    at least 9 pt at ``width`` inches. Returns the matplotlib Figure (rows are its axes, in order).
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

    nets = list(networks) if isinstance(networks, (list, tuple)) else [networks]
    if not nets:
        raise ValueError("give at least one network")
    if titles is not None and len(titles) != len(nets):
        raise ValueError(f"give one title per network: {len(nets)} networks, {len(titles)} titles")
    rows = [network_layers(n) for n in nets]
    n_max = max(len(r) for r in rows)
    fig, axes = plt.subplots(len(nets), 1, figsize=(width, row_height * len(nets)), squeeze=False)
    biggest = max(s["size"] for r in rows for s in r)
    for i, (ax, stages) in enumerate(zip(axes[:, 0], rows)):
        ax.set_xlim(0, n_max)
        ax.set_ylim(-1.25, 1.2)
        ax.axis("off")
        box_w = 0.62
        for j, s in enumerate(stages):
            x0 = j + (1 - box_w) / 2
            h = 0.25 + 1.25 * math.log10(max(s["size"], 1)) / math.log10(max(biggest, 10))
            ax.add_patch(FancyBboxPatch((x0, -h / 2), box_w, h, boxstyle="round,pad=0.02",
                                        fc=_COLORS[s["kind"]], ec="k", lw=1))
            symbol = "K" if s["kind"] in ("data", "output") else ("r" if s["kind"] == "fixed" else
                                                                 "D" if s["kind"] == "latent" else "")
            size = f"{symbol} = {s['size']}" if symbol else f"{s['size']}"
            ax.text(j + 0.5, 0, size, ha="center", va="center", fontsize=10, fontweight="bold")
            ax.text(j + 0.5, -0.82, s["label"], ha="center", va="top", fontsize=9)
            if j:
                ax.add_patch(FancyArrowPatch((j - 0.5 + box_w / 2 + 0.03, 0), (x0 - 0.03, 0), arrowstyle="-|>",
                                             mutation_scale=12, lw=1.2, color="k"))
                if s["weights"]:
                    note = "fixed" if s["kind"] == "fixed" else _count(s["weights"])
                    ax.text(j, 0.12, note, ha="center", va="bottom", fontsize=9, color="#444444")
        heads = next(j for j, s in enumerate(stages) if s["kind"] == "latent")
        for name, a, b in (("encoder", 0.85, heads + 0.85), ("decoder", heads + 1.85, len(stages) - 0.15)):
            ax.plot([a, b], [0.9, 0.9], color="#555555", lw=1.5)
            ax.text((a + b) / 2, 0.93, name, ha="center", va="bottom", fontsize=10, color="#555555")
        if titles is not None:
            ax.set_title(titles[i], fontsize=11, loc="left")
    fig.tight_layout()
    return fig
