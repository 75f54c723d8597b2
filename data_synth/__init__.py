"""Procedural deforming-mesh collections standing in for the data sets of Tan et al. (CVPR 2018).

``make_collection(name, seed=0, resolution=None)`` builds one; ``list_collections()`` names them.
See docs/data_synth.md.
"""

from data_synth.collection import SynthCollection
from data_synth.registry import COLLECTIONS, list_collections, make_collection

__all__ = ["COLLECTIONS", "SynthCollection", "list_collections", "make_collection"]
