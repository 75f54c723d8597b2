"""What the per-collection comparison benchmarks share: their record options and their main loop.

A benchmark of this kind runs one collection at a time (``run(name, args) -> dict``, a JSON-ready
record with a ``collection`` key), appends each record to ``--out`` as soon as it is done (replacing
an older record of the same collection, so that runs split over processes merge into one file) and
prints its markdown table (``markdown(records) -> str``) of a recorded file with ``--table``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def add_record_options(p: argparse.ArgumentParser) -> None:
    """``--threads``, ``--out`` and ``--table``."""
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--out", type=Path, default=None, help="append the records to this JSON file")
    p.add_argument("--table", type=Path, default=None, help="print the markdown table of this JSON file and stop")


def run_collections(args, run, markdown) -> int:
    """``--table``: print ``markdown`` of that file; otherwise ``run`` every ``args.collections`` with
    ``args.threads`` torch threads, appending each record to ``args.out``. Returns the exit status."""
    if args.table is not None:
        data = json.loads(args.table.read_text())
        print(markdown(data["records"] if isinstance(data, dict) else data))  # a list, or a dict that holds one
        return 0
    import torch

    torch.set_num_threads(args.threads)
    for name in args.collections:
        rec = run(name, args)
        if args.out is not None:
            old = json.loads(args.out.read_text()) if args.out.exists() else []
            args.out.write_text(json.dumps([*[o for o in old if o["collection"] != name], rec], indent=1) + "\n")
    return 0
