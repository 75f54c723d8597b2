"""Experiment results: the table an experiment returns, a recorded run read back, its fingerprint.

:class:`ExperimentTable`; :class:`RecordedResults` and :func:`read_results` for a ``results.json``;
:func:`definition_fingerprint`, which tells when recorded results are stale.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshvae_lib.paper.settings import ExperimentSettings

__all__ = ["ExperimentTable", "RecordedResults", "read_results", "definition_fingerprint"]


def _fmt(x) -> str:
    if isinstance(x, (float, np.floating)):
        if not np.isfinite(x):
            return "—"
        if x != 0 and (abs(x) < 1e-2 or abs(x) >= 1e4):
            return f"{x:.3e}"
        return f"{x:.4f}"
    return "—" if x is None else str(x)


@dataclass
class ExperimentTable:
    """The result of one experiment.

    Attributes
    ----------
    name : short id (also the file name the runner writes)
    title : one line
    columns : list of str
    rows : list of lists (one cell per column: str, int, float or None)
    notes : list of str, printed under the table
    data : dict of raw arrays and numbers for plots and checks
    seconds : wall-clock time of the experiment
    """

    name: str
    title: str
    columns: list
    rows: list = field(default_factory=list)
    notes: list = field(default_factory=list)
    data: dict = field(default_factory=dict)
    seconds: float = 0.0

    def as_dicts(self) -> list[dict]:
        """The rows as dicts keyed by column."""
        return [dict(zip(self.columns, r)) for r in self.rows]

    def column(self, name: str) -> list:
        j = self.columns.index(name)
        return [r[j] for r in self.rows]

    def to_markdown(self) -> str:
        """Title, the table, and the notes, in markdown."""
        lines = [f"**{self.title}**", "", "| " + " | ".join(self.columns) + " |",
                 "|" + " --- |" * len(self.columns)]
        for r in self.rows:
            lines.append("| " + " | ".join(_fmt(c) for c in r) + " |")
        if self.notes:
            lines.append("")
            lines += [f"- {n}" for n in self.notes]
        lines.append("")
        lines.append(f"_({self.seconds:.0f} s)_")
        return "\n".join(lines)

    def plot(self):
        """A matplotlib Figure for this table (not registered with pyplot); see :mod:`.plots`."""
        from meshvae_lib.paper.plots import plot_table

        return plot_table(self)


def definition_fingerprint(settings: ExperimentSettings) -> str:
    """sha256 (hex) of what defines the experiments' numbers: the source of every module of
    ``meshvae_lib/paper`` (the experiments, their training protocol, the paper's reference numbers
    and the plots), by relative path in sorted order, and ``settings``. Recorded with committed
    results (``benchmarks/experiments.py``), so that a test can tell when they are stale."""
    import dataclasses
    import hashlib
    import json
    from pathlib import Path

    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for rel in sorted(p.relative_to(root).as_posix() for p in root.rglob("*.py")):
        h.update(f"{rel}\0".encode())
        h.update((root / rel).read_bytes())
    h.update(json.dumps(dataclasses.asdict(settings), sort_keys=True).encode())
    return h.hexdigest()


@dataclass
class RecordedResults:
    """A finished run of ``benchmarks/experiments.py`` read back from its ``results.json``.

    tables : dict experiment key (``"table1"``, ``"table2"``, ...) -> ExperimentTable (no ``data``);
    settings : the ExperimentSettings it ran with; seconds : its total run time; provenance : dict
    with ``definition_fingerprint``, ``commit``, ``versions``, ``machine``, ``preset``.
    """

    tables: dict
    settings: ExperimentSettings
    seconds: float
    provenance: dict

    def is_current(self) -> bool:
        """Whether the experiments are still defined as when these results were recorded."""
        return self.provenance.get("definition_fingerprint") == definition_fingerprint(self.settings)


def read_results(path) -> RecordedResults:
    """Read a ``results.json`` written by ``benchmarks/experiments.py`` (e.g. the committed
    ``docs/results/results.json``). ValueError for an unfinished or failed run or a missing field."""
    import json
    from pathlib import Path

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no experiment results at {path} (run `make experiments`)")
    raw = json.loads(path.read_text())
    missing = [k for k in ("settings", "seconds", "done", "failed", "tables", "provenance") if k not in raw]
    if missing:
        raise ValueError(f"{path} lacks {missing}: not written by benchmarks/experiments.py, or by an older version")
    if not raw["done"] or raw["failed"]:
        raise ValueError(f"{path} holds an unfinished or partly failed run (failed: {raw['failed']})")
    tables = {k: ExperimentTable(t.get("name", k), t["title"], list(t["columns"]), [list(r) for r in t["rows"]],
                                 list(t.get("notes", [])), {}, float(t.get("seconds", 0.0)))
              for k, t in raw["tables"].items()}
    return RecordedResults(tables, ExperimentSettings(**raw["settings"]), float(raw["seconds"]), dict(raw["provenance"]))
