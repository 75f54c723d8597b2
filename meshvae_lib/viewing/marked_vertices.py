"""Shaded meshes with a few chosen vertices circled, so the eye finds them (notebook 01).

A per-vertex colour spreads over the vertex's triangles and fades into its neighbours: a handful
of bad vertices among thousands then shows as faint smudges. :func:`marked_vertices_figure`
draws each mesh in a neutral grey, colours the triangles around every marked vertex strongly and
circles the marked vertices on top (seen through the mesh, so none hides behind it).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib.validation import check_faces

__all__ = ["marked_vertices_figure"]

MARK_COLOUR = "#d00000"


def marked_vertices_figure(meshes, F, marked, titles=None, view=(10, 0), size: float = 4.4,
                           colour: str = MARK_COLOUR, legend: str | None = None):
    """Meshes side by side, each with its own set of vertices circled in a strong colour.

    Parameters
    ----------
    meshes : (k, n_vertices, 3) float or a list of (n_vertices, 3)
    F : (n_faces, 3) int
    marked : (k, n_vertices) bool, or a list of k index arrays
        The vertices to mark on each mesh.
    titles : list of k str, optional
        One title per panel; the number of marked vertices is appended on a line of its own.
    view : (elev, azim)
        See :func:`~meshvae_lib.viewing.render.view_basis`.
    size : float
        Panel size in inches (titles at 10 pt, the legend at 10 pt).
    colour : str
        The colour of the marks and of the triangles around each marked vertex.
    legend : str, optional
        A caption under the panels (what a mark means).

    Returns
    -------
    fig : MeshFigure
        One axes per mesh; each holds the shaded mesh and one scatter collection with ``gid``
        ``"marks"`` whose offsets are the marked vertices' screen positions; ``legend`` becomes a
        swatch of ``colour`` under the panels.
    """
    import matplotlib.colors as mcolors

    from meshvae_lib.viewing.render import _as_mesh_list, render_mesh_grid, view_basis

    Vs = _as_mesh_list(meshes)
    F = check_faces(F, n_vertices=len(Vs[0]), name="F")
    n = len(Vs[0])
    masks = []
    for k, m in enumerate(marked if not isinstance(marked, np.ndarray) or marked.ndim == 2 else [marked]):
        m = np.asarray(m)
        mask = m.astype(bool) if m.dtype == bool else np.isin(np.arange(n), m)
        if mask.shape != (n,):
            raise ValueError(f"marked[{k}] must be {n} booleans or vertex indices, got shape {m.shape}")
        masks.append(mask)
    if len(masks) != len(Vs):
        raise ValueError(f"{len(masks)} sets of marks for {len(Vs)} meshes")
    strong = np.array(mcolors.to_rgb(colour))
    base = np.array([0.78, 0.79, 0.82])
    colours = []
    for mask in masks:
        c = np.tile(base, (n, 1))
        near = np.zeros(n, dtype=bool)
        near[F[mask[F].any(axis=1)].ravel()] = True   # the triangles around each marked vertex
        c[near] = strong
        colours.append(c)
    full = [f"{t}\n" if titles is not None else "" for t in (titles if titles is not None else [None] * len(Vs))]
    full = [f"{t}{int(mask.sum())} {'vertex' if mask.sum() == 1 else 'vertices'} marked" for t, mask in zip(full, masks)]
    fig = render_mesh_grid(Vs, F, colors=colours, titles=full, ncols=len(Vs), size=size, view=view,
                           legend=[(legend, colour)] if legend else None)
    fig.subplots_adjust(top=1.0 - 0.5 / fig.get_figheight())   # room for two title lines
    R = view_basis(view)
    for ax, V, mask in zip(fig.axes, Vs, masks):
        P = V[mask] @ R.T
        ax.scatter(P[:, 0], P[:, 1], s=170, facecolors="none", edgecolors=colour, linewidths=2.0, zorder=5, gid="marks")
    for lg in fig.legends:
        for text in lg.get_texts():
            text.set_fontsize(10)
    return fig
