"""Notebook tooling: execute the notebooks, render them to HTML, write student copies.

The commands that use it (``python -m meshvae_lib.course``) live in :mod:`.commands`.

Exercise solutions in the notebooks sit between ``### BEGIN SOLUTION`` and ``### END SOLUTION``
lines; the student copy replaces them by a placeholder that raises ``NotImplementedError`` and
clears that cell's outputs. The self-check cell after each exercise stays as it is.
"""

from __future__ import annotations

import logging
import re
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
