"""Latent codes fitted to the vertex positions by forward differences (the reference that the
default Gauss-Newton inference, :mod:`~meshvae_lib.model.inference.gauss_newton`, makes fast;
``meshvae evaluate --fit-latent N``; docs/vae.md, issue 12).

The paper's encoder picks z from the *features*; on real collections the features of a held-out
mesh are mostly reproduced in directions that matter little for the vertices. :class:`VertexFit`
minimises instead the decoded mesh's squared vertex error, ``sum_k |decode(z)_k - (R v_k + t)|^2``
over z and the best rigid motion (R, t), by Gauss-Newton from the encoder's means: each iteration
takes the Jacobian of the decoded vertices with respect to the latent dimensions the decoder uses
by forward differences (one decode + reconstruction per dimension), solves the linear
least-squares step and halves it (up to 3 times) until the error falls. The decoder, normaliser
and reconstruction are not changed: this is the same model, encoded by fitting.
Cost: ``iterations x (dimensions used + 1)`` decodes per mesh.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import GAUSS_NEWTON_ITERATIONS
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.model.inference.base import InferenceStrategy
from meshvae_lib.tolerances import FIT_LATENT_STEP
from meshvae_lib.validation import check_count

__all__ = ["VertexFit"]



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
        eye = np.eye(model.latent_dim)[used] * self.step
        for j in progress_bar(range(len(vertices)), desc="fitting codes", unit="mesh", disable=not progress):
            c = None if conditions is None else conditions[j]
            Z[j] = self._fit_one(model, vertices[j], Z[j], c, used, eye)
        return Z

    def _fit_one(self, model, V: np.ndarray, z: np.ndarray, c, used: np.ndarray, eye: np.ndarray) -> np.ndarray:
        """Gauss-Newton from ``z (D,)`` for the mesh ``V (n, 3)`` with condition ``c (C,)`` or None."""
        err = None
        for _ in range(self.iterations):
            batch = np.vstack([z[None], z[None] + eye])
            P = model.decode_latent(batch, conditions=None if c is None else np.broadcast_to(c, (len(batch), len(c))))
            P0 = P[0]
            target = rigid_align(V, P0)
            r0 = (target - P0).ravel()
            err = float(r0 @ r0) if err is None else err
            J = ((P[1:] - P0).reshape(len(used), -1) / self.step).T  # (3n, d)
            if not (np.isfinite(J).all() and np.isfinite(r0).all()):
                break  # a non-finite decode: LAPACK's least squares may not return on it; keep z
            dz, *_ = np.linalg.lstsq(J, r0, rcond=None)
            t = 1.0
            for _ in range(4):
                z_new = z.copy()
                z_new[used] += t * dz
                Pn = model.decode_latent(z_new, conditions=c)
                rn = (rigid_align(V, Pn) - Pn).ravel()
                if float(rn @ rn) < err:
                    z, err = z_new, float(rn @ rn)
                    break
                t *= 0.5
            else:
                break  # no step lowered the error: done
        return z
