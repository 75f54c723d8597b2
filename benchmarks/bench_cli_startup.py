"""Start-up time of the ``meshvae`` command line: commands that need no model must not wait for torch.

Usage::

    .venv/bin/python benchmarks/bench_cli_startup.py [--repeats 5]

Runs each command as a fresh process (``python -m meshvae_lib.cli ...``) ``--repeats`` times and
prints the median wall-clock time. The machine is shared and noisy: compare medians.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = (["--help"], ["--version"], ["synth", "--list"], ["features", "--help"], ["reconstruct", "--help"],
            ["train", "--help"], ["python", "-c", "import torch"])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args(argv)
    print(f"{'command':>32} | median of {args.repeats} (s)")
    for cmd in COMMANDS:
        full = [sys.executable, *cmd[1:]] if cmd[0] == "python" else [sys.executable, "-m", "meshvae_lib.cli", *cmd]
        times = []
        for _ in range(args.repeats):
            t = time.perf_counter()
            subprocess.run(full, cwd=ROOT, capture_output=True, check=True)
            times.append(time.perf_counter() - t)
        label = " ".join(cmd) if cmd[0] != "python" else "(for scale) python -c 'import torch'"
        print(f"{label:>32} | {statistics.median(times):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
