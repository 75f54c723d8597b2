"""Diagrams of the RIMD feature (notebook 02): the polar decomposition and the feature layout.

- :func:`polar_decomposition_figure` draws what ``T = R S`` does to a one-ring, in 2D: ``S``
  stretches it along its eigenvectors, then ``R`` turns it.
- :func:`feature_layout_figure` draws one feature vector as a bar: the rotation block (``log dR_ij``
  of every directed edge, 3 numbers each) and the scaling block (``S_i`` of every vertex, 6 numbers
  each), to scale, with the places of one edge's two directions and of one vertex's ``S_i`` marked.

Both return a new matplotlib Figure (``plt.show()`` displays it) and change nothing else.
"""

from __future__ import annotations

import numpy as np

__all__ = ["polar_decomposition_figure", "feature_layout_figure"]


def _one_ring(n: int = 6) -> np.ndarray:
    angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.stack([np.cos(angles), np.sin(angles)], axis=1)


def polar_decomposition_figure(T, n_neighbours: int = 6, figsize=(9.0, 3.2)):
    """Three panels: a 2D one-ring, the same after ``S``, and after ``R S = T``.

    Parameters
    ----------
    T : (2, 2) float
        The deformation gradient (2D analogue of a vertex's ``T_i``), ``det T > 0``.
    n_neighbours : int
        Neighbours of the drawn one-ring, evenly spaced on the unit circle.

    Returns
    -------
    matplotlib.figure.Figure
        Panels titled "reference one-ring", "S: stretch ..." and "R S = T: ...". The reference ring
        is drawn in grey in every panel; the second panel shows the eigenvectors of ``S`` scaled by
        their eigenvalues, the third the turn of ``R`` as an arc with its angle in degrees.

    Raises
    ------
    ValueError
        If ``T`` is not a 2x2 matrix with a positive determinant.
    """
    import matplotlib.pyplot as plt

    T = np.asarray(T, dtype=float)
    if T.shape != (2, 2) or not np.linalg.det(T) > 0:
        raise ValueError("T must be a 2x2 matrix with a positive determinant")
    U, sig, Vt = np.linalg.svd(T)
    R = U @ Vt
    S = Vt.T @ np.diag(sig) @ Vt
    angle = float(np.degrees(np.arctan2(R[1, 0], R[0, 0])))
    ring = _one_ring(n_neighbours)
    circle = _one_ring(120)
    stages = [("reference one-ring", np.eye(2)),
              (f"S: stretch by {sig.max():.2f} and {sig.min():.2f}", S),
              (f"R S = T: then turn by {angle:.0f}°", T)]
    fig, axes = plt.subplots(1, 3, figsize=figsize)
    lim = 1.15 * max(1.0, float(sig.max()))
    for ax, (title, M) in zip(axes, stages):
        ax.plot(*np.vstack([circle, circle[:1]]).T, color="0.8", lw=1)
        for p in ring:
            ax.plot([0, p[0]], [0, p[1]], color="0.75", lw=1)
        q = ring @ M.T
        c = circle @ M.T
        ax.plot(*np.vstack([c, c[:1]]).T, color="C0", lw=1.5)
        for k, p in enumerate(q):
            ax.plot([0, p[0]], [0, p[1]], color="C0", lw=2)
        ax.plot(*q[0], "o", color="C3", ms=7, label="neighbour 1")
        ax.plot(0, 0, "ko", ms=5)
        ax.set_title(title, fontsize=11)
        ax.set_xlim(-lim, lim)
        ax.set_ylim(-lim, lim)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
    w, v = np.linalg.eigh(S)
    for lam, vec in zip(w, v.T):
        axes[1].annotate("", xy=lam * vec, xytext=(0, 0),
                         arrowprops=dict(arrowstyle="->", color="C1", lw=2.5))
    axes[1].plot([], [], color="C1", lw=2.5, label="eigenvectors of S")
    start = np.degrees(np.arctan2(*(S @ ring[0])[::-1]))
    arc = np.radians(np.linspace(start, start + angle, 40))
    r_arc = 0.45 * lim
    axes[2].plot(r_arc * np.cos(arc), r_arc * np.sin(arc), color="C2", lw=2, label="turn of R")
    for ax in axes[1:]:
        ax.legend(fontsize=9, loc="lower right")
    fig.tight_layout()
    return fig


def feature_layout_figure(layout, edge, figsize=(9.5, 2.6)):
    """One RIMD feature vector drawn to scale, with one edge's and one vertex's entries marked.

    Parameters
    ----------
    layout : meshvae_lib.geometry.rimd.RIMDLayout
        The layout of the feature (``RIMDEncoder(...).layout``).
    edge : (int, int)
        An edge ``(i, j)`` of the mesh: the places of ``log dR_ij``, of ``log dR_ji`` (paper layout)
        and of ``S_i`` are marked.

    Returns
    -------
    matplotlib.figure.Figure
        One axes: the rotation block and the scaling block as two coloured spans over ``[0, K)``
        (labelled with their sizes), and a marker with a label at each marked entry.
    """
    import matplotlib.pyplot as plt

    i, j = (int(edge[0]), int(edge[1]))
    rot, sca = layout.rotation_slice, layout.scaling_slice
    K = layout.K
    fig, ax = plt.subplots(figsize=figsize)
    ax.axvspan(rot.start, rot.stop, ymin=0.3, ymax=0.6, color="C1", alpha=0.8)
    ax.axvspan(sca.start, sca.stop, ymin=0.3, ymax=0.6, color="C2", alpha=0.8)
    ax.text((rot.start + rot.stop) / 2, 0.45, f"rotation block: log dR, 3 per directed edge\n{rot.stop - rot.start} numbers",
            ha="center", va="center", fontsize=10)
    ax.text((sca.start + sca.stop) / 2, 0.45, f"S block: 6 per vertex\n{sca.stop - sca.start} numbers",
            ha="center", va="center", fontsize=10)
    marks = [(int(layout.edge_feature_index(i, j)[0]), f"log dR_{i},{j}", "C3", 0.75)]
    if layout.layout == "paper":
        marks.append((int(layout.edge_feature_index(j, i)[0]), f"log dR_{j},{i}", "C3", 0.92))
    marks.append((int(layout.vertex_feature_index(i)[0]), f"S_{i}", "C0", 0.75))
    for pos, label, color, y in marks:
        ax.plot([pos, pos], [0.28, y - 0.04], color=color, lw=2)
        ha = "left" if pos < 0.15 * K else "right" if pos > 0.85 * K else "center"
        ax.text(pos, y, f"{label} at f[{pos}]", color=color, ha=ha, va="bottom", fontsize=10)
    ax.set_xlim(0, K)
    ax.set_ylim(0.1, 1.1)
    ax.set_yticks([])
    ax.set_xlabel(f"position in the feature vector (K = {K})", fontsize=10)
    for side in ("left", "right", "top"):
        ax.spines[side].set_visible(False)
    fig.tight_layout()
    return fig
