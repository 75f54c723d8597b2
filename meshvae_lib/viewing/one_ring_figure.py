"""A one-ring drawn with its cotangent angles and its normal edge (notebook 01, Eq. 1).

One pure function, :func:`one_ring_figure`, returns a matplotlib Figure of two panels drawn from
a real mesh: the one-ring of vertex ``i`` seen from above (projected onto its tangent plane), with
the edge ``(i, j)`` and the two angles opposite it, and the same ring seen from the side, with the
extra *normal edge* ``m_i = l n_i`` that the reference implementation adds to Eq. (1).
"""

from __future__ import annotations

import numpy as np

from meshvae_lib import defaults as hp
from meshvae_lib.geometry.topology import edges, vertex_normals
from meshvae_lib.validation import check_faces, check_vertices

__all__ = ["one_ring_figure", "opposite_apexes"]

_FS = 11   # points: titles and labels


def opposite_apexes(F, i: int, j: int) -> tuple[int, int]:
    """The third vertices ``(a, b)`` of the two triangles that share the edge ``(i, j)``.

    ``a`` is the apex of the triangle in which ``i -> j`` runs counter-clockwise (the angle
    alpha_ij of Eq. 1), ``b`` the apex of the other one (beta_ij). Raises ``ValueError`` unless
    exactly two triangles share the edge (a boundary edge has one).
    """
    F = np.asarray(F)
    a = b = None
    for tri in F[(F == i).any(axis=1) & (F == j).any(axis=1)]:
        k = int(np.flatnonzero(tri == i)[0])
        third = int(next(v for v in tri if v not in (i, j)))
        if tri[(k + 1) % 3] == j:
            a = third
        else:
            b = third
    if a is None or b is None:
        raise ValueError(f"the edge ({i}, {j}) must border two triangles (an interior edge)")
    return a, b


def _angle(p, q, r) -> float:
    """The angle at ``p`` between ``q - p`` and ``r - p``, in radians."""
    u, v = q - p, r - p
    return float(np.arctan2(np.linalg.norm(np.cross(u, v)), u @ v))


def one_ring_figure(V, F, i: int, j: int | None = None, size: float = 4.6):
    """Vertex ``i``'s one-ring, the edge ``(i, j)`` with its cotangent angles, and the normal edge.

    Left panel (the ring seen along the vertex normal, projected onto the tangent plane): the
    triangles around ``i`` in grey, the edge vectors ``e_ij = p_i - p_j`` as thin lines, the edge
    ``(i, j)`` in red, its two triangles in blue and orange, and an arc at each apex marking the
    angles ``alpha_ij`` and ``beta_ij`` opposite the edge, labelled with their values in degrees
    (measured in 3D). The title gives ``c_ij = cot alpha_ij + cot beta_ij``.

    Right panel (the same ring seen from the side, along the tangent direction perpendicular to
    ``(i, j)``): the ring's vertices and edges, almost on one line because a one-ring is nearly
    flat, and the normal edge ``m_i = l n_i`` as a green arrow from ``p_i``, with
    ``l = NORMAL_EDGE_SCALE x`` the mesh's mean edge length (as in
    :class:`~meshvae_lib.geometry.deformation_gradient.DeformationGradientOperator`).

    Parameters
    ----------
    V : (n_vertices, 3) float
    F : (n_faces, 3) int
    i : int
        The centre vertex.
    j : int, optional
        A neighbour of ``i`` whose edge is highlighted (default: the neighbour with the smallest
        index). The edge must border two triangles.
    size : float
        Height of the figure in inches (the width is twice that).

    Returns
    -------
    fig : matplotlib.figure.Figure
        Not registered with pyplot. Its two axes are titled; the apex arcs carry the
        ``gid`` ``"alpha"`` and ``"beta"``, the highlighted edge ``"edge-ij"`` and the normal
        edge ``"normal-edge"``.
    """
    from matplotlib.figure import Figure

    V = check_vertices(V, "V", batch=False, finite=True)
    F = check_faces(F, n_vertices=len(V), name="F")
    i = int(i)
    ring_faces = F[(F == i).any(axis=1)]
    if len(ring_faces) == 0:
        raise ValueError(f"vertex {i} belongs to no triangle")
    ring = np.unique(ring_faces[ring_faces != i])
    j = int(ring.min()) if j is None else int(j)
    if j not in ring:
        raise ValueError(f"vertex {j} is not a neighbour of vertex {i}")
    a, b = opposite_apexes(F, i, j)

    n = vertex_normals(V, F)[i]
    E = edges(F)
    length = float(hp.NORMAL_EDGE_SCALE * np.linalg.norm(V[E[:, 0]] - V[E[:, 1]], axis=1).mean())
    d = V[j] - V[i]
    t1 = d - (d @ n) * n
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    top = (V - V[i]) @ np.stack([t1, t2]).T      # tangent-plane coordinates
    side = (V - V[i]) @ np.stack([t2, n]).T       # seen along t1: the edge (i, j) points at the viewer
    alpha, beta = _angle(V[a], V[i], V[j]), _angle(V[b], V[i], V[j])
    c_ij = 1 / np.tan(alpha) + 1 / np.tan(beta)

    fig = Figure(figsize=(2.1 * size, size), dpi=100)
    ax, ax2 = fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2)
    scale = float(np.abs(top[ring]).max())
    _draw_top(ax, top, ring_faces, ring, (i, j, a, b), (alpha, beta), scale)
    ax.set_title(f"one-ring of vertex {i}, seen from above\n"
                 rf"$c_{{ij}}=\cot\alpha_{{ij}}+\cot\beta_{{ij}}$ = {c_ij:.2f}", fontsize=_FS)
    _draw_side(ax2, side, ring_faces, ring, i, length, scale)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.02, top=0.86, wspace=0.05)
    return fig


