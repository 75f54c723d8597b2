"""Every tolerance, epsilon and numerical constant of the library, in one place.

Modules import the names they need from here; nothing else in the library hard-codes a threshold.
Values quoted from the paper or from the reference implementation say so.
"""

# --- cotangent weights (reference implementation) -------------------------------------------
#: smallest edge weight kept; smaller (and negative) weights are clamped to this.
COT_WEIGHT_MIN = 1e-10
#: weights above this (and NaN) are replaced by COT_WEIGHT_FALLBACK.
COT_WEIGHT_MAX = 100.0
#: replacement for NaN or huge cotangent weights.
COT_WEIGHT_FALLBACK = 1.0

# --- deformation gradients -------------------------------------------------------------------
#: length of the extra "normal edge", as a fraction of the mean edge length (reference: 0.3).
NORMAL_EDGE_SCALE = 0.3

# --- mesh validation -------------------------------------------------------------------------
#: a face whose area is below this fraction of (mean edge length)^2 counts as zero-area.
DEGENERATE_AREA_RTOL = 1e-12

# --- feature normalisation (paper Sec. 4.1, Eq. 3) -------------------------------------------
#: features are mapped to [-a, a].
NORMALIZE_A = 0.9
#: a constant component c is treated as spanning [c - eps, c + eps].
NORMALIZE_EPS = 1e-6

# --- mesh VAE (paper Sec. 4.2) ---------------------------------------------------------------
#: deviation output sigma = SIGMA_MAX * sigmoid(x).
SIGMA_MAX = 2.0
#: weight of the reconstruction term in Eq. 4.
DEFAULT_ALPHA = 1e6
#: default latent size.
DEFAULT_LATENT = 128
#: Adam learning rate.
DEFAULT_LR = 1e-3
#: slope of the leaky ReLU on internal layers.
LEAKY_RELU_SLOPE = 0.1

# --- applications: embedding (paper Sec. 5.4) ------------------------------------------------
#: prior deviation of the embedded latent dimensions of the sigma_object model (paper: 0.1).
EMBEDDING_SIGMA_SMALL = 0.1
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
#: regulariser of the local reconstruction weights, times the trace of the local Gram matrix.
NPE_REG = 1e-3
#: ridge on X^T X in NPE's generalised eigenproblem, times its mean eigenvalue.
NPE_REG_EIG = 1e-6
#: principal components with singular value below this fraction of the largest are dropped (NPE).
NPE_PCA_RTOL = 1e-8
#: t-SNE perplexity (paper: 30).
TSNE_PERPLEXITY = 30.0
#: t-SNE inputs are reduced to this many principal components first.
TSNE_PCA_DIMS = 50

# --- applications: exploration (paper Sec. 5.5, Fig. 8) -------------------------------------
#: prior deviations of the exploration model: first two, next two, the rest.
EXPLORATION_SIGMA_OBJECT = (0.1, 0.1, 0.5, 0.5)
#: browsing range of each explored latent dimension.
EXPLORATION_RANGE = (-2.0, 2.0)

# --- applications: interpolation / implausibility ---------------------------------------------
#: triangles closer than this fraction of the mean edge length do not count as intersecting
#: (touching is not crossing).
SELF_INTERSECTION_RTOL = 1e-9
#: cross products shorter than this (relative) are treated as parallel axes in the SAT test.
SAT_PARALLEL_RTOL = 1e-12

# --- geometry core: deformation gradients, rotations, reconstruction (issue 2) ----------------
#: weight of the extra normal "edge" in the fit of T_i, relative to the cotangent weights
#: c_ij = cot a + cot b (an equilateral one-ring has c_ij = 1.15).
NORMAL_EDGE_WEIGHT = 1.0
#: polar decomposition: Newton iterations at most, of which the first few are scaled (Higham 1986).
POLAR_MAX_ITERATIONS = 40
POLAR_SCALED_ITERATIONS = 8
#: stop Newton when no entry changed by more than this in an unscaled step: convergence is
#: quadratic, so the result is then orthogonal to ~1e-16.
POLAR_CONVERGENCE = 1e-9
#: |det T| below this times |T|_F^3 counts as singular (SVD fallback).
POLAR_SINGULAR_RTOL = 1e-12
#: a Newton result farther than this from orthogonal is redone by SVD.
POLAR_ORTHOGONALITY_TOL = 1e-10
#: below this angle (rad) SO(3) exp/log use their Taylor series.
SO3_SMALL_ANGLE = 1e-4
#: log: when cos(theta) is below this, the axis comes from the symmetric part of R (near pi).
SO3_NEAR_PI_COS = -0.7
#: rotation recovery: no global (Lie-algebra least-squares) sweep when every edge residual
#: |axial(R_i dR_ij R_j^T)| is below this (exact features).
ROTATION_SYNC_TOL = 1e-13
#: rotation recovery: at most this many global sweeps.
ROTATION_SYNC_MAX_SWEEPS = 3
#: rotation recovery: stop the sweeps once the largest correction (rad) is below this (the next
#: Gauss-Newton correction would be of its square: 1e-6 rad).
ROTATION_SYNC_STEP_TOL = 1e-3

