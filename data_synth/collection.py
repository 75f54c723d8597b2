"""The result of every generator: a named collection of meshes sharing one connectivity."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from data_synth import constants as C

__all__ = ["SynthCollection", "resolve_resolution"]


@dataclass
class SynthCollection:
    """A synthetic deforming-mesh collection.

    Attributes
    ----------
    vertices : (n_meshes, n_vertices, 3) float64
    faces : (n_faces, 3) int64, counter-clockwise seen from outside (shared by every mesh).
    names : list of str, one per mesh, unique.
    labels : dict str -> (n_meshes,) ndarray of str or int64, one entry per label column.
    description : str, one line.
    extras : dict, generator-specific data (e.g. ``shape_params`` of the bodies).
    """

    vertices: np.ndarray
    faces: np.ndarray
    names: list
    labels: dict
    description: str
    extras: dict = field(default_factory=dict)

    def __post_init__(self):
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int64)
        n = len(self.vertices)
        if self.vertices.ndim != 3 or self.vertices.shape[2] != 3:
            raise ValueError(f"vertices must be (n_meshes, n_vertices, 3), got {self.vertices.shape}")
        if len(self.names) != n or len(set(self.names)) != n:
            raise ValueError(f"names must be {n} unique strings, got {len(self.names)} "
                             f"({len(set(self.names))} unique)")
        for key, value in self.labels.items():
            value = np.asarray(value)
            if value.shape != (n,):
                raise ValueError(f"label {key!r} must have shape ({n},), got {value.shape}")
            self.labels[key] = value

    def __len__(self) -> int:
        return len(self.vertices)

    @property
    def n_vertices(self) -> int:
        return self.vertices.shape[1]

    @property
    def n_meshes(self) -> int:
        """``len(collection)`` (the name meshvae_lib's MeshCollection does not have)."""
        return len(self.vertices)

    @property
    def rest(self) -> np.ndarray:
        """The template in its rest pose, ``(n_vertices, 3) float64`` (``extras['rest']``)."""
        return self.extras["rest"]


def resolve_resolution(resolution, default: int | None = None) -> int:
    """The vertex count a generator is asked for: ``resolution`` (or ``default`` when it is None)
    as an int, checked against [MIN_RESOLUTION, MAX_RESOLUTION]; ValueError showing the value."""
    resolution = default if resolution is None else int(resolution)
    if resolution is None or not C.MIN_RESOLUTION <= resolution <= C.MAX_RESOLUTION:
        raise ValueError(f"resolution must lie in [{C.MIN_RESOLUTION}, {C.MAX_RESOLUTION}], got {resolution}")
    return resolution
