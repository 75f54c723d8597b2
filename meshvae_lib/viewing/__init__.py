"""Seeing the meshes: pythreejs viewers, ipywidgets players and explorers, matplotlib figures.

Importing this package imports nothing heavy: the public names are loaded on first use, so
``from meshvae_lib.viewing import render_mesh_grid`` pulls in matplotlib only, and pythreejs and
ipywidgets are imported only by :mod:`~meshvae_lib.viewing.viewer` and
:mod:`~meshvae_lib.viewing.widgets`, :mod:`~meshvae_lib.viewing.explorer` and
:mod:`~meshvae_lib.viewing.latent_pad`.

==========================  =====================================================================
module                      public names
==========================  =====================================================================
``buffers``                 ``position_buffer``, ``normal_buffer``, ``index_buffer``,
                            ``color_buffer``, ``row_offsets``, ``fit_camera``
``colors``                  ``ColorMapping``, ``scalar_colors``, ``error_colors``,
                            ``label_colors``, ``colorbar_html``, ``legend_html``
``render``                  ``render_mesh``, ``render_mesh_grid``, ``figure_to_png``
``fallback``                ``resolve_mode``, ``ImageView``
``gallery``                 ``gallery_indices``, ``mesh_caption``, ``angular_stripes``,
                            ``align_on_part``
``viewer``                  ``MeshViewer``
``widgets``                 ``FramePlayer``, ``InterpolationSlider``
``explorer``                ``LatentExplorer``
``latent_pad``              ``LatentPad``
``convergence_curves``      ``convergence_figure``, ``epochs_past_best``
``floor_figures``           ``per_mesh_error_figure``, ``floor_ratio_figure``
``embedding_maps``          ``embedding_maps_figure``
``interpolation_measures``  ``interpolation_measures_figure``
``marked_vertices``         ``marked_vertices_figure``
``normalization_margins``   ``normalization_margin_figure``
``rimd_diagrams``           ``feature_layout_figure``, ``polar_decomposition_figure``
``network_diagram``,        ``network_diagram``, ``one_ring_figure``, ``pipeline_diagram``,
``one_ring_figure``, ...    ``readable_figure`` (each the name of its own module: imported with
                            the package, so that the module never hides the function)
==========================  =====================================================================
"""

from __future__ import annotations

from meshvae_lib.exports import exports_of, lazy_exports
# names that are also their module's name: imported here (light modules, no matplotlib)
from meshvae_lib.viewing.network_diagram import network_diagram
from meshvae_lib.viewing.one_ring_figure import one_ring_figure
from meshvae_lib.viewing.pipeline_diagram import pipeline_diagram
from meshvae_lib.viewing.readable_figure import readable_figure

#: module (under this package) and the public names it defines, one line each.
EXPORTS = exports_of(__name__, """
buffers                 position_buffer normal_buffer index_buffer color_buffer row_offsets fit_camera
colors                  ColorMapping scalar_colors error_colors label_colors colorbar_html legend_html
gallery                 gallery_indices mesh_caption angular_stripes align_on_part
render                  render_mesh render_mesh_grid figure_to_png
fallback                resolve_mode ImageView
viewer                  MeshViewer
widgets                 FramePlayer InterpolationSlider
explorer                LatentExplorer
latent_pad              LatentPad
convergence_curves      convergence_figure epochs_past_best
floor_figures           per_mesh_error_figure floor_ratio_figure
embedding_maps          embedding_maps_figure
interpolation_measures  interpolation_measures_figure
marked_vertices         marked_vertices_figure
normalization_margins   normalization_margin_figure
rimd_diagrams           feature_layout_figure polar_decomposition_figure
""")

__all__ = sorted([*EXPORTS, "network_diagram", "one_ring_figure", "pipeline_diagram", "readable_figure"])

__getattr__, __dir__ = lazy_exports(__name__, EXPORTS)
