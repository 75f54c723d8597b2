"""Speed of the latent inference strategies: seconds to encode one mesh (issue 23).

Loads a trained model (``--model m.pt`` with its collection ``--real NAME`` of ../shared/data), or
trains a default RIMD model on ``--real NAME`` alone or on a data_synth collection, and times ``encode_meshes`` of single
held-out meshes with each strategy: the paper's encoder, the default Gauss-Newton (analytic
Jacobian) and, with ``--finite-difference``, the old forward-difference fit. Medians over
``--repeats`` runs of each of ``--meshes`` meshes (the machines are shared and noisy).

    python benchmarks/feature_comparison.py --real samba --kinds rimd --save-models /tmp/models
    python benchmarks/bench_inference.py --model /tmp/models/samba_rimd.pt --real samba
    python benchmarks/bench_inference.py --real samba --subsample 3  # trains the default model first
    python benchmarks/bench_inference.py --synth scape            # without the real data
    python benchmarks/bench_inference.py --real samba --jobs 1 2 --solvers   # issue 38's measurements
    python benchmarks/bench_inference.py --real samba --meshes 8 --step-options   # fewer steps: error and time

``--jobs 1 2`` also times ``encode_meshes`` of all ``--meshes`` meshes at once with that many worker
processes (seconds per mesh = total / meshes: the throughput of ``evaluate``). ``--solvers`` times
the sparse solves of one Jacobian alone: the synchronisation and position systems with three
right-hand sides per used dimension, by SuperLU (in chunks of 12, and all at once) and by CHOLMOD
(``cholespy``, the library's choice): the floor of one Jacobian. ``--step-options`` fits the
``--meshes`` meshes (one process) with fewer Gauss-Newton steps and with chord steps
(``meshvae evaluate --gn-steps N --chord-steps M``) and prints, against the default (4 steps), the
mean error's ratio, the worst single mesh's ratio and the seconds per mesh.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
import torch

from feature_comparison import load_real
from meshvae_lib.model.inference.gauss_newton import GaussNewton
from meshvae_lib.model.meshvae_model import load_model
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--model", default=None, help="a trained checkpoint (with --real)")
    ap.add_argument("--real", default=None, help="its collection in ../shared/data")
    ap.add_argument("--subsample", type=int, default=1)
    ap.add_argument("--synth", default="scape", help="data_synth collection when no model is given")
    ap.add_argument("--meshes", type=int, default=3)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--finite-difference", action="store_true", help="also time the forward-difference fit (slow)")
    ap.add_argument("--jobs", type=int, nargs="*", default=[], help="also time all meshes at once with these worker counts")
    ap.add_argument("--solvers", action="store_true", help="also time one Jacobian's sparse solves alone")
    ap.add_argument("--step-options", action="store_true",
                    help="also fit the meshes with fewer Gauss-Newton steps and with chord steps (error and time)")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    if args.model:
        coll = load_real(args.real, args.subsample)
        model = load_model(args.model, coll)
    elif args.real:
        coll = load_real(args.real, args.subsample)
        t0 = time.perf_counter()
        model = MeshVAEModel("rimd", TrainConfig(progress=False), holdout_every=5).fit(coll)
        print(f"trained the default RIMD model on {args.real}/{args.subsample} in {time.perf_counter() - t0:.0f} s")
    else:
        from data_synth.registry import make_collection

        coll = make_collection(args.synth, seed=0)
        model = MeshVAEModel("rimd", TrainConfig(progress=False), holdout_every=5).fit(coll)
    V = np.asarray(coll.vertices, dtype=np.float64)[model.holdout_mask_][: args.meshes]
    model.encode_meshes(V[:1])                       # build the reconstructor's factorisations once
    methods = ["encoder", "gauss-newton"] + (["finite-difference"] if args.finite_difference else [])
    print(f"{V.shape[1]} vertices, K = {model.n_features}, latent {model.latent_dim},"
          f" {torch.get_num_threads()} thread(s); seconds per mesh, median of {args.repeats} x {len(V)}")
    for method in methods:
        times = []
        for _ in range(args.repeats):
            for x in V:
                t0 = time.perf_counter()
                options = {} if method == "encoder" else {"iterations": 4 if method == "gauss-newton" else 3}
                model.encode_meshes(x[None], inference=method, **options)
                times.append(time.perf_counter() - t0)
        extra = f", {model.last_inference_!r}" if method == "gauss-newton" else ""
        print(f"{method:18s} {statistics.median(times):8.3f} s  (min {min(times):.3f}, max {max(times):.3f}){extra}",
              flush=True)
    for jobs in args.jobs:
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            Z = model.encode_meshes(V, inference=GaussNewton(n_jobs=jobs))
            times.append((time.perf_counter() - t0) / len(V))
        print(f"all {len(V)} meshes, {jobs} process(es): {statistics.median(times):.3f} s per mesh (min {min(times):.3f},"
              f" max {max(times):.3f}), mean error {model.last_inference_.final_error.mean():.6g}", flush=True)
    if args.solvers:
        solver_floor(model, args.repeats)
    if args.step_options:
        step_options(model, V)


#: (Jacobians at most, chord steps after each accepted step) measured by ``--step-options``; the first
#: is the default.
STEP_OPTIONS = ((4, 0), (3, 0), (2, 0), (1, 0), (3, 1), (2, 1), (2, 2), (1, 2))


def step_options(model, V: np.ndarray) -> None:
    """Held-out error and time with fewer Gauss-Newton steps or chord steps, against the default."""
    from meshvae_lib.model.inference.gauss_newton import gauss_newton_codes

    mu, _ = model.encode_rows(model.features_of(V), None)
    base = None
    print(f"fewer steps, {len(V)} meshes, one process (error ratios against 4 steps):")
    for iterations, chord in STEP_OPTIONS:
        t0 = time.perf_counter()
        _, report = gauss_newton_codes(model, V, mu, n_jobs=1, iterations=iterations, chord_steps=chord)
        seconds = (time.perf_counter() - t0) / len(V)
        err = report.final_error
        base = err if base is None else base
        print(f"  --gn-steps {iterations} --chord-steps {chord}: mean error {err.mean():.6g}"
              f" ({err.mean() / base.mean():.4f}x, worst mesh {np.max(err / base):.3f}x), {seconds:.2f} s per mesh,"
              f" {report.iterations.mean():.2f} Jacobians and {report.decodes.mean():.2f} decodes per mesh", flush=True)


def solver_floor(model, repeats: int) -> None:
    """The sparse solves of one Jacobian alone, by each solver (see the module docstring)."""
    from meshvae_lib.geometry.spd_factor import SPDFactor

    rec = model.feature_kind.reconstructor
    rr, ps = rec.rotation_recovery, rec.position_solver
    n = rr.n_vertices
    systems = {"synchronisation": rr.system_matrix(), "position": ps.system_matrix()}
    cols = 3 * len(model.used_latent_dims)
    B = np.random.default_rng(0).standard_normal((n, cols))
    print(f"one Jacobian's solves, {cols} right-hand sides ({len(model.used_latent_dims)} used dimensions x 3),"
          f" median of {repeats}:")
    for name, M in systems.items():
        row = []
        for label, factor in (("SuperLU chunks of 12", SPDFactor(M, "superlu", chunk=12)),
                              ("SuperLU all at once", SPDFactor(M, "superlu", chunk=None)),
                              ("CHOLMOD all at once", SPDFactor(M, "cholmod"))):
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                factor.solve(B)
                times.append(time.perf_counter() - t0)
            row.append(f"{label} {statistics.median(times):.3f} s")
        print(f"  {name:16s} " + ", ".join(row), flush=True)


if __name__ == "__main__":
    main()
