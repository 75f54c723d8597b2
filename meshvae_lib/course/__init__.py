"""The course layer: notebook tooling (:mod:`.notebooks`), the course's trained models
(:mod:`.models`), stable printing of round-off (:mod:`.display`) and the ``python -m meshvae_lib.course`` commands (:mod:`.commands`).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.course import course_model, model_summary``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module (under this package) and the public names it defines, one line each.
EXPORTS = exports_of(__name__, """
display      describe_model first_argmax local_parts_figure local_parts_stretch_table local_parts_table model_summary
display      roundoff
display      real_feature_table real_inference_table span_ceiling_table spiral_figure spiral_table
models       course_model get_spec
answer_rerun record_cells rerun_answer
forbidden    LIBRARY_PCA forbidden_calls
gradient_fits gradient_fit_stats
prior_costs  one_dimension_cost prior_cost_figure
table_row    FLOOR_COLUMN column_reconstructions
tour         linear_floor_detail unseen_surfaces shuffled_gallery
""")

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
