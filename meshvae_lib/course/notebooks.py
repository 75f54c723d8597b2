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

from meshvae_lib.course.answer_rerun import (ANSWER_SOURCE, bound_names, rerun_answer,  # noqa: F401  (re-exported)
                                             without_magics)

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
                     store_widget_state: bool | None = None, parameters: dict[str, str] | None = None):
    """Execute a notebook on a fresh kernel, in its own folder, and return it.

    Parameters
    ----------
    path : Path
        The ``.ipynb`` file.
    timeout : int
        Seconds allowed per cell.
    kernel_name : str
        The Jupyter kernel to run it on.
    store_widget_state : bool, optional
        Store the widgets' state in the notebook. Off by default: the 3D views' state holds
        every vertex buffer (megabytes) and an HTML export of it needs the three.js widget code
        from a CDN; without it each view exports as the PNG snapshot the viewer stores beside it.
        ``None`` (the default) does what the notebook asks in its metadata
        (``"meshvae": {"store_widget_state": true}``: notebooks 00, 05 and 08, whose state is small
        enough to keep), else stores nothing; without state, any state an earlier run left is
        removed, since it would describe widgets that no output shows any more.
    parameters : dict of str to str, optional
        Overrides of the parameters cell (see :func:`inject_parameters`).
    """
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    if store_widget_state is None:
        store_widget_state = bool(nb.metadata.get("meshvae", {}).get("store_widget_state", False))
    if not store_widget_state:
        nb.metadata.pop("widgets", None)
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


#: the trivial answers tried for every exercise (see :func:`trivial_answer_notebook`).
TRIVIAL_ANSWERS = ("unchanged", "None", "zeros")
TRIVIAL_MARKER = "TRIVIAL-ANSWER-OUTCOMES"


def solution_names(source: str) -> list[str]:
    """The names a solution block binds in the notebook's global scope (its answer), in order of
    first binding.

    source : a code cell's source with ``### BEGIN SOLUTION`` ... ``### END SOLUTION``. Every
    binding at module scope counts -- assignments, ``for`` targets and ``with ... as`` names, also
    inside loop, ``if`` and ``with`` bodies --; imports do not (they are tools, not answers), nor
    names bound inside functions, classes, lambdas and comprehensions (a function or class counts
    by its own name).
    """
    names: list[str] = []
    for match in _SOLUTION_BLOCK.finditer(source):
        block = match.group(0)
        for name in bound_names("\n".join(line[len(match.group(1)):] for line in block.splitlines())):
            if name not in names:
                names.append(name)
    return names


_TRIVIAL_CELL = '''\
import json as _tj, numpy as _tnp
_t_names, _t_check, _t_wrong = {names!r}, {check!r}, {wrong!r}
_t_real = {{n: globals()[n] for n in _t_names if n in globals()}}
def _t_zero(v):
    if isinstance(v, bool):
        return False
    if isinstance(v, (int, float, complex)):
        return type(v)(0)
    if isinstance(v, _tnp.ndarray):
        return _tnp.zeros_like(v)
    if hasattr(v, "zero_") and hasattr(v, "clone"):
        return v.clone().zero_()
    if isinstance(v, (str, list, tuple, dict, set)):
        return type(v)()
    return None
_t_outcomes = {{}}
for _t_answer in {answers!r} + tuple(_t_wrong):
    for _t_n in _t_names:
        globals().pop(_t_n, None)
        if _t_answer in ("unchanged", *_t_wrong) and _t_n in _t_before:
            globals()[_t_n] = _t_before[_t_n]
        elif _t_answer == "None":
            globals()[_t_n] = None
        elif _t_answer == "zeros":
            globals()[_t_n] = _t_zero(_t_real.get(_t_n))
    _t_known = set(globals())
    globals()[{source_name!r}] = _t_wrong.get(_t_answer, "")
    try:
        if _t_answer in _t_wrong:
            try:
                exec(_t_wrong[_t_answer], globals())
            except BaseException as _t_e:
                _t_outcomes[_t_answer] = "the wrong answer itself raised " + type(_t_e).__name__
                continue
        exec(_t_check, globals())
        _t_outcomes[_t_answer] = "passed"
    except BaseException as _t_e:
        _t_outcomes[_t_answer] = type(_t_e).__name__
    finally:
        for _t_n in set(globals()) - _t_known:
            if not _t_n.startswith("_t_"):
                globals().pop(_t_n, None)
globals().pop({source_name!r}, None)
for _t_n in _t_names:
    globals().pop(_t_n, None)
globals().update(_t_real)
print({marker!r}, _tj.dumps(_t_outcomes))
'''


