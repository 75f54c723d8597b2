"""The two measures of an interpolation drawn step by step (notebook 05, Fig. 4 in numbers).

:func:`interpolation_measures_figure` draws, for each interpolation method, its edge-length
distortion (left) and its self-intersections (right) at every step ``t`` of the path. The right
panel also draws, as a dotted grey line, the larger self-intersection count of the two end meshes:
a path that stays on or below it adds no crossing of its own. The method named ``highlight`` is
drawn dashed with open squares on top of the others, so it stays visible where it lies on another
curve.
"""

from __future__ import annotations

import numpy as np

__all__ = ["interpolation_measures_figure"]


def interpolation_measures_figure(t, edge_distortion: dict, self_intersections: dict, end_counts=None,
                                  highlight: str | None = None, figsize=(10.0, 3.6), fontsize: float = 11.0):
    """Edge-length distortion and self-intersections along each interpolation path.

    Parameters
    ----------
    t : (n_steps,) float
        The interpolation parameter of each step.
    edge_distortion, self_intersections : dict method -> (n_steps,) float / int
        The two measures per method (e.g. ``ImplausibilityTable.edge_distortion`` and
        ``.self_intersections`` of :func:`meshvae_lib.applications.interpolation.implausibility`),
        with the same keys.
    end_counts : sequence of int, optional
        The self-intersections of the two end meshes; their maximum is drawn as a dotted line.
    highlight : str, optional
        The method drawn dashed with open squares, on top.

    Returns
    -------
    matplotlib.figure.Figure
        Two axes, each with one line per method (plus the dotted end line on the right axis when
        ``end_counts`` is given) and a legend on the left axis; both y axes start at 0.

    Raises
    ------
    ValueError
        If the two dicts have different keys or a curve's length differs from ``t``'s.
    """
    import matplotlib.pyplot as plt

    t = np.asarray(t, dtype=float)
    if list(edge_distortion) != list(self_intersections):
        raise ValueError("edge_distortion and self_intersections must have the same methods")
    for name in edge_distortion:
        if len(edge_distortion[name]) != len(t) or len(self_intersections[name]) != len(t):
            raise ValueError(f"{name!r}: one value per step of t expected")
    fig, (left, right) = plt.subplots(1, 2, figsize=figsize)
    for name in edge_distortion:
        style = dict(ls="--", marker="s", ms=8, mfc="none", lw=2, zorder=3) if name == highlight else dict(marker="o", lw=2)
        left.plot(t, edge_distortion[name], label=name, **style)
        right.plot(t, self_intersections[name], label=name, **style)
    if end_counts is not None:
        top = max(int(c) for c in end_counts)
        right.axhline(top, color="0.5", ls=":", lw=1.5, zorder=1)
        right.text(t[-1], top + 0.1, f"end meshes: {', '.join(str(int(c)) for c in end_counts)}", color="0.35",
                   ha="right", va="bottom", fontsize=fontsize - 1)
    left.set_xlabel("t", fontsize=fontsize)
    left.set_ylabel("edge-length distortion", fontsize=fontsize)
    left.set_title("distance from the nearest real pose", fontsize=fontsize)
    right.set_xlabel("t", fontsize=fontsize)
    right.set_ylabel("crossing triangle pairs", fontsize=fontsize)
    right.set_title("self-intersections", fontsize=fontsize)
    for ax in (left, right):
        ax.set_ylim(bottom=0)
        ax.tick_params(labelsize=fontsize - 1)
    ymax = max(max(np.max(v) for v in self_intersections.values()), 1)
    right.set_ylim(0, 1.25 * ymax + 1)
    left.legend(fontsize=fontsize - 1)
    fig.tight_layout()
    return fig
