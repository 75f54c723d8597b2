"""A mesh collection: meshes sharing one connectivity, with their names and labels.

:class:`MeshCollection` is what :func:`~meshvae_lib.geometry.collection_io.read_collection` returns
and what the model, the applications and the command line take (see ``docs/ARCHITECTURE.md``): one
``faces`` array for all meshes, so vertex ``k`` of every mesh is the same point of the shape.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshvae_lib.validation import check_faces, check_vertices

__all__ = ["MeshCollection", "default_names", "mesh_digests", "find_meshes"]


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


def mesh_digests(vertices) -> list[str]:
    """The identity of each mesh: a digest (blake2b, 32 hex digits) of its vertex positions as
    float64 bytes, so that a mesh read back from an ``.npz``, an OBJ, OFF or PLY file (all of which
    keep float64 positions exactly) is recognised whatever its name or place in a collection.

    vertices : (n_meshes, n_vertices, 3) float. Returns a list of n_meshes str.
    """
    import hashlib

    V = np.ascontiguousarray(check_vertices(vertices, "vertices", batch=True), dtype="<f8")
    return [hashlib.blake2b(V[k].tobytes(), digest_size=16).hexdigest() for k in range(len(V))]


def find_meshes(digests, vertices) -> tuple[np.ndarray, np.ndarray]:
    """Where the meshes with ``digests`` (:func:`mesh_digests`) are among ``vertices``.

    digests : list of str (a digest may repeat: as many equal meshes are then looked for).
    vertices : (n_meshes, n_vertices, 3) float.

    Returns ``(found, missing)``: ``found`` (k,) int64, for each digest found the index of its mesh
    in ``vertices`` (each index used once, in the order of ``digests``); ``missing`` (m,) int64, the
    positions in ``digests`` of those not found.
    """
    places: dict[str, list[int]] = {}
    for k, d in enumerate(mesh_digests(vertices)):
        places.setdefault(d, []).append(k)
    found, missing = [], []
    for j, d in enumerate(digests):
        (found.append(places[d].pop(0)) if places.get(d) else missing.append(j))
    return np.asarray(found, dtype=np.int64), np.asarray(missing, dtype=np.int64)