# --- applications: the MSE-vs-cross-entropy experiment (paper Sec. 5.1) ----------------------
#: range the features are mapped to for the sigmoid + binary cross-entropy alternative.
BCE_TARGET_RANGE = (0.1, 0.9)
#: exact reconstruction: weight of the paper's Eq. 1 energy added to the exact least-squares
#: system, relative to the mean diagonals. It only decides the rare position modes the exact system
#: cannot see (on perfectly symmetric one-rings); its bias on exact features is far below 1e-8.
EXACT_REGULARIZATION = 1e-10
#: exact reconstruction: Gauss-Newton steps stop when no vertex moves more than this fraction of
#: the reference's bounding-box diagonal, or after EXACT_REFINE_MAX_STEPS steps.
EXACT_REFINE_TOL = 1e-9
EXACT_REFINE_MAX_STEPS = 3
#: exact reconstruction: no Gauss-Newton step when every entry of T_i(p') - T_i is below this
#: fraction of the largest |T| entry (exact features on generic meshes need none).
EXACT_RESIDUAL_TOL = 1e-10

# --- mesh VAE training defaults (measured: docs/vae.md) --------------------------------------
#: training epochs when none are given (enough for 50-200 meshes at batch 32).
DEFAULT_EPOCHS = 1000
#: meshes per Adam step.
DEFAULT_BATCH_SIZE = 32
#: internal layer sizes for the coordinate baselines of Table 2 with the paper's random start.
#: With the PCA initialisation (TrainConfig.init="pca") none is better for every kind on the real
#: collections (docs/vae.md, issue 12): on pcow (every 3rd frame) this default (256, random start)
#: gave 0.109 held-out for raw coordinates, the PCA-initialised network without internal layers 0.022.
HIDDEN_COORDS = (256,)
#: half-width a of the normalised range (Eq. 3) used with the PCA initialisation. The paper's 0.9
#: puts training values where tanh is strongly curved; a decoder that is linear before the tanh
#: then interpolates held-out meshes badly (pcow, coordinates: 0.141 held-out at a = 0.9, 0.031 at
#: 0.5, 0.022 at 0.3, linear PCA 0.020). Networks trained without the PCA initialisation keep 0.9.
PCA_FEATURE_RANGE = 0.3
#: early stopping: every this-many-th training mesh is set aside to choose the number of epochs.
VALIDATION_EVERY = 8
#: early stopping: stop choosing after this many epochs without a lower validation error.
EARLY_STOPPING_PATIENCE = 100
#: MeshVAEModel.fit_latent: forward-difference step in latent units (the PCA-started latent
#: dimensions have unit spread over the training meshes).
FIT_LATENT_STEP = 1e-2
#: PCA initialisation: principal directions with singular value below this fraction of the
#: largest are not used.
PCA_INIT_RTOL = 1e-8
#: coordinate PCA baseline (evaluation.CoordinatePCA): singular values below this fraction of the
#: largest count as zero when the span of the training meshes is measured.
PCA_RANK_RTOL = 1e-12

# --- viewing (meshvae_lib.viewing) -----------------------------------------------------------
#: a latent slider decodes while it is dragged as long as one update (decode + normals + buffers)
#: takes less than this many milliseconds; slower models switch to decoding on release.
LIVE_UPDATE_MAX_MS = 150.0
#: exact reconstruction, refine="auto": Gauss-Newton steps are switched on for a reference mesh when
#: the linear solve misses a twist of that mesh by more than this fraction of its diagonal (max over
#: vertices). Measured: 1e-11 to 1e-9 on the horse, cat and cow meshes (off), 1e-6 to 1e-4 on
#: perfectly regular procedural meshes (on).
EXACT_SELFTEST_TOL = 1e-8
#: floor added to the encoder's deviation in the experiments' networks, so that log(sigma^2) in
#: the KL term stays finite when alpha = 1e6 drives sigma towards 0 (float32 underflow otherwise).
SIGMA_FLOOR = 1e-6
#: floor of the deviation head's input: sigma = SIGMA_MAX * sigmoid(max(s, SIGMA_LOGIT_MIN)) keeps
#: sigma >= 1.9e-13, so log(sigma^2) stays finite when alpha = 1e6 drives sigma towards 0.
SIGMA_LOGIT_MIN = -30.0
