"""``meshvae features DATA -o feats.npz``: RIMD features of a mesh collection."""

from __future__ import annotations

import argparse
import logging
import sys
from pathlib import Path

import numpy as np

from meshvae_lib.defaults import LAYOUTS
from . import add_allow_degenerate

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
    p = subparsers.add_parser(
        "features", help="RIMD features of a mesh collection", description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("data", metavar="DATA", help="collection: .npz file or folder of meshes")
    p.add_argument("-o", "--output", required=True, metavar="FEATS.npz",
                   help="feature file to write (.npz)")
    p.add_argument("--reference", default="0", metavar="FILE_OR_INDEX",
                   help="reference mesh: an index into the collection (default 0, the first mesh; "
                   "negative counts from the end), a mesh name from the collection, or a mesh file "
                   "with the same connectivity")
    p.add_argument("--layout", choices=LAYOUTS, default="paper",
                   help="feature layout (default: paper)")
    add_allow_degenerate(p)
    p.set_defaults(func=run)
    return p


def _pick_reference(spec: str, collection, allow_degenerate: bool) -> tuple[np.ndarray, str]:
    from meshvae_lib.geometry.mesh_io import read_mesh

    n = len(collection)
    try:
        k = int(spec)
    except ValueError:
        k = None
    if k is not None:
        if not -n <= k < n:
            raise ValueError(f"--reference {k} is out of range for {n} meshes")
        return collection.vertices[k], f"mesh {collection.names[k]!r} (index {k % n})"
    if spec in collection.names:
        k = collection.names.index(spec)
        return collection.vertices[k], f"mesh {spec!r} (index {k})"
    path = Path(spec)
    if not path.exists():
        raise FileNotFoundError(
            f"--reference {spec!r} is neither an index, a mesh name of the collection, nor a file")
    V, F = read_mesh(path, allow_degenerate=allow_degenerate)
    if len(V) != collection.n_vertices or F.shape != collection.faces.shape or np.any(
            F != collection.faces):
        raise ValueError(
            f"--reference {path.name}: its connectivity ({len(V)} vertices, {len(F)} faces) differs "
            f"from the collection's ({collection.n_vertices} vertices, {len(collection.faces)} faces)")
    return V, f"file {path.name}"


def run(args) -> int:
    from meshvae_lib.geometry.mesh_io import read_collection
    from meshvae_lib.geometry.rimd import RIMDEncoder, save_features

    out = Path(args.output)
    if out.suffix.lower() != ".npz":
        raise ValueError(f"the output must be an .npz file, got {out}")
    if not out.parent.is_dir():
        raise FileNotFoundError(f"folder does not exist: {out.parent}")
    col = read_collection(args.data, allow_degenerate=args.allow_degenerate, progress=True)
    V0, what = _pick_reference(args.reference, col, args.allow_degenerate)
    logger.info("reference: %s", what)
    enc = RIMDEncoder(V0, col.faces, layout=args.layout)
    feats = enc.transform(col.vertices, progress=len(col) > 8)
    save_features(out, feats, V0, col.faces, col.names, col.labels, layout=args.layout)
    print(f"wrote {feats.shape[0]} feature vectors of length K = {feats.shape[1]} "
          f"({args.layout} layout, reference: {what}) to {out}", file=sys.stderr)
    return 0
