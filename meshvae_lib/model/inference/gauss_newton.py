"""Semi-amortised inference (the default): the encoder's mean, then a few damped Gauss-Newton
(Levenberg-Marquardt) steps on the decoded mesh's squared vertex error,
``min_z min_(R,t) sum_k |decode(z)_k - (R x_k + t)|^2``, with the **analytic** Jacobian of decoder
and reconstruction: the network's public linearisation (``Network.linearization``; then the affine
maps of the output range and Eq. 3) times the feature kind's linearisation (``FeatureKind.linearize``; for RIMD
:mod:`~meshvae_lib.geometry.reconstruction_linearization`). One step costs one Jacobian (two
factorised sparse solves per latent dimension) and usually one decode. On real collections the
encoder alone spends its code on feature directions that barely move the vertices (docs/vae.md,
"Why the encoder falls short"); this fixes that without changing the model.

The rigid motion is eliminated by projecting the six rigid vertex fields (three translations,
three rotations about the centroid) out of the Jacobian and aligning the target to each decoded
mesh; the model's decoder, normaliser and reconstruction are not changed. The network's Jacobian
comes through the network contract (:mod:`~meshvae_lib.model.network_base`): the mesh VAE's closed
form (its own override), or autograd for any other registered network, so every network gets this
inference.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import GAUSS_NEWTON_ITERATIONS
from meshvae_lib.model.inference.base import InferenceStrategy
from meshvae_lib.model.inference.least_squares import (  # noqa: F401 (re-exported)
    FitState, MarquardtFit, marquardt_fit, rigid_fields, without_rigid_motions)
from meshvae_lib.validation import check_count
from meshvae_lib.workers import map_forked, resolve_jobs

__all__ = ["GaussNewton", "rigid_fields", "without_rigid_motions", "GaussNewtonReport",
           "gauss_newton_codes", "marquardt_fit", "MarquardtFit", "FitState", "LatentDecoder"]


class GaussNewtonReport:
    """What :func:`gauss_newton_codes` did, per mesh.

    Attributes
    ----------
    initial_error, final_error : (N,) float64
        Mean vertex distance (after the best rigid motion) at the starting code and at the result.
    iterations : (N,) int64
        Jacobians computed (accepted or not).
    decodes : (N,) int64
        Decodes (reconstructions) made, the starting one included.
    """

    def __init__(self, n: int):
        self.initial_error = np.zeros(n)
        self.final_error = np.zeros(n)
        self.iterations = np.zeros(n, np.int64)
        self.decodes = np.zeros(n, np.int64)

    def __repr__(self) -> str:
        return (f"GaussNewtonReport(n={len(self.iterations)}, mean error {self.initial_error.mean():.4g}"
                f" -> {self.final_error.mean():.4g}, iterations {self.iterations.mean():.1f}/mesh)")


class LatentDecoder:
    """Codes -> features and their Jacobian for one model, through the network's public
    linearisation (``network.linearization(used)``: built once, e.g. the mesh VAE's used weight
    columns converted to float64 once; evaluated at every state).

    Attributes
    ----------
    used : (n_used,) int64, the latent dimensions the decoder reads (``model.used_latent_dims``).
    offset, scale : (K,) float64, features = offset + scale * network rows.
    linearization : the network's :class:`~meshvae_lib.model.linearization.DecoderLinearization`.
    """

    def __init__(self, model, conditions: np.ndarray | None):
        net = model.network
        self.kind, self.network, self.conditions = model.feature_kind, net, conditions
        K = net.n_features
        # rows -> features is affine per column (the output range, then Eq. 3 inverted)
        self.offset = np.asarray(model.features_from_rows(np.zeros((1, K))), dtype=np.float64)[0]
        self.scale = np.asarray(model.features_from_rows(np.ones((1, K))), dtype=np.float64)[0] - self.offset
        self.used = np.asarray(model.used_latent_dims, dtype=np.int64)
        self.linearization = net.linearization(self.used)

    def state(self, z: np.ndarray, c, x: np.ndarray) -> "_DecodedState":
        """The decoded mesh of code ``z (D,)`` against the target ``x (n, 3)``, with what its Jacobian needs."""
        point = self.linearization.at(z, c)
        return _DecodedState(self.kind.linearize(self.offset + self.scale * point.rows), x, point)

    def feature_jacobian(self, state: "_DecodedState") -> np.ndarray:
        """d features / d z[used] at a decoded state: (K, n_used) float64."""
        return state.point.jacobian(self.scale)

    def vertex_jacobian(self, state: "_DecodedState") -> np.ndarray:
        """d positions / d z[used] at a decoded state, rigid motions projected out: (3 n, n_used) float64."""
        J = state.lin.jvp(self.feature_jacobian(state)).reshape(-1, len(self.used))
        return without_rigid_motions(J, state.lin.positions)


class _DecodedState(FitState):
    """A decoded code: :class:`FitState` plus the network's linearisation at the code (its
    :class:`~meshvae_lib.model.linearization.DecoderPoint`)."""

    def __init__(self, lin, x: np.ndarray, point):
        self.point = point
        super().__init__(lin, x)


def gauss_newton_codes(model, vertices: np.ndarray, z0: np.ndarray, conditions: np.ndarray | None = None,
                       iterations: int = GAUSS_NEWTON_ITERATIONS, progress: bool = False,
                       n_jobs: int | None = None, chord_steps: int = 0
                       ) -> tuple[np.ndarray, GaussNewtonReport]:
    """Codes fitted to vertex positions by damped Gauss-Newton with the analytic Jacobian
    (:func:`marquardt_fit` over the latent dimensions the decoder uses).

    Parameters
    ----------
    model : fitted MeshVAEModel
    vertices : (N, n_vertices, 3) float64
        The meshes to encode (any rigid pose).
    z0 : (N, D) float64
        Starting codes (the encoder's means).
    conditions : (N, C) float or None
        Condition vectors of a conditional model (held fixed).
    iterations : int >= 1
        Jacobians per mesh at most; each is followed by up to ``GN_MAX_TRIES`` damped steps until
        one lowers the squared vertex error (the fit stops when none does, or when the decrease is
        below ``GN_REL_DECREASE``).
    progress : show a progress bar.
    chord_steps : int >= 0
        Chord steps after each accepted step (:func:`marquardt_fit`; 0, the default, keeps the
        results of the plain method).
    n_jobs : int >= 1 or None
        Processes fitting meshes at once (None: every available core;
        :func:`meshvae_lib.workers.map_forked`). The result does not depend on it.

    Returns
    -------
    Z : (N, D) float64
        Never worse than ``z0`` in the vertex error (a step is only taken when it lowers it).
    report : GaussNewtonReport
    """
    from meshvae_lib.progress import progress as progress_bar

    V = np.asarray(vertices, dtype=np.float64)
    Z = np.array(z0, dtype=np.float64)
    report = GaussNewtonReport(len(V))
    decoder = LatentDecoder(model, conditions)
    used = decoder.used                    # none: the decoder ignores the code, nothing to fit
    if resolve_jobs(n_jobs, len(V)) > 1:
        # build whatever the decoding builds on first use (the reconstructor's factorisations) here,
        # once, rather than in every worker
        decoder.state(Z[0], None if conditions is None else conditions[0], V[0])

    def fit_one(j: int) -> tuple:
        c = None if conditions is None else conditions[j]
        start = Z[j].copy()

        def state_at(u: np.ndarray) -> _DecodedState:
            z = start.copy()
            z[used] = u
            return decoder.state(z, c, V[j])

        fit = marquardt_fit(start[used], state_at, decoder.vertex_jacobian, iterations, chord_steps)
        return fit.u, fit.start.mean_error, fit.state.mean_error, fit.jacobians, fit.decodes

    bar = progress_bar(total=len(V), desc="fitting codes", unit="mesh", disable=not progress)
    try:
        fits = map_forked(fit_one, len(V), n_jobs, on_result=bar.update)
    finally:
        bar.close()
    for j, (u, first, last, jacobians, decodes) in enumerate(fits):
        Z[j][used] = u
        report.initial_error[j], report.final_error[j] = first, last
        report.iterations[j], report.decodes[j] = jacobians, decodes
    return Z, report


class GaussNewton(InferenceStrategy):
    """The encoder's mean refined by damped Gauss-Newton steps on the vertex error
    (:func:`gauss_newton_codes`; the module docstring). Never worse than the encoder's mean.

    Parameters
    ----------
    iterations : Jacobians per mesh at most (>= 1).
    n_jobs : processes fitting meshes at once (>= 1; None: every available core). The codes do not
        depend on it.
    chord_steps : chord steps after each accepted step (>= 0; :func:`marquardt_fit`). Measured for
        issue 38 (docs/results/inference_speed.md): ``iterations=3, chord_steps=1`` is 12-38 % faster
        than the default and as accurate or more; the default keeps the recorded results.

    Attributes
    ----------
    report_ : :class:`GaussNewtonReport` of the latest :meth:`infer` (errors before and after,
        steps and decodes per mesh), None before.
    """

    name = "gauss-newton"
    options = ("iterations", "n_jobs", "chord_steps")

    def __init__(self, iterations: int = GAUSS_NEWTON_ITERATIONS, n_jobs: int | None = None, chord_steps: int = 0):
        self.iterations = check_count(iterations, "iterations", minimum=1)
        self.chord_steps = check_count(chord_steps, "chord_steps", minimum=0)
        resolve_jobs(n_jobs, 1)            # checked here, resolved per call
        self.n_jobs = n_jobs
        self.report_ = None

    def report(self) -> "GaussNewtonReport | None":
        """:attr:`report_`: the latest :meth:`infer`'s errors, steps and decodes per mesh."""
        return self.report_

    def describe(self) -> str:
        chord = f" (+{self.chord_steps} chord each)" if self.chord_steps else ""
        return f"encoder + Gauss-Newton, {self.iterations} step{'s' if self.iterations != 1 else ''}{chord}"

    def infer(self, model, vertices: np.ndarray, conditions: np.ndarray | None, progress: bool = False) -> np.ndarray:
        mu, _ = model.encode_rows(model.features_of(vertices), conditions)
        c = None if conditions is None else np.asarray(conditions, dtype=np.float64)
        Z, self.report_ = gauss_newton_codes(model, vertices, mu, c, iterations=self.iterations, progress=progress,
                                           n_jobs=self.n_jobs, chord_steps=self.chord_steps)
        return Z
