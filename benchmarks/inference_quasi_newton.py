"""Cheaper steps for the Gauss-Newton inference: a fixed metric and BFGS with exact gradients (issue 23).

The default inference (``model.inference.gauss_newton``) computes the full Jacobian of the decoded
mesh with respect to the used latent dimensions at every step: one column per dimension, about
0.01 s each at 10k vertices. This benchmark measures two candidates that need only the *gradient*
``J^T r`` per step (one adjoint product, ``ReconstructionLinearization.vjp``, plus a decode):

- ``fixed``: the Gauss-Newton matrix ``J^T J`` averaged over ``--metric-meshes`` training meshes'
  encoder codes, computed once, used with Marquardt's damping at every step;
- ``bfgs``: the same start, updated by BFGS from the exact gradients of successive steps.

Both are compared with the default (exact Jacobian, ``GAUSS_NEWTON_ITERATIONS`` steps) on the first
``--meshes`` held-out meshes: mean vertex error after rigid alignment and seconds per mesh.

    python benchmarks/inference_quasi_newton.py --real samba --subsample 3 --meshes 6
    python benchmarks/inference_quasi_newton.py --synth scape
"""

from __future__ import annotations

import argparse
import time

import numpy as np
import torch

from feature_comparison import load_real
from meshvae_lib import tolerances as tol
from meshvae_lib.model.inference.gauss_newton import LatentDecoder, gauss_newton_codes
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig


def _gradient(decoder, state) -> np.ndarray:
    """``J^T r`` over the used dimensions by one adjoint product (default network: no hidden layer)."""
    return decoder.W.T @ (decoder.scale * state.slope * state.lin.vjp(state.residual))


def _descend(decoder, x, z, H0, iterations: int, bfgs: bool) -> float:
    used = decoder.used
    state = decoder.state(z, None, x)
    g = _gradient(decoder, state)
    B, damping = H0.copy(), tol.GN_DAMPING_START
    for _ in range(iterations):
        scale = np.maximum(np.diag(B), tol.GN_DIAG_FLOOR_RTOL * np.trace(B) / len(used))
        for _ in range(tol.GN_MAX_TRIES):
            step = np.linalg.solve(B + damping * np.diag(scale), g)
            z_new = z.copy()
            z_new[used] += step
            trial = decoder.state(z_new, None, x)
            if trial.sq_error < state.sq_error:
                damping = max(damping * tol.GN_DAMPING_DOWN, tol.GN_DAMPING_FLOOR)
                break
            damping *= tol.GN_DAMPING_UP
        else:
            break
        g_new = _gradient(decoder, trial)
        if bfgs:
            y = g - g_new                     # the change of the half squared error's gradient
            sy = float(step @ y)
            if sy > 0:
                Bs = B @ step
                B = B - np.outer(Bs, Bs) / float(step @ Bs) + np.outer(y, y) / sy
        z, state, g = z_new, trial, g_new
    return state.mean_error


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", default=None, help="a collection in ../shared/data")
    ap.add_argument("--subsample", type=int, default=1)
    ap.add_argument("--synth", default="scape")
    ap.add_argument("--meshes", type=int, default=6)
    ap.add_argument("--metric-meshes", type=int, default=8)
    ap.add_argument("--iterations", default="2,4,6,10")
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    if args.real:
        coll = load_real(args.real, args.subsample)
    else:
        from data_synth.registry import make_collection

        coll = make_collection(args.synth, seed=0)
    model = MeshVAEModel("rimd", TrainConfig(progress=False), holdout_every=5).fit(coll)
    if model.network.hidden:
        raise SystemExit("this benchmark reads the default network (no hidden layer)")
    V = np.asarray(coll.vertices, dtype=np.float64)
    Vh, Vt = V[model.holdout_mask_][: args.meshes], V[~model.holdout_mask_]
    decoder = LatentDecoder(model, None)
    mu_t, _ = model.encode_rows(model.features_of(Vt), None)
    t0 = time.perf_counter()
    picks = np.linspace(0, len(Vt) - 1, args.metric_meshes).round().astype(int)
    H0 = np.mean([(lambda J: J.T @ J)(decoder.vertex_jacobian(decoder.state(mu_t[i], None, Vt[i]))) for i in picks], axis=0)
    print(f"{len(decoder.used)} used dimensions; metric from {len(picks)} training meshes in {time.perf_counter() - t0:.1f} s")
    mu, _ = model.encode_rows(model.features_of(Vh), None)
    t0 = time.perf_counter()
    _, report = gauss_newton_codes(model, Vh, mu)
    print(f"| method | steps | error | s / mesh |\n| --- | --- | --- | --- |")
    print(f"| encoder | 0 | {report.initial_error.mean():.4g} | - |")
    print(f"| exact Jacobian (default) | {report.iterations.max()} | {report.final_error.mean():.4g}"
          f" | {(time.perf_counter() - t0) / len(Vh):.2f} |", flush=True)
    for it in (int(k) for k in args.iterations.split(",")):
        for bfgs in (False, True):
            t0 = time.perf_counter()
            err = [_descend(decoder, x, z.copy(), H0, it, bfgs) for x, z in zip(Vh, mu)]
            print(f"| {'BFGS' if bfgs else 'fixed metric'} | {it} | {np.mean(err):.4g} | {(time.perf_counter() - t0) / len(Vh):.2f} |",
                  flush=True)


if __name__ == "__main__":
    main()
