"""meshvae_lib: mesh variational autoencoders (Tan, Gao, Lai, Xia, CVPR 2018) in Python.

The library is a set of small modules, one concept each; import what you need::

    from meshvae_lib.geometry.collection_io import read_collection
    from meshvae_lib.geometry.rimd import rimd_features
    from meshvae_lib.geometry.reconstruction import RIMDReconstructor

Importing the package does no work: heavy dependencies (torch, pythreejs) are imported only by the
modules that need them.
"""

__version__ = "0.1.0"
