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
