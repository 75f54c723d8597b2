"""The course tooling: solution stripping for student copies, notebook execution, HTML."""

from __future__ import annotations

import nbformat
import pytest

from meshvae_lib.course.commands import main
from meshvae_lib.course.notebooks import (STUDENT_PLACEHOLDER, coalesce_streams, inject_parameters, strip_solutions,
                                           student_notebook)


def test_strip_solutions_replaces_block_and_keeps_the_rest():
    src = "x = 1\n### BEGIN SOLUTION\ny = x + 1\nz = 2\n### END SOLUTION\nprint(y)\n"
    out, n = strip_solutions(src)
    assert n == 1
    assert out == "x = 1\n" + STUDENT_PLACEHOLDER + "\nprint(y)\n"
    assert "y = x + 1" not in out


def test_strip_solutions_keeps_indentation_and_handles_two_blocks():
    src = (
        "def f(a):\n    ### BEGIN SOLUTION\n    return a * 2\n    ### END SOLUTION\n"
        "### BEGIN SOLUTION\nb = 3\n### END SOLUTION"
    )
    out, n = strip_solutions(src)
    assert n == 2
    assert out.splitlines() == [
        "def f(a):",
        "    # YOUR CODE HERE",
        "    raise NotImplementedError()",
        "# YOUR CODE HERE",
        "raise NotImplementedError()",
    ]


@pytest.mark.parametrize(
    "src",
    ["### BEGIN SOLUTION\nx = 1\n", "x = 1\n### END SOLUTION\n", "### END SOLUTION\nx\n### BEGIN SOLUTION\n"],
)
def test_strip_solutions_rejects_unbalanced_markers(src):
    with pytest.raises(ValueError, match="solution markers"):
        strip_solutions(src)


def _tiny_notebook():
    nb = nbformat.v4.new_notebook()
    nb.cells = [
        nbformat.v4.new_markdown_cell("# Tiny lesson\nText."),
        nbformat.v4.new_code_cell("a = 20 + 1\nprint(a)"),
        nbformat.v4.new_code_cell("### BEGIN SOLUTION\nanswer = a * 2\n### END SOLUTION"),
        nbformat.v4.new_code_cell("assert answer == 42\nprint('self-check passed')"),
    ]
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    return nb


def test_student_notebook_removes_solution_and_its_outputs():
    nb = _tiny_notebook()
    nb.cells[2].outputs = [nbformat.v4.new_output("stream", name="stdout", text="secret\n")]
    student = student_notebook(nb)
    assert "answer = a * 2" not in student.cells[2].source
    assert student.cells[2].outputs == []
    assert student.cells[3].source == nb.cells[3].source  # the self-check stays
    assert "answer = a * 2" in nb.cells[2].source  # the teacher's copy is untouched


@pytest.mark.slow
def test_execute_html_and_student_commands(tmp_path, capsys):
    path = tmp_path / "00_tiny.ipynb"
    nbformat.write(_tiny_notebook(), path)
    assert main(["execute", str(path)]) == 0
    executed = nbformat.read(path, as_version=4)
    assert executed.cells[1].outputs[0]["text"] == "21\n"
    assert executed.cells[3].outputs[0]["text"] == "self-check passed\n"

    assert main(["html", "--out", str(tmp_path / "html"), str(path)]) == 0
    page = (tmp_path / "html" / "00_tiny.html").read_text()
    assert "self-check passed" in page
    assert "Tiny lesson" in (tmp_path / "html" / "index.html").read_text()

    assert main(["student", "--out", str(tmp_path / "student"), str(path)]) == 0
    student = nbformat.read(tmp_path / "student" / "00_tiny.ipynb", as_version=4)
    assert "raise NotImplementedError()" in student.cells[2].source


def test_missing_notebook_is_a_clear_error(tmp_path, capsys):
    assert main(["student", "--out", str(tmp_path), str(tmp_path / "nope.ipynb")]) == 1
    assert "no notebook at" in capsys.readouterr().err


def _stream(name, text):
    return nbformat.v4.new_output("stream", name=name, text=text)


def test_coalesce_streams_merges_runs_of_one_stream_only():
    outs = [_stream("stdout", "a\n"), _stream("stdout", "b\n"), _stream("stderr", "w\n"), _stream("stdout", "c\n"),
            nbformat.v4.new_output("execute_result", data={"text/plain": "1"}, execution_count=1),
            _stream("stdout", "d\n")]
    merged = coalesce_streams(outs)
    assert [(o.output_type, o.get("name"), o.get("text")) for o in merged] == [
        ("stream", "stdout", "a\nb\n"), ("stream", "stderr", "w\n"), ("stream", "stdout", "c\n"),
        ("execute_result", None, None), ("stream", "stdout", "d\n")]
    assert coalesce_streams([]) == []


def test_inject_parameters_goes_right_after_the_parameters_cell():
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("# L"), nbformat.v4.new_code_cell("# Parameters\nSEED = 0\nN = 3\n"),
                nbformat.v4.new_code_cell("print(SEED)")]
    nb.cells[1].metadata["tags"] = ["parameters"]
    inject_parameters(nb, {"SEED": "7"})
    assert [c.source for c in nb.cells][1:3] == ["# Parameters\nSEED = 0\nN = 3\n", "# Injected parameters\nSEED = 7\n"]
    assert nb.cells[2].metadata["tags"] == ["injected-parameters"]
    with pytest.raises(ValueError, match="'LR' is not assigned"):
        inject_parameters(nb, {"LR": "1"})
    nb.cells[1].metadata["tags"] = []
    with pytest.raises(ValueError, match="no cell tagged 'parameters'"):
        inject_parameters(nb, {"SEED": "1"})


def test_execute_with_set_needs_out_and_a_valid_assignment(tmp_path, capsys):
    path = tmp_path / "00_tiny.ipynb"
    nbformat.write(_tiny_notebook(), path)
    assert main(["execute", str(path), "--set", "A=1"]) == 1
    assert "--out" in capsys.readouterr().err
    assert main(["execute", str(path), "--set", "no equals", "--out", str(tmp_path / "o")]) == 1
    assert "NAME=VALUE" in capsys.readouterr().err
