"""``meshvae synth NAME -o OUT``: write a procedural deforming-mesh collection."""

from __future__ import annotations

import argparse
import logging
import time
from pathlib import Path

from . import UsageError, add_command, check_output, result

logger = logging.getLogger(__name__)

DESCRIPTION = """\
Generate one of the procedural collections that stand in for the paper's data sets (SCAPE, Dyna,
Vlasic's Jumping, the flag, the bar, the hand and the face) and write it as an .npz (OUT ends in
.npz: vertices (N, V, 3), faces (F, 3), names (N,) and one label_<column> array per label) or,
otherwise, as a folder of OBJ files plus labels.csv (a name column, then one column per label).
Every mesh of a collection shares one connectivity. The result is the same for the same --seed.

--resolution is the approximate vertex count of the template (defaults: about 2,500 for the
bodies, 1,000 to 2,000 for the others; about 7,000 matches a real body scan).

examples:
  meshvae synth --list
  meshvae synth scape -o scape.npz
  meshvae synth dyna -o dyna/ --seed 3
  meshvae synth jumping -o jumping_7k.npz --resolution 7000
  meshvae synth scape -o scape_noisy.npz --noise 1e-3
"""


def add_parser(subparsers) -> argparse.ArgumentParser:
    p = add_command(subparsers, "synth", "write a procedural deforming-mesh collection (scape, dyna, flag, ...)",
                    DESCRIPTION, run)
    p.add_argument("name", nargs="?", metavar="NAME", help="collection name (see --list)")
    p.add_argument("-o", "--output", metavar="OUT",
                   help="file ending in .npz, or a folder for OBJ files plus labels.csv")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument("--resolution", type=int, default=None, metavar="R",
                   help="approximate vertex count of the template (default: the collection's)")
    p.add_argument("--noise", type=float, default=0.0, metavar="S",
                   help="capture noise: Gaussian noise of S x the bounding-box diagonal on every vertex "
                        "coordinate (default 0: exact meshes)")
    p.add_argument("--list", action="store_true", help="list the collections, one a line, and exit")
    return p


def run(args) -> int:
    from data_synth import list_collections, make_collection

    if args.list:
        for name, description in list_collections():
            result(f"{name}\t{description}")
        return 0
    names = [n for n, _ in list_collections()]
    if not args.name:
        raise UsageError(f"give a collection NAME (one of {', '.join(names)}) or --list")
    if args.name not in names:
        from meshvae_lib.input_checks import short_name

        raise UsageError(f"unknown collection {short_name(repr(args.name))}; choose one of {', '.join(names)}")
    if not args.output:
        raise UsageError("give the output with -o OUT (a .npz file or a folder)")
    if args.seed < 0:
        raise UsageError(f"--seed must be non-negative, got {args.seed}")
    if not 0 <= args.noise < float("inf"):
        raise UsageError(f"--noise must be a finite number >= 0, got {args.noise}")
    out = Path(args.output)
    if out.suffix.lower() == ".npz" and not out.parent.exists():
        raise UsageError(f"folder does not exist: {out.parent}")
    if out.exists() and not out.is_dir() and out.suffix.lower() != ".npz":
        raise UsageError(f"OUT must end in .npz or name a folder, got the file {out}")
    if args.resolution is not None:
        from data_synth import constants as C

        if not C.MIN_RESOLUTION <= args.resolution <= C.MAX_RESOLUTION:
            raise UsageError(f"--resolution must lie in [{C.MIN_RESOLUTION:,}, {C.MAX_RESOLUTION:,}] vertices,"
                             f" got {args.resolution:,}")
    check_output(out, collection=True)
    start = time.perf_counter()
    col = make_collection(args.name, seed=args.seed, resolution=args.resolution, noise=args.noise)
    logger.info("built %s in %.2f s", args.name, time.perf_counter() - start)
    from meshvae_lib.geometry.collection_io import write_collection

    write_collection(out, col.vertices, col.faces, names=col.names, labels=col.labels)
    result(f"wrote {args.name}: {len(col.vertices)} meshes x {col.vertices.shape[1]} vertices, "
           f"{len(col.faces)} faces, labels {', '.join(col.labels) or '(none)'} -> {out}")
    return 0
