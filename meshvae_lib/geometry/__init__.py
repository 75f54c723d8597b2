"""The geometry layer: meshes, deformation gradients, RIMD features and their reconstruction (no learning).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.geometry import rimd_features, RIMDReconstructor``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module -> the public names it defines (here as name -> module).
EXPORTS = exports_of({
    "meshvae_lib.geometry.alignment": ("bounding_box_diagonal", "rigid_align"),
    "meshvae_lib.geometry.boundaries": ("boundary_loops",),
    "meshvae_lib.geometry.collection": ("MeshCollection",),
    "meshvae_lib.geometry.collection_io": ("read_collection", "write_collection"),
    "meshvae_lib.geometry.cotangent": ("cotangent_weights",),
    "meshvae_lib.geometry.deformation_gradient": ("DeformationGradientOperator", "deformation_gradients"),
    "meshvae_lib.geometry.intersections": ("self_intersections",),
    "meshvae_lib.geometry.polar": ("polar_decomposition",),
    "meshvae_lib.geometry.reconstruction": ("RIMDReconstructor",),
    "meshvae_lib.geometry.rimd": ("RIMDEncoder", "rimd_features"),
    "meshvae_lib.geometry.rotations": ("rotation_angle", "so3_exp", "so3_log"),
    "meshvae_lib.geometry.spd_factor": ("SPDFactor",),
    "meshvae_lib.geometry.topology": ("directed_edges", "edge_index", "edges", "face_normals", "one_rings", "vertex_normals"),
})

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
