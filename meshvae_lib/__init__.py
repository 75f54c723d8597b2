"""meshvae_lib: mesh variational autoencoders (Tan, Gao, Lai, Xia, CVPR 2018) in Python.

The face of the library, for scripts and notebooks::

    import meshvae_lib as mv

    coll = mv.read_collection("my_meshes/")          # a folder of OBJ/PLY/OFF files or an .npz
    model = mv.MeshVAEModel("rimd").fit(coll)        # the paper's mesh VAE on RIMD features
    model.save("model.pt"); model = mv.load_model("model.pt", coll)

The same names live in small modules, one concept each (``meshvae_lib.geometry.rimd``,
``meshvae_lib.model.meshvae_model``, ...); :data:`FACADE` says where. Each first-level subpackage
(``geometry``, ``model``, ``applications``, ``viewing``, ``course``, ``paper``) exports its public
names the same way: ``from meshvae_lib.model import MeshVAEModel, evaluate_model``. Importing the
package does no work: each name is imported from its module the first time it is used
(:func:`~meshvae_lib.exports.lazy_exports`), so ``import meshvae_lib`` pulls in neither torch nor
pythreejs.
"""

from __future__ import annotations

from meshvae_lib.exports import lazy_exports

__version__ = "0.1.0"

#: name -> the module that defines it.
FACADE = {
    "read_collection": "meshvae_lib.geometry.collection_io",
    "MeshCollection": "meshvae_lib.geometry.collection",
    "cotangent_weights": "meshvae_lib.geometry.cotangent",
    "deformation_gradients": "meshvae_lib.geometry.deformation_gradient",
    "rimd_features": "meshvae_lib.geometry.rimd",
    "RIMDReconstructor": "meshvae_lib.geometry.reconstruction",
    "MeshVAEModel": "meshvae_lib.model.meshvae_model",
    "load_model": "meshvae_lib.model.meshvae_model",
    "TrainConfig": "meshvae_lib.model.train_config",
}

__all__ = ["__version__", *FACADE]


__getattr__, __dir__ = lazy_exports(__name__, FACADE)
