"""When does a nonlinear decoder pay? The linear decoder against the corrected one (issue 47).

For every collection and latent size D, on the same held-out meshes:

- **PCA on coordinates** with D directions (the linear floor, ``pca_baseline``);
- **coords, corrected**: :class:`~meshvae_lib.model.corrected_decoder.CorrectedLinearDecoder` on the
  vertex coordinates (PCA with D directions plus a correction that is zero at the start, kept only
  where it helps on validation meshes set aside from the training meshes);
- **RIMD, linear**: ``tanh`` of the D principal directions of the pre-activations ``atanh(x)`` of
  the normalised RIMD rows (the default network's decoder: its PCA start is this decoder's optimum);
- **RIMD, corrected**: the corrected decoder on the same rows (the correction in the pre-activations).

Held-out codes are fitted to the held-out rows (coordinates; RIMD rows through the tanh); RIMD rows
are decoded through the normaliser and the RIMD reconstruction, and every error is the mean vertex distance after rigid alignment (the number
``meshvae evaluate`` reports). This is the feature-space fit, not the library's Gauss-Newton
inference on the vertices (which lowers RIMD's errors further, docs/results/inference_real.md): the
comparison between the linear and the corrected decoder is what this benchmark measures.

Two experiments:

- ``--crossover`` (the ``poses`` collection: one body, 1,200 poses of 16 joint angles drawn
  independently): the last ``--test-size`` poses (100) are held out; the decoders are trained on the
  first N of the first 1,000 for N in ``--train-sizes``, at every latent size: where does the correction start
  to pay, in coordinates and in RIMD?
- the collections (every 5th mesh held out, as ``meshvae train``): real captures from
  ``../shared/data`` (``name/k``: every k-th frame) and the synthetic stand-ins.

    python benchmarks/nonlinearity_crossover.py --crossover --out docs/results/nonlinearity_crossover.json
    python benchmarks/nonlinearity_crossover.py --collections samba/3 pcow/3 --out docs/results/nonlinearity_real.json
    python benchmarks/nonlinearity_crossover.py --table docs/results/nonlinearity_real.json
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

from meshvae_lib.model import (CorrectedLinearDecoder, FeatureNormalizer, holdout_mask, make_kind, per_vertex_error,
                               principal_directions)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from spiral_comparison import load  # noqa: E402

def linear_rows(Y_train: np.ndarray, Y_eval: np.ndarray, D: int) -> np.ndarray:
    """PCA with D directions fitted on ``Y_train``: the projection of ``Y_eval``."""
    mean, basis, _ = principal_directions(Y_train, D)
    return mean + ((Y_eval - mean) @ basis.T) @ basis


class RIMDRows:
    """Normalised RIMD rows of a collection (the normaliser fitted on its training meshes) and their
    way back to vertices."""

    def __init__(self, X: np.ndarray, kind, train: np.ndarray):
        self.kind = kind
        self.normalizer = FeatureNormalizer().fit(X[train])
        self.X = self.normalizer.transform(X)

    def vertices(self, rows: np.ndarray) -> np.ndarray:
        return self.kind.decode(self.normalizer.inverse_transform(rows))


def compare(V: np.ndarray, train: np.ndarray, test: np.ndarray, D: int, rimd: RIMDRows | None, seed: int) -> dict:
    """The four decoders at latent size D: errors on the test meshes, and what the corrections kept."""
    out = {"latent": D, "n_train": int(train.sum()), "n_test": int(test.sum())}
    C = V.reshape(len(V), -1)
    Vt, Vtrain = V[test], V[train]
    shape = V.shape[1:]
    t = time.perf_counter()
    out["pca_coords"] = float(np.mean(per_vertex_error(linear_rows(C[train], C[test], D).reshape(Vt.shape), Vt)))
    m = CorrectedLinearDecoder(D, seed=seed).fit(
        C[train], score=lambda R, idx: per_vertex_error(R.reshape((len(idx),) + shape), Vtrain[idx]))
    out["coords_corrected"] = float(np.mean(per_vertex_error(m.reconstruct(C[test]).reshape(Vt.shape), Vt)))
    out["coords_kept"], out["coords_report"] = m.kept_, _report(m)
    out["coords_seconds"] = time.perf_counter() - t
    if rimd is not None:
        X = rimd.X
        t = time.perf_counter()
        lin = CorrectedLinearDecoder(D, output="tanh").fit_linear(X[train])
        out["rimd_linear"] = float(np.mean(per_vertex_error(rimd.vertices(lin.reconstruct(X[test])), Vt)))
        out["rimd_linear_seconds"] = time.perf_counter() - t
        t = time.perf_counter()
        m = CorrectedLinearDecoder(D, output="tanh", seed=seed).fit(
            X[train], score=lambda R, idx: per_vertex_error(rimd.vertices(R), Vtrain[idx]))
        out["rimd_corrected"] = (out["rimd_linear"] if m.kept_ == "linear"
                                 else float(np.mean(per_vertex_error(rimd.vertices(m.reconstruct(X[test])), Vt))))
        out["rimd_kept"], out["rimd_report"] = m.kept_, _report(m)
        out["rimd_seconds"] = time.perf_counter() - t
    return out


def _report(m: CorrectedLinearDecoder) -> dict:
    r = m.report_
    return {"linear_validation": r.linear_validation, "corrected_validation": r.corrected_validation,
            "linear_score": r.linear_score, "corrected_score": r.corrected_score,
            "gain_lower_bound": r.gain_lower_bound, "linear_errors": r.linear_errors,
            "corrected_errors": r.corrected_errors,
            "best_step": r.best_step, "steps": r.steps, "reason": r.reason}


def rimd_features(V: np.ndarray, faces: np.ndarray, reference: int = 0):
    kind = make_kind("rimd", V[reference], faces)
    return kind, kind.encode(V)


def crossover(args) -> list[dict]:
    coll, _ = load("poses")
    V = np.asarray(coll.vertices, np.float64)
    test = np.zeros(len(V), bool)
    test[-args.test_size:] = True
    t = time.perf_counter()
    kind, X = rimd_features(V, coll.faces)
    print(f"poses: {len(V)} meshes, {V.shape[1]} vertices, RIMD K = {X.shape[1]} ({time.perf_counter() - t:.1f} s)",
          flush=True)
    records = []
    for n in args.train_sizes:
        train = np.zeros(len(V), bool)
        train[:n] = True
        rimd = RIMDRows(X, kind, train) if "rimd" in args.kinds else None
        for D in args.latents:
            rec = {"collection": "poses", "experiment": "crossover", **compare(V, train, test, D, rimd, args.seed)}
            records.append(rec)
            _print(rec)
            _save(args.out, records)
    return records


def collections(args) -> list[dict]:
    records = []
    for name in args.collections:
        coll, source = load(name)
        V = np.asarray(coll.vertices, np.float64)
        held = holdout_mask(len(V), 5)
        t = time.perf_counter()
        kind, X = rimd_features(V, coll.faces)
        print(f"{name} ({source}): {len(V)} meshes ({int((~held).sum())} train / {int(held.sum())} held out), "
              f"{V.shape[1]} vertices, RIMD K = {X.shape[1]} ({time.perf_counter() - t:.1f} s)", flush=True)
        rimd = RIMDRows(X, kind, ~held)
        for D in args.latents:
            rec = {"collection": name, "source": source, "experiment": "collections",
                   **compare(V, ~held, held, D, rimd, args.seed)}
            records.append(rec)
            _print(rec)
            _save(args.out, records)
    return records


def _print(r: dict) -> None:
    line = (f"  {r['collection']:10s} N={r['n_train']:5d} D={r['latent']:3d}  PCA coords {r['pca_coords']:.4g}  "
            f"coords corrected {r['coords_corrected']:.4g} ({r['coords_kept']})")
    if "rimd_linear" in r:
        line += f"  RIMD linear {r['rimd_linear']:.4g}  RIMD corrected {r['rimd_corrected']:.4g} ({r['rimd_kept']})"
    print(line, flush=True)


def _save(path: Path | None, records: list[dict]) -> None:
    if path is None:
        return
    old = json.loads(path.read_text()) if path.exists() else []
    keys = {(r["experiment"], r["collection"], r["n_train"], r["latent"]) for r in records}
    keep = [o for o in old if (o["experiment"], o["collection"], o["n_train"], o["latent"]) not in keys]
    path.write_text(json.dumps(keep + records, indent=1) + "\n")


def markdown(records: list[dict]) -> str:
    """The recorded comparison as a table: errors and their ratios to the linear decoders."""
    lines = ["| collection | train meshes | latent | PCA on coordinates | coords, corrected (kept) | "
             "ratio to PCA | RIMD, linear | RIMD, corrected (kept) | ratio to RIMD linear |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for r in records:
        rimd = ("" if "rimd_linear" not in r else
                f"{r['rimd_linear']:.4g} | {r['rimd_corrected']:.4g} ({r['rimd_kept']}) | "
                f"{r['rimd_corrected'] / r['rimd_linear']:.3f}")
        lines.append(f"| {r['collection']} | {r['n_train']} | {r['latent']} | {r['pca_coords']:.4g} | "
                     f"{r['coords_corrected']:.4g} ({r['coords_kept']}) | {r['coords_corrected'] / r['pca_coords']:.3f} | "
                     + (rimd or " | | ") + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--crossover", action="store_true", help="the poses collection at several training sizes")
    p.add_argument("--collections", nargs="*", default=[])
    p.add_argument("--latents", type=int, nargs="+", default=[2, 4, 8, 16, 32])
    p.add_argument("--train-sizes", type=int, nargs="+", default=[50, 100, 200, 500, 1000])
    p.add_argument("--kinds", default="coords,rimd")
    p.add_argument("--test-size", type=int, default=100, help="--crossover: the last meshes held out")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--out", type=Path, default=None)
    p.add_argument("--table", type=Path, default=None)
    args = p.parse_args(argv)
    if args.table is not None:
        print(markdown(json.loads(args.table.read_text())))
        return 0
    import torch

    torch.set_num_threads(args.threads)
    if args.crossover:
        crossover(args)
    if args.collections:
        collections(args)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
