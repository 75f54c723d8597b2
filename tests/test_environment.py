"""pyproject.toml (the ranges the code supports), constraints.txt (the lock `make venv` installs)
and environment.yml (conda) must agree, and the running environment must be the locked one."""

from __future__ import annotations

import re
import tomllib
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.version import Version

ROOT = Path(__file__).resolve().parents[1]


def _key(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _pyproject_requirements() -> dict[str, Requirement]:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    reqs = list(data["project"]["dependencies"])
    for extra in data["project"].get("optional-dependencies", {}).values():
        reqs += extra
    return {_key(r.name): r for r in map(Requirement, reqs)}


def _lock() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "constraints.txt").read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if not line:
            continue
        match = re.fullmatch(r"([A-Za-z0-9_.\-]+)==([A-Za-z0-9_.]+)", line)
        assert match, f"constraints.txt: not an exact pin: {line!r}"
        name, version = match.groups()
        assert _key(name) not in pins, f"constraints.txt pins {name} twice"
        pins[_key(name)] = version
    return pins


def _environment_pip_requirements() -> tuple[dict[str, Requirement], list[str]]:
    lines = (ROOT / "environment.yml").read_text().splitlines()
    pip_reqs, conda_deps, in_pip = [], [], False
    for line in lines:
        stripped = line.split("#", 1)[0].rstrip()
        if not stripped.strip():
            continue
        indent = len(stripped) - len(stripped.lstrip())
        item = stripped.strip()
        if item == "- pip:":
            in_pip = True
            continue
        if in_pip and indent >= 6 and item.startswith("- "):
            pip_reqs.append(item[2:])
        elif item.startswith("- "):
            in_pip = False
            conda_deps.append(item[2:])
    return {_key(r.name): r for r in map(Requirement, pip_reqs)}, conda_deps


def test_lock_pins_every_requirement_inside_its_range():
    lock = _lock()
    for key, req in _pyproject_requirements().items():
        assert key in lock, f"{req.name} is a dependency but constraints.txt does not pin it"
        assert Version(lock[key]) in req.specifier, f"constraints.txt pins {req.name}=={lock[key]}, outside {req}"


def test_lock_has_no_local_build_labels():
    # 'torch==2.13.0+cpu' would only install from the index that holds that build
    assert not [v for v in _lock().values() if "+" in v]


def test_environment_yml_installs_what_pyproject_installs_at_the_locked_versions():
    env, _ = _environment_pip_requirements()
    assert set(env) == set(_pyproject_requirements())
    lock = _lock()
    for key, req in env.items():
        pins = [s for s in req.specifier if s.operator == "=="]
        assert len(pins) == 1 and len(req.specifier) == 1, f"environment.yml: {req} is not an exact pin"
        assert pins[0].version == lock[key], f"environment.yml has {req}, constraints.txt {lock[key]}"


def test_environment_pins_python_311_and_torch_2_13():
    env, conda = _environment_pip_requirements()
    assert "python=3.11" in conda
    assert str(env["torch"].specifier) == "==2.13.0"
    assert str(_pyproject_requirements()["torch"].specifier) == "==2.13.0"
    assert _lock()["torch"] == "2.13.0"


def test_running_environment_is_the_locked_one():
    """`make venv` installed the lock: every locked package is present at its pinned version."""
    wrong = {}
    for key, version in _lock().items():
        try:
            installed = metadata.version(key)
        except metadata.PackageNotFoundError:
            wrong[key] = (version, None)
            continue
        if Version(installed).public != Version(version).public:  # 2.13.0+cpu is 2.13.0
            wrong[key] = (version, installed)
    if wrong:
        pytest.fail(f"installed packages differ from constraints.txt (locked, installed): {wrong};"
                    " run `make venv` (or `make lock` to refresh the lock)")
