"""Every hyperparameter default of the library and the allowed values of its string options, in
one place, as plain constants (importable without numpy or torch, so that the command line lists
them in ``--help`` without loading the model). Numerical tolerances live in ``tolerances``.

Modules import the names they need from here; values quoted from the paper or from the reference
implementation say so, values measured here say where.
"""

# --- option choices ----------------------------------------------------------------------------
# (the feature kinds, network architectures and inference methods are registries of their own:
# ``model.feature_kinds.KINDS``, ``model.networks.ARCHITECTURES``, ``model.inference.METHODS``)
#: the feature kind a model uses unless told otherwise (the mesh VAE proper: RIMD, Sec. 3).
DEFAULT_FEATURE_KIND = "rimd"
#: the network architecture a model trains unless told otherwise (``model.networks``).
DEFAULT_ARCHITECTURE = "mesh-vae"
#: RIMD feature layouts: both directions of every edge (the paper's K), or one (``rimd.RIMDEncoder``).
LAYOUTS = ("paper", "compact")
#: the RIMD layout unless told otherwise: the paper's.
DEFAULT_LAYOUT = "paper"
#: how a sigma_object prior enters the latent cost (``loss.kl_divergence``).
PRIOR_FORMS = ("exact", "sibling")
#: the decoder's last activation: the mesh VAE's tanh or sigmoid (``vae.MeshVAE(output=...)``), or none
#: ("linear": the spiral network's, ``spiral_net.SpiralVAE``).
OUTPUTS = ("tanh", "sigmoid", "linear")
#: the reconstruction terms of ``loss.vae_loss`` (``loss=...``; "bce" needs the sigmoid output; "l1" is
#: SpiralNet++'s).
LOSSES = ("mse", "bce", "l1")
#: the feature kinds whose rows are vertex positions (x0, y0, z0, x1, ...): what a network on the
#: mesh's vertices (``spiral_net.SpiralVAE``) can read.
POSITION_KINDS = ("coords", "aligned")
#: network initialisations (``train_config.TrainConfig.init``) and the default.
INIT_MODES = ("pca", "random")
#: ``meshvae train --decoder``: auto (the corrected decoder below the training rank, else the linear
#: one), linear (the mesh VAE at its PCA start), corrected (``architecture="corrected"``).
DECODERS = ("auto", "linear", "corrected")
DEFAULT_INIT = "pca"
#: reconstruction methods and rotation recovery (``reconstruction.RIMDReconstructor``).
RECONSTRUCTION_METHODS = ("exact", "paper")
ROTATION_RECOVERY = ("global", "bfs")

