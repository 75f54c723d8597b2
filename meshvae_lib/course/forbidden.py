"""Self-checks that run a student's cell with library calls made to raise, whatever name reaches them.

A check that patches a function in the module that defines it misses every other module that
imported it under its own name (``from meshvae_lib.model.evaluation import CoordinatePCA`` in a
course helper): the student's cell can reach the forbidden code through that helper.
:func:`forbidden_calls` patches a function under every name any loaded module binds it to, and a
class's methods on the class itself, so every path to them raises.
"""

from __future__ import annotations

import importlib
import inspect
import sys
from contextlib import ExitStack, contextmanager
from unittest import mock

__all__ = ["LIBRARY_PCA", "forbidden_calls"]

#: every principal component analysis the course's environment ships: the library's linear floor
#: (and the course helpers built on it), its PCA starts, and scikit-learn's estimators that find
#: principal directions (``PCA``, ``IncrementalPCA``, ``TruncatedSVD`` -- PCA once the rows are
#: centred --, ``KernelPCA``, ``SparsePCA``, ``MiniBatchSparsePCA``) with its truncated SVD
#: ``randomized_svd``. numpy's and scipy's SVD and eigendecompositions stay allowed: they are the
#: tools of PCA by hand.
LIBRARY_PCA = (
    "meshvae_lib.model.evaluation.CoordinatePCA",
    "meshvae_lib.model.evaluation.pca_baseline",
    "meshvae_lib.model.evaluation.regional_pca_baseline",
    "meshvae_lib.model.gram_pca.principal_directions",
    "meshvae_lib.model.pca_start.pca_start",
    "meshvae_lib.model.pca_start.regional_pca_start",
    "sklearn.decomposition.PCA",
    "sklearn.decomposition.IncrementalPCA",
    "sklearn.decomposition.TruncatedSVD",
    "sklearn.decomposition.KernelPCA",
    "sklearn.decomposition.SparsePCA",
    "sklearn.decomposition.MiniBatchSparsePCA",
    "sklearn.utils.extmath.randomized_svd",
)


def _resolve(path: str):
    """The object a dotted path ``package.module.name`` names, or None where its module cannot be imported."""
    module, _, name = path.rpartition(".")
    try:
        return getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError):
        return None


@contextmanager
def forbidden_calls(targets, message: str, namespace: dict | None = None):
    """Make every call to ``targets`` raise ``AssertionError(message)`` inside the ``with`` block.

    targets : sequence of str, dotted paths of functions or classes (``"pkg.module.name"``; one
        whose module cannot be imported is skipped); message : the error's text (it must not
        print an expected value); namespace : a notebook's globals, optional.

    A function is replaced under every name that binds it in any loaded module; a class has its
    ``__init__`` and every method it defines replaced on the class, which reaches every alias and
    every instance. Yields a dict ``{name: blocker}`` for the names of ``namespace`` bound to a
    target, to pass to :func:`~meshvae_lib.course.answer_rerun.rerun_answer` as inputs, so that
    the notebook's own names raise as well. Everything is restored on leaving the block.
    """
    blocker = mock.Mock(side_effect=AssertionError(message))
    objects = [obj for obj in map(_resolve, targets) if obj is not None]
    function_ids = {id(obj) for obj in objects if not inspect.isclass(obj)}
    with ExitStack() as stack:
        for cls in (obj for obj in objects if inspect.isclass(obj)):
            for attr, value in list(vars(cls).items()):
                if attr == "__init__" or (not attr.startswith("_") and callable(value)):
                    stack.enter_context(mock.patch.object(cls, attr, blocker))
        for module in list(sys.modules.values()):
            binds = getattr(module, "__dict__", None)
            if not isinstance(binds, dict):
                continue
            for name, value in list(binds.items()):
                if id(value) in function_ids:
                    stack.enter_context(mock.patch.object(module, name, blocker))
        object_ids = {id(obj) for obj in objects}
        yield {name: blocker for name, value in (namespace or {}).items() if id(value) in object_ids}
