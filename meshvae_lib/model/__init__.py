"""The model layer: what trains and runs the mesh VAE (see docs/ARCHITECTURE.md).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.model import MeshVAEModel, TrainConfig, evaluate_model``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module (under this package) and the public names it defines, one line each.
EXPORTS = exports_of(__name__, """
corrected_decoder       CorrectedLinearDecoder
corrected_network       CorrectedVAE
gram_pca                principal_directions
evaluation              evaluate_model pca_baseline per_vertex_error regional_pca_baseline CoordinatePCA
feature_kinds           make_kind
inference               make_inference
inference.gauss_newton  FitState GaussNewton GaussNewtonReport LatentDecoder
inference.gauss_newton  gauss_newton_codes marquardt_fit without_rigid_motions
inplace_grad            start_step
loss                    kl_divergence vae_loss
meshvae_model           MeshVAEModel load_model
network_base            Network
networks                ARCHITECTURES ReferenceMesh network_class
normalization           FeatureNormalizer
posterior               decoder_column_norms decoder_sigma
threads                 configure_threads
train_config            TrainConfig
training                holdout_mask train_vae
vae                     MeshVAE
""")

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
