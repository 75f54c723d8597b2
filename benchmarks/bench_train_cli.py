"""Wall-clock time of ``meshvae train`` with its defaults on a real capture (issue 38).

Usage::

    .venv/bin/python benchmarks/bench_train_cli.py [--real samba] [--holdout-every 5] [--repeats 3]

Writes the training meshes of ``--real`` (``../shared/data``; every ``--holdout-every``-th mesh left
out, as ``training.holdout_mask`` does: 140 of samba's 175) to a temporary ``.npz`` and runs
``meshvae train that.npz -o model.pt --no-progress`` as a fresh process ``--repeats`` times: the
command's defaults (RIMD, PCA start, no meshes held out, so no evaluation at the end). Prints each
wall time, the median, the command's own report, and whether every written model is the same
(``torch.equal`` on every tensor of the checkpoint: the network's state, the normaliser, ...).
With ``--evaluate`` it also runs the same command on the whole collection with
``--holdout-every K``: training plus the default inference of the held-out meshes, which is the
inference's cost (``bench_inference.py``).

Measured on 4 December 2026 (2 cores, quiet; docs/results/inference_speed.md): samba, 140 training
meshes, median 26.4 s (25.1-30.0 s over 3 runs), the same tensors every run; the code before issue 38
took 111 s for the same command (its epoch search chose 0 epochs) and wrote the same tensors.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import torch

from feature_comparison import load_real
from meshvae_lib.geometry.collection_io import write_collection
from meshvae_lib.model.training import holdout_mask


def _tensors(state, prefix=""):
    """Every tensor of a nested checkpoint dictionary, by its path."""
    if isinstance(state, torch.Tensor):
        yield prefix, state
    elif isinstance(state, dict):
        for k, v in state.items():
            yield from _tensors(v, f"{prefix}/{k}")


def _run(argv: list[str]) -> tuple[float, str]:
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "meshvae_lib.cli", *argv], capture_output=True, text=True)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"meshvae {' '.join(argv)} failed ({proc.returncode}):\n{proc.stderr[-2000:]}")
    return seconds, (proc.stdout + proc.stderr).strip()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", default="samba")
    ap.add_argument("--holdout-every", type=int, default=5)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--evaluate", action="store_true", help="also time --holdout-every on the whole collection")
    args = ap.parse_args()
    coll = load_real(args.real)
    keep = ~holdout_mask(len(coll.vertices), args.holdout_every)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        data = write_collection(tmp / "train.npz", coll.subset(keep))
        print(f"{args.real}: {int(keep.sum())} training meshes of {len(keep)}, {coll.vertices.shape[1]} vertices")
        times, states = [], []
        for r in range(args.repeats):
            out = tmp / f"model{r}.pt"
            seconds, report = _run(["train", str(data), "-o", str(out), "--no-progress"])
            times.append(seconds)
            states.append(dict(_tensors(torch.load(out, map_location="cpu", weights_only=False))))
            print(f"  run {r + 1}: {seconds:.1f} s")
        print(f"meshvae train (defaults): median {statistics.median(times):.1f} s over {args.repeats} runs")
        print("  its report:\n    " + report.replace("\n", "\n    "))
        same = all(a.keys() == states[0].keys() and all(torch.equal(a[k], states[0][k]) for k in a)
                   for a in states[1:])
        print(f"  every run wrote the same tensors ({len(states[0])}): {same}")
        if args.evaluate:
            whole = write_collection(tmp / "whole.npz", coll)
            seconds, report = _run(["train", str(whole), "-o", str(tmp / "eval.pt"), "--no-progress",
                                    "--holdout-every", str(args.holdout_every)])
            print(f"meshvae train --holdout-every {args.holdout_every} (with the held-out evaluation): {seconds:.1f} s")
            print("  its report:\n    " + report.replace("\n", "\n    "))


if __name__ == "__main__":
    main()
