"""Course tooling: execute the notebooks, render them to HTML, write student copies.

Used by the Makefile (``make notebooks``, ``make course``, ``make student``)::

    python -m meshvae_lib.course execute notebooks/0*.ipynb
    python -m meshvae_lib.course html --out build/course notebooks/0*.ipynb
    python -m meshvae_lib.course student --out build/student notebooks/0*.ipynb

Exercise solutions in the notebooks sit between ``### BEGIN SOLUTION`` and ``### END SOLUTION``
lines; the student copy replaces them by a placeholder that raises ``NotImplementedError`` and
clears that cell's outputs. The self-check cell after each exercise stays as it is.
"""

from __future__ import annotations

import argparse
import html
import logging
import re
import sys
import time
from pathlib import Path

logger = logging.getLogger(__name__)

BEGIN_SOLUTION = "### BEGIN SOLUTION"
END_SOLUTION = "### END SOLUTION"
STUDENT_PLACEHOLDER = "# YOUR CODE HERE\nraise NotImplementedError()"

_SOLUTION_BLOCK = re.compile(
    r"^([ \t]*)" + re.escape(BEGIN_SOLUTION) + r"[^\n]*\n.*?^[ \t]*" + re.escape(END_SOLUTION) + r"[^\n]*(\n|$)",
    flags=re.MULTILINE | re.DOTALL,
)


def strip_solutions(source: str) -> tuple[str, int]:
    """Replace every solution block of a cell's source by the student placeholder.

    Parameters
    ----------
    source : str
        A code cell's source.

    Returns
    -------
    stripped : str
        The source with each ``### BEGIN SOLUTION`` ... ``### END SOLUTION`` block (markers
        included) replaced by the placeholder, indented like the ``BEGIN`` marker.
    n_blocks : int
        How many blocks were replaced.

    Raises
    ------
    ValueError
        When the markers are unbalanced (a ``BEGIN`` without its ``END`` or the reverse).
    """
    n_begin = source.count(BEGIN_SOLUTION)
    n_end = source.count(END_SOLUTION)
    if n_begin != n_end:
        raise ValueError(
            f"unbalanced solution markers: {n_begin} '{BEGIN_SOLUTION}' and {n_end} '{END_SOLUTION}' in:\n{source}"
        )

    def _replace(match: re.Match) -> str:
        indent = match.group(1)
        placeholder = "\n".join(indent + line for line in STUDENT_PLACEHOLDER.splitlines())
        return placeholder + match.group(2)

    stripped, n = _SOLUTION_BLOCK.subn(_replace, source)
    if n != n_begin:
        raise ValueError(f"solution markers are nested or out of order in:\n{source}")
    return stripped, n


def student_notebook(nb):
    """Return a copy of a notebook with every solution removed (see :func:`strip_solutions`).

    Parameters
    ----------
    nb : nbformat.NotebookNode
        The teacher's notebook.

    Returns
    -------
    nbformat.NotebookNode
        The student copy; cells whose solutions were removed have their outputs cleared.
    """
    import copy

    out = copy.deepcopy(nb)
    for cell in out.cells:
        if cell.cell_type != "code":
            continue
        stripped, n = strip_solutions(cell.source)
        if n:
            cell.source = stripped
            cell.outputs = []
            cell.execution_count = None
    return out


def inject_parameters(nb, parameters: dict[str, str]):
    """Insert a cell that overrides parameters right after the notebook's ``parameters`` cell.

    As papermill does: the new cell (tagged ``injected-parameters``) assigns each value, so the
    lesson runs with, say, another seed without editing it. Values derived inside the parameters
    cell itself (``RESOLUTION = None if FULL else 600``) are not recomputed.

    Parameters
    ----------
    nb : nbformat.NotebookNode
        The notebook (changed in place and returned).
    parameters : dict of str to str
        Parameter name to a Python expression, e.g. ``{"SEED": "1"}``.

    Raises
    ------
    ValueError
        When the notebook has no ``parameters`` cell, or a name is not assigned in it.
    """
    import nbformat

    index = next((i for i, c in enumerate(nb.cells)
                  if c.cell_type == "code" and "parameters" in c.metadata.get("tags", [])), None)
    if index is None:
        raise ValueError("the notebook has no cell tagged 'parameters'")
    source = nb.cells[index].source
    for name in parameters:
        if not re.search(rf"^{re.escape(name)}\s*=", source, flags=re.MULTILINE):
            raise ValueError(f"parameter {name!r} is not assigned in the parameters cell:\n{source}")
    cell = nbformat.v4.new_code_cell("# Injected parameters\n" + "".join(f"{k} = {v}\n" for k, v in parameters.items()))
    cell.metadata["tags"] = ["injected-parameters"]
    nb.cells.insert(index + 1, cell)
    return nb


