"""``meshvae features DATA -o feats.npz``: RIMD features of a mesh collection."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

from meshvae_lib.defaults import DEFAULT_LAYOUT, LAYOUTS
from . import UsageError, add_allow_degenerate, add_command, add_output_argument, check_output, resolve_mesh, result

logger = logging.getLogger(__name__)

DESCRIPTION = """\
Compute the RIMD feature (paper Sec. 3, Eq. 2) of every mesh of a collection relative to one
reference mesh, and write them with the reference, the faces, the names and any labels to one
.npz file (float64). DATA is an .npz collection (vertices (N, V, 3), faces (F, 3), optional names
and label_<column>) or a folder of OBJ/PLY/OFF files sharing one connectivity (natural order,
optional labels.csv).

Feature layout (see docs/geometry.md): `paper` (default) stores log dR_ij of every directed edge
(3 numbers each) and then the 6 upper-triangle entries of S_i of every vertex: K = 6V + 6E;
`compact` stores each undirected edge once: K = 6V + 3E.

examples:
  meshvae features horse.npz -o horse_feats.npz
  meshvae features poses/ -o feats.npz --reference 3
  meshvae features poses/ -o feats.npz --reference rest.obj --layout compact
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "features", "RIMD features of a mesh collection", DESCRIPTION, run)
    p.add_argument("data", metavar="DATA", help="collection: .npz file or folder of meshes")
    add_output_argument(p, "FEATS.npz", "feature file to write (.npz)")
    p.add_argument("--reference", default="0", metavar="FILE_OR_INDEX",
                   help="reference mesh: an index into the collection (default 0, the first mesh; "
                   "negative counts from the end), a mesh name from the collection, or a mesh file "
                   "with the same connectivity")
    p.add_argument("--layout", choices=LAYOUTS, default=DEFAULT_LAYOUT,
                   help=f"feature layout (default: {DEFAULT_LAYOUT})")
    add_allow_degenerate(p)
    return p


def run(args) -> int:
    from meshvae_lib.geometry.collection_io import read_collection
    from meshvae_lib.geometry.rimd import RIMDEncoder
    from meshvae_lib.geometry.rimd_files import save_features

    out = Path(args.output)
    if out.suffix.lower() != ".npz":
        raise UsageError(f"the output must be an .npz file, got {out}")
    if not out.parent.is_dir():
        raise UsageError(f"folder does not exist: {out.parent}")
    check_output(out)
    col = read_collection(args.data, allow_degenerate=args.allow_degenerate, progress=True)
    ref = resolve_mesh(args.reference, col, "--reference", allow_degenerate=args.allow_degenerate)
    logger.info("reference: %s", ref.describe())
    enc = RIMDEncoder(ref.vertices, col.faces, layout=args.layout)
    feats = enc.transform(col.vertices, progress=len(col) > 8)
    save_features(out, feats, ref.vertices, col.faces, col.names, col.labels, layout=args.layout)
    result(f"wrote {feats.shape[0]} feature vectors of length K = {feats.shape[1]} "
           f"({args.layout} layout, reference: {ref.describe()}) to {out}")
    return 0
