"""``import meshvae_lib as mv``: the facade's names are the library's own objects, loaded lazily."""

import subprocess
import sys

import pytest

import meshvae_lib as mv


def test_every_facade_name_is_the_object_of_its_module():
    import importlib

    for name, module in mv.FACADE.items():
        assert getattr(mv, name) is getattr(importlib.import_module(module), name), name
    assert set(mv.FACADE) <= set(dir(mv)) and set(mv.FACADE) <= set(mv.__all__)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'MeshVae'"):
        mv.MeshVae  # noqa: B018


def test_importing_the_package_loads_neither_torch_nor_the_modules():
    code = ("import sys, meshvae_lib as mv\n"
            "heavy = [m for m in ('torch', 'pythreejs', 'meshvae_lib.model.meshvae_model') if m in sys.modules]\n"
            "mv.read_collection\n"
            "print(heavy, 'torch' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "[] False", out


SUBPACKAGES = ("geometry", "model", "applications", "viewing", "course", "paper")


@pytest.mark.parametrize("package", SUBPACKAGES)
def test_every_subpackage_name_is_the_object_of_its_module(package):
    import importlib

    pkg = importlib.import_module(f"meshvae_lib.{package}")
    for name, module in getattr(pkg, "EXPORTS", {}).items():
        assert getattr(pkg, name) is getattr(importlib.import_module(module), name), (package, name)
    assert set(pkg.__all__) <= set(dir(pkg))
    for name in pkg.__all__:
        getattr(pkg, name)                                          # every listed name resolves
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        pkg.no_such_name  # noqa: B018


def test_importing_the_subpackages_loads_no_torch():
    code = ("import sys\nimport meshvae_lib.geometry, meshvae_lib.model, meshvae_lib.applications, meshvae_lib.viewing,"
            " meshvae_lib.course, meshvae_lib.paper\n"
            "from meshvae_lib.model import TrainConfig\n"        # the config is torch-free too
            "print([m for m in ('torch', 'pythreejs', 'matplotlib') if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "[]", out


def test_the_notebooks_import_only_from_the_package_level():
    """Every ``meshvae_lib`` import of a notebook's code is from ``meshvae_lib`` or a first-level
    subpackage or module, and every name it imports is there (issue 48)."""
    import ast
    import importlib
    import importlib.util
    import json
    from pathlib import Path

    below, missing, n = [], [], 0
    for path in sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb")):
        for cell in json.loads(path.read_text())["cells"]:
            if cell["cell_type"] != "code":
                continue
            source = "".join(line for line in "".join(cell["source"]).splitlines(True)
                             if not line.lstrip().startswith(("%", "!")))
            for node in ast.walk(ast.parse(source)):
                if isinstance(node, ast.ImportFrom) and (node.module or "").split(".")[0] == "meshvae_lib":
                    n += 1
                    if node.module.count(".") > 1:
                        below.append(f"{path.name}: from {node.module}")
                        continue
                    module = importlib.import_module(node.module)
                    missing += [f"{path.name}: {node.module}.{a.name}" for a in node.names
                                if a.name not in dir(module)
                                and importlib.util.find_spec(f"{node.module}.{a.name}") is None]
                elif isinstance(node, ast.Import):
                    below += [f"{path.name}: import {a.name}" for a in node.names
                              if a.name.split(".")[0] == "meshvae_lib" and a.name.count(".") > 1]
    assert n > 100 and below == [] and missing == [], (n, below, missing)