def execute_notebook(path: Path, timeout: int = 600, kernel_name: str = "python3",
                     store_widget_state: bool = False, parameters: dict[str, str] | None = None):
    """Execute a notebook on a fresh kernel, in its own folder, and return it.

    Parameters
    ----------
    path : Path
        The ``.ipynb`` file.
    timeout : int
        Seconds allowed per cell.
    kernel_name : str
        The Jupyter kernel to run it on.
    store_widget_state : bool
        Store the widgets' state in the notebook. Off by default: the 3D views' state holds
        every vertex buffer (megabytes) and an HTML export of it needs the three.js widget code
        from a CDN; without it each view exports as the PNG snapshot the viewer stores beside it.
    parameters : dict of str to str, optional
        Overrides of the parameters cell (see :func:`inject_parameters`).
    """
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    if parameters:
        inject_parameters(nb, parameters)
    for cell in nb.cells:  # timestamps of an earlier run would only churn the committed file
        cell.metadata.pop("execution", None)
    client = NotebookClient(
        nb,
        timeout=timeout,
        kernel_name=kernel_name,
        resources={"metadata": {"path": str(path.parent)}},
        store_widget_state=store_widget_state,
        record_timing=False,
    )
    client.execute()
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs = coalesce_streams(cell.outputs)
    return nb


def coalesce_streams(outputs: list) -> list:
    """Merge consecutive stream outputs of the same stream (stdout or stderr) into one.

    How a kernel splits a cell's printing into messages depends on timing; merged, the stored
    outputs of a deterministic cell are the same on every run (nbval compares the merged text too).

    Parameters
    ----------
    outputs : list of nbformat output nodes
        A code cell's outputs.

    Returns
    -------
    list
        The same outputs, with each run of same-stream ``stream`` outputs joined into the first.
    """
    merged: list = []
    for out in outputs:
        prev = merged[-1] if merged else None
        if (out.get("output_type") == "stream" and prev is not None and prev.get("output_type") == "stream"
                and prev.get("name") == out.get("name")):
            prev["text"] = prev["text"] + out["text"]
        else:
            merged.append(out)
    return merged


def _notebook_paths(paths: list[str]) -> list[Path]:
    result = []
    for p in paths:
        path = Path(p)
        if not path.is_file():
            raise FileNotFoundError(f"no notebook at {path}")
        if path.suffix != ".ipynb":
            raise ValueError(f"not a notebook (expected .ipynb): {path}")
        result.append(path)
    return result


def _cmd_execute(args) -> int:
    import nbformat

    parameters = _parameters(args.set)
    if parameters and not args.out:
        raise ValueError("--set changes the lesson: give --out DIR so the stored notebooks are not overwritten")
    out = Path(args.out) if args.out else None
    if out:
        out.mkdir(parents=True, exist_ok=True)
    for path in _notebook_paths(args.notebooks):
        start = time.perf_counter()
        nb = execute_notebook(path, timeout=args.timeout, parameters=parameters)
        target = out / path.name if out else path
        nbformat.write(nb, target)
        print(f"executed {path} -> {target} in {time.perf_counter() - start:.1f} s")
    return 0


def _parameters(assignments: list[str] | None) -> dict[str, str]:
    result = {}
    for text in assignments or []:
        name, sep, value = text.partition("=")
        if not sep or not name.strip().isidentifier() or not value.strip():
            raise ValueError(f"--set expects NAME=VALUE, got {text!r}")
        result[name.strip()] = value.strip()
    return result


def _cmd_html(args) -> int:
    import nbformat
    from nbconvert import HTMLExporter

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    exporter = HTMLExporter()
    entries = []
    total = time.perf_counter()
    for path in _notebook_paths(args.notebooks):
        start = time.perf_counter()
        nb = execute_notebook(path, timeout=args.timeout)
        body, _ = exporter.from_notebook_node(nb)
        target = out / (path.stem + ".html")
        target.write_text(body, encoding="utf-8")
        title = next(
            (c.source.splitlines()[0].lstrip("# ").strip() for c in nb.cells if c.cell_type == "markdown" and c.source),
            path.stem,
        )
        seconds = time.perf_counter() - start
        entries.append((target.name, title, seconds))
        print(f"{path} -> {target} ({seconds:.1f} s)")
    items = "\n".join(
        f'<li><a href="{html.escape(name)}">{html.escape(title)}</a> <small>({seconds:.0f} s)</small></li>'
        for name, title, seconds in entries
    )
    (out / "index.html").write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>Mesh VAE course</title></head>"
        f"<body><h1>Mesh VAE: the course</h1><ol>{items}</ol></body></html>\n",
        encoding="utf-8",
    )
    print(f"wrote {out / 'index.html'}: {len(entries)} notebooks in {time.perf_counter() - total:.1f} s")
    return 0


def _cmd_student(args) -> int:
    import nbformat

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for path in _notebook_paths(args.notebooks):
        nb = nbformat.read(path, as_version=4)
        student = student_notebook(nb)
        nbformat.write(student, out / path.name)
        n = sum(c.source.count("raise NotImplementedError()") for c in student.cells if c.cell_type == "code")
        print(f"{path} -> {out / path.name} ({n} exercise(s) to solve)")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m meshvae_lib.course", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("execute", help="execute notebooks in place (refreshes their stored outputs)")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--timeout", type=int, default=600, help="seconds per cell (default 600)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="override a parameter of the parameters cell (repeatable), e.g. --set SEED=1; needs --out")
    p.add_argument("--out", metavar="DIR", help="write the executed notebooks here instead of in place")
    p.set_defaults(func=_cmd_execute)
    p = sub.add_parser("html", help="execute notebooks and write an HTML course with an index")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--out", required=True)
    p.add_argument("--timeout", type=int, default=600, help="seconds per cell (default 600)")
    p.set_defaults(func=_cmd_html)
    p = sub.add_parser("student", help="write student copies with the solutions removed")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--out", required=True)
    p.set_defaults(func=_cmd_student)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
