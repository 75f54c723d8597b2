"""The generated part of ``docs/ARCHITECTURE.md``: the folder tree and every module's public names.

Read from the source with :mod:`ast` (nothing is imported, so no torch): a module's public names
are its ``__all__`` (or, without one, its top-level functions and classes not starting with ``_``),
what it holds is the first sentence of its docstring. ``python -m meshvae_lib.course architecture``
rewrites the part of the page between :data:`BEGIN` and :data:`END`; a test checks that the page
and the code agree.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

__all__ = ["BEGIN", "END", "LAYER_ORDER", "module_summary", "architecture_markdown", "update_architecture"]

BEGIN = "<!-- BEGIN GENERATED: python -m meshvae_lib.course architecture -->"
END = "<!-- END GENERATED -->"

#: the library's folders from the bottom layer up, with what each holds.
LAYER_ORDER = (
    ("", "base: tolerances, hyperparameter defaults, input validation"),
    ("geometry", "meshes, deformation gradients (Eq. 1), RIMD features (Eq. 2) and their reconstruction"),
    ("model", "normalisation (Eq. 3), the mesh VAE (Eq. 4, 5), training, the fitted model, checkpoints, evaluation"),
    ("applications", "generation, interpolation, embedding, retrieval, exploration (Sec. 4.5, 5)"),
    ("paper", "the paper's experiments (Sec. 5): one module per table or figure"),
    ("viewing", "static and interactive 3D views (beside the model: it draws meshes, whatever made them)"),
    ("course", "the course's trained models and notebook tooling"),
    ("cli", "the `meshvae` command line"),
)


#: a sentence ends at a full stop before a capital, not after "Eq", "Fig", "Sec", "e.g", "i.e".
_SENTENCE_END = re.compile(r"(?<!Eq)(?<!Fig)(?<!Sec)(?<!e\.g)(?<!i\.e)\.\s+(?=[A-Z(`])")


def module_summary(path: Path) -> tuple[str, list[str]]:
    """(first sentence of the docstring, public names) of the module at ``path``."""
    tree = ast.parse(Path(path).read_text(), str(path))
    doc = (ast.get_docstring(tree) or "").strip()
    first = " ".join(doc.split("\n\n")[0].split())
    end = _SENTENCE_END.search(first)
    summary = first if end is None else first[: end.start() + 1]
    names = None
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            names = [ast.literal_eval(e) for e in node.value.elts]
    if names is None:
        names = [n.name for n in tree.body
                 if isinstance(n, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)) and not n.name.startswith("_")]
    if not names:   # a module of constants
        names = [t.id for n in tree.body if isinstance(n, ast.Assign) for t in n.targets
                 if isinstance(t, ast.Name) and t.id.isupper()]
    return summary, names


def _modules(lib: Path, folder: str) -> list[Path]:
    root = lib / folder if folder else lib
    return sorted(p for p in root.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))


def _packages(lib: Path, folder: str) -> list[Path]:
    """The sub-packages of a layer's folder (registries with one module per entry)."""
    if not folder:
        return []
    return sorted(p for p in (lib / folder).iterdir() if (p / "__init__.py").is_file())


def _table_modules(lib: Path, folder: str) -> list[Path]:
    """The modules a layer's table lists: its own, then each sub-package's ``__init__`` (its
    registry) and modules."""
    out = list(_modules(lib, folder))
    for pkg in _packages(lib, folder):
        out += [pkg / "__init__.py"] + _modules(lib, f"{folder}/{pkg.name}")
    return out


def architecture_markdown(lib: Path | None = None) -> str:
    """The generated Markdown: a tree of the library's folders and modules, then one table per
    folder (module, what it holds, public names)."""
    lib = Path(__file__).resolve().parents[1] if lib is None else Path(lib)
    tree = ["```", "meshvae_lib/"]
    for folder, what in LAYER_ORDER:
        mods = _modules(lib, folder)
        if folder:
            tree.append(f"├── {folder}/{'':<{14 - len(folder)}}# {what}")
            tree += [f"│   ├── {p.name}" for p in mods]
            for pkg in _packages(lib, folder):
                summary = module_summary(pkg / "__init__.py")[0].split(":")[0]
                tree.append(f"│   ├── {pkg.name}/{'':<{16 - len(pkg.name)}}# {summary}, a registry")
                tree += [f"│   │   ├── {p.name}" for p in _modules(lib, f"{folder}/{pkg.name}")]
        else:
            tree += [f"├── {p.name}{'':<{20 - len(p.name)}}# {what}" if i == 0 else f"├── {p.name}"
                     for i, p in enumerate(mods)]
    tree.append("```")
    tables = []
    for folder, what in LAYER_ORDER:
        rows = ["| module | what it holds | public names |", "| --- | --- | --- |"]
        for p in _table_modules(lib, folder):
            summary, names = module_summary(p)
            parts = p.relative_to(lib).with_suffix("").parts
            dotted = ".".join(("meshvae_lib",) + (parts[:-1] if parts[-1] == "__init__" else parts))
            listed = ", ".join(f"`{n}`" for n in names) or "(none)"
            summary = summary.replace("|", "\\|")
            rows.append(f"| `{dotted}` | {summary} | {listed} |")
        title = f"`meshvae_lib/{folder}/`" if folder else "`meshvae_lib/` (base)"
        tables.append(f"### {title}: {what}\n\n" + "\n".join(rows))
    return "\n".join(tree) + "\n\n" + "\n\n".join(tables) + "\n"


def update_architecture(page: Path, lib: Path | None = None, check: bool = False) -> bool:
    """Rewrite the generated part of ``page`` (between BEGIN and END). Returns whether it changed;
    with ``check`` nothing is written. ValueError when the page lacks the markers."""
    page = Path(page)
    text = page.read_text()
    if BEGIN not in text or END not in text:
        raise ValueError(f"{page} has no generated part: add the lines {BEGIN!r} and {END!r}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    new = f"{head}{BEGIN}\n{architecture_markdown(lib)}{END}{tail}"
    if new != text and not check:
        page.write_text(new)
    return new != text
