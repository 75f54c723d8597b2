"""environment.yml (conda) and pyproject.toml (pip) must install the same packages."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _normalise(req: str) -> str:
    name, spec = re.match(r"\s*([A-Za-z0-9_.\-]+)\s*(.*)", req).groups()
    return name.lower().replace("_", "-") + spec.replace(" ", "")


def _pyproject_requirements() -> set[str]:
    data = tomllib.loads((ROOT / "pyproject.toml").read_text())
    reqs = list(data["project"]["dependencies"])
    for extra in data["project"].get("optional-dependencies", {}).values():
        reqs += extra
    return {_normalise(r) for r in reqs}


def _environment_pip_requirements() -> tuple[set[str], list[str]]:
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
    return {_normalise(r) for r in pip_reqs}, conda_deps


def test_environment_installs_what_pyproject_installs():
    pip_reqs, _ = _environment_pip_requirements()
    assert pip_reqs == _pyproject_requirements()


def test_environment_pins_python_311_and_torch_2_13():
    pip_reqs, conda = _environment_pip_requirements()
    assert "python=3.11" in conda
    assert "torch==2.13.0" in pip_reqs
    assert "torch==2.13.0" in _pyproject_requirements()
