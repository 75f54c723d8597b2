"""The one lookup behind the model layer's registries (feature kinds, network architectures,
inference methods): each maps a name to ``"module:Class"``, imported only when the name is used, so
that the registries themselves import neither numpy nor torch."""

from __future__ import annotations

import importlib

__all__ = ["registered_class"]


def registered_class(registry: dict, name: str, what: str) -> type:
    """The class ``registry[name]`` names (``"module:Class"``), imported on demand.

    registry : dict name -> "module:Class"; name : the key; what : the option's name for the error,
    e.g. "feature kind". ValueError naming the registered keys for an unknown ``name``.
    """
    if name not in registry:
        raise ValueError(f"{what} must be one of {tuple(registry)}, got {name!r}")
    module, _, attr = registry[name].partition(":")
    return getattr(importlib.import_module(module), attr)
