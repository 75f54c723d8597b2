"""The course layer: notebook tooling (:mod:`.notebooks`), the course's trained models
(:mod:`.models`), stable printing of round-off (:mod:`.display`) and the ``python -m meshvae_lib.course`` commands (:mod:`.commands`).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.course import course_model, model_summary``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module -> the public names it defines (here as name -> module).
EXPORTS = exports_of({
    "meshvae_lib.course.display": ("describe_model", "first_argmax", "local_parts_figure", "local_parts_table", "model_summary", "real_feature_table", "real_inference_table", "roundoff", "span_ceiling_table", "spiral_figure", "spiral_table"),
    "meshvae_lib.course.models": ("course_model", "get_spec"),
    "meshvae_lib.course.prior_costs": ("one_dimension_cost", "prior_cost_figure"),
})

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