def trivial_answer_notebook(nb, answers=TRIVIAL_ANSWERS, wrong_answers=None):
    """A copy of ``nb`` that tries trivial answers, and known wrong ones, on every exercise's self-check.

    For each solution cell (``### BEGIN SOLUTION``) followed by its self-check (the next code
    cell), a cell before the solution remembers the answer names' starting values, and a cell
    after it (a) sets the names the solution binds (:func:`solution_names`) to each trivial
    answer in turn -- ``"unchanged"``: their values before the solution (undefined if they had
    none), ``"None"``, ``"zeros"``: a zero of the real answer's type and shape (0, zeros_like,
    an empty container; None for other objects) --, (b) runs the self-check's source on it and
    records whether it raised, then (c) restores the real answers, so that the rest of the
    notebook runs as usual. This is what a student copy (:func:`student_notebook`) with that
    answer in place of the solution would do.

    ``wrong_answers`` adds named wrong answers per exercise: ``{exercise number (1-based, in
    notebook order): {name: code}}``. Each code runs in place of the solution, on the state
    before it (the solution's names back at their starting values, undefined if they had none);
    then the self-check runs as above. Names the wrong answer or the check bind that did not
    exist before are removed afterwards. A wrong answer whose own code raises is recorded as
    ``"the wrong answer itself raised <exception>"``, not as caught. While a self-check runs, the
    code that stands for the student's cell (the wrong answer's; ``""`` for a trivial answer, which
    only sets the names) is under :data:`ANSWER_SOURCE`, where :func:`rerun_answer` finds it.

    Executing it prints a ``TRIVIAL-ANSWER-OUTCOMES {...}`` line per exercise (:func:`trivial_answer_outcomes`).
    Returns (notebook, exercises): per exercise ``(solution cell index in nb, names)``.

    Raises
    ------
    ValueError
        When a solution has no self-check after it, or ``wrong_answers`` names an exercise the
        notebook does not have or reuses a trivial answer's name.
    """
    import copy

    import nbformat

    wrong_answers = dict(wrong_answers or {})
    src = copy.deepcopy(nb)
    cells, exercises = [], []
    code_after = {}
    code_idx = [i for i, c in enumerate(src.cells) if c.cell_type == "code"]
    for a, b in zip(code_idx, code_idx[1:]):
        code_after[a] = b
    for i, cell in enumerate(src.cells):
        is_solution = cell.cell_type == "code" and BEGIN_SOLUTION in cell.source
        if not is_solution:
            cells.append(cell)
            continue
        if i not in code_after:
            raise ValueError(f"the solution in cell {i} has no self-check cell after it")
        names = solution_names(cell.source)
        exercises.append((i, names))
        wrong = dict(wrong_answers.get(len(exercises), {}))
        clash = set(wrong) & set(answers)
        if clash:
            raise ValueError(f"wrong answers of exercise {len(exercises)} reuse the trivial answers' names {sorted(clash)}")
        cells.append(nbformat.v4.new_code_cell(f"_t_before = {{n: globals()[n] for n in {names!r} if n in globals()}}"))
        cells.append(cell)
        check = src.cells[code_after[i]].source
        cells.append(nbformat.v4.new_code_cell(_TRIVIAL_CELL.format(names=names, check=check, answers=tuple(answers),
                                                                  wrong=wrong, marker=TRIVIAL_MARKER,
                                                                  source_name=ANSWER_SOURCE)))
    unknown = sorted(set(wrong_answers) - set(range(1, len(exercises) + 1)))
    if unknown:
        raise ValueError(f"wrong answers for exercises {unknown}, but the notebook has {len(exercises)} exercise(s)")
    src.cells = cells
    return src, exercises


def trivial_answer_outcomes(executed_nb) -> list[dict]:
    """The outcome lines of an executed :func:`trivial_answer_notebook`, in exercise order:
    one dict per exercise, answer -> the exception the self-check raised, or ``"passed"``."""
    import json

    found = []
    for cell in executed_nb.cells:
        if cell.cell_type != "code":
            continue
        # a kernel may split one printed line over several stream messages: join a cell's stdout first
        stdout = "".join(out.get("text", "") for out in cell.get("outputs", [])
                         if out.get("output_type") == "stream" and out.get("name", "stdout") == "stdout")
        for line in stdout.splitlines():
            if line.startswith(TRIVIAL_MARKER):
                found.append(json.loads(line[len(TRIVIAL_MARKER):]))
    return found
