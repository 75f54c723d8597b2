"""How good can a RIMD decoder of the default form be on a held-out mesh? (issue 23)

The default mesh VAE's decoder is, after its PCA start, an affine map of the code into the span of
the training meshes' features (through the tanh of Eq. 3's range). This benchmark asks what the
*best* code in that family gives, independently of the network and of the encoder, and compares it
with linear PCA on coordinates on the same held-out meshes:

- ``PCA coords``: PCA on vertex coordinates with every direction the training meshes span
  (``evaluation.pca_baseline``), the linear floor;
- ``feature projection``: the held-out mesh's own RIMD feature projected orthogonally onto the affine
  span of the training features, then reconstructed (what a perfect feature-space encoder gives);
- ``vertex-optimal in span``: the point of that affine span whose reconstruction is closest to the
  held-out vertices, found by damped Gauss-Newton on the vertex error from the projection, with the
  analytic Jacobian of the reconstruction (``RIMDReconstructor.linearize``), the default inference's
  own Levenberg-Marquardt (``gauss_newton.marquardt_fit``) and ``--iterations`` steps; no network, no
  tanh: the ceiling of any decoder whose image is that span;
- ``default model``: the library's default model trained on the same split and its default inference
  (encoder, then Gauss-Newton on the vertices).

Every ``--holdout-every``-th mesh is held out (``training.holdout_mask``); ``--meshes`` takes the first
few held-out meshes (all by default). Errors are mean vertex distances after rigid alignment, in the
mesh's units, averaged over the same meshes for every row.

    python benchmarks/inference_span_oracle.py --real pcow
    python benchmarks/inference_span_oracle.py --real samba --meshes 8
    python benchmarks/inference_span_oracle.py --synth scape          # without ../shared/data
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
import torch

from feature_comparison import REAL_CITATIONS, load_real
from meshvae_lib import tolerances as tol
from meshvae_lib.model.evaluation import pca_baseline, per_vertex_error
from meshvae_lib.model.feature_kinds import make_kind
from meshvae_lib.model.inference.gauss_newton import FitState, marquardt_fit, without_rigid_motions
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import holdout_mask


def _fit_in_span(kind, x: np.ndarray, mean: np.ndarray, B: np.ndarray, z: np.ndarray, iterations: int) -> float:
    """The library's damped Gauss-Newton (``marquardt_fit``) over ``f = mean + B z`` on the vertex
    error to ``x``. Returns the final mean vertex error."""
    def jacobian_at(state: FitState) -> np.ndarray:
        return without_rigid_motions(state.lin.jvp(B).reshape(-1, B.shape[1]), state.lin.positions)

    return marquardt_fit(z, lambda u: FitState(kind.linearize(mean + B @ u), x), jacobian_at, iterations).state.mean_error


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", default=None, help="a collection in ../shared/data")
    ap.add_argument("--subsample", type=int, default=1)
    ap.add_argument("--synth", default="scape", help="data_synth collection when --real is not given")
    ap.add_argument("--holdout-every", type=int, default=5)
    ap.add_argument("--meshes", type=int, default=None, help="the first this-many held-out meshes (default: all)")
    ap.add_argument("--iterations", type=int, default=8, help="Gauss-Newton steps in the span")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--json", default=None, help="write the result here")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    if args.real:
        coll, name = load_real(args.real, args.subsample), args.real + (f"/{args.subsample}" if args.subsample > 1 else "")
        print("Data:", "; ".join(REAL_CITATIONS))
    else:
        from data_synth.registry import make_collection

        coll, name = make_collection(args.synth, seed=0), args.synth
    V = np.asarray(coll.vertices, dtype=np.float64)
    hold = holdout_mask(len(V), args.holdout_every)
    Vt, Vh = V[~hold], V[hold][: args.meshes]
    kind = make_kind("rimd", V[0], coll.faces)
    Ft, Fh = kind.encode(Vt), kind.encode(Vh)
    mean = Ft.mean(axis=0)
    U, s, _ = np.linalg.svd((Ft - mean).T, full_matrices=False)
    B = U[:, s > tol.GN_UNUSED_DIM_RTOL * s[0]]
    print(f"{name}: {len(Vt)} training meshes, {len(Vh)} held out, {V.shape[1]} vertices, span of {B.shape[1]} directions",
          flush=True)

    pca = pca_baseline(Vt, Vh)["per_mesh"]
    proj, span, t_span = [], [], []
    for x, f in zip(Vh, Fh):
        z = B.T @ (f - mean)
        proj.append(per_vertex_error(kind.decode((mean + B @ z)[None])[0], x))
        t0 = time.perf_counter()
        span.append(_fit_in_span(kind, x, mean, B, z, args.iterations))
        t_span.append(time.perf_counter() - t0)
    model = MeshVAEModel("rimd", TrainConfig(progress=False), holdout_every=args.holdout_every).fit(coll)
    model.encode_meshes(Vh)
    default = model.last_inference_.final_error.tolist()

    rows = {"PCA coords": pca, "feature projection": proj, "vertex-optimal in span": span, "default model": default}
    floor = float(np.mean(pca))
    print(f"\n| {name} ({len(Vh)} held-out meshes) | mean vertex error | / PCA coords | meshes below PCA |")
    print("| --- | --- | --- | --- |")
    for label, errs in rows.items():
        errs = np.asarray(errs)
        print(f"| {label} | {errs.mean():.4g} | {errs.mean() / floor:.2f} | {int((errs < np.asarray(pca)).sum())} of {len(errs)} |")
    print(f"\nvertex-optimal fit: {np.median(t_span):.1f} s per mesh (median), {args.iterations} steps at most")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"collection": name, "holdout_every": args.holdout_every, "span_directions": int(B.shape[1]),
                       "iterations": args.iterations, "per_mesh": rows}, fh, indent=1)


if __name__ == "__main__":
    main()
