"""The library's choices (the allowed values of its string options) and the defaults that go with
them, as plain constants: importable without numpy or torch, so that the command line can list
them in ``--help`` without loading the model. The modules that implement each option import its
choices from here; numerical tolerances and hyperparameter values live in ``tolerances``.
"""

#: feature kinds (the columns of the paper's Table 2; baseline first): ``features.FeatureExtractor``.
FEATURE_KINDS = ("coords", "aligned", "rimd")
#: RIMD feature layouts: both directions of every edge (the paper's K), or one (``rimd.RIMDEncoder``).
LAYOUTS = ("paper", "compact")
#: how a sigma_object prior enters the latent cost (``vae.kl_divergence``).
PRIOR_FORMS = ("exact", "sibling")
#: network initialisations (``training.TrainConfig.init``) and the default.
INIT_MODES = ("pca", "random")
DEFAULT_INIT = "pca"
#: reconstruction methods and rotation recovery (``reconstruction.RIMDReconstructor``).
RECONSTRUCTION_METHODS = ("exact", "paper")
ROTATION_RECOVERY = ("global", "bfs")
