"""Every tolerance, epsilon and numerical constant of the library, in one place (hyperparameter
defaults live in ``defaults``).

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

# --- mesh validation -------------------------------------------------------------------------
#: a face whose area is below this fraction of (mean edge length)^2 counts as zero-area.
DEGENERATE_AREA_RTOL = 1e-12

# --- feature normalisation (paper Sec. 4.1, Eq. 3) -------------------------------------------
#: a constant component c is treated as spanning [c - eps, c + eps].
NORMALIZE_EPS = 1e-6

# --- applications: embedding (paper Sec. 5.4) ------------------------------------------------
#: regulariser of the local reconstruction weights, times the trace of the local Gram matrix.
NPE_REG = 1e-3
#: ridge on X^T X in NPE's generalised eigenproblem, times its mean eigenvalue.
NPE_REG_EIG = 1e-6
#: principal components with singular value below this fraction of the largest are dropped (NPE).
NPE_PCA_RTOL = 1e-8

# --- geometry: self-intersections (geometry.intersections) -----------------------------------
#: triangles closer than this fraction of the mean edge length do not count as intersecting
#: (touching is not crossing).
SELF_INTERSECTION_RTOL = 1e-9
#: cross products shorter than this (relative) are treated as parallel axes in the SAT test.
SAT_PARALLEL_RTOL = 1e-12
#: broad phase: the grid cell doubles until the triangles' boxes touch at most this many cells
#: each on average (3 x 3 x 3), so the candidate list stays linear in the number of triangles...
SELF_INTERSECTION_CELLS_PER_TRIANGLE = 27
#: ...but it stops growing at this multiple of the starting cell (a mesh of one huge triangle).
SELF_INTERSECTION_MAX_CELL_GROWTH = 1e6

# --- geometry: divisions by a length that may be exactly zero --------------------------------
#: floor of a norm, length or scale that is divided by, so that an exact zero (a zero-area
#: vertex neighbourhood, a zero rotation vector, a constant coordinate) gives a finite result;
#: far below any length a float64 mesh can hold, it changes no other value.
DIVISION_FLOOR = 1e-300

# --- geometry core: deformation gradients, rotations, reconstruction (issue 2) ----------------
#: polar decomposition: Newton iterations at most, of which the first few are scaled (Higham 1986).
POLAR_MAX_ITERATIONS = 40
POLAR_SCALED_ITERATIONS = 8
#: ...and scaling stops earlier once every scale factor g is within this of 1 (it no longer
#: speeds convergence up; the unscaled steps then have the quadratic convergence test below).
POLAR_SCALING_OFF = 1e-3
#: stop Newton when no entry changed by more than this in an unscaled step: convergence is
#: quadratic, so the result is then orthogonal to ~1e-16.
POLAR_CONVERGENCE = 1e-9
#: |det T| below this times |T|_F^3 counts as singular (SVD fallback).
POLAR_SINGULAR_RTOL = 1e-12
#: a Newton result farther than this from orthogonal is redone by SVD.
POLAR_ORTHOGONALITY_TOL = 1e-10
#: deformation gradients: the one-ring matrix A_i (sum_j c_ij e_ij e_ij^T + normal term) counts as
#: singular when |det A_i| is below this times |A_i|_F^3 (a flat one-ring without normal term, a
#: degenerate reference mesh); the operator then refuses the reference mesh.
ONE_RING_SINGULAR_RTOL = 1e-14
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

# --- geometry: exact reconstruction (geometry.position_solvers) --------------------------------
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
#: exact reconstruction, refine="auto": Gauss-Newton steps are switched on for a reference mesh when
#: the linear solve misses a twist of that mesh by more than this fraction of its diagonal (max over
#: vertices). Measured: 1e-11 to 1e-9 on the horse, cat and cow meshes (off), 1e-6 to 1e-4 on
#: perfectly regular procedural meshes (on).
EXACT_SELFTEST_TOL = 1e-8

# --- mesh VAE training defaults (measured: docs/vae.md) --------------------------------------
#: the "finite-difference" inference (model/inference/vertex_fit.py): forward-difference step in latent
#: units (the PCA-started latent dimensions have unit spread over the training meshes).
FIT_LATENT_STEP = 1e-2
#: PCA initialisation: principal directions with singular value below this fraction of the
#: largest are not used.
PCA_INIT_RTOL = 1e-8
#: coordinate PCA baseline (evaluation.CoordinatePCA): singular values below this fraction of the
#: largest count as zero when the span of the training meshes is measured.
PCA_RANK_RTOL = 1e-12
#: a collection whose held-out meshes PCA on (aligned) coordinates reproduces below this fraction of
#: their bounding-box diagonal is linear data: a learned model's error on it is a training residual,
#: not a property of its representation (issue 24; meshvae_lib.paper.linear_floor).
LINEAR_DATA_RTOL = 1e-4

# --- mesh VAE: floors of the encoder's deviation ----------------------------------------------
#: floor added to the encoder's deviation in the experiments' networks, so that log(sigma^2) in
#: the KL term stays finite when alpha = 1e6 drives sigma towards 0 (float32 underflow otherwise).
SIGMA_FLOOR = 1e-6
#: floor of the deviation head's input: sigma = SIGMA_MAX * sigmoid(max(s, SIGMA_LOGIT_MIN)) keeps
#: sigma >= 1.9e-13, so log(sigma^2) stays finite when alpha = 1e6 drives sigma towards 0.
SIGMA_LOGIT_MIN = -30.0

# --- small guards outside the geometry core -------------------------------------------------
#: render.view_basis: a view direction this close to parallel to the up axis (|cross| below this)
#: takes another axis to define "right".
VIEW_PARALLEL_TOL = 1e-9
#: LatentExplorer.from_encodings: a latent dimension's slider range is at least this wide (a
#: dimension the encoder never varies would otherwise get a zero-width slider).
MIN_LATENT_SPREAD = 1e-6
#: GenerationResult.novelty_ratio: training-set nearest distances below this fraction of the
#: largest are exact duplicates (shared rest frames) and are left out of the typical spacing.
DUPLICATE_DISTANCE_RTOL = 1e-9
#: retrieval.precision_recall_curve: slack when the rank reaching recall rho is rounded up, so that
#: rho * n_relevant landing exactly on an integer is not pushed to the next rank by round-off.
RECALL_RANK_SLACK = 1e-9

# --- mesh identity (geometry.collection.mesh_fingerprints, issue 50) ----------------------------
#: a mesh's fingerprint: its positions projected on this many fixed unit directions, and its length.
MESH_FINGERPRINT_DIRECTIONS = 16
#: the seed those directions are drawn from (numpy's PCG64 gives the same numbers on every machine).
MESH_FINGERPRINT_SEED = 20180618
#: two fingerprints name the same mesh when every entry agrees within this fraction of the length.
#: Builds of one synthetic collection under four BLAS kernels differ by at most 9e-16 relative.
MESH_IDENTITY_RTOL = 1e-9

# --- course: lessons whose printed outputs must not depend on the last bits (issue 21) ---------
#: course.display.first_argmax: values within this fraction of the largest count as tied, and the
#: earliest is taken. Far above round-off (1e-16 to 1e-13 after a few thousand operations; two
#: frames of notebook 00 tie to 8e-16), far below any digit a lesson prints.
TIE_RTOL = 1e-9

# --- latent inference by Gauss-Newton (model.inference, issue 23) -------------------------------
#: geometry.reconstruction_linearization: directions pushed through the linearised reconstruction
#: together. Per-edge intermediates of 32 columns (10k vertices: 23 MB) stay below the allocator's
#: reuse threshold; all 139 at once were 25 % slower on samba (issue 38).
JVP_BLOCK = 32
#: geometry.spd_factor: right-hand sides per SuperLU solve, the fallback without cholespy (it slows beyond ~16).
SPARSE_SOLVE_CHUNK = 12
#: Levenberg-Marquardt damping of the Gauss-Newton inference, as a fraction of each diagonal entry of
#: J^T J (Marquardt's scaling): where it starts, how it grows on a rejected step and shrinks on an
#: accepted one, its floor and the number of tries per iteration before the fit stops. Measured on
#: samba, pdance and pcow: undamped steps overshoot on the first iteration (the encoder's code is far
#: off on real meshes). Damping by a multiple of the *mean* diagonal instead froze the latent
#: directions that move the vertices little: on full pdance 4 steps left 2.5-6x the error of
#: Marquardt's 4 steps (docs/vae.md, "Inference by Gauss-Newton").
GN_DAMPING_START = 1e-3
GN_DAMPING_UP = 10.0
GN_DAMPING_DOWN = 0.3
GN_DAMPING_FLOOR = 1e-5
GN_MAX_TRIES = 6
#: Marquardt's scaling never damps a direction by less than this fraction of the mean diagonal of
#: J^T J (a latent direction the decoded mesh does not follow would otherwise get no damping).
GN_DIAG_FLOOR_RTOL = 1e-9
#: the fit stops early when an accepted step lowers the squared vertex error by less than this
#: fraction.
GN_REL_DECREASE = 1e-4
#: a latent dimension whose decoded-feature Jacobian column is below this fraction of the largest
#: takes no part in the fit (a PCA-started decoder leaves the dimensions beyond the data's rank at 0).
GN_UNUSED_DIM_RTOL = 1e-9

#: FeatureKind.linearize for a kind without an analytic linearisation: forward-difference step,
#: relative to 1 + the feature row's norm (about the square root of float64's epsilon).
FD_LINEARIZE_STEP = 1e-7

# --- input range (issue 39) ---------------------------------------------------------------------
#: the largest coordinate magnitude a mesh may have. The geometry multiplies up to six coordinates
#: (squared lengths, areas, the determinant of a one-ring's 3x3 matrix): at 1e40 that is 1e240, far
#: from float64's 1.8e308; a mesh beyond it is refused (its squares overflow) instead of turning into
#: infinities and NaN deep in a solver. Scale such a mesh down first.
MAX_ABS_COORDINATE = 1e40
#: rows of a tanh output are clipped into [-TANH_ROW_CLIP, TANH_ROW_CLIP] before ``atanh`` where only a
#: start is needed (``corrected_decoder``: the projection that starts a code's fit through the tanh).
TANH_ROW_CLIP = 0.999
#: L-BFGS stopping rules of the corrected decoder's code fits (torch's defaults are 1e-7 and 1e-9):
#: all rows are fitted at once, so the fit stops only where every row's code has converged, and a
#: row's code does not depend on the rows fitted beside it (to 1e-6; torch's defaults: 5e-5).
CODE_FIT_GRAD_TOL = 1e-10
CODE_FIT_CHANGE_TOL = 1e-14
#: principal directions computed through the Gram matrix (``corrected_decoder.principal_directions``)
#: whose singular value is below this fraction of the largest are numerical noise (the Gram matrix
#: squares the condition number: rounding leaves singular values near sqrt(eps) = 1.5e-8 of the largest).
GRAM_RANK_RTOL = 1e-6
