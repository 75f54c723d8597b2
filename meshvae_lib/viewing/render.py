"""Shaded matplotlib renderings of triangle meshes: static figures, the README, and the fallback.

A small software renderer: an orthographic view from ``(elev, azim)``, Lambert shading of the
face normals (:func:`meshvae_lib.geometry.topology.face_normals`, two-sided, light from the upper left of
the viewer), and the painter's algorithm (faces drawn far to near as one ``PolyCollection``). It
uses a plain 2D axes, so it is fast (a 5k-face mesh renders in well under a second) and looks the
same in every backend. Only ``matplotlib.figure`` and ``matplotlib.collections`` are imported;
figures are created without pyplot, so nothing is left open in pyplot's figure manager.
"""

from __future__ import annotations

import io
import math

import numpy as np
from matplotlib.figure import Figure

from meshvae_lib.geometry.topology import face_normals
from meshvae_lib.tolerances import VIEW_PARALLEL_TOL
from meshvae_lib.validation import check_choice, check_count, check_faces, check_vertices
from .buffers import color_buffer
from .colors import DEFAULT_MESH_COLOR, ColorMapping

__all__ = ["MeshFigure", "view_basis", "project", "shade", "render_mesh", "render_mesh_grid", "figure_to_png"]

#: default view (elevation, azimuth) in degrees: slightly from above and from the front-right.
DEFAULT_VIEW = (15.0, 30.0)
_UP_AXES = {"y": np.array([0.0, 1.0, 0.0]), "z": np.array([0.0, 0.0, 1.0])}


class MeshFigure(Figure):
    """A matplotlib Figure that Jupyter shows as a PNG even when pyplot was never imported.

    Figures made without pyplot have no PNG formatter until the inline backend is loaded, so a
    cell ending in ``fig`` would show only ``<Figure size ...>``; ``_repr_png_`` fixes that.
    """

    def _repr_png_(self):
        return figure_to_png(self)


def view_basis(view=DEFAULT_VIEW, up: str = "y") -> np.ndarray:
    """Orthonormal camera frame for a view.

    Parameters
    ----------
    view : (elev, azim) degrees
        ``(0, 0)`` looks at the front (from +z towards the origin when ``up="y"``, from -y when
        ``up="z"``); positive ``elev`` looks from above, positive ``azim`` turns the camera to the
        right about the up axis.
    up : {"y", "z"}
        Which model axis points up on screen.

    Returns
    -------
    R : (3, 3) float64
        Rows: screen right, screen up, towards the viewer.
    """
    check_choice(up, tuple(_UP_AXES), "up")
    elev, azim = (math.radians(float(a)) for a in view)
    if up == "y":
        d = np.array([math.cos(elev) * math.sin(azim), math.sin(elev), math.cos(elev) * math.cos(azim)])
    else:
        d = np.array([math.cos(elev) * math.sin(azim), -math.cos(elev) * math.cos(azim), math.sin(elev)])
    u = _UP_AXES[up]
    right = np.cross(u, d)
    if np.linalg.norm(right) < VIEW_PARALLEL_TOL:  # looking straight down the up axis
        right = np.cross(np.array([0.0, 0.0, 1.0]) if up == "y" else np.array([0.0, 1.0, 0.0]), d)
    right /= np.linalg.norm(right)
    true_up = np.cross(d, right)
    return np.stack([right, true_up, d])


def project(V, view=DEFAULT_VIEW, up: str = "y") -> np.ndarray:
    """Vertices in camera coordinates.

    Parameters
    ----------
    V : (n_vertices, 3) float

    Returns
    -------
    P : (n_vertices, 3) float64
        Columns: screen x, screen y, depth (larger is nearer the viewer).
    """
    return check_vertices(V, "V", batch=False, finite=True) @ view_basis(view, up).T


