"""The model layer: what trains and runs the mesh VAE (see docs/ARCHITECTURE.md).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.model import MeshVAEModel, TrainConfig, evaluate_model``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module -> the public names it defines (here as name -> module).
EXPORTS = exports_of({
    "meshvae_lib.model.evaluation": ("evaluate_model", "pca_baseline", "per_vertex_error", "regional_pca_baseline"),
    "meshvae_lib.model.feature_kinds": ("make_kind",),
    "meshvae_lib.model.inference": ("make_inference",),
    "meshvae_lib.model.inference.gauss_newton": ("FitState", "GaussNewton", "GaussNewtonReport", "LatentDecoder",
                                                 "gauss_newton_codes", "marquardt_fit", "without_rigid_motions"),
    "meshvae_lib.model.inplace_grad": ("start_step",),
    "meshvae_lib.model.loss": ("kl_divergence", "vae_loss"),
    "meshvae_lib.model.meshvae_model": ("MeshVAEModel", "load_model"),
    "meshvae_lib.model.network_base": ("Network",),
    "meshvae_lib.model.networks": ("ARCHITECTURES", "ReferenceMesh", "network_class"),
    "meshvae_lib.model.normalization": ("FeatureNormalizer",),
    "meshvae_lib.model.posterior": ("decoder_column_norms", "decoder_sigma"),
    "meshvae_lib.model.threads": ("configure_threads",),
    "meshvae_lib.model.train_config": ("TrainConfig",),
    "meshvae_lib.model.training": ("holdout_mask", "train_vae"),
    "meshvae_lib.model.vae": ("MeshVAE",),
})

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
