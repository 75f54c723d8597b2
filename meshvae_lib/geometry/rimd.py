"""The RIMD feature (rotation-invariant mesh difference, paper Sec. 3, Eq. 2).

For a deformed mesh with deformation gradients ``T_i = R_i S_i`` relative to a reference mesh, the
feature collects ``log dR_ij`` with ``dR_ij = R_i^T R_j`` for the edges and the symmetric
``S_i`` for the vertices (Eq. 2: ``f = {log dR_ij; S_i}``). Both are unchanged by a rigid motion of
the deformed mesh; a uniform scale by ``s`` multiplies every ``S_i`` by ``s`` and leaves the
rotations alone.

Feature layout (:class:`RIMDLayout`), one row ``f`` of ``K`` float64 numbers:

``layout="paper"`` (default, as in the paper: ``K = 6 n_vertices + 6 n_edges``; 60012 for 2502
vertices and 7500 edges)::

    f[3 d : 3 d + 3]                  log dR_ij of directed edge d = (i, j), the rotation vector
                                      (axis * angle) of the skew-symmetric log; directed edges are
                                      ordered by i then j (``topology.directed_edges``), so the
                                      edges of vertex i are contiguous, i.e. its one-ring
    f[6 E + 6 i : 6 E + 6 i + 6]      S_i, upper triangle (S00, S01, S02, S11, S12, S22)

with ``E = n_edges``; ``log dR_ji = -log dR_ij``, so half of the rotation block is redundant.

``layout="compact"`` (``K = 6 n_vertices + 3 n_edges``): the rotation block holds each undirected
edge once, ``(i, j)`` with ``i < j`` in the order of ``topology.edges``; the S block follows it.

``RIMDLayout.edge_feature_index(i, j)`` and ``RIMDLayout.vertex_feature_index(i)`` return the
positions, so a lesson can point at "the rotation part of edge (i, j)" and "S of vertex i".
"""

from __future__ import annotations

import logging

import numpy as np

from meshvae_lib.defaults import DEFAULT_LAYOUT, LAYOUTS
from meshvae_lib.geometry.deformation_gradient import DeformationGradientOperator
from meshvae_lib.geometry.polar import polar_rs_soa
from meshvae_lib.geometry.rotations import quat_from_soa, relative_log_quat
from meshvae_lib.geometry.topology import MeshTopology, edge_index
from meshvae_lib.progress import progress as progress_bar
from meshvae_lib.validation import check_choice, check_rows

__all__ = ["S_ENTRIES", "RIMDLayout", "RIMDEncoder", "rimd_features"]

logger = logging.getLogger(__name__)

#: the 6 stored entries (row, column) of each symmetric S_i, in feature order.
S_ENTRIES = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
_S_FLAT = np.array([3 * a + b for a, b in S_ENTRIES])


