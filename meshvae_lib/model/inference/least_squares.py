"""Damped Gauss-Newton on a squared vertex error, up to rigid motions: the numerics every fitting
inference shares (the default's latent codes, the finite-difference reference, the span benchmarks).

:func:`marquardt_fit` is the one Levenberg-Marquardt loop (Marquardt's scaling, the damping schedule
of ``tolerances.GN_*``); :class:`FitState` is a decoded mesh against its target, aligned rigidly; the
rigid motions' vertex fields (:func:`rigid_fields`) are projected out of a Jacobian
(:func:`without_rigid_motions`) because the alignment already absorbs them.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import tolerances as tol
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.validation import check_count

__all__ = ["rigid_fields", "without_rigid_motions", "FitState", "MarquardtFit", "marquardt_fit"]


def rigid_fields(P: np.ndarray) -> np.ndarray:
    """Orthonormal basis of the rigid motions' vertex fields at a mesh.

    Parameters
    ----------
    P : (n_vertices, 3) float64

    Returns
    -------
    Q : (3 n_vertices, 6) float64
        Columns spanning the three translations and the three infinitesimal rotations about the
        centroid (flattened row-major like ``P.ravel()``), orthonormalised.
    """
    n = len(P)
    q = P - P.mean(axis=0)
    A = np.zeros((n, 3, 6))
    A[:, 0, 0] = A[:, 1, 1] = A[:, 2, 2] = 1.0
    A[:, 1, 3], A[:, 2, 3] = q[:, 2], -q[:, 1]
    A[:, 0, 4], A[:, 2, 4] = -q[:, 2], q[:, 0]
    A[:, 0, 5], A[:, 1, 5] = q[:, 1], -q[:, 0]
    Q, _ = np.linalg.qr(A.reshape(3 * n, 6))
    return Q


def without_rigid_motions(J: np.ndarray, P: np.ndarray) -> np.ndarray:
    """Columns of a vertex Jacobian ``J (3 n_vertices, p)`` with the rigid motions' fields at the mesh
    ``P (n_vertices, 3)`` (:func:`rigid_fields`) projected out: what the fit's rigid alignment of the
    target cannot tell from a move of the mesh. Returns (3 n_vertices, p) float64."""
    Q = rigid_fields(P)
    return J - Q @ (Q.T @ J)


class FitState:
    """A decoded mesh against the mesh it should match: what :func:`marquardt_fit` reads.

    Parameters
    ----------
    lin : the decoding's linearisation (``FeatureKind.linearize``): ``positions (n, 3)``, ``jvp``, ``vjp``.
    x : (n, 3) float64, the target mesh (any rigid pose).

    Attributes
    ----------
    residual : (n, 3) float64
        The target moved rigidly onto the decoded positions, minus them.
    sq_error, mean_error : float
        Its squared norm and mean vertex distance; ``inf`` when not finite (never accepted).
    """

    def __init__(self, lin, x: np.ndarray):
        self.lin = lin
        P = lin.positions
        self.residual = rigid_align(x, P) - P
        self.sq_error = float(np.einsum("ij,ij->", self.residual, self.residual))
        self.mean_error = float(np.linalg.norm(self.residual, axis=1).mean())
        if not np.isfinite(self.sq_error):
            self.sq_error = self.mean_error = np.inf


class MarquardtFit:
    """What :func:`marquardt_fit` found.

    Attributes
    ----------
    u : (p,) float64
        The parameters at the end (the start when no step lowered the error).
    state, start : the objects ``state_at`` returned for ``u`` and for the starting parameters.
    jacobians : int
        Jacobians computed (accepted or not).
    decodes : int
        Calls of ``state_at``, the starting one included.
    """

    def __init__(self, u: np.ndarray, state, start, jacobians: int, decodes: int):
        self.u, self.state, self.start, self.jacobians, self.decodes = u, state, start, jacobians, decodes


def marquardt_fit(u0: np.ndarray, state_at, jacobian_at, iterations: int, chord_steps: int = 0) -> MarquardtFit:
    """Damped Gauss-Newton (Levenberg-Marquardt with Marquardt's scaling) on a squared vertex error.

    Each step solves ``(J^T J + lambda diag(J^T J)) delta = J^T r`` (the diagonal floored at
    ``GN_DIAG_FLOOR_RTOL`` of its mean) and is taken only if it lowers the error; a rejected step is
    retried with ``GN_DAMPING_UP`` times the damping (``GN_MAX_TRIES`` tries), an accepted one lowers
    it by ``GN_DAMPING_DOWN`` (floor ``GN_DAMPING_FLOOR``). Stops after ``iterations`` Jacobians, when no
    try lowers the error, when the error falls by less than ``GN_REL_DECREASE``, or where the mesh
    does not move with the parameters (a zero or non-finite ``J^T J``). With ``chord_steps``, each
    accepted step is followed by up to that many chord steps, ``(J^T J + lambda D) delta = J^T r`` with
    the same Jacobian and the new residual, each kept only while it lowers the error: a decode each
    instead of a Jacobian (issue 38: at 10k vertices a Jacobian costs 10-20 decodes). Docs: docs/vae.md,
    "The method".

    Parameters
    ----------
    u0 : (p,) float
        Starting parameters (the used latent dimensions of a code, or coordinates in a feature span).
    state_at : callable ``u -> state``
        Decodes ``u``; the state has ``residual`` ((n, 3) float64: the target aligned rigidly onto the
        decoded mesh, minus the mesh) and ``sq_error`` (float, its squared norm; ``inf`` is never
        accepted), as a :class:`FitState` has.
    jacobian_at : callable ``state -> (3 n, p) float64``
        ``d positions / d u`` at a state, with the rigid motions' fields projected out
        (:func:`without_rigid_motions`).
    iterations : int >= 0
        Jacobians at most (none when ``u0`` is empty).
    chord_steps : int >= 0
        Chord steps after each accepted step (0: plain Levenberg-Marquardt, the default).

    Returns
    -------
    MarquardtFit
    """
    u = np.array(u0, dtype=np.float64).reshape(-1)
    iterations = check_count(iterations, "iterations", minimum=0) if len(u) else 0   # nothing to fit: no Jacobian
    chord_steps = check_count(chord_steps, "chord_steps", minimum=0)
    state = start = state_at(u)
    jacobians, decodes = 0, 1
    damping = tol.GN_DAMPING_START
    for _ in range(iterations):
        jacobians += 1
        J = jacobian_at(state)
        H = J.T @ J
        g = J.T @ state.residual.ravel()
        mean_diag = float(np.trace(H)) / len(u)
        if not (mean_diag > 0 and np.isfinite(H).all() and np.isfinite(g).all()):
            break     # the decoded mesh does not move with the parameters here (a saturated output)
        # Marquardt's scaling: each direction damped in proportion to its own curvature, so the
        # directions that barely move the vertices are not frozen by the large ones
        scale = np.maximum(np.diag(H), tol.GN_DIAG_FLOOR_RTOL * mean_diag)
        accepted = None
        for _ in range(tol.GN_MAX_TRIES):
            u_new = u + np.linalg.solve(H + damping * np.diag(scale), g)
            trial = state_at(u_new)
            decodes += 1
            if trial.sq_error < state.sq_error:
                accepted = (u_new, trial)
                damping = max(damping * tol.GN_DAMPING_DOWN, tol.GN_DAMPING_FLOOR)
                break
            damping *= tol.GN_DAMPING_UP
        if accepted is None:
            break
        decrease = 1.0 - accepted[1].sq_error / state.sq_error
        u, state = accepted
        if decrease < tol.GN_REL_DECREASE:
            break
        if chord_steps:
            lhs = H + damping * np.diag(scale)
            for _ in range(chord_steps):
                u_new = u + np.linalg.solve(lhs, J.T @ state.residual.ravel())
                trial = state_at(u_new)
                decodes += 1
                if not trial.sq_error < state.sq_error:
                    break
                u, state = u_new, trial
    return MarquardtFit(u, state, start, jacobians, decodes)
