"""``meshvae interpolate model.pt A B --steps S -o OUT``: a deformation sequence between two meshes."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from . import add_allow_degenerate

DESCRIPTION = """\
Encode meshes A and B to their latent means, interpolate linearly in the latent space and decode
every step (paper Sec. 5, "Interpolation"). A and B are mesh files (OBJ/PLY/OFF, same connectivity
as the model's mesh) or, with --data, indices into a collection. The sequence starts at A and ends
at B (S steps, both ends included). OUT ending in .npz gets an .npz collection, any other OUT a
folder of OBJ files.

examples:
  meshvae interpolate jumping.pt 0 120 --data jumping.npz --steps 10 -o jump_seq/
  meshvae interpolate scape.pt a.obj b.obj --steps 8 -o seq.npz
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser("interpolate", help="interpolate between two meshes in the latent space",
                              description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("model", metavar="MODEL.pt", help="checkpoint written by `meshvae train`")
    p.add_argument("a", metavar="A", help="start: mesh file, or index into --data")
    p.add_argument("b", metavar="B", help="end: mesh file, or index into --data")
    p.add_argument("--steps", type=int, default=10, metavar="S", help="meshes in the sequence, ends included (default 10)")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help=".npz file or folder for OBJ files")
    p.add_argument("--data", default=None, metavar="DATA", help="collection that A and B index into")
    add_allow_degenerate(p)
    p.set_defaults(func=run)
    return p


def _resolve(spec: str, collection, what: str):
    """-> (vertices (n, 3), label row dict or None, name)."""
    from meshvae_lib.geometry.mesh_io import read_mesh

    if collection is not None:
        try:
            i = int(spec)
        except ValueError:
            i = None
        if i is None and spec in collection.names:
            i = collection.names.index(spec)
        if i is not None:
            n = len(collection)
            if not -n <= i < n:
                raise ValueError(f"{what} index {i} is outside 0..{n - 1} of {n} meshes")
            labels = {k: np.asarray(v)[[i]] for k, v in collection.labels.items()}
            return collection.vertices[i], labels, collection.names[i]
    path = Path(spec)
    if not path.exists():
        hint = "" if collection is not None else " (to use an index, give --data DATA)"
        raise FileNotFoundError(f"{what}: no mesh file {spec!r}{hint}")
    V, F = read_mesh(path)
    return V, None, path.stem, F


def run(args) -> int:
    from meshvae_lib.model.checkpoint import load_model
    from meshvae_lib.geometry.mesh_io import read_collection, write_collection

    if args.steps < 2:
        raise ValueError(f"--steps must be >= 2 (both ends are included), got {args.steps}")
    collection = read_collection(args.data, allow_degenerate=args.allow_degenerate) if args.data else None
    model = load_model(args.model, collection)
    ends = []
    for spec, what in ((args.a, "A"), (args.b, "B")):
        res = _resolve(spec, collection, what)
        V, labels, name = res[:3]
        model.extractor_.check_compatible(V[None], res[3] if len(res) > 3 else None)
        ends.append((V, labels, name))
    cond = None
    if model.is_conditional:
        if ends[0][1] is None or ends[1][1] is None:
            raise ValueError("this model is conditional: give A and B as indices into --data so that"
                             " their labels are known")
        c = [model.conditions_.transform(e[1]) for e in ends]
    z = [model.encode_meshes(e[0][None], conditions=c[i] if model.is_conditional else None) for i, e in enumerate(ends)]
    t = np.linspace(0.0, 1.0, args.steps)[:, None]
    Z = (1 - t) * z[0] + t * z[1]
    if model.is_conditional:
        cond = ((1 - t) * c[0] + t * c[1]).astype(np.float32)
    V = model.decode_latent(Z, conditions=cond)
    names = [f"step_{i:03d}" for i in range(args.steps)]
    out = write_collection(args.output, V, model.faces, names=names)
    print(f"wrote {args.steps} meshes from {ends[0][2]} to {ends[1][2]} to {out}")
    return 0