class RIMDLayout:
    """Where each number of a RIMD feature vector lives.

    Parameters
    ----------
    F : (n_faces, 3) int
    n_vertices : int
    layout : {"paper", "compact"}
    topology : MeshTopology of ``F``, optional
        Precomputed (then ``F`` is not checked again).

    Attributes
    ----------
    layout : str
    n_vertices, n_edges : int
    edges : (n_edges, 2) int64
        Undirected edges, ``i < j`` (``topology.edges``).
    rotation_edges : (n_rotation_edges, 2) int64
        The edge ``(i, j)`` of each 3-number block of the rotation part: every directed edge for
        ``"paper"``, each undirected edge once for ``"compact"``.
    K : int
        Feature length.
    rotation_slice, scaling_slice : slice
        The rotation block (``3 * n_rotation_edges`` numbers) and the S block (``6 * n_vertices``).
    """

    def __init__(self, F, n_vertices: int, layout: str = DEFAULT_LAYOUT, topology: MeshTopology | None = None):
        check_choice(layout, LAYOUTS, "layout")
        n_vertices = int(n_vertices)
        if topology is None or topology.n_vertices != n_vertices:
            topology = MeshTopology(F, n_vertices)
        self.layout = layout
        self.n_vertices = n_vertices
        self.edges = topology.edges
        self.n_edges = len(self.edges)
        if layout == "paper":
            D = topology.directed
            self.rotation_edges = D
            self._undirected = edge_index(self.edges, D[:, 0], D[:, 1])
            self._sign = np.where(D[:, 0] < D[:, 1], 1.0, -1.0)
            fwd = np.empty(self.n_edges, np.int64)
            bwd = np.empty(self.n_edges, np.int64)
            pos = np.arange(len(D))
            fwd[self._undirected[self._sign > 0]] = pos[self._sign > 0]
            bwd[self._undirected[self._sign < 0]] = pos[self._sign < 0]
            self._forward, self._backward = fwd, bwd
        else:
            self.rotation_edges = self.edges
            self._undirected = np.arange(self.n_edges)
            self._sign = np.ones(self.n_edges)
        self.n_rotation_edges = len(self.rotation_edges)
        r = 3 * self.n_rotation_edges
        self.rotation_slice = slice(0, r)
        self.scaling_slice = slice(r, r + 6 * n_vertices)
        self.K = r + 6 * n_vertices

    @property
    def forward_blocks(self) -> np.ndarray:
        """Paper layout: for each undirected edge ``(i, j)``, ``i < j``, the row of
        ``rotation_edges`` that stores ``log dR_ij``: (n_edges,) int64, read-only."""
        return self._paper_blocks(self._forward)

    @property
    def backward_blocks(self) -> np.ndarray:
        """Paper layout: for each undirected edge ``(i, j)``, the row that stores ``log dR_ji``:
        (n_edges,) int64, read-only."""
        return self._paper_blocks(self._backward)

    def _paper_blocks(self, blocks: np.ndarray) -> np.ndarray:
        if self.layout != "paper":
            raise ValueError(f"only the paper layout stores both directions of an edge; this one is {self.layout!r}")
        view = blocks.view()
        view.setflags(write=False)
        return view

    def __repr__(self) -> str:
        return (f"RIMDLayout(layout={self.layout!r}, n_vertices={self.n_vertices}, "
                f"n_edges={self.n_edges}, K={self.K})")

    def edge_feature_index(self, i: int, j: int) -> np.ndarray:
        """Positions of ``log dR_ij`` in a feature vector.

        Returns
        -------
        idx : (3,) int64

        Raises
        ------
        ValueError
            If ``(i, j)`` is not an edge, or (compact layout) if ``i > j``: that edge is stored
            as ``(j, i)`` and ``log dR_ij = -f[edge_feature_index(j, i)]``
            (see :meth:`rotation_part`).
        """
        i, j = int(i), int(j)
        if self.layout == "compact":
            if i > j:
                raise ValueError(
                    f"the compact layout stores edge ({j}, {i}) only; log dR_{i}{j} = "
                    f"-f[edge_feature_index({j}, {i})] (or use rotation_part)"
                )
            d = int(edge_index(self.edges, i, j))
        else:
            u = int(edge_index(self.edges, i, j))  # raises when (i, j) is no edge
            D = self.rotation_edges
            lo = np.searchsorted(D[:, 0], i, side="left")
            hi = np.searchsorted(D[:, 0], i, side="right")
            d = int(lo + np.searchsorted(D[lo:hi, 1], j))
            assert self._undirected[d] == u
        return 3 * d + np.arange(3)

    def vertex_feature_index(self, i: int) -> np.ndarray:
        """Positions of the 6 stored entries of ``S_i`` (order :data:`S_ENTRIES`).

        Returns
        -------
        idx : (6,) int64
        """
        i = int(i)
        if not 0 <= i < self.n_vertices:
            raise ValueError(f"vertex {i} out of range [0, {self.n_vertices - 1}]")
        return self.scaling_slice.start + 6 * i + np.arange(6)

    def check_features(self, features) -> np.ndarray:
        """Feature vector(s) in this layout.

        Parameters
        ----------
        features : (K,) or (n_meshes, K) float

        Returns
        -------
        f : float64 array of the input's shape
        """
        return check_rows(features, "features", self.K, what=f"for this {self.layout!r} layout")

    def rotation_part(self, features, i: int, j: int) -> np.ndarray:
        """``log dR_ij`` (rotation vector) from feature vector(s), for any edge direction.

        Parameters
        ----------
        features : (K,) or (n_meshes, K) float

        Returns
        -------
        w : (3,) or (n_meshes, 3) float64
        """
        f = self.check_features(features)
        if self.layout == "compact" and int(i) > int(j):
            return -f[..., self.edge_feature_index(j, i)]
        return f[..., self.edge_feature_index(i, j)]

    def scaling_part(self, features, i: int) -> np.ndarray:
        """``S_i`` as a symmetric matrix from feature vector(s).

        Returns
        -------
        S : (3, 3) or (n_meshes, 3, 3) float64
        """
        f = self.check_features(features)
        s6 = f[..., self.vertex_feature_index(i)]
        return _sym_from_6(s6)

    def pack(self, log_dR, S6) -> np.ndarray:
        """Assemble feature rows from undirected rotation vectors and S entries.

        Parameters
        ----------
        log_dR : (n_meshes, n_edges, 3) float
            ``log dR_ij`` for each undirected edge ``(i, j)``, ``i < j``, in ``edges`` order.
        S6 : (n_meshes, n_vertices, 6) float
            Entries :data:`S_ENTRIES` of each ``S_i``.

        Returns
        -------
        f : (n_meshes, K) float64
        """
        N = log_dR.shape[0]
        out = np.empty((N, self.K))
        rot = out[:, self.rotation_slice].reshape(N, self.n_rotation_edges, 3)
        np.multiply(log_dR[:, self._undirected, :], self._sign[None, :, None], out=rot)
        out[:, self.scaling_slice] = S6.reshape(N, -1)
        return out

    def unpack(self, features) -> tuple[np.ndarray, np.ndarray]:
        """Split feature rows into undirected rotation vectors and symmetric ``S``.

        For the paper layout the two stored directions of each edge are averaged:
        ``(log dR_ij - log dR_ji) / 2`` (equal for exact features; for a decoder's output this
        halves the noise variance).

        Parameters
        ----------
        features : (K,) or (n_meshes, K) float

        Returns
        -------
        log_dR : (n_meshes, n_edges, 3) float64
        S : (n_meshes, n_vertices, 3, 3) float64
        """
        f = self.check_features(features)
        f = f.reshape(-1, self.K)
        N = f.shape[0]
        rot = f[:, self.rotation_slice].reshape(N, self.n_rotation_edges, 3)
        if self.layout == "paper":
            log_dR = 0.5 * (rot[:, self._forward] - rot[:, self._backward])
        else:
            log_dR = rot.copy()
        S = _sym_from_6(f[:, self.scaling_slice].reshape(N, self.n_vertices, 6))
        return log_dR, S


