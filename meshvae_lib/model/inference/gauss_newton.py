"""Semi-amortised inference (the default): the encoder's mean, then a few damped Gauss-Newton
(Levenberg-Marquardt) steps on the decoded mesh's squared vertex error,
``min_z min_(R,t) sum_k |decode(z)_k - (R x_k + t)|^2``, with the **analytic** Jacobian of decoder
and reconstruction: :func:`decoder_jacobian` (the network, then the affine maps of the output range
and Eq. 3) times the feature kind's linearisation (``FeatureKind.linearize``; for RIMD
:mod:`~meshvae_lib.geometry.reconstruction_linearization`). One step costs one Jacobian (two
factorised sparse solves per latent dimension) and usually one decode. On real collections the
encoder alone spends its code on feature directions that barely move the vertices (docs/vae.md,
"Why the encoder falls short"); this fixes that without changing the model.

The rigid motion is eliminated by projecting the six rigid vertex fields (three translations,
three rotations about the centroid) out of the Jacobian and aligning the target to each decoded
mesh; the model's decoder, normaliser and reconstruction are not changed. The analytic Jacobian
reads the output layer of :class:`~meshvae_lib.model.vae.MeshVAE` (``decoder_head``, and
``decoder_body`` with internal layers).
"""

from __future__ import annotations

import numpy as np
import torch

from meshvae_lib import tolerances as tol
from meshvae_lib.defaults import GAUSS_NEWTON_ITERATIONS
from meshvae_lib.model.inference.base import InferenceStrategy
from meshvae_lib.model.inference.least_squares import (  # noqa: F401 (re-exported)
    FitState, MarquardtFit, marquardt_fit, rigid_fields, without_rigid_motions)
from meshvae_lib.validation import check_count
from meshvae_lib.workers import map_forked, resolve_jobs

__all__ = ["GaussNewton", "decoder_jacobian", "rigid_fields", "without_rigid_motions", "GaussNewtonReport",
           "gauss_newton_codes", "marquardt_fit", "MarquardtFit", "FitState"]


