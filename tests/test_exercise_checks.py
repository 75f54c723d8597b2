"""Every exercise's self-check fails on a trivial answer.

For each notebook, :func:`~meshvae_lib.course.notebooks.trivial_answer_notebook` gives the names
each solution binds three trivial answers in turn -- left unchanged (undefined, or the value they
had before the exercise), ``None``, and zeros of the real answer's type and shape -- runs the
self-check on each, then restores the real answer. The notebook is executed once (the course
models come from the cache, as for nbval), and every self-check must raise on every trivial answer.
"""

from __future__ import annotations

from pathlib import Path

import nbformat
import pytest

from meshvae_lib.course.notebooks import (TRIVIAL_ANSWERS, solution_names, trivial_answer_notebook,
                                          trivial_answer_outcomes)

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))


def test_solution_names_are_the_global_bindings():
    src = ("x = 1\n### BEGIN SOLUTION\na, (b, c) = 1, (2, 3)\nfor i in range(2):\n    inner = i\n"
           "total += 1\nwith open('f') as fh:\n    pass\ndef helper():\n    hidden = 1\n"
           "sq = [k * k for k in range(3)]\nf = lambda u: u\nif a:\n    late = 2\nimport os.path\n"
           "### END SOLUTION\ny = 2\n")
    assert solution_names(src) == ["a", "b", "c", "i", "inner", "total", "fh", "helper", "sq", "f", "late"]


def test_the_trivial_answer_notebook_wraps_each_exercise():
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("start = 5"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = start * 2\n### END SOLUTION"),
        nbformat.v4.new_markdown_cell("check:"),
        nbformat.v4.new_code_cell("assert answer == 10"),
    ])
    out, exercises = trivial_answer_notebook(nb)
    assert exercises == [(1, ["answer"])]
    assert [c.cell_type for c in out.cells] == ["code", "code", "code", "code", "markdown", "code"]
    assert "assert answer == 10" in out.cells[3].source and "TRIVIAL-ANSWER-OUTCOMES" in out.cells[3].source
    ns = {}
    for cell in out.cells:
        if cell.cell_type == "code":
            import contextlib
            import io

            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                exec(cell.source, ns)
            if "TRIVIAL" in buf.getvalue():
                line = buf.getvalue()
    assert '"unchanged": "NameError"' in line and '"None": "AssertionError"' in line and '"zeros": "AssertionError"' in line
    assert ns["answer"] == 10, "the real answer is restored for the rest of the notebook"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_self_check_raises_on_trivial_answers(path):
    from nbclient import NotebookClient

    nb, exercises = trivial_answer_notebook(nbformat.read(path, as_version=4))
    assert len(exercises) >= 2, f"{path.stem} has {len(exercises)} exercise(s)"
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK_DIR)}}).execute()
    outcomes = trivial_answer_outcomes(nb)
    assert len(outcomes) == len(exercises)
    passed = [(cell, names, answer) for (cell, names), o in zip(exercises, outcomes)
              for answer in TRIVIAL_ANSWERS if o[answer] == "passed"]
    assert not passed, f"{path.stem}: self-checks that accept a trivial answer (cell, answer names, answer): {passed}"
