"""Lazy public names of a package: each imported from its module the first time it is used, so
that importing a package does no work (the learning modules import torch only when a name from
them is used). One helper for ``meshvae_lib`` and each of its first-level subpackages."""

from __future__ import annotations

import importlib
import sys

__all__ = ["lazy_exports", "exports_of"]


def lazy_exports(package: str, names: dict[str, str]):
    """The ``(__getattr__, __dir__)`` of the package ``package`` whose public ``names`` (name -> the
    module that defines it, e.g. ``"meshvae_lib.geometry.rimd"``) are imported on first use.

    A resolved name is stored on the package, so ``__getattr__`` runs once per name. A name that is
    also the name of its own module (``viewing.network_diagram``) must be imported by the package
    itself: the import system sets the submodule on the package when the module is first loaded,
    which would hide a lazy name.
    """

    def __getattr__(name: str):
        try:
            module = names[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted(set(vars(sys.modules[package])) | set(names))

    return __getattr__, __dir__


def exports_of(package: str, table: str) -> dict[str, str]:
    """``{name: module}`` from a table of lines ``module name name ...`` (modules relative to
    ``package``, e.g. ``evaluation`` or ``inference.gauss_newton``), the form :func:`lazy_exports` reads."""
    return {name: f"{package}.{module}" for module, *names in (line.split() for line in table.strip().splitlines())
            for name in names}