def _sym_from_6(s6: np.ndarray) -> np.ndarray:
    S = np.empty(s6.shape[:-1] + (3, 3))
    for k, (a, b) in enumerate(S_ENTRIES):
        S[..., a, b] = s6[..., k]
        S[..., b, a] = s6[..., k]
    return S


class RIMDEncoder:
    """Feature extraction against one reference mesh, precomputed once.

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        Reference mesh.
    F : (n_faces, 3) int
    layout : {"paper", "compact"}
    operator : DeformationGradientOperator of ``(V0, F)``, optional
        Built already (e.g. for a :class:`~meshvae_lib.geometry.reconstruction.RIMDReconstructor`
        of the same mesh); then ``V0`` and ``F`` are its own.

    Attributes
    ----------
    layout : RIMDLayout
    operator : DeformationGradientOperator
    """

    def __init__(self, V0, F, layout: str = DEFAULT_LAYOUT, operator: DeformationGradientOperator | None = None):
        self.operator = DeformationGradientOperator(V0, F) if operator is None else operator
        self.layout = RIMDLayout(self.operator.faces, self.operator.n_vertices, layout, topology=self.operator.topology)
        self.V0 = np.asarray(V0, dtype=np.float64)
        self.faces = self.operator.faces

    @property
    def K(self) -> int:
        return self.layout.K

    def transform(self, V, batch_size: int | None = None, progress: bool = False) -> np.ndarray:
        """RIMD features of deformed mesh(es) (Eq. 2).

        Parameters
        ----------
        V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
            Same connectivity as the reference.
        batch_size : int, optional
            Meshes processed together. Default: about 20,000 vertices per batch (one mesh at a
            time from 20k vertices up); larger batches were measured slower per mesh (cache).
        progress : bool
            Show a progress bar (stderr).

        Returns
        -------
        f : (K,) or (n_meshes, K) float64
        """
        V = self.operator.check_deformed(V)
        single = V.ndim == 2
        Vb = V[None] if single else V
        N = Vb.shape[0]
        out = np.empty((N, self.K))
        if batch_size is None:
            batch_size = max(1, 20_000 // self.operator.n_vertices)
        batch_size = max(1, int(batch_size))
        starts = range(0, N, batch_size)
        if progress:
            starts = progress_bar(starts, desc="RIMD features", unit="batch")
        for s in starts:
            out[s:s + batch_size] = self._transform_batch(Vb[s:s + batch_size])
        return out[0] if single else out

    def _transform_batch(self, V: np.ndarray) -> np.ndarray:
        N, n = V.shape[0], self.operator.n_vertices
        t = self.operator.apply_soa(V)  # (9, N n)
        r, s = polar_rs_soa(t)
        E = self.layout.edges
        offs = (np.arange(N) * n)[:, None]
        ii = (offs + E[:, 0]).reshape(-1)
        jj = (offs + E[:, 1]).reshape(-1)
        # log(R_i^T R_j) through unit quaternions: fewer operations than forming R_i^T R_j
        # (checked against so3_log in the tests)
        q = quat_from_soa(r)  # (4, N n)
        w = relative_log_quat(q[:, ii], q[:, jj])  # (3, N E)
        log_dR = np.ascontiguousarray(w.T).reshape(N, len(E), 3)
        S6 = np.ascontiguousarray(s[_S_FLAT].T).reshape(N, n, 6)
        return self.layout.pack(log_dR, S6)


def rimd_features(V0, V, F, layout: str = DEFAULT_LAYOUT) -> np.ndarray:
    """RIMD feature(s) of deformed mesh(es) relative to the reference ``V0`` (paper Eq. 2): a
    one-off ``RIMDEncoder(V0, F, layout).transform(V)`` (build the encoder once to encode more meshes
    against the same reference).

    Parameters
    ----------
    V0 : (n_vertices, 3) float
        Reference mesh.
    V : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        Deformed mesh(es), same connectivity.
    F : (n_faces, 3) int
    layout : {"paper", "compact"}
        See the module docstring; :class:`RIMDLayout` maps positions to edges and vertices.

    Returns
    -------
    f : (K,) or (n_meshes, K) float64
    """
    return RIMDEncoder(V0, F, layout=layout).transform(V)
