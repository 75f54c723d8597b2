"""How many CPU threads torch (and the BLAS under numpy) may use, with an environment override.

The notebooks and the command line call :func:`configure_threads` with the thread count they
were recorded with (2). The environment variable ``MESHVAE_NUM_THREADS`` overrides that count
everywhere at once, which is how ``make test-portable`` re-runs the whole course under another
float summation order (one thread splits every reduction differently from two) without editing a
notebook.
"""

from __future__ import annotations

import logging
import os
from contextlib import contextmanager

__all__ = ["ENV_VAR", "configure_threads", "threads_from_environment", "torch_threads"]

logger = logging.getLogger(__name__)

#: environment variable that overrides the thread count asked for by a notebook or a command.
ENV_VAR = "MESHVAE_NUM_THREADS"


def threads_from_environment(default: int) -> int:
    """The thread count to use: ``MESHVAE_NUM_THREADS`` when set, else ``default``.

    Parameters
    ----------
    default : int
        The count asked for by the caller (>= 1).

    Returns
    -------
    int
        The count, >= 1.

    Raises
    ------
    ValueError
        When ``default`` is below 1, or the environment variable is set to something that is not
        a positive integer.
    """
    if int(default) < 1:
        raise ValueError(f"thread count must be >= 1, got {default!r}")
    raw = os.environ.get(ENV_VAR, "").strip()
    if not raw:
        return int(default)
    try:
        n = int(raw)
    except ValueError:
        raise ValueError(f"{ENV_VAR} must be a positive integer, got {raw!r}") from None
    if n < 1:
        raise ValueError(f"{ENV_VAR} must be a positive integer, got {raw!r}")
    return n


def configure_threads(default: int = 2) -> int:
    """Set torch's intra-op threads and the BLAS threads to ``default`` or ``MESHVAE_NUM_THREADS``.

    Parameters
    ----------
    default : int
        Threads to use when the environment variable is not set.

    Returns
    -------
    int
        The thread count now in force.
    """
    import torch
    from threadpoolctl import threadpool_limits

    n = threads_from_environment(default)
    torch.set_num_threads(n)
    threadpool_limits(limits=n, user_api="blas")  # numpy's / scipy's BLAS, for the rest of the process
    logger.debug("torch and BLAS threads: %d", n)
    return n


@contextmanager
def torch_threads(n: int):
    """torch's intra-op thread count set to ``n`` (>= 1) inside the ``with`` block, restored after.

    For many small operations (a network of a few hundred units on a few hundred rows, thousands of
    steps) one thread is faster than several: each operation is too small to split, and on a busy
    machine the threads wait for each other (measured: an Adam step of a 4-128-128-36 network on 40
    rows took 1.8 ms on one thread and 61 ms on two, with other work on both cores). The results do
    not depend on the thread count of the caller then.
    """
    import torch

    if int(n) < 1:
        raise ValueError(f"thread count must be >= 1, got {n!r}")
    before = torch.get_num_threads()
    torch.set_num_threads(int(n))
    try:
        yield
    finally:
        torch.set_num_threads(before)
