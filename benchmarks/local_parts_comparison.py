"""The decoder of local parts beside the global default and the linear floors, at equal capacity (issue 40).

For each collection, every ``--holdout-every``-th mesh held out (``training.holdout_mask``; the
first ``--first`` of them evaluated), the same error for every row (mean vertex distance after rigid
alignment, mesh units, ``evaluate_model`` / ``pca_baseline``), all inference by the default
Gauss-Newton:

- the local-parts network (``TrainConfig(architecture="local-parts")``) for each ``--variants``
  ``R:method`` (R regions found by the rule ``method``, ``--latent / R`` dimensions a region);
- PCA on coordinates with the same regions and the same directions a region
  (``regional_pca_baseline``): the linear floor of a decoder of parts at equal capacity;
- the global default (RIMD, latent resolved by ``TrainConfig``: one dimension per direction the
  training meshes span), and where that is more than ``--latent`` the same network at latent
  ``--latent`` (equal capacity); global PCA on coordinates with ``--latent`` directions (capped at
  the training meshes' N - 1) and with all of them.

``--stretch``: edge stretch (``interpolation.edge_length_distortion``: mean relative edge-length
change against the nearest training mesh) of the held-out meshes, of ``--samples`` meshes whose
parts are mixed from the training meshes' codes (``generation.mix_parts``) and of as many prior
samples (``model.generate``), for the first variant.

    python benchmarks/local_parts_comparison.py --collections scape dyna samba/3 --out docs/results/local_parts.json
    python benchmarks/local_parts_comparison.py --table docs/results/local_parts.json

Records are appended to ``--out`` (JSON, one per collection) so that runs split over processes merge.
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from collection_records import add_record_options, run_collections
from spiral_comparison import load
from meshvae_lib.applications.generation import mix_parts
from meshvae_lib.applications.interpolation import edge_length_distortion
from meshvae_lib.model.evaluation import evaluate_model, pca_baseline, regional_pca_baseline
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig
from meshvae_lib.model.training import holdout_mask


def _evaluate(model: MeshVAEModel, coll, idx) -> dict:
    t = time.perf_counter()
    r = evaluate_model(model, coll, indices=idx, inference="gauss-newton")
    return {"error": r["mean_vertex_error"], "per_mesh": r.get("per_mesh"),
            "seconds_per_mesh": (time.perf_counter() - t) / len(idx)}


def _stretch(model: MeshVAEModel, coll, args) -> dict:
    V, F = np.asarray(coll.vertices, np.float64), np.asarray(coll.faces)
    mask = model.holdout_mask_
    train = V[~mask]
    held, _ = edge_length_distortion(V[mask], F, train)
    codes = model.encode_meshes(train, inference="encoder")
    h = float(np.mean(held))
    out = {"held_out": h}
    for k in [None, *args.neighbours]:
        z, _ = mix_parts(codes, model.network.latent_region.numpy(), args.samples, seed=0, neighbours=k)
        mixed = float(np.mean(edge_length_distortion(model.decode_latent(z), F, train)[0]))
        key = "mixed_parts" if k is None else f"mixed_parts_{k}"
        out[key], out[key.replace("parts", "ratio")] = mixed, mixed / h
    prior = float(np.mean(edge_length_distortion(model.generate(args.samples, seed=0), F, train)[0]))
    out["prior"], out["prior_ratio"] = prior, prior / h
    return out


def run(name: str, args) -> dict:
    coll, source = load(name)
    V = np.asarray(coll.vertices, np.float64)
    rec = {"collection": name, "source": source, "meshes": len(V), "vertices": V.shape[1], "latent": args.latent,
           "variants": {}}
    mask = holdout_mask(len(V), args.holdout_every)
    idx = np.flatnonzero(mask)[: args.first]
    for variant in args.variants:
        R, method = variant.split(":")
        cfg = TrainConfig(architecture="local-parts", latent_dim=args.latent, progress=False, device="cpu",
                          network_options={"n_regions": int(R), "method": method})
        t = time.perf_counter()
        model = MeshVAEModel("rimd", cfg, holdout_every=args.holdout_every).fit(coll)
        train_s = time.perf_counter() - t
        assert np.array_equal(mask, model.holdout_mask_)
        regions = model.network.vertex_region.numpy()
        row = {"train_seconds": train_s, "used": int(len(model.used_latent_dims)),
               "region_sizes": np.bincount(regions).tolist(), **_evaluate(model, coll, idx)}
        floor = regional_pca_baseline(V[~mask], V[idx], regions, args.latent // int(R))
        row["regional_pca"], row["regional_pca_directions"] = floor["mean_vertex_error"], floor["n_components"]
        if args.stretch and variant == args.variants[0]:
            row["stretch"] = _stretch(model, coll, args)
        rec["variants"][variant] = row
        print(name, variant, json.dumps({k: v for k, v in row.items() if k != "per_mesh"}), flush=True)
    rec["n_train"], rec["n_held_out"], rec["n_evaluated"] = int((~mask).sum()), int(mask.sum()), len(idx)
    t = time.perf_counter()
    default = MeshVAEModel("rimd", TrainConfig(progress=False, device="cpu"), holdout_every=args.holdout_every).fit(coll)
    rec["default"] = {"train_seconds": time.perf_counter() - t, "latent": default.latent_dim,
                      "used": int(len(default.used_latent_dims)), **_evaluate(default, coll, idx)}
    print(name, "default", json.dumps({k: v for k, v in rec["default"].items() if k != "per_mesh"}), flush=True)
    if default.latent_dim > args.latent:  # the global model at the local one's capacity
        equal = MeshVAEModel("rimd", TrainConfig(latent_dim=args.latent, progress=False, device="cpu"),
                             holdout_every=args.holdout_every).fit(coll)
        rec["default_equal"] = {"latent": equal.latent_dim, "used": int(len(equal.used_latent_dims)), **_evaluate(equal, coll, idx)}
        print(name, "default_equal", json.dumps({k: v for k, v in rec["default_equal"].items() if k != "per_mesh"}), flush=True)
    k = min(args.latent, rec["n_train"] - 1)
    rec["pca"], rec["pca_directions"] = pca_baseline(V[~mask], V[idx], n_components=k)["mean_vertex_error"], k
    rec["pca_all"] = pca_baseline(V[~mask], V[idx])["mean_vertex_error"]
    print(name, "pca", rec["pca"], "pca with every direction", rec["pca_all"], flush=True)
    return rec


def markdown(records: list[dict]) -> str:
    """The table of the records: one row per collection and variant."""
    head = ("| collection | vertices | train / held out (evaluated) | local parts R:rule (used dims) | **local parts** "
            "| regional PCA coords, same dims | global default (used dims) | global RIMD at the same latent size "
            "| global PCA coords (dims) | PCA, all dims | encode s/mesh local / default |\n" + "| --- " * 11 + "|\n")
    rows = []
    for r in records:
        d, e = r["default"], r.get("default_equal")
        same = f"{e['error']:.3g} ({e['used']})" if e else "= default"
        for key, v in r["variants"].items():
            rows.append(
                f"| {r['collection']} ({r['source']}) | {r['vertices']:,} | {r['n_train']} / {r['n_held_out']}"
                f" ({r['n_evaluated']}) | {key} ({v['used']}) | **{v['error']:.3g}** | {v['regional_pca']:.3g}"
                f" | {d['error']:.3g} ({d['used']}) | {same} | {r['pca']:.3g} ({r['pca_directions']}) | {r['pca_all']:.3g}"
                f" | {v['seconds_per_mesh']:.2f} / {d['seconds_per_mesh']:.2f} |")
    out = head + "\n".join(rows) + "\n"
    st = [(r["collection"], key, v["stretch"]) for r in records for key, v in r["variants"].items() if "stretch" in v]
    if st:
        ks = sorted({k for *_, s in st for k in s if k.startswith("mixed_parts_")}, key=lambda k: -int(k.rsplit("_", 1)[1]))
        cell = lambda s, k: f"{s[k]:.3g} ({s[k.replace('parts', 'ratio')]:.2f})" if k in s else "—"  # noqa: E731
        out += ("\n| collection | local parts | stretch, held out | mixed parts, any sources (ratio) | "
                + " | ".join(f"mixed parts, {k.rsplit('_', 1)[1]} nearest (ratio)" for k in ks)
                + " | prior samples (ratio) |\n" + "| --- " * (5 + len(ks)) + "|\n")
        out += "\n".join(f"| {c} | {key} | {s['held_out']:.3g} | {cell(s, 'mixed_parts')} | "
                         + "".join(f"{cell(s, k)} | " for k in ks) + f"{s['prior']:.3g} ({s['prior_ratio']:.2f}) |"
                         for c, key, s in st) + "\n"
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--collections", nargs="+", default=["scape", "dyna", "samba/3", "pdance/3", "pcow/3", "pcow"])
    p.add_argument("--variants", nargs="*", default=["4:spectral"], help="R:method of the local-parts network")
    p.add_argument("--latent", type=int, default=128)
    p.add_argument("--holdout-every", type=int, default=5)
    p.add_argument("--first", type=int, default=None, help="evaluate only the first this-many held-out meshes")
    p.add_argument("--stretch", action="store_true", help="also measure the edge stretch of generated meshes")
    p.add_argument("--samples", type=int, default=20)
    p.add_argument("--neighbours", type=int, nargs="*", default=[5], help="mixed parts drawn among a base's k nearest codes")
    add_record_options(p)
    return run_collections(p.parse_args(argv), run, markdown)


if __name__ == "__main__":
    raise SystemExit(main())
