"""The course's notebooks follow the course's rules (docs/NOTEBOOKS.md).

nbval checks that each notebook runs and reproduces its stored outputs; these tests check the shape
of each lesson: objectives at the top, a parameters cell, exercises with solutions and
self-checks at the end, stored outputs without errors or noise.
"""

from __future__ import annotations

import re
from pathlib import Path

import nbformat
import pytest

from meshvae_lib.course.notebooks import BEGIN_SOLUTION, END_SOLUTION, student_notebook, without_magics

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))
NOISE = re.compile(r"Warning|warn\(|DEPRECAT|Traceback|INFO:|DEBUG:", re.IGNORECASE)


def test_the_course_has_its_twelve_numbered_notebooks():
    numbers = [p.name[:2] for p in NOTEBOOKS]
    assert numbers == [f"{i:02d}" for i in range(12)], [p.name for p in NOTEBOOKS]
    for p in NOTEBOOKS:
        assert re.fullmatch(r"\d\d_[a-z0-9_]+\.ipynb", p.name), p.name


@pytest.fixture(params=NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def nb(request):
    return nbformat.read(request.param, as_version=4)


def _text(cell) -> str:
    return cell.source if isinstance(cell.source, str) else "".join(cell.source)


def test_opens_with_objectives_and_prerequisites(nb):
    first = nb.cells[0]
    assert first.cell_type == "markdown"
    text = _text(first).lower()
    assert text.startswith("# "), "the first cell is the lesson's title"
    assert "what you will learn" in text
    assert "what you need" in text


def test_has_a_parameters_cell_near_the_top(nb):
    code = [c for c in nb.cells if c.cell_type == "code"][:4]
    assert any(
        "parameters" in c.metadata.get("tags", []) and _text(c).startswith("# Parameters") for c in code
    ), "one of the first code cells must be tagged 'parameters' and start with '# Parameters'"


def test_ends_with_summary_and_exercises(nb):
    headings = [_text(c).lower() for c in nb.cells if c.cell_type == "markdown"]
    i_summary = max((i for i, t in enumerate(headings) if "## summary" in t), default=-1)
    i_exercises = max((i for i, t in enumerate(headings) if "## exercises" in t), default=-1)
    assert i_summary >= 0 and i_exercises >= 0, "needs '## Summary' and '## Exercises' sections"
    assert i_summary < i_exercises or i_summary == i_exercises
    assert i_exercises >= len(headings) - 8, "the exercises come at the end"


def test_every_solution_is_followed_by_a_self_check(nb):
    cells = nb.cells
    n_solutions = 0
    for i, cell in enumerate(cells):
        if cell.cell_type != "code" or BEGIN_SOLUTION not in _text(cell):
            continue
        n_solutions += 1
        assert _text(cell).count(BEGIN_SOLUTION) == _text(cell).count(END_SOLUTION)
        later = [c for c in cells[i + 1 :] if c.cell_type == "code"]
        assert later and "assert" in _text(later[0]), f"no self-check after the solution in cell {i}"
    assert n_solutions >= 1, "each lesson ends with at least one exercise"
    student = student_notebook(nb)
    assert all(BEGIN_SOLUTION not in _text(c) for c in student.cells)


def test_is_committed_with_outputs_and_without_noise(nb):
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.execution_count is not None for c in code), "run `make notebooks` before committing"
    for c in code:
        for out in c.outputs:
            assert out.output_type != "error", _text(c)
            if out.output_type == "stream":
                assert out.name == "stdout", f"stderr output in cell:\n{_text(c)}\n{out.text}"
                assert not NOISE.search(out.text), out.text


def test_markdown_refers_to_the_paper(nb):
    markdown = "\n".join(_text(c) for c in nb.cells if c.cell_type == "markdown")
    assert re.search(r"(Eq\.|Sec\.|Fig\.|Table)\s*\(?\d", markdown), "point to the paper by number"


def test_threads_go_through_the_library(nb):
    """`MESHVAE_NUM_THREADS` must reach every notebook (the portability pass relies on it)."""
    code = "\n".join(_text(c) for c in nb.cells if c.cell_type == "code")
    assert "set_num_threads" not in code, "call meshvae_lib.model.threads.configure_threads instead"
    if "import torch" in code or ("meshvae_lib" in code and ("train" in code or "fit(" in code)):
        assert "configure_threads(" in code


def test_every_ignored_output_is_checked_by_an_assertion(nb):
    """A cell whose output nbval ignores asserts what matters, or is a solution whose self-check
    follows; the comment under the marker says why the digits may differ."""
    cells = [c for c in nb.cells if c.cell_type == "code"]
    for i, cell in enumerate(cells):
        src = _text(cell)
        lines = src.splitlines()
        if "# NBVAL_IGNORE_OUTPUT" not in lines:
            continue
        at = lines.index("# NBVAL_IGNORE_OUTPUT")
        assert at + 1 < len(lines) and lines[at + 1].startswith("# ("), f"say why under the marker:\n{src}"
        if BEGIN_SOLUTION in src:
            assert i + 1 < len(cells) and "assert" in _text(cells[i + 1]), f"no self-check after:\n{src}"
        else:
            assert re.search(r"^\s*assert ", src, flags=re.MULTILINE), f"ignored output without an assertion:\n{src}"


def _definitions(source: str) -> list[str]:
    """Names of the functions, classes and lambdas a cell defines (IPython magics blanked out)."""
    import ast

    found = []
    for node in ast.walk(ast.parse(without_magics(source))):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            found.append(node.name)
        elif isinstance(node, ast.Lambda):
            found.append("lambda")
    return found


def test_defines_no_function_or_class_outside_exercise_solutions(nb):
    """Notebooks call the library: helpers live there, where they are tested (exercise solutions,
    which the student writes, are exempt)."""
    for cell in nb.cells:
        src = _text(cell)
        if cell.cell_type != "code" or BEGIN_SOLUTION in src:
            continue
        assert not _definitions(src), f"defines {_definitions(src)}; move it to the library:\n{src}"


def test_the_definition_check_sees_definitions():
    assert _definitions("def f(x):\n    return x\nclass A: pass\ng = lambda y: y") == ["f", "A", "lambda"]
    assert _definitions("%matplotlib inline\n!ls {x}\ny = sorted(z, key=len)") == []
