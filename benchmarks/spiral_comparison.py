"""The spiral-convolution network beside the paper's network and the linear floor, at the same latent size.

For each collection, every ``--holdout-every``-th mesh held out (``training.holdout_mask``), the same
error for every row (mean vertex distance after rigid alignment, mesh units, ``evaluate_model``):

- PCA on coordinates with ``--latent`` directions (the linear floor at equal capacity);
- the spiral network (``TrainConfig(architecture="spiral")``, SpiralNet++'s settings, latent
  ``--latent``) on coordinates, through its encoder and through the default Gauss-Newton inference;
- the paper's network on RIMD features at latent ``--latent`` (its PCA start, same inferences);
- the RIMD default (latent resolved by ``TrainConfig``: one dimension per direction the training
  meshes span), marked with its used dimensions: it has more than ``--latent``.

Training time (features + training) and encoding time per held-out mesh (default inference) beside
each. Collections: the real ones in ``../shared/data`` (not part of the repository) and the
``data_synth`` stand-ins, e.g.::

    python benchmarks/spiral_comparison.py --collections scape samba/3 pcow/3 pcow --out docs/results/spiral_real.json

One torch thread per run (``--threads``); results are appended to ``--out`` (JSON, one record per
collection) so that runs split over processes can be merged by :func:`markdown`.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from collection_records import add_record_options, run_collections
from feature_comparison import SHARED_DATA, load_real
from meshvae_lib.model.evaluation import evaluate_model, pca_baseline
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig


def load(name: str) -> tuple[object, str]:
    """``name`` = a real collection of ../shared/data, optionally ``/k`` (every k-th frame), or a
    data_synth collection."""
    base, _, k = name.partition("/")
    if (SHARED_DATA / f"{base}.npz").exists():
        return load_real(base, int(k or 1)), "real"
    from data_synth.registry import make_collection

    return make_collection(base, seed=0), "synthetic stand-in"


def _row(model: MeshVAEModel, coll, inference: str, first: int | None) -> dict:
    idx = np.flatnonzero(model.holdout_mask_)[:first]
    t = time.perf_counter()
    r = evaluate_model(model, coll, indices=idx, inference=inference)
    return {"error": r["mean_vertex_error"], "seconds_per_mesh": (time.perf_counter() - t) / len(idx),
            "n_meshes": len(idx)}


def run(name: str, args) -> dict:
    coll, source = load(name)
    V = np.asarray(coll.vertices, np.float64)
    rec = {"collection": name, "source": source, "meshes": len(V), "vertices": V.shape[1], "latent": args.latent}
    models = {
        "spiral": ("coords", TrainConfig(architecture="spiral", latent_dim=args.latent, progress=False, device="cpu")),
        "rimd_equal": ("rimd", TrainConfig(latent_dim=args.latent, progress=False, device="cpu")),
        "rimd_default": ("rimd", TrainConfig(progress=False, device="cpu")),
    }
    mask = None
    for key, (kind, cfg) in models.items():
        t = time.perf_counter()
        model = MeshVAEModel(kind, cfg, holdout_every=args.holdout_every).fit(coll)
        mask = model.holdout_mask_
        rec[key] = {"train_seconds": time.perf_counter() - t, "latent": model.latent_dim,
                    "used": int(len(model.used_latent_dims)), "epochs": int(model.train_epochs_),
                    "encoder": _row(model, coll, "encoder", args.first),
                    "gauss_newton": _row(model, coll, "gauss-newton", args.first)}
        print(name, key, json.dumps(rec[key]), flush=True)
    idx = np.flatnonzero(mask)[: args.first]
    rec["n_train"], rec["n_held_out"] = int((~mask).sum()), int(mask.sum())
    rec["pca"] = pca_baseline(V[~mask], V[idx], n_components=args.latent)["mean_vertex_error"]
    rec["pca_all"] = pca_baseline(V[~mask], V[idx])["mean_vertex_error"]
    print(name, "pca", rec["pca"], "pca with every direction", rec["pca_all"], flush=True)
    return rec


def markdown(records: list[dict]) -> str:
    """The table of the records (one row per collection)."""
    head = ("| collection | vertices | train / held out (evaluated) | PCA coords, D | spiral, encoder | **spiral, Gauss-Newton** "
            "| RIMD, D, encoder | **RIMD, D, Gauss-Newton** | RIMD default (used dims > D) | spiral train (s) | RIMD D train (s) "
            "| encode s/mesh spiral / RIMD D / default |\n" + "| --- " * 12 + "|\n")
    rows = []
    for r in records:
        s, q, d = r["spiral"], r["rimd_equal"], r["rimd_default"]
        n_eval = s["gauss_newton"]["n_meshes"]
        rows.append(
            f"| {r['collection']} ({r['source']}) | {r['vertices']:,} | {r['n_train']} / {r['n_held_out']} ({n_eval})"
            f" | {r['pca']:.3g} (D = {r['latent']}) | {s['encoder']['error']:.3g} | **{s['gauss_newton']['error']:.3g}**"
            f" | {q['encoder']['error']:.3g} | **{q['gauss_newton']['error']:.3g}** | {d['gauss_newton']['error']:.3g}"
            f" ({d['used']} dims; PCA with all: {r['pca_all']:.3g}) | {s['train_seconds']:.0f} | {q['train_seconds']:.0f}"
            f" | {s['gauss_newton']['seconds_per_mesh']:.2f} / {q['gauss_newton']['seconds_per_mesh']:.2f}"
            f" / {d['gauss_newton']['seconds_per_mesh']:.2f} |")
    return head + "\n".join(rows) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--collections", nargs="+", default=["scape", "samba/3", "pcow/3", "pcow"])
    p.add_argument("--latent", type=int, default=16)
    p.add_argument("--holdout-every", type=int, default=5)
    p.add_argument("--first", type=int, default=None, help="evaluate only the first this-many held-out meshes")
    add_record_options(p)
    return run_collections(p.parse_args(argv), run, markdown)


if __name__ == "__main__":
    raise SystemExit(main())
