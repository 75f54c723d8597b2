"""The geometry layer: meshes, deformation gradients, RIMD features and their reconstruction (no learning).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.geometry import rimd_features, RIMDReconstructor``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module (under this package) and the public names it defines, one line each.
EXPORTS = exports_of(__name__, """
alignment             bounding_box_diagonal rigid_align
boundaries            boundary_loops
collection            MeshCollection
collection_io         read_collection write_collection
cotangent             cotangent_weights
deformation_gradient  DeformationGradientOperator deformation_gradients
intersections         self_intersections
polar                 polar_decomposition
reconstruction        RIMDReconstructor
rimd                  RIMDEncoder rimd_features
rotations             rotation_angle so3_exp so3_log
spd_factor            SPDFactor
topology              directed_edges edge_index edges face_normals one_rings vertex_normals
""")

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
