"""Which code a course model depends on: the import closure of its training, found statically.

:func:`import_closure` starts from a few modules and follows every ``import`` statement (at the
top of a module or inside a function: both run when the model is trained) and every registry
entry that names a module in a string (``"meshvae_lib.model.vae:MeshVAE"``: the feature kinds,
network architectures and inference methods are imported by name), within the given packages,
package ``__init__`` modules included. Nothing is imported. :func:`closure_fingerprint` hashes the
closure's syntax trees without docstrings: the course-model cache key changes when, and only
when, code that trains a model or makes its data changes.
"""

from __future__ import annotations

import ast
import hashlib
import re
from pathlib import Path

__all__ = ["import_closure", "closure_fingerprint", "code_without_docstrings"]

_MODULE_STRING = re.compile(r"^([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)+)(?::\w+)?$")


def _path(module: str, roots: dict) -> Path | None:
    """The file of ``module`` (``pkg.sub.mod``) under ``roots`` (package name -> folder), or None."""
    top, *rest = module.split(".")
    if top not in roots:
        return None
    base = Path(roots[top]).joinpath(*rest)
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _imports(path: Path, module: str, roots: dict) -> set[str]:
    """The modules of ``roots``' packages that ``path`` (module ``module``) imports or names."""
    tree = ast.parse(path.read_text(), str(path))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[: len(parts) - (node.level - 1)])
                source = f"{base}.{node.module}" if node.module else base
            else:
                source = node.module or ""
            names.add(source)
            names.update(f"{source}.{a.name}" for a in node.names)  # kept when they are modules
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            match = _MODULE_STRING.match(node.value)
            if match:
                names.add(match.group(1))
    found = set()
    for name in names:
        parts = name.split(".")
        for i in range(1, len(parts) + 1):  # importing a.b.c runs a, a.b and a.b.c
            prefix = ".".join(parts[:i])
            if _path(prefix, roots) is not None:
                found.add(prefix)
    return found


def _excluded(module: str, exclude) -> bool:
    return any(module == e or module.startswith(e + ".") for e in exclude)


def import_closure(entries, roots: dict, exclude=()) -> list[str]:
    """Every module of ``roots`` (package name -> folder) that the modules ``entries`` import,
    directly or not, themselves included; sorted. ``exclude``: packages or modules (dotted names)
    left out together with what only they import."""
    seen: set[str] = set()
    todo = [m for m in entries]
    while todo:
        module = todo.pop()
        path = _path(module, roots)
        if module in seen or path is None or _excluded(module, exclude):
            continue
        seen.add(module)
        todo.extend(_imports(path, module, roots) - seen)
    missing = [m for m in entries if m not in seen]
    if missing:
        raise ValueError(f"no module {missing} under {roots}")
    return sorted(seen)


def code_without_docstrings(source: str) -> str:
    """``ast.dump`` of ``source`` with every module, class and function docstring removed."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree)


def closure_fingerprint(entries, roots: dict, exclude=()) -> str:
    """sha256 (hex) of the modules in :func:`import_closure` (``exclude`` left out): their names and
    syntax trees without docstrings, in sorted order."""
    h = hashlib.sha256()
    for module in import_closure(entries, roots, exclude):
        h.update(f"{module}\0".encode())
        h.update(code_without_docstrings(_path(module, roots).read_text()).encode())
    return h.hexdigest()
