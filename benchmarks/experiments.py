"""Run every experiment of the paper (Sec. 5) and write markdown tables and PNG figures.

    .venv/bin/python benchmarks/experiments.py --out build/experiments [--quick] [--only table1,embedding]

``make experiments`` runs it at full size (3 to 30 minutes on two CPU cores, depending on the machine) into ``docs/results``, whose
tables are committed: notebook 09 shows them, and a test fails when the experiments change after they
were recorded (``results.json`` holds the definitions' fingerprint, the commit, the package versions,
the machine and the run time). Writes, in ``--out``:

- ``<experiment>.md`` and ``<experiment>.png`` for every experiment (see
  ``meshvae_lib.paper``; ``table1_converged``, ``table2_converged`` and ``table3_converged`` are
  Tables 1-3 with every model trained until its validation error stops improving, their curves in
  ``<table>_converged_curves.png`` and in ``results.json``; ``noise_diversity`` (the lesson on when
  RIMD wins, notebook 09) is trained that way only), plus renderings: ``generation_meshes.png`` (generated meshes over
  their nearest training meshes), ``interpolation_meshes.png`` (Fig. 4), ``exploration_level1.png``
  and ``exploration_level2.png`` (Fig. 8);
- ``summary.md``: all tables, the settings and the run times; ``results.json``: the numbers.

One experiment failing does not stop the others; the exit code is 1 if any failed.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import os
import sys
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from meshvae_lib import paper  # noqa: E402

SHORT = {
    "table1": paper.latent_size_table,
    "table1_converged": lambda settings, cache: paper.latent_size_table(
        settings=dataclasses.replace(settings, converge=True), cache=cache),
    "table2": paper.feature_table,
    "table2_converged": lambda settings, cache: paper.feature_table(
        settings=dataclasses.replace(settings, converge=True), cache=cache),
    "table3": paper.robustness_table,
    "table3_converged": lambda settings, cache: paper.robustness_table(
        settings=dataclasses.replace(settings, converge=True), cache=cache),
    "loss": paper.loss_table,
    "embedding": paper.embedding_table,
    "generation": paper.generation_table,
    "interpolation": paper.interpolation_table,
    "exploration": paper.exploration_table,
    "noise_diversity": lambda settings, cache: paper.noise_diversity_table(
        settings=dataclasses.replace(settings, converge=True), cache=cache),
}


def _save(fig, path: Path) -> None:
    fig.savefig(path, dpi=100, bbox_inches="tight")


def _renderings(table, out: Path) -> list[str]:
    """Extra mesh renderings for the tables that have meshes."""
    try:
        from meshvae_lib.viewing.render import render_mesh_grid
    except Exception:  # the viewing package is optional for the numbers
        logging.warning("meshvae_lib.viewing.render is not available: no mesh renderings")
        return []
    written = []
    d = table.data
    if table.name == "generation" and "unconditional" in d:
        res = d["unconditional"]
        k = min(6, len(res.vertices))
        meshes = np.concatenate([res.vertices[:k], d["train_vertices"][res.nearest[:k]]])
        titles = [f"generated {i}" for i in range(k)] + [
            f"nearest: {res.nearest[i]} (d={res.distance[i]:.2f})" for i in range(k)]
        _save(render_mesh_grid(meshes, d["faces"], titles=titles, ncols=k,
                               suptitle="generated (top) and nearest training mesh (bottom)"), out / "generation_meshes.png")
        written.append("generation_meshes.png")
        if "conditional" in d:
            r = d["conditional"]
            col, val = d["condition"]
            _save(render_mesh_grid(r.vertices[:k], d["conditional_faces"], ncols=k,
                                   suptitle=f"conditional mesh VAE, {col} = {val}"), out / "generation_conditional.png")
            written.append("generation_conditional.png")
    if table.name == "interpolation":
        seqs = d["sequences"]
        names = list(seqs)
        n = len(next(iter(seqs.values())))
        meshes = np.concatenate([seqs[m] for m in names])
        imp = d["implausibility"]
        titles = [f"{m.split()[0]} {i}: {imp.self_intersections[m][i]}x" for m in names for i in range(n)]
        _save(render_mesh_grid(meshes, d["faces"], titles=titles, ncols=n, size=1.8,
                               suptitle="rows: " + " / ".join(names) + "   (x: crossing triangle pairs)"),
              out / "interpolation_meshes.png")
        written.append("interpolation_meshes.png")
    if "validation_curves" in d:  # a converged table: the validation curve of every model
        from meshvae_lib.paper.plots import plot_validation_curves

        _save(plot_validation_curves(table), out / f"{table.name}_curves.png")
        written.append(f"{table.name}_curves.png")
    if table.name == "exploration":
        for key, fname in (("level1", "exploration_level1.png"), ("level2", "exploration_level2.png")):
            g = d[key]
            na, nb = g.vertices.shape[:2]
            titles = [f"z{g.dims[0] + 1}={a:+.1f}, z{g.dims[1] + 1}={b:+.1f}" for a in g.values_a for b in g.values_b]
            _save(render_mesh_grid(g.vertices.reshape(na * nb, -1, 3), d["faces"], titles=titles, ncols=nb, size=1.8,
                                   suptitle=f"latent dims {g.dims[0] + 1} (rows) and {g.dims[1] + 1} (columns)"),
                  out / fname)
            written.append(fname)
    return written


def _jsonable(table) -> dict:
    def cell(c):
        if isinstance(c, (np.floating, float)):
            return float(c)
        if isinstance(c, (np.integer, int)):
            return int(c)
        return None if c is None else str(c)

    out = {"name": table.name, "title": table.title, "columns": table.columns, "rows": [[cell(c) for c in r] for r in table.rows],
           "notes": table.notes, "seconds": table.seconds}
    if "validation_curves" in table.data:  # a converged table keeps every model's validation curve
        out["validation_curves"] = table.data["validation_curves"]
    return out


def _write_summary(out, args, settings, total, parts, results, failed, done: bool, provenance: dict) -> None:
    """summary.md and results.json (rewritten after every experiment, so a cut run keeps its tables)."""
    state = "" if done else " (in progress)"
    header = (f"# Experiments ({'quick' if args.quick else 'full'} size){state}\n\n"
              f"Total time: {total:.0f} s on {os.cpu_count()} CPU core(s), torch threads {args.threads}.\n\n"
              f"Settings: `{dataclasses.asdict(settings)}`\n\n")
    (out / "summary.md").write_text(header + "\n".join(parts))
    (out / "results.json").write_text(json.dumps({"settings": dataclasses.asdict(settings), "seconds": total,
                                                  "done": done, "failed": failed, "provenance": provenance,
                                                  "tables": results}, indent=1))


def _provenance(args, settings) -> dict:
    """What the numbers depend on: the experiments' definitions, the commit, versions, the machine.
    Taken before the first table is written: the run's own outputs (into a tracked folder such as
    docs/results) must not count as uncommitted changes of the source."""
    import platform

    import scipy
    import torch

    from provenance import cpu_name, source_state

    return {"definition_fingerprint": paper.definition_fingerprint(settings), **source_state(),
            "versions": {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
                         "torch": torch.__version__},
            "machine": {"cpu": cpu_name(), "cores": os.cpu_count(), "torch_threads": args.threads, "system": platform.platform()},
            "preset": "quick" if args.quick else "full"}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", default="build/experiments", help="output folder")
    p.add_argument("--quick", action="store_true", help="tiny settings (a few minutes in all)")
    p.add_argument("--only", default="", help="comma-separated subset of: " + ",".join(SHORT))
    p.add_argument("--threads", type=int, default=2, help="torch threads (default 2)")
    p.add_argument("-v", "--verbose", action="store_true")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    import torch

    torch.set_num_threads(args.threads)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    settings = paper.ExperimentSettings.quick() if args.quick else paper.ExperimentSettings()
    chosen = [s.strip() for s in args.only.split(",") if s.strip()] or list(SHORT)
    unknown = [c for c in chosen if c not in SHORT]
    if unknown:
        p.error(f"unknown experiments {unknown}; choose from {list(SHORT)}")
    cache: dict = {}
    provenance = _provenance(args, settings)
    results, failed, parts = {}, [], []
    t_all = time.perf_counter()
    for key in chosen:
        fn = SHORT[key]
        print(f"== {key} ({fn.__name__})", flush=True)
        try:
            table = fn(settings=settings, cache=cache)
        except Exception as exc:  # keep going: report it
            failed.append(key)
            tb = traceback.format_exc()
            print(tb, file=sys.stderr, flush=True)
            parts.append(f"## {key}\n\nFAILED: `{type(exc).__name__}: {exc}`\n")
            continue
        md = table.to_markdown()
        (out / f"{table.name}.md").write_text(md + "\n")
        files = []
        try:
            _save(table.plot(), out / f"{table.name}.png")
            files.append(f"{table.name}.png")
            files += _renderings(table, out)
        except Exception:
            print(traceback.format_exc(), file=sys.stderr, flush=True)
        results[key] = _jsonable(table)
        parts.append(f"## {key}\n\n{md}\n\n" + "".join(f"![{f}]({f})\n" for f in files))
        print(md, flush=True)
        print(f"   ({table.seconds:.0f} s)", flush=True)
        _write_summary(out, args, settings, time.perf_counter() - t_all, parts, results, failed, done=False, provenance=provenance)
    total = time.perf_counter() - t_all
    _write_summary(out, args, settings, total, parts, results, failed, done=True, provenance=provenance)
    print(f"wrote {out}/summary.md ({total:.0f} s); failed: {failed or 'none'}", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
