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
``gallery``                 ``gallery_indices``, ``mesh_caption``, ``angular_stripes``
``viewer``                  ``MeshViewer``
``widgets``                 ``FramePlayer``, ``InterpolationSlider``
``explorer``                ``LatentExplorer``
``latent_pad``              ``LatentPad``
==========================  =====================================================================
"""

from __future__ import annotations

import importlib

_NAMES = {
    "position_buffer": "buffers",
    "normal_buffer": "buffers",
    "index_buffer": "buffers",
    "color_buffer": "buffers",
    "row_offsets": "buffers",
    "fit_camera": "buffers",
    "ColorMapping": "colors",
    "scalar_colors": "colors",
    "error_colors": "colors",
    "label_colors": "colors",
    "colorbar_html": "colors",
    "legend_html": "colors",
    "gallery_indices": "gallery",
    "mesh_caption": "gallery",
    "angular_stripes": "gallery",
    "render_mesh": "render",
    "render_mesh_grid": "render",
    "figure_to_png": "render",
    "resolve_mode": "fallback",
    "ImageView": "fallback",
    "MeshViewer": "viewer",
    "FramePlayer": "widgets",
    "LatentExplorer": "explorer",
    "LatentPad": "latent_pad",
    "InterpolationSlider": "widgets",
}

__all__ = sorted(_NAMES)


def __getattr__(name: str):
    try:
        module = _NAMES[name]
    except KeyError:
        raise AttributeError(f"module 'meshvae_lib.viewing' has no attribute {name!r}") from None
    return getattr(importlib.import_module(f"{__name__}.{module}"), name)


def __dir__():
    return sorted(list(globals()) + __all__)
