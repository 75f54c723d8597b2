"""Every exercise's self-check fails on a trivial answer, and on the wrong answers known to fool it.

For each notebook, :func:`~meshvae_lib.course.notebooks.trivial_answer_notebook` gives the names
each solution binds three trivial answers in turn -- left unchanged (undefined, or the value they
had before the exercise), ``None``, and zeros of the real answer's type and shape --, then runs
each named wrong answer of :data:`WRONG_ANSWERS` in place of the solution; it runs the self-check
on each, then restores the real answer. The notebook is executed once (the course models come
from the cache, as for nbval), and every self-check must raise on every one of them.
"""

from __future__ import annotations

import runpy
from pathlib import Path

import nbformat
import pytest

from meshvae_lib.course.notebooks import (TRIVIAL_ANSWERS, rerun_answer, solution_names, trivial_answer_notebook,
                                          trivial_answer_outcomes)

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NOTEBOOKS = sorted(NOTEBOOK_DIR.glob("[0-9][0-9]_*.ipynb"))

#: (notebook stem, exercise number from 1) -> {name: code run in place of the solution}: wrong
#: answers a student would try, each of which its self-check must reject. One file per notebook in
#: tests/wrong_answers/ (its WRONG_ANSWERS maps exercise -> {name: code}).
WRONG_ANSWERS = {(path.stem, exercise): answers
                 for path in sorted((Path(__file__).resolve().parent / "wrong_answers").glob("[0-9][0-9]_*.py"))
                 for exercise, answers in runpy.run_path(str(path))["WRONG_ANSWERS"].items()}


def wrong_answers_of(stem: str) -> dict[int, dict[str, str]]:
    """The named wrong answers of one notebook, by exercise number."""
    return {exercise: answers for (nb_stem, exercise), answers in WRONG_ANSWERS.items() if nb_stem == stem}


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
    ns, printed = _run_cells(out)
    line = [p for p in printed if "TRIVIAL" in p][-1]
    assert '"unchanged": "NameError"' in line and '"None": "AssertionError"' in line and '"zeros": "AssertionError"' in line
    assert ns["answer"] == 10, "the real answer is restored for the rest of the notebook"


def _run_cells(nb) -> tuple[dict, list[str]]:
    import contextlib
    import io

    ns, printed = {}, []
    for cell in nb.cells:
        if cell.cell_type == "code":
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                exec(cell.source, ns)
            printed.append(buf.getvalue())
    return ns, printed


def test_the_trivial_answer_notebook_tries_named_wrong_answers():
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("start = 5"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = start * 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("assert answer == 2 * start"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nsquare = answer ** 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("assert square > 0"),
    ])
    wrong = {1: {"typed in": "answer = 10\nscratch = 1", "tripled": "answer = start * 3", "broken": "answer = nope"},
             2: {"negative": "square = -answer"}}
    out, exercises = trivial_answer_notebook(nb, wrong_answers=wrong)
    assert exercises == [(1, ["answer"]), (3, ["square"])]
    ns, printed = _run_cells(out)
    outcomes = trivial_answer_outcomes(nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell(outputs=[nbformat.v4.new_output("stream", name="stdout", text=text)]) for text in printed]))
    assert outcomes[0] == {"unchanged": "NameError", "None": "AssertionError", "zeros": "AssertionError",
                           "typed in": "passed", "tripled": "AssertionError",
                           "broken": "the wrong answer itself raised NameError"}
    assert outcomes[1] == {"unchanged": "NameError", "None": "TypeError", "zeros": "AssertionError",
                           "negative": "AssertionError"}
    assert ns["answer"] == 10 and ns["square"] == 100, "the real answers are restored"
    assert "scratch" not in ns, "names a wrong answer adds are removed"
    with pytest.raises(ValueError, match="exercises \\[3\\]"):
        trivial_answer_notebook(nb, wrong_answers={3: {"x": "pass"}})
    with pytest.raises(ValueError, match="trivial answers' names"):
        trivial_answer_notebook(nb, wrong_answers={1: {"None": "answer = None"}})


