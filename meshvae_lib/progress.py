"""Progress bars for long loops: live in a terminal or a notebook, sparing in a log file.

tqdm redraws a bar up to ten times a second. In a terminal or a notebook each redraw replaces the
last; where stderr is a file or a pipe (a CI log, ``make models > log``) every redraw stays, and
one training of 1000 epochs leaves a thousand lines. :func:`progress` is tqdm (``tqdm.auto``: the
notebook widget in Jupyter), but where its stream is not a terminal and no notebook shows it, it
redraws at most every ``PROGRESS_LOG_SECONDS`` seconds, and once more with the final count.
"""

from __future__ import annotations

import sys

from meshvae_lib.defaults import PROGRESS_LOG_SECONDS

__all__ = ["progress", "in_notebook", "is_terminal"]


def in_notebook() -> bool:
    """True when ``tqdm.auto`` draws notebook widgets (a Jupyter kernel with ipywidgets)."""
    from tqdm.autonotebook import tqdm as auto
    from tqdm.std import tqdm as text

    return auto is not text


def is_terminal(stream) -> bool:
    """True when ``stream`` (a file object) is an interactive terminal; False for files, pipes,
    closed or detached streams."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError, OSError):
        return False


def progress(iterable=None, *, desc: str | None = None, unit: str = "it", total: int | None = None,
             disable: bool = False, file=None):
    """A tqdm progress bar over ``iterable`` (``tqdm.auto.tqdm`` with these arguments).

    file : the text stream to draw on (default sys.stderr). Where it is not a terminal and the
    code does not run in a notebook, the bar redraws at most every ``PROGRESS_LOG_SECONDS``
    seconds (tqdm's ``mininterval`` and ``maxinterval``), so that a log holds a line every few
    seconds instead of one per step; the closing line still shows the final count.
    """
    from tqdm.auto import tqdm

    options = {}
    if not disable and not in_notebook() and not is_terminal(sys.stderr if file is None else file):
        options = {"mininterval": PROGRESS_LOG_SECONDS, "maxinterval": PROGRESS_LOG_SECONDS}
    return tqdm(iterable, desc=desc, unit=unit, total=total, disable=disable, file=file, **options)