def shade(normals, basis, ambient: float = 0.35, diffuse: float = 0.65) -> np.ndarray:
    """Two-sided Lambert intensity per face.

    Parameters
    ----------
    normals : (n_faces, 3) float64
        Unit face normals in model coordinates.
    basis : (3, 3) float64
        From :func:`view_basis`; the light comes from the viewer's upper left.
    ambient, diffuse : float

    Returns
    -------
    intensity : (n_faces,) float64 in [ambient, ambient + diffuse]
    """
    light = np.array([-0.35, 0.55, 1.0]) @ basis  # camera frame -> model frame
    light /= np.linalg.norm(light)
    return ambient + diffuse * np.abs(normals @ light)


def _face_colors(colors, n_vertices: int, F: np.ndarray) -> np.ndarray:
    """Base RGB per face: per-vertex colours are averaged over the face's corners."""
    if colors is None:
        colors = DEFAULT_MESH_COLOR
    C = None if isinstance(colors, str) else np.asarray(colors, dtype=np.float64)
    if C is not None and C.ndim == 2 and C.shape[0] == len(F) and C.shape[0] != n_vertices:
        return np.array(color_buffer(C, len(F)), dtype=np.float64)  # already per face
    Cv = color_buffer(colors, n_vertices).astype(np.float64)
    return Cv[F].mean(axis=1)


def render_mesh(
    ax,
    V,
    F,
    colors=None,
    view=DEFAULT_VIEW,
    up: str = "y",
    ambient: float = 0.35,
    edgecolor=None,
    linewidth: float = 0.0,
    cull_backfaces: bool = False,
    extent=None,
    center=None,
    props=None,
):
    """Draw one shaded mesh into a 2D matplotlib axes.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        A plain 2D axes; its limits are set to frame the mesh and its frame is hidden.
    V : (n_vertices, 3) float
    F : (n_faces, 3) int
    colors : None, str, (3,), (n_vertices, 3) or (n_faces, 3) float in [0, 1]
        Base colour(s) before shading (default a light blue-grey).
    view : (elev, azim) degrees, see :func:`view_basis`.
    up : {"y", "z"}
    ambient : float
        Intensity of faces lit edge-on; ``1 - ambient`` is added for faces facing the light.
    edgecolor, linewidth
        Passed to the collection (e.g. ``edgecolor="k", linewidth=0.1`` for a wireframe look).
    cull_backfaces : bool
        Skip faces pointing away from the viewer (only for closed, consistently oriented meshes).
    extent : float, optional
        Half size of the square frame, in model units (default: fits this mesh). Pass one value to
        several axes to draw them at one scale.
    center : (2,) float, optional
        Screen-space centre of the frame (default: the centre of the mesh's projection).
    props : list of (V (k, 3) float, F (m, 3) int, colour), optional
        Static scenery drawn with the mesh and depth-sorted with it (e.g. a flag's pole); it does
        not move the frame, which stays fitted to the mesh.

    Returns
    -------
    collection : matplotlib.collections.PolyCollection
    """
    from matplotlib.collections import PolyCollection

    V = check_vertices(V, "V", batch=False, finite=True)
    F = _faces(F, len(V), "F")
    R = view_basis(view, up)
    P_mesh = V @ R.T
    V, F, base = _with_props(V, F, _face_colors(colors, len(V), F), props)
    P = V @ R.T
    N = face_normals(V, F)
    rgb = np.clip(base * shade(N, R, ambient=ambient, diffuse=1.0 - ambient)[:, None], 0.0, 1.0)
    depth = P[F, 2].mean(axis=1)
    keep = np.ones(len(F), dtype=bool)
    if cull_backfaces:
        keep = (N @ R[2]) > 0.0
    order = np.argsort(depth[keep], kind="stable")
    idx = np.flatnonzero(keep)[order]
    polys = P[F[idx]][:, :, :2]
    coll = PolyCollection(
        polys,
        facecolors=rgb[idx],
        edgecolors=rgb[idx] if edgecolor is None else edgecolor,
        linewidths=linewidth if edgecolor is not None else 0.3,
        antialiaseds=True,
    )
    ax.add_collection(coll)
    _frame(ax, P_mesh, center, extent)
    return coll


def _faces(F, n_vertices: int, name: str) -> np.ndarray:
    """Triangles into ``n_vertices`` vertices, at least one: (n_faces, 3) int64."""
    F = check_faces(F, n_vertices=n_vertices, name=name)
    if len(F) == 0:
        raise ValueError(f"{name} must have shape (n_faces, 3) with n_faces > 0, got {F.shape}")
    return F


