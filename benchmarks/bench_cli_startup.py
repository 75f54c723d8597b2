"""Start-up time of the ``meshvae`` command line: commands that need no model must not wait for torch.

Usage::

    .venv/bin/python benchmarks/bench_cli_startup.py [--repeats 5]

Runs each command as a fresh process (``python -m meshvae_lib.cli ...``) ``--repeats`` times and
prints the median wall-clock time. ``features`` and ``reconstruct`` run for real on a small
collection (``synth bar --resolution 300``, 60 meshes of 300 vertices, written once to a temporary
folder first), so their time is start-up plus a little work. The machine is shared and noisy:
compare medians.

Measured on the course's shared 2-core machine (median of 5, seconds; ``import torch`` alone takes
1.0-1.1 there). Before: ``--help`` 0.10, ``synth --list`` 0.33, ``features --help`` 0.09,
``train --help`` 0.13 (three command modules imported numpy when the parser was built). After (no
command module imports numpy or torch before it runs): ``--help`` 0.04, ``synth --list`` 0.37-0.42
(data_synth's own imports, scipy among them), ``features --help`` 0.04, ``train --help`` 0.04;
``features`` and ``reconstruct`` on the 60 x 300 collection 0.32-0.42.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = (["--help"], ["--version"], ["synth", "--list"], ["features", "--help"], ["reconstruct", "--help"],
            ["train", "--help"], ["features", "{tmp}/bar.npz", "-o", "{tmp}/feats.npz"],
            ["reconstruct", "{tmp}/feats.npz", "-o", "{tmp}/rebuilt.npz"], ["python", "-c", "import torch"])


def _cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "meshvae_lib.cli", *args]


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="meshvae_bench_") as tmp:
        subprocess.run(_cli("synth", "bar", "-o", f"{tmp}/bar.npz", "--resolution", "300"), cwd=ROOT,
                       capture_output=True, check=True)
        print(f"{'command':>36} | median of {args.repeats} (s)")
        for cmd in COMMANDS:
            cmd = [c.format(tmp=tmp) for c in cmd]
            full = [sys.executable, *cmd[1:]] if cmd[0] == "python" else _cli(*cmd)
            times = []
            for _ in range(args.repeats):
                t = time.perf_counter()
                subprocess.run(full, cwd=ROOT, capture_output=True, check=True)
                times.append(time.perf_counter() - t)
            label = (" ".join(cmd) if cmd[0] != "python" else "(for scale) python -c 'import torch'")
            label = label.replace(f"{tmp}/", "")
            print(f"{label:>36} | {statistics.median(times):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
