"""Self-checks that run the student's answer cell again, on inputs the student has not seen (issue 49).

:func:`rerun_answer` finds the latest cell that binds the answer and runs it in a copy of the
notebook's globals with other inputs, so that a typed, pasted or copied answer fails where code
passes; :func:`record_cells` lets it find that cell where the kernel keeps no history (nbval).
"""

from __future__ import annotations

__all__ = ["ANSWER_SOURCE", "rerun_answer", "record_cells", "bound_names", "without_magics"]


def without_magics(source: str) -> str:
    """A code cell's source with its IPython lines (``%magic``, ``!shell``) blanked, so that ``ast``
    can parse it; line numbers stay as they are."""
    return "\n".join("" if line.lstrip().startswith(("%", "!")) else line for line in source.splitlines())


def bound_names(code: str) -> list[str]:
    """The names a piece of code binds at module scope, in order of first binding (the rules of
    :func:`~meshvae_lib.course.notebooks.solution_names`, for the whole code; its IPython lines are ignored)."""
    import ast

    names: list[str] = []

    def add(name: str) -> None:
        if name not in names:
            names.append(name)

    def visit(node) -> None:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            add(node.name)
            return
        if isinstance(node, (ast.Lambda, ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp)):
            return
        if isinstance(node, (ast.Import, ast.ImportFrom)):   # tools, not answers: left as imported
            return
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            add(node.id)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(ast.parse(without_magics(code)))
    return names


#: the global name under which :func:`~meshvae_lib.course.notebooks.trivial_answer_notebook` hands :func:`rerun_answer` the code
#: it ran in place of a solution: a wrong answer runs outside a cell, so the kernel's history lacks it.
ANSWER_SOURCE = "_t_answer_source"


def rerun_answer(namespace: dict, names, **inputs):
    """Run the student's cell again on inputs the student has not seen, and return what it binds.

    A self-check calls it to tell code from a pasted or copied answer: typed-in numbers stay the
    same when the inputs change.

    namespace : the notebook's globals (``globals()`` in the check cell); names : the answer's name,
    or a sequence of names; inputs : the names the cell reads, given other values (``a=3, b=7``).

    The student's cell is the latest cell before the running one, among those the kernel ran since
    :func:`record_cells` was called (else in the kernel's history ``In``), that binds every one
    of ``names`` at module scope (:func:`bound_names`); it runs
    in a copy of ``namespace`` with ``inputs`` in place, so the notebook's own names keep their
    values (objects the cell changes in place are changed, as a rerun of the cell would). (A
    :func:`~meshvae_lib.course.notebooks.trivial_answer_notebook` gives the code it runs in place of the solution under
    :data:`ANSWER_SOURCE` instead.)

    Returns the value of ``names`` (a str), or a tuple of values (a sequence).

    Raises
    ------
    LookupError
        When no earlier cell binds the names, or the rerun leaves one unbound.
    """
    wanted = [names] if isinstance(names, str) else list(names)
    source = namespace.get(ANSWER_SOURCE)
    if source is None:
        history = (_RECORDED or list(namespace.get("In", namespace.get("_ih", []))))[:-1]   # the last is the running cell
        source = next((cell for cell in reversed(history) if cell and set(wanted) <= set(_bound_or_none(cell))), None)
        if source is None:
            raise LookupError(f"no earlier cell binds {wanted}: write the answer in one cell, in terms of "
                              f"{sorted(inputs)}, and run it (after the lesson's first cell, which calls record_cells())")
    scope = dict(namespace)
    scope.update(inputs)
    exec(source, scope)
    missing = [n for n in wanted if n not in scope]
    if missing:
        raise LookupError(f"run again, the answer's cell left {missing} unbound")
    values = tuple(scope[n] for n in wanted)
    return values[0] if isinstance(names, str) else values


#: the cells this IPython kernel ran since :func:`record_cells` was called, as Python (magics translated):
#: the kernel's own history (``In``) stays empty where cells run without it (nbval's
#: ``store_history=False``).
_RECORDED: list[str] = []


def record_cells() -> None:
    """Record every cell the running IPython kernel starts from now on (in :data:`_RECORDED`), so
    that :func:`rerun_answer` finds a student's cell where the kernel keeps no history (nbval).
    A lesson whose self-checks rerun answers calls it in its first cell; calling it again, or
    outside IPython, does nothing."""
    try:
        from IPython import get_ipython
    except ImportError:
        return
    shell = get_ipython()
    if shell is None or getattr(shell, "_meshvae_records_cells", False):
        return
    shell.events.register("pre_run_cell", lambda info: _RECORDED.append(shell.transform_cell(info.raw_cell or "")))
    shell._meshvae_records_cells = True


def _bound_or_none(code: str) -> list[str]:
    """:func:`bound_names` of a history entry, empty where it does not parse."""
    try:
        return bound_names(code)
    except SyntaxError:
        return []
