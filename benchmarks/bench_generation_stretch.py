"""Do prior samples and latent paths of the default model stretch edges like real meshes? (issue 23)

For each collection a RIMD model is trained with the library's defaults (every ``--holdout-every``-th
mesh held out). Three sets of meshes are measured by ``interpolation.edge_length_distortion``: the
mean relative edge-length change against the nearest *training* mesh:

- the held-out real meshes (the reference: how far a new real pose is from the training poses);
- ``--samples`` prior samples (``model.generate``);
- latent paths: for consecutive pairs of held-out meshes, their codes (the default inference), and
  ``--steps`` meshes decoded along the straight line between them (end points excluded).

The ratios samples / held-out and paths / held-out are the figures of issue 23 (target: at most 1.5);
``--temperatures`` adds the ratios of prior samples drawn at lower temperatures (``generate(temperature=...)``).

    python benchmarks/bench_generation_stretch.py                       # samba and pcow when present
    python benchmarks/bench_generation_stretch.py --real pcow --subsample 3
    python benchmarks/bench_generation_stretch.py --synth scape          # without the real data
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
import torch

from feature_comparison import SHARED_DATA, load_real
from meshvae_lib.applications.interpolation import edge_length_distortion
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.meshvae_model import MeshVAEModel
from meshvae_lib.model.train_config import TrainConfig


def measure(coll, name: str, args) -> dict:
    t0 = time.perf_counter()
    saved = Path(args.models or "") / f"{name.replace('/', '_')}_rimd.pt"
    if args.models and saved.exists():
        from meshvae_lib.model.meshvae_model import load_model

        model = load_model(saved, coll)
    else:
        model = MeshVAEModel("rimd", TrainConfig(seed=args.seed, progress=False, device="cpu"),
                             holdout_every=args.holdout_every).fit(coll)
    train_s = time.perf_counter() - t0
    V, F = np.asarray(coll.vertices, dtype=np.float64), np.asarray(coll.faces)
    mask = model.holdout_mask_
    train, held = V[~mask], V[mask]
    real, _ = edge_length_distortion(held, F, train)
    # prior samples at the paper's temperature 1 and at --temperatures: their stretch, and their variety
    # (how far they lie from their own mean, over the same for the training meshes rigidly aligned to
    # the reference, as decoded meshes are)
    spread = lambda M: float(np.linalg.norm(M - M.mean(axis=0), axis=-1).mean())  # noqa: E731
    data_spread = spread(np.stack([rigid_align(x, model.reference_vertices) for x in train]))
    tempered = {}
    for t in [1.0] + [t for t in args.temperatures if t != 1.0]:
        M = model.generate(args.samples, seed=args.seed, temperature=t)
        tempered[t] = (edge_length_distortion(M, F, train)[0], spread(M) / data_spread)
    samples, variety = tempered.pop(1.0)
    z = model.encode_meshes(held)
    t = np.linspace(0.0, 1.0, args.steps + 2)[1:-1]
    path_z = np.concatenate([(1 - t)[:, None] * z[k] + t[:, None] * z[k + 1] for k in range(len(z) - 1)])
    paths, _ = edge_length_distortion(model.decode_latent(path_z), F, train)
    row = {"collection": name, "n_train": int((~mask).sum()), "n_held_out": int(mask.sum()),
           "held_out_real": float(real.mean()), "prior_samples": float(samples.mean()),
           "latent_paths": float(paths.mean()), "samples_ratio": float(samples.mean() / real.mean()),
           "paths_ratio": float(paths.mean() / real.mean()), "train_seconds": train_s,
           "samples_variety": variety,
           "tempered": {str(t): {"samples_ratio": float(v.mean() / real.mean()), "variety": var}
                        for t, (v, var) in tempered.items()}}
    print(f"{name:10s} held-out real {row['held_out_real']:.4f}  prior samples {row['prior_samples']:.4f}"
          f" ({row['samples_ratio']:.2f}x)  latent paths {row['latent_paths']:.4f} ({row['paths_ratio']:.2f}x)"
          f"  [{row['n_train']} train / {row['n_held_out']} held out; {args.samples} samples;"
          f" {len(path_z)} path meshes]", flush=True)
    print(f"{'':10s} prior samples' variety {row['samples_variety']:.2f} of the training meshes' spread", flush=True)
    for t, r in row["tempered"].items():
        print(f"{'':10s} prior samples at temperature {t}: {r['samples_ratio']:.2f}x, variety {r['variety']:.2f}", flush=True)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--real", default=None, help="comma-separated collections of ../shared/data (default: samba,pcow)")
    ap.add_argument("--synth", default=None, help="a data_synth collection instead")
    ap.add_argument("--subsample", type=int, default=1)
    ap.add_argument("--holdout-every", type=int, default=5)
    ap.add_argument("--samples", type=int, default=32)
    ap.add_argument("--steps", type=int, default=3)
    ap.add_argument("--temperatures", type=lambda t: [float(x) for x in t.split(",") if x], default=[0.7, 0.5],
                    help="also measure prior samples drawn at these temperatures (model.generate(temperature=...))")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--models", default=None, metavar="DIR",
                    help="load DIR/<collection>_rimd.pt where present (feature_comparison.py --save-models) instead of training")
    ap.add_argument("--json", default=None, metavar="OUT.json")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    rows = []
    if args.synth:
        from data_synth.registry import make_collection

        rows.append(measure(make_collection(args.synth, seed=args.seed), args.synth, args))
    else:
        names = args.real.split(",") if args.real else [n for n in ("samba", "pcow") if (SHARED_DATA / f"{n}.npz").exists()]
        for name in names:
            rows.append(measure(load_real(name, args.subsample), name + (f"/{args.subsample}" if args.subsample > 1 else ""),
                                args))
    if args.json:
        Path(args.json).write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
