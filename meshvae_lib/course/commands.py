"""``python -m meshvae_lib.course``: the course's commands.

Used by the Makefile (``make notebooks``, ``make course``, ``make student``, ``make models``)::

    python -m meshvae_lib.course execute notebooks/0*.ipynb
    python -m meshvae_lib.course html --out build/course notebooks/0*.ipynb
    python -m meshvae_lib.course student --out build/student notebooks/0*.ipynb
    python -m meshvae_lib.course models            # build every missing course model
    python -m meshvae_lib.course architecture      # regenerate docs/ARCHITECTURE.md's module tables
    python -m meshvae_lib.course portable --command "pytest notebooks ..." "A=1" "B=2 C=3"   # make test-portable
"""

from __future__ import annotations

import argparse
import html
import logging
import sys
import time
from pathlib import Path

from .notebooks import execute_notebook, student_notebook

logger = logging.getLogger(__name__)


def _notebook_paths(paths: list[str]) -> list[Path]:
    result = []
    for p in paths:
        path = Path(p)
        if not path.is_file():
            raise FileNotFoundError(f"no notebook at {path}")
        if path.suffix != ".ipynb":
            raise ValueError(f"not a notebook (expected .ipynb): {path}")
        result.append(path)
    return result


def _cmd_execute(args) -> int:
    import nbformat

    parameters = _parameters(args.set)
    if parameters and not args.out:
        raise ValueError("--set changes the lesson: give --out DIR so the stored notebooks are not overwritten")
    out = Path(args.out) if args.out else None
    if out:
        out.mkdir(parents=True, exist_ok=True)
    for path in _notebook_paths(args.notebooks):
        start = time.perf_counter()
        nb = execute_notebook(path, timeout=args.timeout, parameters=parameters)
        target = out / path.name if out else path
        nbformat.write(nb, target)
        print(f"executed {path} -> {target} in {time.perf_counter() - start:.1f} s")
    return 0


def _parameters(assignments: list[str] | None) -> dict[str, str]:
    result = {}
    for text in assignments or []:
        name, sep, value = text.partition("=")
        if not sep or not name.strip().isidentifier() or not value.strip():
            raise ValueError(f"--set expects NAME=VALUE, got {text!r}")
        result[name.strip()] = value.strip()
    return result


def _cmd_html(args) -> int:
    import nbformat
    from nbconvert import HTMLExporter

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    exporter = HTMLExporter()
    entries = []
    total = time.perf_counter()
    for path in _notebook_paths(args.notebooks):
        start = time.perf_counter()
        nb = execute_notebook(path, timeout=args.timeout, store_widget_state=False)   # offline HTML: PNG snapshots
        body, _ = exporter.from_notebook_node(nb)
        target = out / (path.stem + ".html")
        target.write_text(body, encoding="utf-8")
        title = next(
            (c.source.splitlines()[0].lstrip("# ").strip() for c in nb.cells if c.cell_type == "markdown" and c.source),
            path.stem,
        )
        seconds = time.perf_counter() - start
        entries.append((target.name, title, seconds))
        print(f"{path} -> {target} ({seconds:.1f} s)")
    items = "\n".join(
        f'<li><a href="{html.escape(name)}">{html.escape(title)}</a> <small>({seconds:.0f} s)</small></li>'
        for name, title, seconds in entries
    )
    (out / "index.html").write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>Mesh VAE course</title></head>"
        f"<body><h1>Mesh VAE: the course</h1><ol>{items}</ol></body></html>\n",
        encoding="utf-8",
    )
    print(f"wrote {out / 'index.html'}: {len(entries)} notebooks in {time.perf_counter() - total:.1f} s")
    return 0


def _cmd_student(args) -> int:
    import nbformat

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for path in _notebook_paths(args.notebooks):
        nb = nbformat.read(path, as_version=4)
        student = student_notebook(nb)
        nbformat.write(student, out / path.name)
        n = sum(c.source.count("raise NotImplementedError()") for c in student.cells if c.cell_type == "code")
        print(f"{path} -> {out / path.name} ({n} exercise(s) to solve)")
    return 0