def test_rerun_answer_runs_the_latest_cell_that_binds_the_answer_on_other_inputs():
    history = ["", "x = 3", "### BEGIN SOLUTION\nanswer = x * 2\nother = 1\n### END SOLUTION", "print(answer)",
               "assert rerun_answer(globals(), 'answer', x=5) == 10"]
    ns = {"In": history, "x": 3, "answer": 6}
    assert rerun_answer(ns, "answer", x=5) == 10
    assert rerun_answer(ns, ["answer", "other"], x=1) == (2, 1)
    assert ns["x"] == 3 and ns["answer"] == 6, "the notebook's own names keep their values"
    pasted = {**ns, "In": history[:2] + ["answer = 6"] + history[3:]}
    assert rerun_answer(pasted, "answer", x=5) == 6, "a typed-in answer stays what it was"
    with pytest.raises(LookupError, match="no earlier cell binds"):
        rerun_answer({"In": ["x = 3", "rerun_answer(...)"]}, "answer", x=5)
    nb = nbformat.v4.new_notebook(cells=[
        nbformat.v4.new_code_cell("x = 3"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = x * 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("from meshvae_lib.course.notebooks import rerun_answer\n"
                                  "assert answer == 2 * x and rerun_answer(globals(), 'answer', x=5) == 10"),
    ])
    out, _ = trivial_answer_notebook(nb, wrong_answers={1: {"typed in": "answer = 6", "doubled by hand": "answer = x + x"}})
    ns, printed = {"In": []}, []
    import contextlib
    import io

    for cell in out.cells:   # as a kernel would: the running cell is the last entry of In
        ns["In"].append(cell.source)
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            exec(cell.source, ns)
        printed.append(buf.getvalue())
    line = [p for p in printed if "TRIVIAL" in p][-1]
    assert '"typed in": "AssertionError"' in line and '"doubled by hand": "passed"' in line
    assert "_t_answer_source" not in ns, "the harness leaves no answer source behind for the real check"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_exercise_is_attacked_with_at_least_two_wrong_answers(path):
    _, exercises = trivial_answer_notebook(nbformat.read(path, as_version=4))
    wrong = wrong_answers_of(path.stem)
    thin = {number: len(wrong.get(number, {})) for number in range(1, len(exercises) + 1) if len(wrong.get(number, {})) < 2}
    assert not thin, f"{path.stem}: exercises with fewer than two wrong answers in tests/wrong_answers/{path.stem}.py: {thin}"


def test_every_wrong_answer_names_an_existing_exercise():
    for (stem, exercise), answers in WRONG_ANSWERS.items():
        path = NOTEBOOK_DIR / f"{stem}.ipynb"
        assert path.exists(), stem
        assert answers and not set(answers) & set(TRIVIAL_ANSWERS), (stem, exercise)
        trivial_answer_notebook(nbformat.read(path, as_version=4), wrong_answers={exercise: answers})


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_every_self_check_raises_on_trivial_and_known_wrong_answers(path):
    from nbclient import NotebookClient

    wrong = wrong_answers_of(path.stem)
    nb, exercises = trivial_answer_notebook(nbformat.read(path, as_version=4), wrong_answers=wrong)
    assert len(exercises) >= 2, f"{path.stem} has {len(exercises)} exercise(s)"
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK_DIR)}}).execute()
    outcomes = trivial_answer_outcomes(nb)
    assert len(outcomes) == len(exercises)
    accepted = []   # (exercise, solution cell, answer names, answer, outcome)
    for number, ((cell, names), o) in enumerate(zip(exercises, outcomes), start=1):
        for answer in (*TRIVIAL_ANSWERS, *wrong.get(number, {})):
            print(f"{path.stem} exercise {number} (cell {cell}), {answer!r}: {o[answer]}")
            if o[answer] == "passed" or o[answer].startswith("the wrong answer itself"):
                accepted.append((number, cell, names, answer, o[answer]))
    assert not accepted, (f"{path.stem}: self-checks that accept a trivial or wrong answer, or wrong answers that do "
                          f"not run (exercise, cell, answer names, answer, outcome): {accepted}")
