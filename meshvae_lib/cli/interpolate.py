"""``meshvae interpolate model.pt A B --steps S -o OUT``: a deformation sequence between two meshes."""

from __future__ import annotations

import argparse

from . import (UsageError, add_allow_degenerate, add_command, add_model_argument, add_output_argument,
               check_at_least, check_budget, check_output, resolve_mesh, result)

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
    p = add_command(subparsers, "interpolate", "interpolate between two meshes in the latent space", DESCRIPTION, run)
    add_model_argument(p)
    p.add_argument("a", metavar="A", help="start: mesh file, or index (or mesh name) into --data")
    p.add_argument("b", metavar="B", help="end: mesh file, or index (or mesh name) into --data")
    p.add_argument("--steps", type=int, default=10, metavar="S", help="meshes in the sequence, ends included (default 10)")
    add_output_argument(p)
    p.add_argument("--data", default=None, metavar="DATA", help="collection that A and B index into")
    add_allow_degenerate(p)
    return p


def run(args) -> int:
    import numpy as np

    from meshvae_lib.applications.interpolation import LatentPath, linear_steps
    from meshvae_lib.model.meshvae_model import load_model
    from meshvae_lib.geometry.collection_io import read_collection, write_collection

    check_at_least(args.steps, 2, "--steps", "both ends are included")
    check_output(args.output, collection=True)
    collection = read_collection(args.data, allow_degenerate=args.allow_degenerate) if args.data else None
    model = load_model(args.model, collection)
    check_budget(args.steps, len(model.reference_vertices), "--steps")
    ends = [resolve_mesh(spec, collection, what, faces=model.faces, n_vertices=len(model.reference_vertices),
                         owner="the model's", allow_degenerate=args.allow_degenerate,
                         hint="" if collection is not None else " (to use an index, give --data DATA)")
            for spec, what in ((args.a, "A"), (args.b, "B"))]
    c_ends = c_path = None  # a conditional model: the two ends' condition vectors and the path between them
    if model.is_conditional:
        if any(e.index is None for e in ends):
            raise UsageError("this model is conditional: give A and B as indices into --data so that"
                             " their labels are known")
        c_ends = [model.condition_vector({col: collection.labels[col][e.index] for col in model.labels})
                  for e in ends]  # (1, C) each
        c_path = linear_steps(c_ends[0][0], c_ends[1][0], args.steps).astype(np.float32)

    z = model.encode_meshes(np.stack([np.asarray(e.vertices) for e in ends]),
                            conditions=None if c_ends is None else np.vstack(c_ends))
    _, V = LatentPath(lambda Z: model.decode_latent(Z, conditions=c_path), z[0], z[1]).steps(args.steps)
    names = [f"step_{i:03d}" for i in range(args.steps)]
    out = write_collection(args.output, V, model.faces, names=names)
    result(f"wrote {args.steps} meshes from {ends[0].name} to {ends[1].name} to {out}")
    return 0