# --- hyperparameter defaults -------------------------------------------------------------------
#: length of the extra "normal edge", as a fraction of the mean edge length (reference: 0.3).
NORMAL_EDGE_SCALE = 0.3
#: features are mapped to [-a, a] (Eq. 3; the paper's a).
NORMALIZE_A = 0.9
#: deviation output sigma = SIGMA_MAX * sigmoid(x).
SIGMA_MAX = 2.0
#: weight of the reconstruction term in Eq. 4.
DEFAULT_ALPHA = 1e6
#: default latent size (the paper's).
DEFAULT_LATENT = 128
#: the course's small latent size (06's plain and conditional models, 08's exploration model): the
#: smallest of the paper's Table 1.
COURSE_SMALL_LATENT = 16
#: a PCA-started network's default latent size grows beyond DEFAULT_LATENT to the N - 1 directions its N
#: training meshes span, up to this many (``TrainConfig.resolved_latent_dim``). Measured on the full
#: real collections (140-164 training meshes): with 128 dimensions even the training meshes came back
#: above PCA's held-out error (docs/vae.md, "Inference by Gauss-Newton").
PCA_LATENT_MAX = 256
#: the spiral network's defaults (``spiral_net.SpiralVAE``): SpiralNet++'s reconstruction settings
#: (Gong et al. 2019, their code's defaults): channel widths from the finest level down, spiral length,
#: the down-sampling factor of each level (CoMA's), latent size and epochs (Adam at DEFAULT_LR, batch 32).
SPIRAL_CHANNELS = (32, 32, 32, 64)
SPIRAL_LENGTH = 9
SPIRAL_DOWNSAMPLING = (4, 4, 4, 4)
SPIRAL_LATENT = 16
SPIRAL_EPOCHS = 300
#: the local-parts network's defaults (``local_parts.LocalPartsVAE``): regions of the reference mesh,
#: the rule that finds them (``geometry.regions.REGION_METHODS``) and the latent size (the paper's,
#: LOCAL_PARTS_LATENT / LOCAL_PARTS_REGIONS dimensions a region; docs/vae.md, "A decoder of local parts").
LOCAL_PARTS_REGIONS = 4
#: the rules that find regions (``geometry.regions.mesh_regions``) and the local-parts network's.
REGION_METHODS = ("kmeans", "spectral")
LOCAL_PARTS_METHOD = "spectral"
LOCAL_PARTS_LATENT = 128
#: Adam learning rate.
DEFAULT_LR = 1e-3
#: slope of the leaky ReLU on internal layers.
LEAKY_RELU_SLOPE = 0.1
#: prior deviations of the embedding model's first latent dimensions, the embedded ones (paper: 0.1 for
#: two); the rest are 1 (``train_config.pad_sigma_object``).
EMBEDDING_SIGMA_OBJECT = (0.1, 0.1)
#: reconstruction weight of the embedding and exploration models. The paper's 1e6 ("for most tasks") leaves the
#: latent cost negligible, so sigma_object changes nothing; 1e3 lets it act (measured on the
#: Dyna-like collection: docs/applications.md, "Embedding").
EMBEDDING_ALPHA = 1e3
#: internal layer of the embedding and exploration models: with none, the encoder mean is a linear map of the
#: features and the 2D map a linear projection, which cannot beat PCA by much.
EMBEDDING_HIDDEN = (256,)
#: weight of the reconstruction term for the course's conditional model (notebook 06): at the paper's 1e6 the
#: KL term is too weak to push the labels out of z, and a model asked for a motion generated it for 29% of the
#: samples (5 bodies x 7 motions, 300 vertices, 60 epochs); at 1e3 with a hidden layer and 1000 epochs, 84%
#: of the motions and 98% of the bodies at 1,464 vertices (nearest-neighbour label of 10 samples per value).
CONDITIONAL_ALPHA = 1e3
#: internal layer of the course's conditional model: without one the label only shifts a linear decoder's
#: output (64% of the motions obeyed at 300 vertices, against 79% with 256 units).
CONDITIONAL_HIDDEN = (256,)
#: training seeds of the embedding model; the table reports the median AUC over them.
EMBEDDING_SEEDS = (0, 1, 2, 3, 4)
#: neighbours of Neighborhood Preserving Embedding (paper: k = 25).
NPE_N_NEIGHBORS = 25
#: t-SNE perplexity (paper: 30).
TSNE_PERPLEXITY = 30.0
#: t-SNE inputs are reduced to this many principal components first.
TSNE_PCA_DIMS = 50
#: prior deviations of the exploration model's first four latent dimensions; the rest are 1.
EXPLORATION_SIGMA_OBJECT = (0.1, 0.1, 0.5, 0.5)
#: browsing range of each explored latent dimension (paper Fig. 8; also the latent explorer's sliders).
EXPLORATION_RANGE = (-2.0, 2.0)
#: weight of the extra normal "edge" in the fit of T_i, relative to the cotangent weights
#: c_ij = cot a + cot b (an equilateral one-ring has c_ij = 1.15).
NORMAL_EDGE_WEIGHT = 1.0
#: range the features are mapped to for the sigmoid + binary cross-entropy alternative.
BCE_TARGET_RANGE = (0.1, 0.9)
#: training epochs when none are given (enough for 50-200 meshes at batch 32).
DEFAULT_EPOCHS = 1000
#: meshes per Adam step.
DEFAULT_BATCH_SIZE = 32
#: internal layer sizes for the coordinate baselines of Table 2 with the paper's random start.
#: With the PCA initialisation (TrainConfig.init="pca") none is better for every kind on the real
#: collections (docs/vae.md, issue 12): on pcow (every 3rd frame) this default (256, random start)
#: gave 0.109 held-out for raw coordinates, the PCA-initialised network without internal layers 0.022.
HIDDEN_COORDS = (256,)
#: a of Eq. 3 (the half-width of the normalised range) used with the PCA initialisation. The paper's 0.9
#: puts training values where tanh is strongly curved; a decoder that is linear before the tanh
#: then interpolates held-out meshes badly (pcow, coordinates: 0.141 held-out at a = 0.9, 0.031 at
#: 0.5, 0.022 at 0.3, linear PCA 0.020). Networks trained without the PCA initialisation keep 0.9.
PCA_NORMALIZE_A = 0.3
#: early stopping: every this-many-th training mesh is set aside to choose the number of epochs.
VALIDATION_EVERY = 8
#: early stopping: stop choosing after this many epochs without a lower validation error.
EARLY_STOPPING_PATIENCE = 100
#: LatentExplorer coloured by displacement: the colour scale reaches at least this fraction of the
#: mesh's bounding-box diagonal (at the start every displacement is 0, and a zero-width scale
#: would show no colour bar worth reading).
EXPLORER_MIN_DISPLACEMENT = 0.01
#: a latent slider decodes while it is dragged as long as one update (decode + normals + buffers)
#: takes less than this many milliseconds; slower models switch to decoding on release.
LIVE_UPDATE_MAX_MS = 150.0
#: what a page without a widget front end (a static notebook page, a PDF) shows of a FramePlayer:
#: this many evenly spaced frames in a strip; of a LatentExplorer: its first this-many dimensions,
#: each at the low end, the start and the high end of its slider; panels this many inches, at this dpi.
STATIC_STRIP_FRAMES = 6
STATIC_GRID_DIMS = 4
STATIC_PANEL_INCHES = 2.2
STATIC_DPI = 90
#: a progress bar (meshvae_lib.progress) whose stream is not a terminal -- a CI log, a pipe --
#: redraws at most every this many seconds (in a terminal or a notebook: tqdm's 0.1 s).
PROGRESS_LOG_SECONDS = 10.0

