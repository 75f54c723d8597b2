"""Can the stand-in collections tell representations apart? Their linear floor and their defects.

Usage::

    .venv/bin/python benchmarks/bench_synth_floor.py [--repeats 3] [--json OUT] [NAME ...]

For every ``data_synth`` collection at its default size (seed 0): PCA on vertex coordinates and on
aligned coordinates with every direction the training meshes span, every 5th mesh held out, the
mean vertex error after rigid alignment (``meshvae_lib.paper.linear_floor``, the experiments' own
floor) as a fraction of the bounding-box diagonal, against the target (``data_synth.constants``:
``FLOOR_TARGET`` for every collection, ``POSE_FLOOR_TARGET`` for the pose collections); the meshes
with crossing triangles (``meshvae_lib.geometry.intersections.self_intersections``) and the pairs of
identical meshes (``data_synth.quality.duplicate_pairs``); the generation time (median of
``--repeats`` runs in fresh template caches; the machine is shared and noisy). Prints a markdown table;
``--json`` writes the numbers.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def measure(name: str, repeats: int) -> dict:
    import numpy as np

    from bench_synth import clear_caches
    from data_synth import constants as C
    from data_synth import make_collection
    from data_synth.quality import bounding_box_diagonals, duplicate_pairs
    from meshvae_lib.geometry.intersections import self_intersections
    from meshvae_lib.paper.linear_floor import linear_floor

    times = []
    for _ in range(repeats):
        clear_caches()
        t0 = time.perf_counter()
        coll = make_collection(name, seed=0)
        times.append(time.perf_counter() - t0)
    V = coll.vertices
    floor = linear_floor(V, 5)
    diag = float(np.median(bounding_box_diagonals(V)))
    crossings = self_intersections(V, coll.faces)
    target = C.POSE_FLOOR_TARGET if name in C.POSE_COLLECTIONS else C.FLOOR_TARGET
    return {"collection": name, "meshes": int(V.shape[0]), "vertices": int(V.shape[1]), "diagonal": diag,
            "pca_coords": floor["pca_coords"], "pca_aligned": floor["pca_aligned"], "floor_relative": floor["relative"],
            "target": target, "meets_target": bool(floor["relative"] >= target),
            "meshes_with_crossings": int((crossings > 0).sum()), "max_crossing_pairs": int(crossings.max()),
            "duplicate_pairs": int(len(duplicate_pairs(V))), "generation_seconds": statistics.median(times)}


def markdown(rows) -> str:
    lines = ["| collection | meshes | vertices | diagonal | PCA coords | floor / diagonal | target | met |"
             " meshes with crossing triangles (max pairs) | duplicate pairs | generation (s) |",
             "|" + " --- |" * 11]
    for r in rows:
        lines.append(f"| {r['collection']} | {r['meshes']} | {r['vertices']} | {r['diagonal']:.2f} | {r['pca_coords']:.1e}"
                     f" | {r['floor_relative']:.1e} | {r['target']:.0e} | {'yes' if r['meets_target'] else 'no'}"
                     f" | {r['meshes_with_crossings']} ({r['max_crossing_pairs']}) | {r['duplicate_pairs']}"
                     f" | {r['generation_seconds']:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    from data_synth import list_collections

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--json", type=Path, default=None, help="write the rows here")
    args = parser.parse_args(argv)
    names = args.names or [n for n, _ in list_collections()]
    rows = []
    for name in names:
        rows.append(measure(name, args.repeats))
        print(markdown(rows[-1:]).splitlines()[-1], flush=True)
    print()
    print(markdown(rows))
    if args.json:
        args.json.write_text(json.dumps({"rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