def _with_props(V, F, base, props):
    """The mesh and the scenery ``props`` in one set of vertices, faces and face colours."""
    if not props:
        return V, F, base
    parts_V, parts_F, parts_C, offset = [V], [F], [base], len(V)
    for k, prop in enumerate(props):
        if len(prop) != 3:
            raise ValueError(f"props[{k}] must be (V, F, colour), got {len(prop)} items")
        Vp = check_vertices(prop[0], f"props[{k}] V", batch=False, finite=True)
        try:
            Fp = _faces(prop[1], len(Vp), f"props[{k}] F")
        except ValueError as exc:
            raise ValueError(f"props[{k}] F must be (n_faces, 3) indices into its {len(Vp)} vertices ({exc})") from None
        parts_V.append(Vp)
        parts_F.append(Fp + offset)
        parts_C.append(_face_colors(prop[2], len(Vp), Fp))
        offset += len(Vp)
    return np.concatenate(parts_V), np.concatenate(parts_F), np.concatenate(parts_C)


def _frame(ax, P_mesh, center, extent) -> None:
    """Square limits around the projected mesh ``P_mesh`` (or ``center`` / ``extent``), no frame."""
    lo, hi = P_mesh[:, :2].min(axis=0), P_mesh[:, :2].max(axis=0)
    c = 0.5 * (lo + hi) if center is None else np.asarray(center, dtype=np.float64)
    e = 0.55 * float(np.max(hi - lo)) if extent is None else float(extent)
    e = max(e, 1e-12)
    ax.set_xlim(c[0] - e, c[0] + e)
    ax.set_ylim(c[1] - e, c[1] + e)
    ax.set_aspect("equal")
    ax.set_axis_off()


def _as_mesh_list(meshes) -> list[np.ndarray]:
    if isinstance(meshes, np.ndarray) and meshes.ndim == 2:
        meshes = [meshes]
    if isinstance(meshes, np.ndarray) and meshes.ndim != 3:
        raise ValueError(f"meshes must be (n_vertices, 3), (n_meshes, n_vertices, 3) or a list, got {meshes.shape}")
    out = [check_vertices(V, f"meshes[{i}]", batch=False, finite=True) for i, V in enumerate(meshes)]
    if not out:
        raise ValueError("no meshes to render")
    n = {len(V) for V in out}
    if len(n) != 1:
        raise ValueError(f"all meshes must share one connectivity; got vertex counts {sorted(n)}")
    return out


def _per_mesh(colors, k: int, n_vertices: int) -> list:
    """Split ``colors`` into one entry per mesh (None, one shared colour, or one per mesh)."""
    if colors is None or isinstance(colors, str):
        return [colors] * k
    if isinstance(colors, (list, tuple)) and len(colors) == k and not np.isscalar(colors[0]):
        return list(colors)
    C = np.asarray(colors, dtype=np.float64)
    if C.ndim == 3:
        if C.shape[0] != k:
            raise ValueError(f"colors has {C.shape[0]} entries for {k} meshes")
        return list(C)
    return [C] * k


