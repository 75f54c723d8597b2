"""Inference: how a fitted model finds the latent code of a mesh, one strategy per module, in one
registry.

A strategy (:class:`~meshvae_lib.model.inference.base.InferenceStrategy`) maps meshes to latent codes
using only the model's public API (``features_of``, ``encode_rows``, ``decode_latent``,
``features_from_rows``, ``network``, ``feature_kind``, ``used_latent_dims``). Three are registered:
"gauss-newton" (the default: the encoder's mean refined by Gauss-Newton steps on the vertex error
with the analytic Jacobian), "encoder" (the paper's feed-forward encoder) and "finite-difference"
(the same fit with forward-difference Jacobians, the slow reference). :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel` is given one by name
(``MeshVAEModel(..., inference="encoder")``, or per call: ``model.reconstruct(V, inference=...)``)
and uses it in ``encode_meshes`` and ``reconstruct``. The registry below maps each name to its
class (``"module:Class"``); it imports neither numpy nor torch, so the command line lists the
names in ``--help``.

To add a strategy: write a module with an :class:`InferenceStrategy` subclass (``name``,
``infer``; ``options`` for its constructor keywords) and add one line to :data:`METHODS`.
"""

from __future__ import annotations

from meshvae_lib.model.registry import registered_class

__all__ = ["METHODS", "INFERENCE_METHODS", "inference_class", "make_inference"]

#: inference name -> "module:Class".
METHODS = {
    "gauss-newton": "meshvae_lib.model.inference.gauss_newton:GaussNewton",
    "encoder": "meshvae_lib.model.inference.encoder:EncoderMean",
    "finite-difference": "meshvae_lib.model.inference.vertex_fit:VertexFit",
}
#: the registered names (the ``choices`` of ``meshvae evaluate --inference``).
INFERENCE_METHODS = tuple(METHODS)


def inference_class(name: str) -> type:
    """The class registered as ``name``; ValueError naming the methods for an unknown one."""
    return registered_class(METHODS, name, "inference")


def make_inference(spec, **options):
    """The strategy ``spec`` names (a registered name, built with ``options``), or ``spec`` itself
    when it already is a strategy (then ``options`` must be empty)."""
    if isinstance(spec, str):
        cls = inference_class(spec)
        unknown = sorted(set(options) - set(cls.options))
        if unknown:
            raise ValueError(f"inference {spec!r} takes the options {cls.options or '()'}, got {unknown}")
        return cls(**options)
    from meshvae_lib.model.inference.base import InferenceStrategy

    if not isinstance(spec, InferenceStrategy) or options:
        raise ValueError(f"inference must be one of {tuple(METHODS)} or a strategy, got {spec!r}")
    return spec
