"""Make a finished matplotlib figure readable at the size it is stored (notebook 09).

The experiment plots of :mod:`meshvae_lib.paper.plots` are part of the recorded experiments'
definition (their source is fingerprinted with the results), so a lesson that shows them larger
does not edit them: :func:`readable_figure` takes the figure one of them returns and raises every
text in it -- titles, axis labels, tick labels, legend entries -- to at least ``min_fontsize``
points, optionally at a new size and with each legend moved beside its axes instead of over the data.
"""

from __future__ import annotations

__all__ = ["readable_figure"]


def readable_figure(fig, min_fontsize: float = 10.0, size=None, legend_outside: bool = False):
    """Raise every text of ``fig`` to at least ``min_fontsize`` points; return ``fig``.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    min_fontsize : float
        Texts smaller than this are set to it; larger ones keep their size.
    size : (width, height) in inches, optional
        The new figure size (the figure's layout engine, if any, lays it out again).
    legend_outside : bool
        Redraw each axes' legend to the right of the axes, its top at the axes' top.

    Returns
    -------
    matplotlib.figure.Figure
        The same figure, changed in place.
    """
    from matplotlib.text import Text

    if not min_fontsize > 0:
        raise ValueError(f"min_fontsize must be positive, got {min_fontsize}")
    if size is not None:
        fig.set_size_inches(*size)
    for ax in fig.axes:
        if legend_outside and ax.get_legend() is not None:
            handles, labels = ax.get_legend_handles_labels()
            ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.0, 1.0), fontsize=min_fontsize)
        for which, axis in (("x", ax.xaxis), ("y", ax.yaxis)):
            labels = axis.get_ticklabels() + axis.get_ticklabels(minor=True)
            if labels and min(t.get_fontsize() for t in labels) < min_fontsize:
                ax.tick_params(axis=which, which="both", labelsize=min_fontsize)
    for text in fig.findobj(Text):
        if text.get_fontsize() < min_fontsize:
            text.set_fontsize(min_fontsize)
    return fig