def render_mesh_grid(
    meshes,
    F,
    titles=None,
    ncols: int = 4,
    colors=None,
    view=DEFAULT_VIEW,
    up: str = "y",
    size: float = 2.4,
    same_scale: bool = True,
    colorbar: ColorMapping | None = None,
    legend=None,
    suptitle: str | None = None,
    dpi: int = 100,
    **render_kw,
):
    """Several meshes of one connectivity in a grid of shaded renderings.

    Parameters
    ----------
    meshes : (n_meshes, n_vertices, 3) float, a list of (n_vertices, 3), or one (n_vertices, 3)
    F : (n_faces, 3) int
    titles : sequence of str, optional
        One title per mesh.
    ncols : int
        Columns of the grid (rows follow).
    colors : None, a colour, (n_vertices, 3), (n_meshes, n_vertices, 3) or a list per mesh
    view, up
        See :func:`view_basis`.
    size : float
        Size of each panel in inches.
    same_scale : bool
        Draw every mesh at one scale (sizes compare); each panel is still centred on its mesh.
    colorbar : ColorMapping, optional
        Adds a horizontal colour bar under the grid (e.g. from :func:`~.colors.error_colors`).
    legend : list of (name, colour), optional
        Adds a legend of swatches (e.g. from :func:`~.colors.label_colors`).
    suptitle : str, optional
    dpi : int
    **render_kw
        Passed to :func:`render_mesh` (``edgecolor``, ``cull_backfaces``, ...).

    Returns
    -------
    fig : MeshFigure (a matplotlib.figure.Figure)
        Not registered with pyplot: display it (Jupyter shows it as the cell's result, as a PNG) or
        save it with ``fig.savefig``; :func:`figure_to_png` gives the PNG bytes.
    """
    Vs = _as_mesh_list(meshes)
    k = len(Vs)
    check_count(ncols, "ncols", minimum=1)
    if titles is not None and len(titles) != k:
        raise ValueError(f"{len(titles)} titles for {k} meshes")
    cols = _per_mesh(colors, k, len(Vs[0]))
    nc = min(ncols, k)
    nr = int(math.ceil(k / nc))
    extra = 0.7 if (colorbar is not None or legend) else 0.0
    lines = max((str(t).count("\n") + 1 for t in titles), default=1) if titles is not None else 0
    top = (0.35 if suptitle else 0.0) + (0.25 + 0.16 * max(lines - (1 if suptitle else 2), 0) if titles is not None else 0.0)
    fig = MeshFigure(figsize=(size * nc, size * nr + extra + top), dpi=dpi)
    R = view_basis(view, up)
    extent = None
    if same_scale:
        extent = 0.55 * max(float(np.max(np.ptp(V @ R[:2].T, axis=0))) for V in Vs)
    for i, V in enumerate(Vs):
        ax = fig.add_subplot(nr, nc, i + 1)
        render_mesh(ax, V, F, colors=cols[i], view=view, up=up, extent=extent, **render_kw)
        if titles is not None:
            ax.set_title(str(titles[i]), fontsize=10)
    height = size * nr + extra + top
    bottom = extra / height
    fig.subplots_adjust(left=0.01, right=0.99, top=1.0 - top / height - 0.01, bottom=bottom + 0.01, wspace=0.02,
                        hspace=(max(0.15, (0.1 + 0.17 * lines) / size) if lines >= 2 else 0.15) if titles is not None else 0.02)
    if colorbar is not None:
        _add_colorbar(fig, colorbar, bottom)
    if legend:
        _add_legend(fig, legend)
    if suptitle:  # hung from the figure's top edge, so that it stays above two-line panel titles
        fig.suptitle(suptitle, y=1.0 - 0.04 / height, va="top")
    return fig


def _add_legend(fig, legend) -> None:
    """Swatches of ``legend`` (a list of (name, colour)) under the grid."""
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=c, edgecolor="#666", label=str(n)) for n, c in legend]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 6), fontsize=8, frameon=False)


def _add_colorbar(fig, colorbar: ColorMapping, bottom: float) -> None:
    """A horizontal colour bar of ``colorbar`` in the figure's bottom margin (``bottom``: its height)."""
    import matplotlib
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize

    cax = fig.add_axes([0.25, 0.62 * bottom, 0.5, 0.2 * bottom])
    sm = ScalarMappable(norm=Normalize(colorbar.vmin, colorbar.vmax), cmap=matplotlib.colormaps[colorbar.cmap])
    cb = fig.colorbar(sm, cax=cax, orientation="horizontal", extend=colorbar.extend)
    cb.ax.tick_params(labelsize=8)
    if colorbar.label:
        cb.set_label(colorbar.label, fontsize=9)


def figure_to_png(fig, dpi=None) -> bytes:
    """PNG bytes of a matplotlib figure.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    dpi : int, optional
        Default the figure's own dpi.

    Returns
    -------
    png : bytes
        Starts with the PNG signature ``b"\\x89PNG"``.
    """
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi, facecolor="white")
    return buf.getvalue()
