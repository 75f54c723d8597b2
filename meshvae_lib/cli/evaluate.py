"""``meshvae evaluate model.pt DATA``: per-vertex reconstruction error of a trained model."""

from __future__ import annotations

import argparse
import json

DESCRIPTION = """\
Encode every mesh of DATA to its latent mean, decode it, align it rigidly to the original and
report the mean per-vertex distance (the error of the paper's Table 3), in the mesh's own units.
With --held-out only the meshes held out during training are measured (DATA must then be the
training collection).

examples:
  meshvae evaluate scape.pt scape.npz
  meshvae evaluate scape.pt scape.npz --held-out --json
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("evaluate", help="per-vertex reconstruction error of a model on a collection",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL.pt", help="checkpoint written by `meshvae train`")
    p.add_argument("data", metavar="DATA", help="collection (.npz or folder) with the model's mesh")
    p.add_argument("--held-out", action="store_true", help="only the meshes held out in training")
    p.add_argument("--json", action="store_true",
                   help="print JSON (mean_vertex_error, n_meshes, relative_error, per_mesh, names)")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    from ..checkpoint import load_model
    from ..evaluation import evaluate_model
    from ..mesh_io import read_collection

    collection = read_collection(args.data)
    model = load_model(args.model, collection)
    res = evaluate_model(model, collection, held_out_only=args.held_out)
    if args.json:
        print(json.dumps(res, indent=2))
    else:
        worst = max(range(res["n_meshes"]), key=lambda i: res["per_mesh"][i])
        print(f"mean per-vertex error: {res['mean_vertex_error']:.6g} over {res['n_meshes']} meshes"
              f" ({100 * res['relative_error']:.3f}% of the bounding-box diagonal; features {res['features']})")
        print(f"worst: {res['names'][worst]} ({res['per_mesh'][worst]:.6g})")
    return 0
