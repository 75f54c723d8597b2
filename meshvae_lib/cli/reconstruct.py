"""``meshvae reconstruct feats.npz -o OUT``: meshes from RIMD features."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from meshvae_lib.defaults import MAX_SOLVER_STEPS, RECONSTRUCTION_METHODS, ROTATION_RECOVERY
from . import UsageError, add_command, add_output_argument, check_at_least, check_at_most, check_output, result

logger = logging.getLogger(__name__)

DESCRIPTION = """\
Rebuild meshes from a RIMD feature file (written by `meshvae features`, or by a decoder in the
same format) and write them as a collection: a folder of OBJ files (+ labels.csv), or, when OUT
ends in .npz, an .npz collection (vertices, faces, names, label_<column>). Every mesh is rigidly
aligned to the reference mesh stored in the feature file.

methods (see docs/geometry.md for measured accuracy and speed):
  exact  (default) inverts the feature extraction: exact features give the meshes back to ~1e-13
         of the bounding-box diagonal; noisy features degrade gracefully.
  paper  minimises the paper's Eq. 1 over positions (one sparse Laplacian solve): an
         approximation, typically 1e-4 to 1e-3 of the diagonal.

examples:
  meshvae reconstruct feats.npz -o meshes/
  meshvae reconstruct feats.npz -o rebuilt.npz --method paper
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "reconstruct", "meshes from RIMD features", DESCRIPTION, run)
    p.add_argument("features", metavar="FEATS.npz", help="feature file from `meshvae features`")
    add_output_argument(p, help="folder to write OBJ files to, or an .npz collection file")
    p.add_argument("--method", choices=RECONSTRUCTION_METHODS, default="exact",
                   help="position solve (default: exact)")
    p.add_argument("--rotations", choices=ROTATION_RECOVERY, default="global",
                   help="rotation recovery: global least squares over all edges (default, robust "
                   "to noise) or the reference's spanning-tree walk")
    p.add_argument("--iterations", type=int, default=0, metavar="N",
                   help="--method paper only: the reference's local/global rounds (default 0)")
    return p


def run(args) -> int:
    from meshvae_lib.geometry.collection_io import write_collection
    from meshvae_lib.geometry.reconstruction import RIMDReconstructor
    from meshvae_lib.geometry.rimd_files import load_features

    out = Path(args.output)
    check_at_least(args.iterations, 0, "--iterations")
    check_at_most(args.iterations, MAX_SOLVER_STEPS, "--iterations", "local/global rounds per mesh")
    if out.suffix.lower() == ".npz" and not out.parent.is_dir():
        raise UsageError(f"folder does not exist: {out.parent}")
    if out.exists() and not out.is_dir() and out.suffix.lower() != ".npz":
        raise UsageError(f"{out} exists and is not a folder")
    check_output(out, collection=True)
    data = load_features(args.features)
    rec = RIMDReconstructor(data["reference"], data["faces"], method=args.method,
                            layout=data["layout"], rotations=args.rotations,
                            iterations=args.iterations)
    V = rec.reconstruct(data["features"], progress=len(data["features"]) > 8)
    write_collection(out, V, data["faces"], data["names"], data["labels"])
    result(f"wrote {len(V)} meshes ({args.method} method) to {out}")
    return 0