# --- latent inference (model.inference, issue 23) ---------------------------------------------
#: how MeshVAEModel.encode_meshes finds a mesh's code unless told otherwise (a name of the registry
#: ``model.inference.METHODS``): the encoder's mean, then damped Gauss-Newton steps on the vertex
#: error with the analytic Jacobian.
DEFAULT_INFERENCE = "gauss-newton"
#: Jacobians per mesh of the Gauss-Newton inference (measured on samba, pdance and pcow: the error
#: falls by <2% after the fourth).
GAUSS_NEWTON_ITERATIONS = 4

# --- limits: work bounded before it starts, names cut in messages (issue 39) ----------------------
#: the most vertex positions one run of ``meshvae generate`` or ``meshvae interpolate`` decodes and
#: writes (meshes x vertices): 2e7 vertices are 0.5 GB of float64 positions and, for RIMD features
#: (about 24 numbers per vertex), 2 GB of float32 decoder output. A larger -n or --steps is refused
#: before any work, with the size and this limit.
MAX_OUTPUT_VERTICES = 20_000_000
#: the most parameters a network ``meshvae train`` builds may have (weights of the encoder and the
#: decoder; Adam keeps two more copies): 2e8 float32 are 0.8 GB, 2.4 GB with Adam's moments.
MAX_NETWORK_PARAMETERS = 200_000_000
#: the most training epochs ``meshvae train --epochs`` accepts (a typo like 1e9 would never end).
MAX_EPOCHS = 1_000_000
#: the most Gauss-Newton steps per mesh ``meshvae evaluate --fit-latent`` and local/global rounds
#: ``meshvae reconstruct --iterations`` accept (each step decodes D + 1 meshes or solves once more).
MAX_SOLVER_STEPS = 1_000
#: the largest ``meshvae generate --temperature``: draws at 10 prior deviations lie far outside
#: anything the decoder saw (1e30 would decode to overflowing positions).
MAX_TEMPERATURE = 10.0
#: the largest random seed the commands accept (PyTorch's generator takes a signed 64-bit seed).
MAX_SEED = 2**63 - 1
#: names (of meshes, files, label values) are cut to this many characters in error messages...
MESSAGE_NAME_CHARS = 60
#: ...and a mesh name to this many characters when it becomes part of a file name (file systems
#: allow 255 bytes).
FILE_NAME_CHARS = 100

# --- the corrected decoder (``model.corrected_decoder``, issue 47) -----------------------------
#: the correction network's internal layers, its AdamW weight decay, the weight of the Gaussian
#: penalty on the free codes, Adam's step, the most full-batch steps, how often (steps) the
#: validation rows are measured and how many checks without a new best end training, which training
#: rows are set aside (every k-th), the least relative gain on them for which the correction is kept,
#: the most principal directions it writes into, and the L-BFGS iterations of a code fit.
CORRECTION_HIDDEN = (128, 128)
CORRECTION_WEIGHT_DECAY = 1e-4
CORRECTION_CODE_PRIOR = 1e-3
CORRECTION_LR = 3e-3
CORRECTION_MAX_STEPS = 4000
CORRECTION_CHECK_EVERY = 50
CORRECTION_PATIENCE = 8
CORRECTION_VALIDATION_EVERY = 5
CORRECTION_MIN_GAIN = 0.02
#: ... with this one-sided confidence (Student's t bound of the mean gain per choosing validation mesh;
#: they are few: at 50 training meshes, 5).
CORRECTION_CONFIDENCE = 0.975
CORRECTION_RANK = 128
CORRECTION_FIT_ITERATIONS = 60
#: the fewest validation rows that choose between the corrected and the linear decoder (fewer: linear).
CORRECTION_MIN_CHOICE_ROWS = 3
