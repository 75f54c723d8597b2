"""Latent codes fitted to the vertex positions by forward differences (the reference that the
default Gauss-Newton inference, :mod:`~meshvae_lib.model.inference.gauss_newton`, makes fast;
``meshvae evaluate --fit-latent N``; docs/vae.md, issue 12).

The paper's encoder picks z from the *features*; on real collections the features of a held-out
mesh are mostly reproduced in directions that matter little for the vertices. :class:`VertexFit`
minimises instead the decoded mesh's squared vertex error, ``sum_k |decode(z)_k - (R v_k + t)|^2``
over z and the best rigid motion (R, t), by Gauss-Newton from the encoder's means: each iteration
takes the Jacobian of the decoded vertices with respect to the latent dimensions the decoder uses
by forward differences (one decode + reconstruction per dimension), and takes the library's one
Levenberg-Marquardt step (:func:`~meshvae_lib.model.inference.least_squares.marquardt_fit`: the
default inference's loop with a difference Jacobian instead of the analytic one). The decoder,
normaliser and reconstruction are not changed: this is the same model, encoded by fitting.
Cost: ``iterations x (dimensions used + 1)`` decodes per mesh.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import GAUSS_NEWTON_ITERATIONS
from meshvae_lib.model.inference.base import InferenceStrategy
from meshvae_lib.model.inference.least_squares import FitState, marquardt_fit, without_rigid_motions
from meshvae_lib.tolerances import FIT_LATENT_STEP
from meshvae_lib.validation import check_count

__all__ = ["VertexFit"]


class _Decoded:
    """A decoded mesh as :class:`FitState` reads it (``positions (n, 3)``), with its code."""

    def __init__(self, positions: np.ndarray, code: np.ndarray):
        self.positions, self.code = positions, code


class VertexFit(InferenceStrategy):
    """Codes fitted to the vertices by Gauss-Newton on forward-difference Jacobians.

    Parameters
    ----------
    iterations : Gauss-Newton steps (>= 1).
    step : finite-difference step in latent units.
    """

    name = "finite-difference"
    options = ("iterations", "step")

    def __init__(self, iterations: int = GAUSS_NEWTON_ITERATIONS, step: float = FIT_LATENT_STEP):
        self.iterations = check_count(iterations, "iterations", minimum=1)
        self.step = float(step)

    def describe(self) -> str:
        return f"fitted to the vertices by finite differences, {self.iterations} steps"

    def infer(self, model, vertices: np.ndarray, conditions: np.ndarray | None, progress: bool = False) -> np.ndarray:
        from meshvae_lib.progress import progress as progress_bar

        mu, _ = model.encode_rows(model.features_of(vertices), conditions)
        Z = np.array(mu, dtype=np.float64)
        used = model.used_latent_dims
        for j in progress_bar(range(len(vertices)), desc="fitting codes", unit="mesh", disable=not progress):
            c = None if conditions is None else conditions[j]
            Z[j][used] = self._fit_one(model, vertices[j], Z[j], c, used)
        return Z

    def _fit_one(self, model, V: np.ndarray, z: np.ndarray, c, used: np.ndarray) -> np.ndarray:
        """The used dimensions of the code fitted from ``z (D,)`` to the mesh ``V (n, 3)`` with
        condition ``c (C,)`` or None: ``(n_used,) float64``."""
        eye = np.eye(len(z))[used] * self.step

        def decode(codes: np.ndarray) -> np.ndarray:
            cond = None if c is None else np.broadcast_to(c, (len(codes), len(c)))
            return model.decode_latent(codes, conditions=cond)

        def state_at(u: np.ndarray) -> FitState:
            code = z.copy()
            code[used] = u
            return FitState(_Decoded(decode(code[None])[0], code), V)

        def jacobian_at(state: FitState) -> np.ndarray:
            P = decode(state.lin.code[None] + eye)
            J = ((P - state.lin.positions) / self.step).reshape(len(used), -1).T     # (3n, n_used)
            return without_rigid_motions(J, state.lin.positions)

        return marquardt_fit(z[used], state_at, jacobian_at, self.iterations).u