def _cmd_models(args) -> int:
    from meshvae_lib.model.threads import configure_threads
    from . import models as cm

    configure_threads(2)  # as the notebooks do (MESHVAE_NUM_THREADS overrides it)

    names = args.names or sorted(cm.COURSE_MODELS)
    for name in names:
        cm.get_spec(name)
    if args.list:
        for name in names:
            spec = cm.COURSE_MODELS[name]
            state = "cached" if cm.is_cached(name) else "missing"
            print(f"{name:22s} {state:8s} {spec.lesson:28s} {spec.description}")
        print(f"cache: {cm.cache_dir()}")
        return 0
    total = time.perf_counter()
    for name in names:
        start = time.perf_counter()
        path = cm.cache_path(name)  # the key hashes the library's source: compute it once per model
        was_cached = path.is_file() and not args.rebuild
        cm.course_model(name, progress=not args.no_progress, rebuild=args.rebuild)
        what = "cached" if was_cached else f"built in {time.perf_counter() - start:.0f} s"
        print(f"{name}: {what} ({path})", flush=True)
    print(f"{len(names)} course model(s) ready in {time.perf_counter() - total:.0f} s")
    return 0


def _cmd_architecture(args) -> int:
    from .architecture import update_architecture

    page = Path(args.page)
    changed = update_architecture(page, check=args.check)
    if args.check:
        print(f"{page} is {'stale: run python -m meshvae_lib.course architecture' if changed else 'current'}")
        return 1 if changed else 0
    print(f"{'rewrote' if changed else 'unchanged:'} {page}")
    return 0


def _cmd_portable(args) -> int:
    import shlex

    from .portable import run_settings, summary

    results = run_settings(args.settings, shlex.split(args.command), args.logs)
    print(summary(results), flush=True)
    return 0 if all(r.ok for r in results) else 1


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m meshvae_lib.course", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("execute", help="execute notebooks in place (refreshes their stored outputs)")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--timeout", type=int, default=600, help="seconds per cell (default 600)")
    p.add_argument("--set", action="append", metavar="NAME=VALUE",
                   help="override a parameter of the parameters cell (repeatable), e.g. --set SEED=1; needs --out")
    p.add_argument("--out", metavar="DIR", help="write the executed notebooks here instead of in place")
    p.set_defaults(func=_cmd_execute)
    p = sub.add_parser("html", help="execute notebooks and write an HTML course with an index")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--out", required=True)
    p.add_argument("--timeout", type=int, default=600, help="seconds per cell (default 600)")
    p.set_defaults(func=_cmd_html)
    p = sub.add_parser("student", help="write student copies with the solutions removed")
    p.add_argument("notebooks", nargs="+")
    p.add_argument("--out", required=True)
    p.set_defaults(func=_cmd_student)
    p = sub.add_parser("models", help="build the course's models that are not cached yet (all, or NAMES)")
    p.add_argument("names", nargs="*", metavar="NAME")
    p.add_argument("--list", action="store_true", help="list the course models and whether each is cached")
    p.add_argument("--rebuild", action="store_true", help="train even when cached")
    p.add_argument("--no-progress", action="store_true", help="no progress bars")
    p.set_defaults(func=_cmd_models)
    p = sub.add_parser("architecture", help="regenerate the module tables of docs/ARCHITECTURE.md from the code")
    p.add_argument("--page", default="docs/ARCHITECTURE.md", help="the page to rewrite (default docs/ARCHITECTURE.md)")
    p.add_argument("--check", action="store_true", help="only say whether the page is current (exit 1 if stale)")
    p.set_defaults(func=_cmd_architecture)
    p = sub.add_parser("portable", help="run a test command under each float setting, all of them, and list the "
                                        "failures by setting (make test-portable)")
    p.add_argument("settings", nargs="+", metavar="SETTING", help='environment assignments, e.g. "OPENBLAS_CORETYPE=Haswell"')
    p.add_argument("--command", required=True, help="the command to run under each setting (one string)")
    p.add_argument("--logs", default="build/portable", help="folder for one log per setting (default build/portable)")
    p.set_defaults(func=_cmd_portable)
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
