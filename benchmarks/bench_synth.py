"""Generation time and size of every synthetic collection (default size and ~7k vertices).

Usage::

    .venv/bin/python benchmarks/bench_synth.py [--repeats 3] [--large 7000] [NAME ...]

Prints a table: median wall-clock time of ``make_collection`` over ``--repeats`` runs in fresh
caches (the first build of a template is part of the cost; templates are cached per process, so
each run clears them), the number of meshes and vertices, and the size of the vertex array.
The machine is shared and noisy: compare medians, not single runs.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def clear_caches() -> None:
    from data_synth.registry import clear_caches as clear

    clear()


def time_collection(name: str, resolution, repeats: int):
    from data_synth import make_collection

    times = []
    for _ in range(repeats):
        clear_caches()
        start = time.perf_counter()
        col = make_collection(name, seed=0, resolution=resolution)
        times.append(time.perf_counter() - start)
    return statistics.median(times), min(times), col


def main(argv=None) -> int:
    from data_synth import list_collections

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--large", type=int, default=7000,
                        help="the large resolution (vertex count) to time as well; 0 skips it")
    args = parser.parse_args(argv)
    names = args.names or [n for n, _ in list_collections()]
    header = f"{'collection':<10} {'resolution':>10} {'meshes':>6} {'vertices':>8} {'faces':>6} " \
             f"{'MB':>6} {'median s':>9} {'min s':>7}"
    print(header)
    print("-" * len(header))
    for name in names:
        for resolution in (None, args.large or None):
            med, low, col = time_collection(name, resolution, args.repeats)
            N, V, _ = col.vertices.shape
            print(f"{name:<10} {str(resolution or 'default'):>10} {N:>6} {V:>8} "
                  f"{len(col.faces):>6} {col.vertices.nbytes / 1e6:>6.1f} {med:>9.2f} {low:>7.2f}",
                  flush=True)
            if not args.large:
                break
    return 0


if __name__ == "__main__":
    sys.exit(main())
