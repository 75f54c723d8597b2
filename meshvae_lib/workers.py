"""Per-item work spread over the machine's cores, in forked worker processes.

The Gauss-Newton inference fits every mesh on its own (:mod:`meshvae_lib.model.inference.gauss_newton`),
and most of a fit holds Python's interpreter lock (the sparse solves, the small per-edge products), so
threads do not run it in parallel; processes do. :func:`map_forked` forks ``n_jobs`` workers that
inherit everything already built (the model, its reconstructor's factorisations: nothing is pickled
but the item's index and its result), and returns the results in item order, so the outcome does not
depend on ``n_jobs``. Each worker runs one BLAS and one torch thread (the workers fill the cores;
with the parent's two threads each, two workers were 1.2x faster than one process instead of 1.7x on
samba/3). ``tests/test_inference_speed.py`` checks that the parallel codes equal the serial ones
exactly.

Where ``fork`` is unavailable (not Linux), or inside a worker, the items run one after another.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from typing import Any, Callable

__all__ = ["available_cores", "resolve_jobs", "map_forked"]

_TASK: Callable[[int], Any] | None = None


def available_cores() -> int:
    """CPU cores this process may run on (its affinity mask where the platform has one)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not Linux
        return max(1, os.cpu_count() or 1)


def resolve_jobs(n_jobs: int | None, n_items: int) -> int:
    """Worker processes for ``n_items`` items: ``n_jobs`` (None: :func:`available_cores`), at most one
    per item, 1 where forking is unavailable or this is already a worker. ValueError below 1."""
    if n_jobs is not None and (isinstance(n_jobs, bool) or not isinstance(n_jobs, int) or n_jobs < 1):
        raise ValueError(f"n_jobs must be a positive integer or None, got {n_jobs!r}")
    jobs = available_cores() if n_jobs is None else n_jobs
    if "fork" not in mp.get_all_start_methods() or mp.current_process().daemon:
        return 1
    return max(1, min(jobs, n_items))


def _one_thread() -> None:
    """Worker initialiser: one BLAS and one torch thread per worker (the workers fill the cores)."""
    from threadpoolctl import threadpool_limits
    import torch

    threadpool_limits(1)
    torch.set_num_threads(1)


def _run(i: int):
    return i, _TASK(i)


def map_forked(task: Callable[[int], Any], n_items: int, n_jobs: int | None = None,
               on_result: Callable[[], None] | None = None) -> list:
    """``[task(0), ..., task(n_items - 1)]``, computed by :func:`resolve_jobs` forked processes.

    Parameters
    ----------
    task : callable ``int -> picklable``
        Run in the workers, which inherit it (it need not be picklable; its results must be).
    n_items : int >= 0
    n_jobs : int >= 1 or None (all available cores).
    on_result : called once per finished item, in the parent (a progress bar's ``update``).

    Returns
    -------
    list of the results, in item order.
    """
    global _TASK
    jobs = resolve_jobs(n_jobs, n_items)
    results: list = [None] * n_items
    if jobs == 1:
        for i in range(n_items):
            results[i] = task(i)
            if on_result is not None:
                on_result()
        return results
    _TASK = task
    try:
        with mp.get_context("fork").Pool(jobs, initializer=_one_thread) as pool:
            for i, r in pool.imap_unordered(_run, range(n_items)):
                results[i] = r
                if on_result is not None:
                    on_result()
    finally:
        _TASK = None
    return results
