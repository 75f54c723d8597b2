"""The folders are the layers: no module imports from a layer above its own.

geometry -> model -> applications -> paper, with the base modules (tolerances, defaults,
validation, progress) under all of them; viewing sits beside the model on top of geometry alone (it draws
meshes, whatever made them); course and cli are the top. Every import counts, also those inside
functions (lazy imports are how the CLI starts fast, not a way around the layers).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

LIB = Path(__file__).resolve().parents[1] / "meshvae_lib"

BASE = {"tolerances", "defaults", "validation", "progress", "__init__", "__version__"}
#: layer -> the layers its modules may import from (its own included)
ALLOWED = {
    "base": {"base"},
    "geometry": {"base", "geometry"},
    "model": {"base", "geometry", "model"},
    "applications": {"base", "geometry", "model", "applications"},
    "paper": {"base", "geometry", "model", "applications", "paper"},
    "viewing": {"base", "geometry", "viewing"},
    "course": {"base", "geometry", "model", "applications", "paper", "viewing", "course"},
    "cli": {"base", "geometry", "model", "applications", "cli"},
}


def layer_of(parts: tuple[str, ...]) -> str:
    """The layer of module ``meshvae_lib.<parts>`` (parts without the package name)."""
    if not parts or parts[0] in BASE:
        return "base"
    if parts[0] not in ALLOWED:
        raise AssertionError(f"meshvae_lib.{'.'.join(parts)} is in no layer: add its folder to ALLOWED")
    return parts[0]


def imported_modules(path: Path) -> list[tuple[int, tuple[str, ...]]]:
    """(line, module parts under meshvae_lib) of every meshvae_lib import in ``path``."""
    rel = path.relative_to(LIB).with_suffix("").parts
    package = rel[:-1] if rel[-1] != "__init__" else rel[:-1]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, tuple(a.name.split(".")[1:])) for a in node.names
                    if a.name.split(".")[0] == "meshvae_lib"]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[: len(package) - (node.level - 1)]
                mod = base + tuple(node.module.split(".")) if node.module else base
            elif node.module and node.module.split(".")[0] == "meshvae_lib":
                mod = tuple(node.module.split(".")[1:])
            else:
                continue
            if node.module is None or len(mod) <= 1:   # from meshvae_lib[.layer] import a, b: modules
                out += [(node.lineno, mod + (a.name,)) for a in node.names]
            else:
                out.append((node.lineno, mod))
    return out


MODULES = sorted(LIB.rglob("*.py"))


@pytest.mark.parametrize("path", MODULES, ids=[p.relative_to(LIB).as_posix() for p in MODULES])
def test_no_module_imports_from_a_layer_above(path):
    own = layer_of(path.relative_to(LIB).with_suffix("").parts)
    bad = [f"line {line}: meshvae_lib.{'.'.join(mod)} ({layer_of(mod)})"
           for line, mod in imported_modules(path) if layer_of(mod) not in ALLOWED[own]]
    assert not bad, f"{path.relative_to(LIB)} ({own}) imports from a layer above:\n" + "\n".join(bad)


def test_the_checker_sees_lazy_relative_and_package_imports(tmp_path, monkeypatch):
    """The test above can fail: a lazy import of the model from geometry is caught."""
    fake = tmp_path / "meshvae_lib"
    (fake / "geometry").mkdir(parents=True)
    src = ("from . import topology\nfrom meshvae_lib import defaults\n"
           "def f():\n    from meshvae_lib.model.training import TrainConfig\n    from ..applications import generation\n")
    (fake / "geometry" / "bad.py").write_text(src)
    monkeypatch.setattr(__import__(__name__), "LIB", fake)
    mods = imported_modules(fake / "geometry" / "bad.py")
    assert [m for _, m in mods] == [("geometry", "topology"), ("defaults",), ("model", "training"),
                                    ("applications", "generation")]
    assert [layer_of(m) for _, m in mods] == ["geometry", "base", "model", "applications"]


def test_every_folder_of_the_library_is_a_layer():
    folders = {p.name for p in LIB.iterdir() if p.is_dir() and not p.name.startswith(("_", "."))}
    assert folders == set(ALLOWED) - {"base"}, f"folders {sorted(folders)} vs layers {sorted(ALLOWED)}"
