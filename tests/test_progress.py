"""meshvae_lib.progress: tqdm bars that redraw at most every few seconds in a log."""

from __future__ import annotations

import io
import time

from meshvae_lib.defaults import PROGRESS_LOG_SECONDS
from meshvae_lib.progress import in_notebook, is_terminal, progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_log_gets_a_redraw_every_few_seconds_a_terminal_as_usual():
    assert not in_notebook() and PROGRESS_LOG_SECONDS >= 5
    assert progress(range(3), file=io.StringIO()).mininterval == PROGRESS_LOG_SECONDS
    assert progress(range(3), file=Terminal()).mininterval < 1        # tqdm's own default (0.1 s)
    assert progress(range(3), file=io.StringIO(), disable=True).disable


def test_a_quick_loop_leaves_two_lines_in_a_log_and_its_final_count():
    log, tty = io.StringIO(), Terminal()
    for stream in (log, tty):
        for _ in progress(range(40), desc="epochs", unit="epoch", file=stream):
            time.sleep(0.01)                                           # 0.4 s: tqdm redraws ~4 times
    assert log.getvalue().count("\r") <= 2 < tty.getvalue().count("\r")
    assert "40/40" in log.getvalue().split("\r")[-1]


def test_is_terminal_on_odd_streams():
    closed = io.StringIO()
    closed.close()
    assert not is_terminal(closed) and not is_terminal(object()) and is_terminal(Terminal())
