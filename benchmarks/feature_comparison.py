"""RIMD against aligned and raw vertex coordinates and linear PCA: the experiment of the paper's Table 2.

The same mesh VAE (library defaults unless told otherwise) is trained on three inputs of each
collection: raw 3D coordinates, coordinates after rigidly aligning every mesh to the reference, and
RIMD features. Every ``--holdout-every``-th mesh is held out (``training.holdout_mask``); the table
gives, per feature kind, the mean per-vertex error of the training and of the held-out meshes
(encoded to the latent mean, decoded, aligned rigidly to the truth, as ``meshvae evaluate``
measures it), in the mesh's units, the training time (features + training), the epochs early
stopping chose and the encoding time per held-out mesh. Every model is evaluated with each
inference strategy of ``--inference`` (default: the library's default, Gauss-Newton from the
encoder's means with the analytic Jacobian, and the paper's feed-forward encoder); with
``--fit-latent N`` also with codes fitted by finite differences (the "finite-difference" inference). Two linear rows close each table: PCA on coordinates and on aligned coordinates,
fitted on the training meshes with every direction they span (``evaluation.pca_baseline``), then the
linear floor as a fraction of the diagonal (``paper.linear_floor``): below 1e-4 the collection is
linear data and its learned rows say nothing about a representation. A run on the real collections
prints what their README asks to cite.

Collections: the real ones in ``../shared/data`` (``samba``, ``pdance``, ``pcow``; not part of the
repository) when that folder exists, else a ``data_synth`` collection. By default it trains with the
library's defaults (the PCA start of issue 12, ``TrainConfig(init="pca")``, see docs/vae.md);
``--legacy`` trains the paper's way (random initialisation, all epochs, a = 0.9, a hidden layer of
256 for the coordinate kinds), to show the difference.

    python benchmarks/feature_comparison.py                              # real collections if present
    python benchmarks/feature_comparison.py --real pcow --subsample 3    # every 3rd frame of pcow
    python benchmarks/feature_comparison.py --synth scape --resolution 500

Measured results and their settings: docs/vae.md.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import time
from pathlib import Path

import numpy as np
import torch

from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.evaluation import evaluate_model, pca_baseline
from meshvae_lib.paper.linear_floor import NOT_INFORMATIVE, linear_floor
from meshvae_lib.geometry.collection import MeshCollection
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import holdout_mask

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
#: what ../shared/data/README.md asks to cite wherever a result on its collections is shown.
REAL_CITATIONS = ("Sumner & Popović, 'Deformation Transfer for Triangle Meshes' (SIGGRAPH 2004)",
                  "Vlasic, Baran, Matusik, Popović, 'Articulated Mesh Animation from Multi-view Silhouettes' (SIGGRAPH 2008)",
                  "Briceño et al., 'Geometry Videos' (SCA 2003)")
REAL = ("samba", "pdance", "pcow")
KINDS = ("coords", "aligned", "rimd")


def load_real(name: str, subsample: int = 1) -> MeshCollection:
    d = np.load(SHARED_DATA / f"{name}.npz")
    V = np.asarray(d["vertices"], dtype=np.float64)[::subsample]
    return MeshCollection(V, np.asarray(d["faces"]), names=[str(n) for n in np.asarray(d["names"])[::subsample]])


def config_for(kind: str, legacy: bool, seed: int, epochs: int | None, latent: int | None = None) -> TrainConfig:
    extra = {} if epochs is None else {"epochs": epochs}
    if latent is not None:
        extra["latent_dim"] = latent
    if legacy:
        hidden = () if kind == "rimd" else (256,)
        return TrainConfig(hidden=hidden, init="random", early_stopping=False, a=0.9, seed=seed,
                           progress=False, device="cpu", **extra)
    return TrainConfig(seed=seed, progress=False, device="cpu", init="pca", **extra)


def run_collection(coll, name: str, args) -> list[dict]:
    V = np.asarray(coll.vertices, dtype=np.float64)
    mask = holdout_mask(len(V), args.holdout_every)
    diag = float(np.mean(np.linalg.norm(np.ptp(V, axis=1), axis=1)))
    print(f"\n{name}: {len(V)} meshes ({int((~mask).sum())} train / {int(mask.sum())} held out), {V.shape[1]} vertices,"
          f" mean bounding-box diagonal {diag:.4g}; {'the paper' if args.legacy else 'library default (PCA start)'} training,"
          f" {torch.get_num_threads()} thread(s)", flush=True)
    print(f"{'features (inference)':26s} {'K':>7s} {'train error':>12s} {'held-out':>10s} {'% diag':>7s} {'epochs':>6s}"
          f" {'train (s)':>9s} {'s / mesh':>9s}", flush=True)
    rows = []
    for kind in args.kinds.split(","):
        t0 = time.perf_counter()
        model = MeshVAEModel(kind, config_for(kind, args.legacy, args.seed, args.epochs, args.latent),
                             holdout_every=args.holdout_every).fit(coll)
        seconds = time.perf_counter() - t0
        if args.save_models:
            Path(args.save_models).mkdir(parents=True, exist_ok=True)
            model.save(Path(args.save_models) / f"{name.replace('/', '_')}_{kind}.pt")
        train = evaluate_model(model, coll, indices=np.flatnonzero(~model.holdout_mask_), inference="encoder")
        for inference in args.inference.split(","):
            held = evaluate_model(model, coll, held_out_only=True, inference=inference)
            label = kind if inference == "gauss-newton" else f"{kind} ({inference})"
            row = {"collection": name, "features": label, "kind": kind, "inference": inference,
                   "K": int(model.n_features), "latent": int(model.latent_dim),
                   "used_latent": int(len(model.used_latent_dims)), "train_error": train["mean_vertex_error"],
                   "held_out_error": held["mean_vertex_error"], "relative_error": held["relative_error"],
                   "epochs": int(model.train_epochs_), "seconds": seconds,
                   "encode_seconds_per_mesh": held["seconds_per_mesh"],
                   "per_mesh": held["per_mesh"]}
            rows.append(row)
            print(f"{label:26s} {row['K']:7d} {row['train_error']:12.4e} {row['held_out_error']:10.4e}"
                  f" {100 * row['relative_error']:7.3f} {row['epochs']:6d} {seconds:9.1f}"
                  f" {held['seconds_per_mesh']:9.3f}", flush=True)
        if args.fit_latent:
            fitted = evaluate_model(model, coll, held_out_only=True, fit_iterations=args.fit_latent)
            label = f"{kind} fit z ({args.fit_latent})"
            rows.append({"collection": name, "features": label, "kind": kind, "inference": "finite-difference",
                         "K": row["K"], "train_error": float("nan"),
                         "held_out_error": fitted["mean_vertex_error"], "relative_error": fitted["relative_error"],
                         "epochs": row["epochs"], "seconds": seconds,
                         "encode_seconds_per_mesh": fitted["seconds_per_mesh"]})
            print(f"{label:26s} {row['K']:7d} {'':>12s} {fitted['mean_vertex_error']:10.4e}"
                  f" {100 * fitted['relative_error']:7.3f} {'':>6s} {seconds:9.1f} {fitted['seconds_per_mesh']:9.3f}"
                  "   (codes fitted by finite differences)", flush=True)
    latent = args.latent or TrainConfig().resolved_latent_dim(int((~mask).sum()))
    pcas = [(False, None), (True, None)]
    if int((~mask).sum()) - 1 > latent:  # the VAE has only D latent dimensions: PCA with as many too
        pcas += [(False, latent), (True, latent)]
    for aligned, k in pcas:
        t0 = time.perf_counter()
        res = pca_baseline(V[~mask], V[mask], n_components=k, aligned=aligned)
        label = ("PCA aligned" if aligned else "PCA coords") + ("" if k is None else f" k={k}")
        row = {"collection": name, "features": label, "K": 3 * V.shape[1], "train_error": res["train_error"],
               "held_out_error": res["mean_vertex_error"], "relative_error": res["relative_error"],
               "epochs": 0, "seconds": time.perf_counter() - t0, "n_components": res["n_components"]}
        rows.append(row)
        print(f"{label:26s} {row['K']:7d} {row['train_error']:12.4e} {row['held_out_error']:10.4e}"
              f" {100 * row['relative_error']:7.3f} {'':>6s} {row['seconds']:9.1f}   ({res['n_components']} components)",
              flush=True)
    floor = linear_floor(V, args.holdout_every)
    next(r for r in rows if r["features"] == "PCA coords").update(floor_relative=floor["relative"],
                                                                   informative=floor["informative"])
    print(f"linear floor: {floor['relative']:.2e} of the diagonal"
          + ("" if floor["informative"] else f" ({NOT_INFORMATIVE}: a held-out mesh is a linear combination of training"
                                             " meshes; no learned row here says anything about a representation)"),
          flush=True)
    err = {r["features"]: r["held_out_error"] for r in rows}
    if all(k in err for k in KINDS):
        r, a, c, p = err["rimd"], err["aligned"], err["coords"], err["PCA coords"]
        print(f"RIMD held-out error is {100 * (1 - r / c):.0f}% lower than 3D coordinates' (paper: 59 to 94% lower)"
              f" and {100 * (1 - r / a):.0f}% lower than aligned coordinates' (paper: 27 to 72%; negative: higher);"
              f" RIMD / PCA on coordinates = {r / p:.3g}; order RIMD < aligned < coords: {'yes' if r < a < c else 'NO'}",
              flush=True)
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", default=None,
                    help=f"comma-separated collections of {SHARED_DATA} (default: {','.join(REAL)} when present)")
    ap.add_argument("--synth", default=None,
                    help="use this data_synth collection instead of the real ones (default when no real data: scape)")
    ap.add_argument("--resolution", type=int, default=500, help="data_synth template vertex count (0: its own)")
    ap.add_argument("--subsample", type=int, default=1, help="keep every k-th mesh of a real collection")
    ap.add_argument("--holdout-every", type=int, default=5)
    ap.add_argument("--kinds", default=",".join(KINDS))
    ap.add_argument("--epochs", type=int, default=None, help="epochs (default: TrainConfig's)")
    ap.add_argument("--latent", type=int, default=None, help="latent size (default: TrainConfig's)")
    ap.add_argument("--legacy", action="store_true", help="the paper's training instead of the library's default (the PCA start)")
    ap.add_argument("--inference", default="gauss-newton,encoder",
                    help="comma-separated inference strategies to evaluate every model with (MeshVAEModel.encode_meshes;"
                         " default: the library's default, gauss-newton, and the paper's encoder)")
    ap.add_argument("--fit-latent", type=int, default=0, metavar="N",
                    help="also evaluate with latent codes fitted by finite differences (N Gauss-Newton steps)")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--json", default=None, metavar="OUT.json", help="also write the rows as JSON")
    ap.add_argument("--save-models", default=None, metavar="DIR",
                    help="also save every trained model to DIR/<collection>_<kind>.pt (for bench_inference.py)")
    args = ap.parse_args()
    os.environ.setdefault("OMP_NUM_THREADS", str(args.threads))
    torch.set_num_threads(args.threads)
    logging.basicConfig(level=logging.WARNING)

    rows = []
    names = args.real.split(",") if args.real else ([] if args.synth else
                                                      [n for n in REAL if (SHARED_DATA / f"{n}.npz").exists()])
    if names:
        print("data: " + "; ".join(REAL_CITATIONS), flush=True)
        for name in names:
            rows += run_collection(load_real(name, args.subsample), name + (f"/{args.subsample}" if args.subsample > 1 else ""),
                                   args)
    else:
        from data_synth.registry import make_collection

        synth = args.synth or "scape"
        coll = make_collection(synth, seed=args.seed, resolution=args.resolution or None)
        rows += run_collection(coll, synth, args)
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
