"""The applications layer: generation, interpolation, embedding and exploration with a fitted mesh VAE (Sec. 4.5, 5).

Its public names are exported here and imported from their modules on first use
(:func:`~meshvae_lib.exports.lazy_exports`): ``from meshvae_lib.applications import mix_parts``.
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports

#: module (under this package) and the public names it defines, one line each.
EXPORTS = exports_of(__name__, """
generation     mix_parts parts_code
interpolation  edge_length_distortion vertex_edge_stretch
exploration_checks  WhitenedPCA RelabelledLatents grid_spread
""")

__all__ = sorted(EXPORTS)

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
