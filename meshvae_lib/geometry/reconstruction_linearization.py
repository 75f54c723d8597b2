"""First-order behaviour of the RIMD reconstruction: Jacobian-vector and adjoint products.

:meth:`RIMDReconstructor.linearize(f) <meshvae_lib.geometry.reconstruction.RIMDReconstructor.linearize>`
reconstructs the mesh of one feature vector ``f`` and returns a :class:`ReconstructionLinearization`:
the positions ``p(f)`` (before the final rigid alignment) and the products of the Jacobian
``dp/df`` with feature-space directions (:meth:`~ReconstructionLinearization.jvp`) and of its
transpose with vertex-space fields (:meth:`~ReconstructionLinearization.vjp`). They let a decoder's
latent code be fitted to vertex positions by Gauss-Newton without differencing the reconstruction
(:mod:`meshvae_lib.model.inference`). Notation of docs/vae.md, "Inference by Gauss-Newton".

The reconstruction has three steps (:mod:`meshvae_lib.geometry.reconstruction`), and so has its
derivative. For a perturbation ``df`` of the feature:

1. an edge rotation ``dR_e = exp(hat(w_e))`` of edge ``e = (i, j)`` turns by
   ``eta_e = J_r(w_e) dw_e`` in its own frame (``J_r``: the right Jacobian of the SO(3)
   exponential), where ``dw_e`` is the change of the edge's rotation vector (for the paper layout
   the mean of its two stored directions, as :meth:`RIMDLayout.unpack` takes it);
2. the recovered rotations turn by global-frame increments ``g_i`` (``R_i <- exp(hat(g_i)) R_i``):
   :meth:`RotationRecovery.linear_response` differentiates the steps the recovery actually took
   (the breadth-first walk, then each Gauss-Newton sweep of the synchronisation, whose matrix is the
   graph Laplacian factorised once), so the derivative is exact also where a decoder's features are
   not consistent and the sweeps stop before the least-squares optimum;
3. ``T_i = R_i S_i`` changes by ``dT_i = hat(g_i) T_i + R_i dS_i``, and the positions by the
   position solve of ``dT`` -- again a fixed, factorised matrix.

So a Jacobian-vector product costs one sparse solve per synchronisation sweep taken (0 to 3) plus
one position solve, all with already-factorised matrices; many directions go through together, in
blocks of ``JVP_BLOCK`` columns (multi-column solves, and intermediates small enough to stay cached), and the adjoint the same solves in
reverse order (the matrices are symmetric). Matches central differences of the reconstruction to
the differences' own accuracy (``tests/test_inference.py``). Not differentiated: the exact solver's
optional Gauss-Newton refinement (active only for meshes with perfectly symmetric one-rings,
``refine_active``), which changes positions by ~1e-5 of the diagonal, and the sweeps' stopping
decisions (piecewise constant).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.geometry.rimd import S_ENTRIES
from meshvae_lib.geometry.rotations import matmul_soa, right_jacobian
from meshvae_lib.tolerances import JVP_BLOCK

__all__ = ["ReconstructionLinearization"]

#: ``hat(e_k)`` for the unit vectors e_0, e_1, e_2.
_GENERATORS = np.zeros((3, 3, 3))
_GENERATORS[0, 2, 1], _GENERATORS[0, 1, 2] = 1.0, -1.0
_GENERATORS[1, 0, 2], _GENERATORS[1, 2, 0] = 1.0, -1.0
_GENERATORS[2, 1, 0], _GENERATORS[2, 0, 1] = 1.0, -1.0
#: the 6 stored entries of a symmetric S -> its 9 row-major entries.
_S6_TO_9 = np.zeros((9, 6))
for _k, (_a, _b) in enumerate(S_ENTRIES):
    _S6_TO_9[3 * _a + _b, _k] = 1.0
    _S6_TO_9[3 * _b + _a, _k] = 1.0


class ReconstructionLinearization:
    """The reconstruction of one feature vector and its first-order behaviour around it.

    Built by :meth:`RIMDReconstructor.linearize`; see the module docstring.

    Attributes
    ----------
    positions : (n_vertices, 3) float64
        ``p(f)``: the reconstructed mesh before the final rigid alignment onto the reference.
    n_features : int
        K of the layout.
    """

    def __init__(self, reconstructor, w: np.ndarray, S: np.ndarray, R: np.ndarray, positions: np.ndarray,
                 record: dict):
        layout = reconstructor.layout
        self._layout = layout
        self._rotations = reconstructor.rotation_recovery
        self._positions_solver = reconstructor.position_solver
        self.positions = positions
        self.positions.setflags(write=False)
        self.n_features = int(layout.K)
        self._record = record
        self._R, self._S, self._w = R, S, w
        self._maps = None

    def _vertex_maps(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The per-edge and per-vertex maps of the products, computed on first use (a decode that
        is never differentiated, such as a rejected trial step, does not pay for them): ``J_r(w_e)``
        ``(E, 3, 3)``: d(edge rotation vector) -> its body-frame turn ``eta_e``; ``g_i -> dT_i =
        hat(g_i) T_i`` ``(n, 9, 3)``; ``dS6_i -> R_i dS_i`` ``(n, 9, 6)``."""
        if self._maps is None:
            n = self._layout.n_vertices
            Rm = np.ascontiguousarray(self._R.T).reshape(n, 3, 3)
            Tm = np.ascontiguousarray(matmul_soa(self._R, self._S).T).reshape(n, 3, 3)
            self._maps = (right_jacobian(np.ascontiguousarray(self._w.T)),
                          np.einsum("kac,ncb->nabk", _GENERATORS, Tm).reshape(n, 9, 3),
                          np.einsum("nac,cbk->nabk", Rm, _S6_TO_9.reshape(3, 3, 6)).reshape(n, 9, 6))
        return self._maps

    # -- feature space <-> per-edge / per-vertex blocks ----------------------------------------
    def _split(self, dF: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lay = self._layout
        d = dF.shape[1]
        rot = dF[lay.rotation_slice].reshape(lay.n_rotation_edges, 3, d)
        if lay.layout == "paper":
            dw = 0.5 * (rot[lay.forward_blocks] - rot[lay.backward_blocks])
        else:
            dw = rot
        return dw, dF[lay.scaling_slice].reshape(lay.n_vertices, 6, d)

    def _join(self, dw_adj: np.ndarray, dS6_adj: np.ndarray) -> np.ndarray:
        lay = self._layout
        d = dw_adj.shape[2]
        out = np.zeros((lay.K, d))
        rot = out[lay.rotation_slice].reshape(lay.n_rotation_edges, 3, d)
        if lay.layout == "paper":
            rot[lay.forward_blocks] = 0.5 * dw_adj
            rot[lay.backward_blocks] = -0.5 * dw_adj
        else:
            rot[:] = dw_adj
        out[lay.scaling_slice] = dS6_adj.reshape(-1, d)
        return out

    # -- products -----------------------------------------------------------------------------
    def jvp(self, dF) -> np.ndarray:
        """Position changes for feature changes: ``dp/df @ dF``.

        Parameters
        ----------
        dF : (K,) or (K, d) float
            Feature-space directions, in the reconstructor's layout.

        Returns
        -------
        dP : (n_vertices, 3) or (n_vertices, 3, d) float64
        """
        dF = np.asarray(dF, dtype=np.float64)
        single = dF.ndim == 1
        dF = dF[:, None] if single else dF
        if dF.ndim != 2 or dF.shape[0] != self.n_features:
            raise ValueError(f"dF must have shape ({self.n_features},) or ({self.n_features}, d), got {dF.shape}")
        edge_map, g_map, s_map = self._vertex_maps()
        d = dF.shape[1]
        dP = np.empty((self._layout.n_vertices, 3, d))
        for k in range(0, d, JVP_BLOCK):     # blocks of columns: the intermediates stay small
            dw, dS6 = self._split(dF[:, k:k + JVP_BLOCK])
            g = self._rotations.linear_response(self._record, edge_map @ dw)   # (n, 3, b)
            dT = g_map @ g
            dT += s_map @ dS6                                                 # (n, 9, b)
            dP[:, :, k:k + JVP_BLOCK] = self._positions_solver.solve_gradients(dT)
        return dP[:, :, 0] if single else dP

    def vjp(self, dP) -> np.ndarray:
        """Feature-space gradients of vertex fields: ``(dp/df)^T @ dP``.

        Parameters
        ----------
        dP : (n_vertices, 3) or (n_vertices, 3, d) float

        Returns
        -------
        dF : (K,) or (K, d) float64
        """
        dP = np.asarray(dP, dtype=np.float64)
        single = dP.ndim == 2
        dP = dP[:, :, None] if single else dP
        n = self._layout.n_vertices
        if dP.ndim != 3 or dP.shape[:2] != (n, 3):
            raise ValueError(f"dP must have shape ({n}, 3) or ({n}, 3, d), got {dP.shape}")
        edge_map, g_map, s_map = self._vertex_maps()
        dT_adj = self._positions_solver.solve_gradients_adjoint(dP)        # (n, 9, d)
        g_adj = g_map.transpose(0, 2, 1) @ dT_adj                        # (n, 3, d)
        dS6_adj = s_map.transpose(0, 2, 1) @ dT_adj                       # (n, 6, d)
        eta_adj = self._rotations.linear_response_adjoint(self._record, g_adj)   # (E, 3, d)
        dw_adj = edge_map.transpose(0, 2, 1) @ eta_adj
        dF = self._join(dw_adj, dS6_adj)
        return dF[:, 0] if single else dF
