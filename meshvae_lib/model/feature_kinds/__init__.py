"""Feature kinds: what the network sees of a mesh, one object per kind, in one registry.

A kind (:class:`~meshvae_lib.model.feature_kinds.base.FeatureKind`) is built from a reference
mesh and its faces; it encodes meshes to rows of ``n_features`` numbers and decodes rows back to
meshes. The registry below maps each kind's name to its class (``"module:Class"``), in the order of
the paper's Table 2 (baseline first). It imports neither numpy nor torch, so the command line
lists the kinds in ``--help`` without loading them.

To add a kind: write a module with a :class:`FeatureKind` subclass (``name``, ``n_features``,
``_encode``, ``_decode``; ``options`` for its constructor keywords) and add one line to
:data:`KINDS`. :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`, its checkpoint, the
command line's ``--features`` and the paper's Table 2 then take it by name.
"""

from __future__ import annotations

from meshvae_lib.model.registry import registered_class

__all__ = ["KINDS", "FEATURE_KINDS", "kind_class", "make_kind", "kind_from_state"]

#: feature kind name -> "module:Class", in the order of the paper's Table 2 (baseline first).
KINDS = {
    "coords": "meshvae_lib.model.feature_kinds.coords:CoordinatesKind",
    "aligned": "meshvae_lib.model.feature_kinds.aligned:AlignedKind",
    "rimd": "meshvae_lib.model.feature_kinds.rimd:RIMDKind",
}
#: the registered kinds' names (the ``choices`` of ``meshvae train --features``).
FEATURE_KINDS = tuple(KINDS)


def kind_class(name: str) -> type:
    """The class registered as ``name``; ValueError naming the kinds for an unknown one."""
    return registered_class(KINDS, name, "feature kind")


def make_kind(name: str, reference, faces, **options):
    """The feature kind ``name`` for one reference mesh.

    reference : (n_vertices, 3) float; faces : (n_faces, 3) int; options : keywords of the model
    that a kind may take (``layout`` for RIMD). Options the kind does not take are left out, as
    the coordinate kinds leave out the RIMD layout.
    """
    cls = kind_class(name)
    return cls(reference, faces, **{k: v for k, v in options.items() if k in cls.options})


def kind_from_state(state: dict):
    """The kind that :meth:`FeatureKind.state_dict` describes (its ``"kind"`` entry names the class)."""
    try:
        name = str(state["kind"])
    except (KeyError, TypeError) as exc:
        raise ValueError(f"not a feature kind state: {exc!r}") from exc
    return kind_class(name).from_state_dict(state)
