"""Meshes from RIMD features: the paper's way and an exact inverse.

:class:`RIMDReconstructor` undoes :mod:`meshvae_lib.geometry.rimd` in three steps, each with its
sparse systems factorised once per reference mesh:

1. rotations (``rotations=``, :mod:`meshvae_lib.geometry.rotation_recovery`): the per-vertex
   ``R_i`` from the edge rotations ``dR_ij = R_i^T R_j``, by the reference implementation's
   breadth-first walk (``"bfs"``) or by the walk followed by a global least-squares fit over all
   edges (``"global"``, default, robust to noise);
2. positions (``method=``, :mod:`meshvae_lib.geometry.position_solvers`) from ``T_i = R_i S_i``:
   ``"paper"`` minimises Eq. 1 with the ``T_i`` fixed (a cotangent-Laplacian system; not an exact
   inverse, since per-vertex ``T_i`` are not integrable in general), optionally followed by the
   reference's local/global rounds (``iterations``, off by default); ``"exact"`` (default) inverts
   the feature extraction, normal term included, and gives the mesh back to rounding error for
   exact features on generic meshes (``refine`` adds Gauss-Newton steps where perfectly symmetric
   one-rings need them);
3. a rigid alignment onto the reference (the feature carries no global pose).

One vertex per connected component is pinned (the feature has no translation); components are
then placed by the final rigid alignment only, so several components keep their relative
placement only up to a translation each.
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.defaults import DEFAULT_LAYOUT, RECONSTRUCTION_METHODS, ROTATION_RECOVERY
from meshvae_lib.geometry.alignment import rigid_align
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator
from meshvae_lib.geometry.position_solvers import ExactPositionSolver, PaperPositionSolver
from meshvae_lib.geometry.reconstruction_linearization import ReconstructionLinearization
from meshvae_lib.geometry.rimd import RIMDLayout
from meshvae_lib.geometry.rotation_recovery import RotationRecovery
from meshvae_lib.geometry.rotations import exp_soa, matmul_soa
from meshvae_lib.progress import progress as progress_bar
from meshvae_lib.validation import check_choice, check_count, check_finite

__all__ = ["RIMDReconstructor"]


class RIMDReconstructor:
    """Meshes from RIMD features, for one reference mesh; all factorisations happen here, once.

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        The reference mesh the features were computed against.
    F : (n_faces, 3) int
    method : {"exact", "paper"}
        Position solve (:mod:`meshvae_lib.geometry.position_solvers`). ``"exact"`` (default)
        inverts the extraction; ``"paper"`` minimises Eq. 1.
    layout : {"paper", "compact"}
        Feature layout (:class:`meshvae_lib.geometry.rimd.RIMDLayout`).
    rotations : {"global", "bfs"}
        Rotation recovery (:mod:`meshvae_lib.geometry.rotation_recovery`). ``"global"``
        (default) is robust to noise.
    iterations : int, optional
        ``method="paper"`` only: local/global refinement rounds after the first solve (the
        reference does 10). Default 0: in our measurements (docs/geometry.md) the rounds move the
        result away from the true mesh, with exact or noisy features alike.
    refine : {"auto", True, False}
        ``method="exact"`` only: Gauss-Newton steps after the linear solve
        (:class:`~meshvae_lib.geometry.position_solvers.ExactPositionSolver`). ``"auto"``
        (default) tests once, here, whether the linear solve alone is exact for this reference
        mesh (a twist of the reference about its main axis) and refines only if not; ``True``
        always checks and refines, ``False`` never. Without them, meshes with perfectly symmetric
        one-rings (procedural meshes) keep errors around 1e-5 of the diagonal.
    operator : DeformationGradientOperator of ``(V0, F)``, optional
        Built already (e.g. by a :class:`~meshvae_lib.geometry.rimd.RIMDEncoder` of the same mesh).

    Attributes
    ----------
    layout : RIMDLayout
    operator : DeformationGradientOperator
    roots : (n_components,) int64
        Root vertex of the rotation walk and pinned vertex, one per connected component.
    refine_active : bool
        ``method="exact"``: whether Gauss-Newton steps are taken (see ``refine``).
    """

    def __init__(self, V0, F, method: str = "exact", layout: str = DEFAULT_LAYOUT,
                 rotations: str = "global", iterations: int | None = None, refine="auto",
                 operator: DeformationGradientOperator | None = None):
        self.method = check_choice(method, RECONSTRUCTION_METHODS, "method")
        self.rotations = check_choice(rotations, ROTATION_RECOVERY, "rotations")
        self.iterations = 0 if iterations is None else check_count(iterations, "iterations")
        self.refine = check_choice(refine, ("auto", True, False), "refine")
        op = DeformationGradientOperator(V0, F) if operator is None else operator
        self.operator = op
        self.V0 = np.asarray(V0, dtype=np.float64)
        self.faces = op.faces
        self.n_vertices = op.n_vertices
        self.layout = RIMDLayout(op.faces, op.n_vertices, layout, topology=op.topology)
        self._rotation_recovery = RotationRecovery(self.layout.edges, op.n_vertices, rotations)
        self.roots = self._rotation_recovery.roots
        if method == "exact":
            self._positions = ExactPositionSolver(op, self.V0, self.roots, refine)
            self.refine_active = self._positions.refine_active
        else:
            self._positions = PaperPositionSolver(op, self.V0, self.roots)
            self.refine_active = False

    def __repr__(self) -> str:
        return (f"RIMDReconstructor(method={self.method!r}, layout={self.layout.layout!r}, "
                f"rotations={self.rotations!r}, n_vertices={self.n_vertices})")

    @property
    def rotation_recovery(self) -> RotationRecovery:
        """The rotation recovery of this mesh (its graph Laplacian factorised once)."""
        return self._rotation_recovery

    @property
    def position_solver(self) -> ExactPositionSolver | PaperPositionSolver:
        """The position solve of this mesh (its system factorised once)."""
        return self._positions

    def linearize(self, features) -> ReconstructionLinearization:
        """Reconstruct one feature vector and linearise the reconstruction around it.

        Parameters
        ----------
        features : (K,) float
            In this reconstructor's layout.

        Returns
        -------
        ReconstructionLinearization
            ``.positions (n_vertices, 3)`` (not aligned to the reference) and the products
            ``jvp(dF)`` / ``vjp(dP)`` with ``dp/df`` (see
            :mod:`meshvae_lib.geometry.reconstruction_linearization`).

        Raises
        ------
        ValueError
            For the paper's local-global iterations (``method="paper"``, ``iterations > 0``), which
            are not differentiated.
        """
        if self.method == "paper" and self.iterations:
            raise ValueError(f"linearize does not differentiate the paper's local-global iterations, got {self.iterations}")
        f = check_finite(self.layout.check_features(features), "features")
        if f.ndim != 1:
            raise ValueError(f"linearize takes one feature vector ({self.layout.K},), got {f.shape}")
        log_dR, S = self.layout.unpack(f)
        w = np.ascontiguousarray(log_dR[0].T)
        Ssoa = np.ascontiguousarray(S[0].reshape(self.n_vertices, 9).T)
        R, record = self._rotation_recovery.recover(w)
        P = self._positions(matmul_soa(R, Ssoa))
        return ReconstructionLinearization(self, w, Ssoa, R, P, record)

    def recover_rotations(self, log_dR) -> np.ndarray:
        """Per-vertex rotations from edge rotation vectors, up to one global rotation.

        Parameters
        ----------
        log_dR : (n_edges, 3) float
            ``log dR_ij`` of each undirected edge ``(i, j)``, ``i < j`` (``layout.edges`` order).

        Returns
        -------
        R : (n_vertices, 3, 3) float64
            ``R[root] = I`` for the BFS walk; the global sweeps keep the roots fixed.
        """
        log_dR = np.asarray(log_dR, dtype=np.float64)
        if log_dR.shape != (self.layout.n_edges, 3):
            raise ValueError(
                f"log_dR must have shape ({self.layout.n_edges}, 3), got {log_dR.shape}")
        r = self._rotation_recovery(np.ascontiguousarray(log_dR.T))
        return np.ascontiguousarray(r.T).reshape(-1, 3, 3)

    def _reconstruct_one(self, w: np.ndarray, S: np.ndarray) -> np.ndarray:
        """``w`` (3, E) undirected log dR, ``S`` (9, n) -> positions (n, 3), not yet aligned."""
        R = self._rotation_recovery(w)
        P = self._positions(matmul_soa(R, S))
        if self.method == "paper" and self.iterations:
            dR = exp_soa(w)
            for _ in range(self.iterations):
                R = self._positions.local_step(P, S, R, dR)
                P = self._positions(matmul_soa(R, S))
        return P

    def reconstruct(self, features, align: bool = True, progress: bool = False) -> np.ndarray:
        """Mesh(es) from RIMD feature(s).

        Parameters
        ----------
        features : (K,) or (n_meshes, K) float
            In this reconstructor's layout (``self.layout.K`` numbers per mesh).
        align : bool
            Align each result rigidly (Kabsch, no scale) to the reference ``V0`` (default).
        progress : bool
            Show a progress bar (stderr).

        Returns
        -------
        V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float64
        """
        f = check_finite(self.layout.check_features(features), "features")
        single = f.ndim == 1
        f = f.reshape(-1, self.layout.K)
        N, n = f.shape[0], self.n_vertices
        out = np.empty((N, n, 3))
        it = range(N)
        if progress:
            it = progress_bar(it, desc="reconstructing", unit="mesh")
        for k in it:
            log_dR, S = self.layout.unpack(f[k])
            w = np.ascontiguousarray(log_dR[0].T)
            Ssoa = np.ascontiguousarray(S[0].reshape(n, 9).T)
            with np.errstate(over="ignore", invalid="ignore"):  # reported just below, once
                out[k] = self._reconstruct_one(w, Ssoa)
            if not np.isfinite(out[k]).all():  # the alignment's SVD may never return on NaN
                raise ValueError(f"features row {k}: the reconstructed positions overflowed float64 (NaN or"
                                 " infinite); its stretch entries are too large")
        if align:
            out = rigid_align(out, self.V0)
        return out[0] if single else out
