"""Speed, memory and accuracy of RIMD feature extraction and reconstruction.

Prints markdown tables:

1. procedural meshes at about 2k, 7k and 12k vertices (a bumpy closed tube, deformed by twists of
   up to 300 degrees and bends of up to 120 degrees): ms per mesh for feature extraction (one mesh,
   and per mesh in a batch of 8), the one-off set-up (operators, factorisations) and ms per mesh
   for reconstruction with both methods; peak memory (tracemalloc: numpy allocations, not
   SuperLU's internal ones) and the process peak RSS;
2. round-trip error (per-vertex distance after rigid alignment, divided by the bounding-box
   diagonal; mean and max over vertices and meshes) without noise and with Gaussian noise of 0.001
   and 0.01 rad on every stored log dR number, for both methods and both rotation recoveries;
3. with ``--shared``: the same on ../shared/data/*.npz when present (horse and cat: Sumner &
   Popovic 2004; pcow: Briceno et al. 2003).

Times are medians of ``--repeats`` runs after one warm-up, wall clock and (in brackets) the CPU time
of this process, which is what an idle machine would show: the work is single-threaded. The
machine is shared, so wall times vary with the load.

    OMP_NUM_THREADS=2 .venv/bin/python benchmarks/bench_rimd.py [--shared] [--repeats 5] [--quick]
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "2")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "2")

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the procedural meshes of the test fixtures

from geometry_fixtures import bumpy, tube, twist_bend  # noqa: E402

from meshvae_lib.geometry.alignment import bounding_box_diagonal, rigid_align  # noqa: E402
from meshvae_lib.geometry.collection_io import read_collection  # noqa: E402
from meshvae_lib.geometry.reconstruction import RIMDReconstructor  # noqa: E402
from meshvae_lib.geometry.rimd import RIMDEncoder  # noqa: E402

SIZES = {"2k": (48, 41), "7k": (90, 76), "12k": (120, 99)}
NOISE = (0.0, 1e-3, 1e-2)
CITES = {"horse-gallop": "Sumner & Popovic 2004", "cat-poses": "Sumner & Popovic 2004",
         "pcow": "Briceno et al. 2003"}


class Timing(float):
    """Median wall-clock ms, carrying the median CPU ms of this process (``.cpu``)."""

    def __str__(self) -> str:
        return f"{float(self):.1f} ({self.cpu:.1f})"


def median_ms(fn, repeats: int) -> Timing:
    """Median wall and CPU ms of ``repeats`` calls after one warm-up. CPU time is what the process
    itself used: close to the wall time of an idle machine, since this work is single-threaded."""
    fn()  # warm-up
    wall, cpu = [], []
    for _ in range(repeats):
        t, c = time.perf_counter(), time.process_time()
        fn()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - t)
    out = Timing(1e3 * statistics.median(wall))
    out.cpu = 1e3 * statistics.median(cpu)
    return out


def peak_mb(fn) -> float:
    tracemalloc.start()
    fn()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return peak / 2**20


def procedural(name: str, n_meshes: int = 8):
    V0, F = tube(*SIZES[name], radius=0.5, height=6.0)
    V0 = bumpy(V0, 0.03, seed=1)
    twists = np.linspace(40, 300, n_meshes)
    bends = np.linspace(20, 120, n_meshes)
    verts = np.stack([twist_bend(V0, t, b) for t, b in zip(twists, bends)])
    return V0, F, verts


def errors(P, V):
    e = np.linalg.norm(rigid_align(P, V) - V, axis=-1) / bounding_box_diagonal(V)[:, None]
    return float(e.mean()), float(e.max())


def add_noise(features, layout, sigma, seed=0):
    if sigma == 0:
        return features
    f = features.copy()
    r = layout.rotation_slice
    f[:, r] += sigma * np.random.default_rng(seed).standard_normal(f[:, r].shape)
    return f


def speed_rows(name, V0, F, verts, repeats):
    enc_setup = median_ms(lambda: RIMDEncoder(V0, F), 1)
    enc = RIMDEncoder(V0, F)
    one = median_ms(lambda: enc.transform(verts[-1]), repeats)
    batch = median_ms(lambda: enc.transform(verts), max(1, repeats // 2))
    batch_cpu = batch.cpu / len(verts)
    batch = Timing(batch / len(verts))
    batch.cpu = batch_cpu
    mem_ext = peak_mb(lambda: enc.transform(verts[-1]))
    feats = enc.transform(verts)
    rows = [f"| {name} | {len(V0)} | {enc.K} | extraction | {enc_setup:.0f} | {one} | "
            f"{batch} | {mem_ext:.0f} |"]
    for method in ("exact", "paper"):
        setup = median_ms(lambda: RIMDReconstructor(V0, F, method=method), 1)
        rec = RIMDReconstructor(V0, F, method=method)
        t_one = median_ms(lambda: rec.reconstruct(feats[-1]), repeats)
        noisy = add_noise(feats, enc.layout, 1e-3)
        t_noisy = median_ms(lambda: rec.reconstruct(noisy[-1]), repeats)
        mem = peak_mb(lambda: rec.reconstruct(feats[-1]))
        rows.append(f"| {name} | {len(V0)} | {enc.K} | reconstruction, {method} | {setup:.0f} | "
                    f"{t_one} | {t_noisy} (noise 1e-3) | {mem:.0f} |")
    return rows, feats, enc


def accuracy_rows(name, V0, F, verts, feats, enc, subset=None):
    rows = []
    idx = slice(None) if subset is None else slice(0, subset)
    for method, rotations in (("exact", "global"), ("exact", "bfs"), ("paper", "global"),
                              ("paper", "bfs")):
        rec = RIMDReconstructor(V0, F, method=method, rotations=rotations)
        cells = []
        for sigma in NOISE:
            P = rec.reconstruct(add_noise(feats[idx], enc.layout, sigma))
            m, x = errors(P, verts[idx])
            cells.append(f"{m:.1e} / {x:.1e}")
        rows.append(f"| {name} | {method} | {rotations} | " + " | ".join(cells) + " |")
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--shared", action="store_true", help="also run on ../shared/data/*.npz")
    ap.add_argument("--quick", action="store_true", help="2k vertices only, 2 repeats")
    args = ap.parse_args(argv)
    sizes = ["2k"] if args.quick else list(SIZES)
    repeats = 2 if args.quick else args.repeats
    print(f"threads: OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS')}, "
          f"cpus visible: {os.cpu_count()}\n")
    speed = ["| mesh | vertices | K | step | set-up ms (once) | ms per mesh, wall (CPU) | "
             "ms per mesh: batch of 8 / noisy, wall (CPU) | peak MB |",
             "|---|---|---|---|---|---|---|---|"]
    acc = ["| mesh | method | rotations | no noise: mean / max | 0.001 rad | 0.01 rad |",
           "|---|---|---|---|---|---|"]
    for name in sizes:
        V0, F, verts = procedural(name)
        rows, feats, enc = speed_rows(f"tube {name}", V0, F, verts, repeats)
        speed += rows
        acc += accuracy_rows(f"tube {name}", V0, F, verts, feats, enc)
        print(f"done: tube {name}", file=sys.stderr)
    if args.shared:
        shared = ROOT.parent / "shared" / "data"
        for path in sorted(shared.glob("*.npz")) if shared.is_dir() else []:
            col = read_collection(path)
            V0, F, verts = col.vertices[0], col.faces, col.vertices
            label = f"{path.stem} ({CITES.get(path.stem, '')})"
            enc = RIMDEncoder(V0, F)
            t = time.perf_counter()
            feats = enc.transform(verts, batch_size=8)
            t_all = 1e3 * (time.perf_counter() - t) / len(verts)
            rows, _, _ = speed_rows(label, V0, F, verts[:8], repeats)
            rows[0] = rows[0].rstrip(" |") + f" (whole set: {t_all:.1f} ms/mesh) |"
            speed += rows
            acc += accuracy_rows(label, V0, F, verts, feats, enc, subset=min(len(verts), 24))
            print(f"done: {path.name}", file=sys.stderr)
    print("## Speed and memory\n")
    print("\n".join(speed))
    print("\n## Round-trip error / bounding-box diagonal (mean / max over vertices and meshes)\n")
    print("\n".join(acc))
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\nprocess peak RSS: {rss:.0f} MB; load average at the end: "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
