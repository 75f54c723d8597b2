"""The folders are the layers: no module imports from a layer above its own.

geometry -> model -> applications -> paper, with the base modules (tolerances, defaults, exports,
validation, input_checks, progress, atomic) under all of them; viewing sits beside the model on top of geometry alone (it draws
meshes, whatever made them); course and cli are the top. Every import counts, also those inside
functions (lazy imports are how the CLI starts fast, not a way around the layers).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

LIB = Path(__file__).resolve().parents[1] / "meshvae_lib"

BASE = {"tolerances", "defaults", "validation", "input_checks", "progress", "atomic", "workers", "exports", "__init__",
        "__version__"}
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


def imported_modules(path: Path, lib: Path | None = None) -> list[tuple[int, tuple[str, ...]]]:
    """(line, module parts under meshvae_lib) of every meshvae_lib import in ``path`` (a module of
    the library at ``lib``, default the real one)."""
    rel = path.relative_to(LIB if lib is None else lib).with_suffix("").parts
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


# --- no circle of imports inside a layer ---------------------------------------------------------


def module_file(parts: tuple[str, ...], lib: Path) -> Path | None:
    """The file of module ``meshvae_lib.<parts>`` (a module or a package's ``__init__``), or None
    for a name that is not a module (``from meshvae_lib.model import MeshVAE``-style names)."""
    base = lib.joinpath(*parts) if parts else lib
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if parts and candidate.is_file():
            return candidate
    return None


def import_graph(lib: Path) -> dict[Path, set[Path]]:
    """module file -> the module files of meshvae_lib it imports (every import, lazy ones included)."""
    graph = {}
    for path in sorted(lib.rglob("*.py")):
        targets = set()
        for _, mod in imported_modules(path, lib):
            target = module_file(mod, lib)
            if target is not None and target != path:
                targets.add(target)
        graph[path] = targets
    return graph


def circles(graph: dict[Path, set[Path]], lib: Path) -> list[list[str]]:
    """Every circle of imports among modules of one layer (strongly connected components of more
    than one module, Tarjan's algorithm), as lists of module paths."""
    def layer(p):
        return layer_of(p.relative_to(lib).with_suffix("").parts)

    index, low, on_stack, stack, out, counter = {}, {}, set(), [], [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in graph.get(v, ()):
            if layer(w) != layer(v):
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(p.relative_to(lib).as_posix() for p in component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_circle_of_imports_inside_a_layer():
    found = circles(import_graph(LIB), LIB)
    assert not found, "modules that import each other (directly or round a circle):\n" + "\n".join(map(str, found))


def test_the_circle_checker_finds_an_injected_circle(tmp_path):
    """The test above can fail: two model modules that import each other, one of them lazily."""
    fake = tmp_path / "meshvae_lib"
    (fake / "model").mkdir(parents=True)
    (fake / "model" / "a.py").write_text("from meshvae_lib.model.b import g\n")
    (fake / "model" / "b.py").write_text("def g():\n    from . import c\n")
    (fake / "model" / "c.py").write_text("from meshvae_lib.model import a\nfrom meshvae_lib import defaults\n")
    (fake / "model" / "d.py").write_text("from meshvae_lib.model import a\n")
    (fake / "defaults.py").write_text("X = 1\n")
    assert circles(import_graph(fake), fake) == [["model/a.py", "model/b.py", "model/c.py"]]