def _draw_top(ax, top, ring_faces, ring, vertices, angles, scale) -> None:
    """The ring seen from above: triangles, edges, the edge (i, j) and the arcs of its opposite angles."""
    from matplotlib.patches import Polygon, Wedge

    i, j, a, b = vertices
    alpha, beta = angles
    for tri in ring_faces:
        shared = {i, j} <= set(tri.tolist())
        colour = "0.9" if not shared else ("#cfe0f3" if a in tri else "#f6dcc8")
        ax.add_patch(Polygon(top[tri], closed=True, fc=colour, ec="0.45", lw=1.0))
    for k in ring:
        ax.plot(*top[[i, k]].T, color="0.2", lw=1.0)
    ax.plot(*top[[i, j]].T, color="#d62728", lw=3.5, gid="edge-ij", solid_capstyle="round")
    ax.plot(*top[ring].T, "o", color="0.2", ms=4)
    ax.plot(*top[i], "o", color="k", ms=7)
    for apex, angle, name, gid, colour in ((a, alpha, r"\alpha_{ij}", "alpha", "#1f5fa8"),
                                           (b, beta, r"\beta_{ij}", "beta", "#b5500b")):
        u, v = top[i] - top[apex], top[j] - top[apex]
        angles = sorted([np.degrees(np.arctan2(u[1], u[0])), np.degrees(np.arctan2(v[1], v[0]))])
        if angles[1] - angles[0] > 180:
            angles = [angles[1], angles[0] + 360]
        ax.add_patch(Wedge(top[apex], 0.22 * scale, angles[0], angles[1], fc=colour, alpha=0.55, ec=colour, gid=gid))
        out = top[apex] - 0.5 * (top[i] + top[j])
        out = out / (np.linalg.norm(out) + 1e-300)
        ax.annotate(rf"${name}$ = {np.degrees(angle):.0f}°", top[apex], xytext=top[apex] + 0.2 * scale * out,
                    ha="center", va="center", fontsize=_FS, color=colour, fontweight="bold")
    for k, name in ((i, "i"), (j, "j")):
        off = top[k] / (np.linalg.norm(top[k]) + 1e-300) if k != i else -top[j] / np.linalg.norm(top[j])
        ax.annotate(name, top[k], xytext=top[k] + 0.13 * scale * off, ha="center", va="center", fontsize=_FS + 1,
                    fontweight="bold")
    ax.annotate(r"$\mathbf{e}_{ij}=\mathbf{p}_i-\mathbf{p}_j$", 0.5 * (top[i] + top[j]),
                xytext=0.5 * (top[i] + top[j]) + np.array([0.0, 0.12 * scale]), ha="center", fontsize=_FS - 1,
                color="#d62728")
    ax.set_xlim(-1.45 * scale, 1.45 * scale)
    ax.set_ylim(-1.45 * scale, 1.45 * scale)
    ax.set_aspect("equal")
    ax.set_axis_off()


def _draw_side(ax2, side, ring_faces, ring, i, length, scale) -> None:
    """The ring seen from the side, with the normal edge m_i = l n_i as a green arrow."""
    from matplotlib.patches import FancyArrowPatch, Polygon

    for tri in ring_faces:
        ax2.add_patch(Polygon(side[tri], closed=True, fc="0.9", ec="0.45", lw=1.0, alpha=0.6))
    ax2.plot(*side[ring].T, "o", color="0.2", ms=4)
    ax2.plot(*side[i], "o", color="k", ms=7)
    ax2.add_patch(FancyArrowPatch(tuple(side[i]), tuple(side[i] + [0.0, length]), arrowstyle="-|>", mutation_scale=18,
                                  lw=2.5, color="#2ca02c", gid="normal-edge"))
    ax2.annotate(r"$\mathbf{m}_i = l\,\mathbf{n}_i$" + f"\n$l$ = {hp.NORMAL_EDGE_SCALE:g} × mean edge length",
                 tuple(side[i] + [0.0, length]), xytext=(12, 0), textcoords="offset points", ha="left", va="center",
                 fontsize=_FS, color="#2ca02c")
    ax2.annotate("i", side[i], xytext=(-12, -4), textcoords="offset points", fontsize=_FS + 1, fontweight="bold")
    ax2.set_xlim(-1.3 * scale, 1.6 * scale)
    lo = min(float(side[ring, 1].min()), 0.0)
    ax2.set_ylim(lo - 0.5 * scale, lo + 1.3 * scale)
    ax2.set_aspect("equal")
    ax2.set_axis_off()
    ax2.set_title("the same ring from the side: nearly flat;\n"
                  r"the normal edge $\mathbf{m}_i$ fixes $\mathbf{T}_i$ along the normal", fontsize=_FS)
