"""The normalisation of Eq. (3) drawn for one feature component (notebook 03).

:func:`normalization_margin_figure` draws two number lines, one above the other: the component's
training values on the feature axis, and the same values after Eq. (3) on the decoder's output
axis, where they fill ``[-a, a]``. Grey lines join the training minimum and maximum to ``-a`` and
``+a``; red lines join the ends of ``tanh``'s range, ``-1`` and ``+1``, to the feature values they
map back to. The red spans on both lines are the margins: outputs in ``(a, 1)`` (and ``(-1, -a)``)
decode to features beyond anything in the training set, ``(1 - a) / (2 a)`` of the component's
range on either side.
"""

from __future__ import annotations

import numpy as np

__all__ = ["normalization_margin_figure"]


def normalization_margin_figure(values, a: float = 0.9, label: str = "feature value", figsize=(9.0, 3.4)):
    """Two number lines: one component's training values, and the same after Eq. (3).

    Parameters
    ----------
    values : (M,) float
        The component over the training meshes (not constant).
    a : float
        The half-width of Eq. (3), ``0 < a < 1``.
    label : str
        The name of the feature axis (its x label).

    Returns
    -------
    matplotlib.figure.Figure
        Two axes: the top one titled with ``label``, the bottom one "decoder output (tanh)".
        On each, the training values as dots, the margins as red spans (two per axis), and on the
        top axis the reachable interval's ends marked "decoder output -1" and "+1".

    Raises
    ------
    ValueError
        If ``values`` is constant or ``a`` is not in ``(0, 1)``.
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import ConnectionPatch

    v = np.asarray(values, dtype=float).ravel()
    lo, hi = float(v.min()), float(v.max())
    if not hi > lo:
        raise ValueError("the component must vary over the training set")
    if not 0 < a < 1:
        raise ValueError("a must lie in (0, 1)")
    scale = (hi - lo) / (2 * a)

    def back(y):   # the inverse of Eq. (3)
        return (np.asarray(y) + a) * scale + lo

    f_lo, f_hi = float(back(-1.0)), float(back(1.0))
    y = 2 * a * (v - lo) / (hi - lo) - a
    fig, (top, bottom) = plt.subplots(2, 1, figsize=figsize)
    for ax, pts, (m_lo, d_lo, d_hi, m_hi) in [(top, v, (f_lo, lo, hi, f_hi)), (bottom, y, (-1.0, -a, a, 1.0))]:
        ax.axhline(0, color="0.6", lw=1)
        ax.axvspan(m_lo, d_lo, color="C3", alpha=0.25)
        ax.axvspan(d_hi, m_hi, color="C3", alpha=0.25)
        ax.axvspan(d_lo, d_hi, color="C0", alpha=0.12)
        ax.plot(pts, np.zeros_like(pts), "o", color="C0", ms=5, alpha=0.7)
        ax.set_yticks([])
        for side in ("left", "right", "top"):
            ax.spines[side].set_visible(False)
        ax.tick_params(labelsize=9)
    pad = 0.1 * (f_hi - f_lo)
    top.set_xlim(f_lo - pad, f_hi + pad)
    bottom.set_xlim(-1.1, 1.1)
    bottom.set_xticks([-1, -a, 0, a, 1])
    top.set_xticks([lo, hi])
    top.set_xticklabels([f"training min {lo:.3g}", f"training max {hi:.3g}"])
    top.set_title(f"{label}: training values (blue) and the margins the decoder can reach (red)", fontsize=10)
    bottom.set_title(f"decoder output (tanh): Eq. (3) maps the training values onto [-{a:g}, {a:g}]", fontsize=10)
    for f, t, color in [(lo, -a, "0.4"), (hi, a, "0.4"), (f_lo, -1.0, "C3"), (f_hi, 1.0, "C3")]:
        fig.add_artist(ConnectionPatch(xyA=(f, 0), coordsA=top.transData, xyB=(t, 0), coordsB=bottom.transData,
                                       color=color, lw=1.2, ls="--"))
    top.text(f_lo, 0.7, f"output -1 decodes to {f_lo:.3g}", color="C3", ha="left", va="bottom", fontsize=9,
             transform=top.get_xaxis_transform())
    top.text(f_hi, 0.7, f"output +1 decodes to {f_hi:.3g}", color="C3", ha="right", va="bottom", fontsize=9,
             transform=top.get_xaxis_transform())
    fig.tight_layout(h_pad=2.5)
    return fig