def _activate(network, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The output activation and its slope, in float64."""
    if network.output == "sigmoid":
        r = 0.5 * (1.0 + np.tanh(0.5 * y))          # the logistic function, without overflow far out
        return r, r * (1.0 - r)
    r = np.tanh(y)
    return r, 1.0 - r * r


def decoder_jacobian(network, z: np.ndarray, c: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The network's decoded rows and their Jacobian with respect to the code.

    Parameters
    ----------
    network : MeshVAE (in eval mode: batch normalisation is then affine)
    z : (D,) float
        One latent code.
    c : (C,) float or None
        Its condition vector (conditional networks).

    Returns
    -------
    rows : (K,) float64
        ``network.decode(z, c)`` (in the network's output range).
    J : (K, D) float64
        ``d rows / d z = act'(y) W dh/dz`` with ``y = W h + b`` the output layer and ``h`` its
        input: ``[z, c]`` without hidden layers (closed form, float64), else the hidden layers'
        output, whose small Jacobian comes from torch's autograd.
    """
    D = network.latent_dim
    z = np.asarray(z, dtype=np.float64).reshape(D)
    W = network.decoder_head.weight.detach().double().numpy()
    b = network.decoder_head.bias.detach().double().numpy()
    if not network.hidden:
        y = W[:, :D] @ z + b
        if network.n_conditions:
            y = y + W[:, D:] @ np.asarray(c, dtype=np.float64).reshape(network.n_conditions)
        rows, slope = _activate(network, y)
        return rows, slope[:, None] * W[:, :D]
    ct = None if c is None else torch.from_numpy(np.asarray(c, dtype=np.float32).reshape(1, -1))

    def body(v):
        return network.decoder_body(network._with_condition(v[None], ct, D, "latent vectors"))[0]

    zt = torch.from_numpy(z.astype(np.float32))
    with torch.no_grad():
        h = body(zt).double().numpy()
    Jh = torch.autograd.functional.jacobian(body, zt).double().numpy()     # (width, D)
    rows, slope = _activate(network, W @ h + b)
    return rows, slope[:, None] * (W @ Jh)


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


class _Decoder:
    """Codes -> features and their Jacobian for one model, with the network's weights converted once."""

    def __init__(self, model, conditions: np.ndarray | None):
        net = model.network
        self.kind, self.network, self.conditions = model.feature_kind, net, conditions
        K, D = net.n_features, net.latent_dim
        # rows -> features is affine per column (the output range, then Eq. 3 inverted)
        self.offset = np.asarray(model.features_from_rows(np.zeros((1, K))), dtype=np.float64)[0]
        self.scale = np.asarray(model.features_from_rows(np.ones((1, K))), dtype=np.float64)[0] - self.offset
        if net.hidden:
            self.used = np.arange(D)
            return
        # the output layer's weights (K x D, K ~ 1e5-1e6) are selected in torch's float32 and only the
        # used columns converted: converting all of them first took 0.3 s per call at 10k vertices
        W = net.decoder_head.weight.detach()
        # a PCA-started decoder leaves the dimensions beyond the data's rank at exactly 0
        size = W[:, :D].abs().amax(dim=0).double().numpy()
        self.used = np.flatnonzero(size > tol.GN_UNUSED_DIM_RTOL * size.max())
        self.W = W.index_select(1, torch.from_numpy(self.used)).double().numpy()
        self.b = net.decoder_head.bias.detach().double().numpy()
        self.Wc = W[:, D:].double().numpy()

    def rows(self, z: np.ndarray, c) -> tuple[np.ndarray, np.ndarray | None]:
        """Network rows (K,) float64 and, without hidden layers, the output's slope (K,)."""
        if self.network.hidden:
            rows, self._J = decoder_jacobian(self.network, z, c)
            return rows, None
        y = self.W @ z[self.used] + self.b
        if self.network.n_conditions:
            y = y + self.Wc @ np.asarray(c, dtype=np.float64)
        return _activate(self.network, y)

    def state(self, z: np.ndarray, c, x: np.ndarray) -> "_DecodedState":
        rows, slope = self.rows(z, c)
        return _DecodedState(self, self.offset + self.scale * rows, slope, x)

    def feature_jacobian(self, state: "_DecodedState") -> np.ndarray:
        """d features / d z[used]: (K, n_used) float64."""
        if self.network.hidden:
            return self.scale[:, None] * state.network_jacobian[:, self.used]
        return (self.scale * state.slope)[:, None] * self.W

    def vertex_jacobian(self, state: "_DecodedState") -> np.ndarray:
        """d positions / d z[used] at a decoded state, rigid motions projected out: (3 n, n_used) float64."""
        J = state.lin.jvp(self.feature_jacobian(state)).reshape(-1, len(self.used))
        return without_rigid_motions(J, state.lin.positions)


class _DecodedState(FitState):
    """A decoded code: :class:`FitState` plus what the network's Jacobian needs (the output's slope,
    or with internal layers the network Jacobian computed with the rows)."""

    def __init__(self, decoder: _Decoder, features: np.ndarray, slope, x: np.ndarray):
        self.slope = slope
        self.network_jacobian = getattr(decoder, "_J", None)
        super().__init__(decoder.kind.linearize(features), x)


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
    decoder = _Decoder(model, conditions)
    used = decoder.used                    # none: the decoder ignores the code, nothing to fit
    if len(V):
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

    def describe(self) -> str:
        chord = f" (+{self.chord_steps} chord each)" if self.chord_steps else ""
        return f"encoder + Gauss-Newton, {self.iterations} steps{chord}"

    def infer(self, model, vertices: np.ndarray, conditions: np.ndarray | None, progress: bool = False) -> np.ndarray:
        if not hasattr(model.network, "decoder_head"):
            raise ValueError(f"the gauss-newton inference needs the analytic Jacobian of a mesh-vae network; this one is"
                             f" {model.network.architecture!r}: use inference='finite-difference' or 'encoder'")
        mu, _ = model.encode_rows(model.features_of(vertices), conditions)
        c = None if conditions is None else np.asarray(conditions, dtype=np.float64)
        Z, self.report_ = gauss_newton_codes(model, vertices, mu, c, iterations=self.iterations, progress=progress,
                                           n_jobs=self.n_jobs, chord_steps=self.chord_steps)
        return Z
