"""A mesh collection: meshes sharing one connectivity, with their names and labels.

:class:`MeshCollection` is what :func:`~meshvae_lib.geometry.collection_io.read_collection` returns
and what the model, the applications and the command line take (see ``docs/ARCHITECTURE.md``): one
``faces`` array for all meshes, so vertex ``k`` of every mesh is the same point of the shape.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshvae_lib.validation import check_faces, check_vertices

__all__ = ["MeshCollection", "default_names", "mesh_fingerprints", "find_meshes"]


@dataclass
class MeshCollection:
    """Meshes sharing one connectivity.

    Attributes
    ----------
    vertices : (n_meshes, n_vertices, 3) float64
    faces : (n_faces, 3) int64
    names : list of str, length n_meshes
    labels : dict str -> (n_meshes,) array (numbers or str)
    description : str, one line (what the collection is)
    extras : dict, anything else that came with the meshes (e.g. a generator's ``rest`` template)
    """

    vertices: np.ndarray
    faces: np.ndarray
    names: list[str] = field(default_factory=list)
    labels: dict[str, np.ndarray] = field(default_factory=dict)
    description: str = ""
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        self.vertices = check_vertices(self.vertices, batch=True)
        self.faces = check_faces(self.faces)
        n = self.vertices.shape[0]
        if not self.names:
            self.names = default_names(n)
        self.names = [str(s) for s in self.names]
        if len(self.names) != n:
            raise ValueError(f"{len(self.names)} names for {n} meshes")
        labels = {}
        for key, val in dict(self.labels).items():
            val = np.asarray(val)
            if val.shape != (n,):
                raise ValueError(f"label {key!r} must have shape ({n},), got {val.shape}")
            labels[str(key)] = val
        self.labels = labels

    def __len__(self) -> int:
        return self.vertices.shape[0]

    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[1]

    def subset(self, indices) -> "MeshCollection":
        """The meshes at ``indices`` (int array-like, or a boolean mask of length ``len(self)``), in
        that order, with their names and labels; the faces are shared. Indices may repeat."""
        idx = np.asarray(indices)
        if idx.dtype == bool:
            if idx.shape != (len(self),):
                raise ValueError(f"a boolean mask must have shape ({len(self)},), got {idx.shape}")
            idx = np.flatnonzero(idx)
        if idx.ndim != 1 or (idx.size and not np.issubdtype(idx.dtype, np.integer)):
            raise ValueError(f"indices must be a 1-D array of integers, got dtype {idx.dtype} shape {idx.shape}")
        if idx.size == 0:
            raise ValueError("a collection needs at least one mesh, got no indices")
        if idx.min() < -len(self) or idx.max() >= len(self):
            raise ValueError(f"indices must lie in [0, {len(self) - 1}], got range [{idx.min()}, {idx.max()}]")
        return MeshCollection(self.vertices[idx], self.faces, [self.names[i] for i in idx],
                              {k: v[idx] for k, v in self.labels.items()}, self.description, dict(self.extras))


def default_names(n: int) -> list[str]:
    """Names of ``n`` unnamed meshes: ``"0000"``, ``"0001"``, ... (at least 4 digits, zero-padded
    so that they sort in order)."""
    width = max(4, len(str(max(n - 1, 0))))
    return [f"{k:0{width}d}" for k in range(n)]


def mesh_fingerprints(vertices) -> np.ndarray:
    """The identity of each mesh, robust to round-off: its vertex positions, flattened to a row of
    3n numbers, projected on ``MESH_FINGERPRINT_DIRECTIONS`` fixed unit directions (standard normal,
    drawn from a fixed seed, the same on every machine), followed by the row's Euclidean length.

    Two builds of the same mesh on machines whose BLAS rounds differently (positions equal to
    about 1e-15 relative) give fingerprints equal within :data:`MESH_IDENTITY_RTOL`; so does a mesh
    read back from an ``.npz``, OBJ, OFF or PLY file. Meshes that differ by more than about
    ``MESH_IDENTITY_RTOL * sqrt(3n)`` of their length differ in at least one projection.

    vertices : (n_meshes, n_vertices, 3) float. Returns (n_meshes, MESH_FINGERPRINT_DIRECTIONS + 1)
    float64.
    """
    from meshvae_lib.tolerances import MESH_FINGERPRINT_DIRECTIONS, MESH_FINGERPRINT_SEED

    V = np.asarray(check_vertices(vertices, "vertices", batch=True), dtype=np.float64)
    rows = V.reshape(len(V), -1)
    W = np.random.default_rng(MESH_FINGERPRINT_SEED).standard_normal((rows.shape[1], MESH_FINGERPRINT_DIRECTIONS))
    W /= np.linalg.norm(W, axis=0)
    return np.concatenate([rows @ W, np.linalg.norm(rows, axis=1)[:, None]], axis=1)


def find_meshes(fingerprints, vertices) -> tuple[np.ndarray, np.ndarray]:
    """Where the meshes with ``fingerprints`` (:func:`mesh_fingerprints`) are among ``vertices``.

    fingerprints : (k, MESH_FINGERPRINT_DIRECTIONS + 1) float (a fingerprint may repeat: as many
        equal meshes are then looked for).
    vertices : (n_meshes, n_vertices, 3) float.

    A mesh matches a fingerprint when every entry agrees within ``MESH_IDENTITY_RTOL`` times the
    larger of the two lengths; among several matches the closest unused one is taken.

    Returns ``(found, missing)``: ``found`` (k',) int64, for each fingerprint found the index of its
    mesh in ``vertices`` (each index used once, in the order of ``fingerprints``); ``missing``
    (m,) int64, the positions in ``fingerprints`` of those not found.
    """
    from meshvae_lib.tolerances import DIVISION_FLOOR, MESH_IDENTITY_RTOL

    here = mesh_fingerprints(vertices)
    wanted = np.asarray(fingerprints, dtype=np.float64).reshape(-1, here.shape[1])
    free = np.ones(len(here), dtype=bool)
    found, missing = [], []
    for j, f in enumerate(wanted):  # one pass per wanted mesh (not per vertex), each over all meshes
        scale = np.maximum(np.abs(here[:, -1]), abs(f[-1])) + DIVISION_FLOOR
        gap = np.abs(here - f).max(axis=1) / scale
        gap[~free] = np.inf
        i = int(np.argmin(gap)) if len(gap) else -1
        if i >= 0 and gap[i] <= MESH_IDENTITY_RTOL:
            free[i] = False
            found.append(i)
        else:
            missing.append(j)
    return np.asarray(found, dtype=np.int64), np.asarray(missing, dtype=np.int64)
