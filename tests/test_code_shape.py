"""The shape of the library's code: no module over 400 lines, no function over 80 lines, and no
caller outside the model layer reading the fitted parts of a model (it uses the model's public
properties and methods: ``network``, ``feature_kind``, ``latent_dim``, ``faces``, ...)."""

from __future__ import annotations

import ast
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LIB = ROOT / "meshvae_lib"
MODULES = sorted(LIB.rglob("*.py"))
IDS = [p.relative_to(LIB).as_posix() for p in MODULES]

MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 80
#: a fitted model's parts: read through the model's properties outside meshvae_lib/model/.
PARTS = re.compile(r"\.(network_|kind_|extractor_|normalizer_|conditions_|train_conditions_)\b")


@pytest.mark.parametrize("path", MODULES, ids=IDS)
def test_no_module_over_400_lines(path):
    n = len(path.read_text().splitlines())
    assert n <= MAX_MODULE_LINES, f"{path.relative_to(LIB)} has {n} lines: split it by concept"


def long_functions(source: str, limit: int = MAX_FUNCTION_LINES) -> list[tuple[str, int]]:
    """(name, lines) of every function or method of ``source`` longer than ``limit`` lines
    (docstring included)."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = node.end_lineno - node.lineno + 1
            if n > limit:
                out.append((node.name, n))
    return out


@pytest.mark.parametrize("path", MODULES, ids=IDS)
def test_no_function_over_80_lines(path):
    assert not long_functions(path.read_text()), f"{path.relative_to(LIB)}: {long_functions(path.read_text())}"


def test_the_function_checker_counts_nested_and_decorated_functions():
    body = "\n".join(f"    x{i} = {i}" for i in range(85))
    src = f"class A:\n    @property\n    def long(self):\n{body.replace('    ', '        ')}\n\ndef short():\n    pass\n"
    assert long_functions(src) == [("long", 86)]


def _sources():
    """(name, code) of every library module outside the model layer, every notebook's code cells and
    every benchmark."""
    for path in MODULES:
        if path.relative_to(LIB).parts[0] != "model":
            yield path.relative_to(ROOT).as_posix(), path.read_text()
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        cells = json.loads(path.read_text())["cells"]
        yield path.name, "\n".join("".join(c["source"]) for c in cells if c["cell_type"] == "code")
    for path in sorted((ROOT / "benchmarks").glob("*.py")):
        yield path.relative_to(ROOT).as_posix(), path.read_text()


def test_no_caller_outside_the_model_reads_a_models_fitted_parts():
    bad = [f"{name}: {m.group(0)}" for name, text in _sources() for m in PARTS.finditer(text)]
    assert not bad, "use the model's public properties instead:\n" + "\n".join(bad)
