"""MeshViewer: one or several meshes of one connectivity, side by side, in a pythreejs scene.

The scene is built once. :meth:`MeshViewer.update` replaces the ``position`` and ``normal``
buffers of the existing geometries in place (normals computed with numpy by
:func:`~meshvae_lib.viewing.buffers.normal_buffer`; ``computeVertexNormals`` is never called in
the browser). All meshes sit in one renderer, so they share one camera and one set of orbit
controls: turning one turns all. When pythreejs cannot display (see
:func:`~meshvae_lib.viewing.fallback.resolve_mode`) the same object shows matplotlib renderings.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from meshvae_lib.geometry.topology import vertex_normals
from meshvae_lib.validation import check_vertices
from .buffers import color_buffer, fit_camera, index_buffer, position_buffer, row_offsets
from .colors import DEFAULT_MESH_COLOR, ColorMapping, colorbar_html, label_colors, legend_html, scalar_colors
from .fallback import ImageView, resolve_mode

__all__ = ["MeshViewer", "as_mesh_stack"]

log = logging.getLogger(__name__)


def as_mesh_stack(V, n_meshes: int | None = None, n_vertices: int | None = None) -> np.ndarray:
    """Meshes as one float64 stack.

    Parameters
    ----------
    V : (n_vertices, 3), (n_meshes, n_vertices, 3) float, or a list of (n_vertices, 3)
    n_meshes, n_vertices : int, optional
        Expected counts (checked when given).

    Returns
    -------
    Vs : (n_meshes, n_vertices, 3) float64
    """
    if isinstance(V, (list, tuple)):
        if not V:
            raise ValueError("no meshes given")
        arrs = [check_vertices(v, f"V[{i}]", batch=False, finite=True) for i, v in enumerate(V)]
        counts = {len(a) for a in arrs}
        if len(counts) != 1:
            raise ValueError(f"all meshes must have the same vertex count, got {sorted(counts)}")
        Vs = np.stack(arrs)
    else:
        Vs = np.asarray(V, dtype=np.float64)
        if Vs.ndim == 2:
            Vs = check_vertices(Vs, "V", batch=False, finite=True)[None]
        elif Vs.ndim != 3 or Vs.shape[2] != 3 or 0 in Vs.shape:
            raise ValueError(f"V must be (n_vertices, 3), (n_meshes, n_vertices, 3) or a list, got {Vs.shape}")
        elif not np.all(np.isfinite(Vs)):
            raise ValueError("V has NaN or infinite coordinates")
    if n_meshes is not None and Vs.shape[0] != n_meshes:
        raise ValueError(f"expected {n_meshes} mesh(es), got {Vs.shape[0]} (shape {Vs.shape})")
    if n_vertices is not None and Vs.shape[1] != n_vertices:
        raise ValueError(f"expected meshes with {n_vertices} vertices, got {Vs.shape[1]}")
    return Vs


class MeshViewer:
    """Interactive 3D view of one or several meshes sharing the faces ``F``.

    Parameters
    ----------
    V : (n_vertices, 3), (n_meshes, n_vertices, 3) float or list of (n_vertices, 3)
        The meshes, placed side by side along x in this order.
    F : (n_faces, 3) int
        Shared triangles.
    colors : colour, (n_vertices, 3), (n_meshes, n_vertices, 3) float, or list per mesh; optional
        Explicit per-vertex RGB in [0, 1] (overrides ``values`` and ``labels``); in a list, None
        means the default colour (e.g. ``[None, err_colors]`` for truth and reconstruction).
    values : (n_vertices,) or (n_meshes, n_vertices) float, optional
        A scalar per vertex (e.g. an error), coloured with ``cmap`` over one shared range, with a
        colour bar under the view.
    cmap, vmin, vmax, value_label
        Colour map, range and colour bar caption for ``values``.
    labels : (n_vertices,) int or str, optional
        A categorical label per vertex (e.g. segments), with a legend.
    titles : list of str, optional
        One caption per mesh, shown above it.
    width, height : int
        Size of the 3D view in pixels.
    gap : float
        Space between neighbouring meshes (fraction of a mesh's width).
    background : str
        CSS colour of the view.
    flat_shading, wireframe : bool
        Material options.
    mode : {"auto", "threejs", "image", "static"}
        How to display (see :func:`~meshvae_lib.viewing.fallback.resolve_mode`).
    snapshot : bool
        In "threejs" mode, also put a small matplotlib PNG of the initial state into the display
        data. JupyterLab shows the live 3D view; exports without widget state (nbconvert HTML,
        GitHub) and untrusted notebooks show the PNG instead of an empty widget.
    snapshot_size : float
        Inches per panel of that PNG (default 2.2, at ``snapshot_dpi`` dots per inch, default 60).

    Attributes
    ----------
    mode : str
        The mode actually used.
    n_meshes, n_vertices : int
    positions : list of (n_vertices, 3) float32
        What the view currently shows (the arrays sent to the browser in "threejs" mode).
    normals : list of (n_vertices, 3) float32
    n_updates : int
    last_update_ms : float
        Kernel-side time of the last :meth:`update` (normals + buffer hand-off), in milliseconds.
    widget : ipywidgets.Widget or None
        The displayable widget (None in "static" mode, where the viewer itself displays a PNG).
    """

    def __init__(self, V, F, colors=None, values=None, cmap: str = "viridis", vmin=None, vmax=None,
                 value_label: str = "", labels=None, titles=None, width: int = 720, height: int = 400,
                 gap: float = 0.25, background: str = "#ffffff", flat_shading: bool = False,
                 wireframe: bool = False, mode: str = "auto", snapshot: bool = True,
                 snapshot_size: float = 2.2, snapshot_dpi: int = 60):
        Vs = as_mesh_stack(V)
        self.n_meshes, self.n_vertices = Vs.shape[0], Vs.shape[1]
        self.F = np.asarray(F).astype(np.int64)
        self._index = index_buffer(self.F, self.n_vertices)  # validates F
        if titles is not None and len(titles) != self.n_meshes:
            raise ValueError(f"{len(titles)} titles for {self.n_meshes} meshes")
        if width < 32 or height < 32:
            raise ValueError(f"width and height must be at least 32 pixels, got {width}x{height}")
        self.titles = None if titles is None else [str(t) for t in titles]
        self.width, self.height = int(width), int(height)
        self.mode = resolve_mode(mode)
        self.snapshot = bool(snapshot)
        if not snapshot_size > 0 or not snapshot_dpi > 0:
            raise ValueError(f"snapshot_size and snapshot_dpi must be positive, got {snapshot_size}, {snapshot_dpi}")
        self.snapshot_size, self.snapshot_dpi = float(snapshot_size), int(snapshot_dpi)
        self.n_updates = 0
        self.last_update_ms = float("nan")
        self.mapping: ColorMapping | None = None
        self.legend = None
        self._colors = self._resolve_colors(colors, values, cmap, vmin, vmax, value_label, labels)
        self.positions = [position_buffer(v) for v in Vs]
        self.normals = list(np.asarray(vertex_normals(Vs, self.F), dtype=np.float32))
        self._offsets = row_offsets(Vs, gap=gap)
        self._image = None
        self.widget = None
        if self.mode == "threejs":
            self._build_three(Vs, background, flat_shading, wireframe)
        else:
            self._image = ImageView(list(Vs), self.F, colors=self._colors, titles=self.titles,
                                    colorbar=self.mapping, legend=self.legend, mode=self.mode)
            self.widget = self._image.widget
            if self.widget is not None:
                self.widget.add_class("meshvae-viewer")

    # -- colours -------------------------------------------------------------------------------
    def _resolve_colors(self, colors, values, cmap, vmin, vmax, value_label, labels) -> list[np.ndarray]:
        """Per-mesh float32 (n_vertices, 3) colours; sets :attr:`mapping` / :attr:`legend`."""
        k, n = self.n_meshes, self.n_vertices
        if colors is not None:
            if isinstance(colors, (list, tuple)) and len(colors) == k and not isinstance(colors[0], (int, float)):
                return [color_buffer(DEFAULT_MESH_COLOR if c is None else c, n) for c in colors]
            C = colors if isinstance(colors, str) else np.asarray(colors, dtype=np.float64)
            if not isinstance(C, str) and C.ndim == 3:
                if C.shape[0] != k:
                    raise ValueError(f"colors has {C.shape[0]} meshes' colours for {k} meshes")
                return [color_buffer(c, n) for c in C]
            return [color_buffer(C, n)] * k
        if values is not None:
            v = np.asarray(values, dtype=np.float64)
            if v.shape == (n,):
                v = np.broadcast_to(v, (k, n))
            if v.shape != (k, n):
                raise ValueError(f"values must have shape ({n},) or ({k}, {n}), got {v.shape}")
            C, self.mapping = scalar_colors(v, cmap=cmap, vmin=vmin, vmax=vmax, label=value_label)
            return [np.ascontiguousarray(c) for c in C]
        if labels is not None:
            lab = np.asarray(labels)
            if lab.shape != (n,):
                raise ValueError(f"labels must have shape ({n},), got {lab.shape}")
            C, self.legend = label_colors(lab)
            return [C] * k
        return [color_buffer(DEFAULT_MESH_COLOR, n)] * k

    def set_colors(self, colors=None, values=None, cmap: str = "viridis", vmin=None, vmax=None,
                   value_label: str = "", labels=None):
        """Recolour the meshes in place (same arguments as the constructor's colour options).

        With none of ``colors``, ``values``, ``labels`` the default colour is restored.
        """
        self.mapping, self.legend = None, None
        self._colors = self._resolve_colors(colors, values, cmap, vmin, vmax, value_label, labels)
        if self.mode == "threejs":
            for attr, c in zip(self._color_attrs, self._colors):
                attr.array = c
            self._caption.value = self._caption_html()
        else:
            self._image.colorbar, self._image.legend = self.mapping, self.legend
            self._image.update(colors=self._colors)

    @property
    def colors(self) -> list[np.ndarray]:
        """Current per-vertex colours, one (n_vertices, 3) float32 array per mesh."""
        return list(self._colors)

    def _caption_html(self) -> str:
        if self.mapping is not None:
            return colorbar_html(self.mapping, width=min(300, self.width // 2))
        if self.legend:
            return legend_html(self.legend)
        return ""

    # -- the pythreejs scene -------------------------------------------------------------------
    def _build_three(self, Vs, background, flat_shading, wireframe):
        import ipywidgets as W
        import pythreejs as three

        index = three.BufferAttribute(array=self._index, normalized=False)
        material = three.MeshPhongMaterial(vertexColors="VertexColors", side="DoubleSide", shininess=20,
                                           specular="#222222", flatShading=flat_shading, wireframe=wireframe)
        self._pos_attrs, self._nrm_attrs, self._color_attrs, self._meshes = [], [], [], []
        for i in range(self.n_meshes):
            pos = three.BufferAttribute(array=self.positions[i], normalized=False)
            nrm = three.BufferAttribute(array=self.normals[i], normalized=False)
            col = three.BufferAttribute(array=self._colors[i], normalized=False)
            geom = three.BufferGeometry(attributes={"position": pos, "normal": nrm, "color": col, "index": index})
            mesh = three.Mesh(geometry=geom, material=material, position=tuple(float(x) for x in self._offsets[i]),
                              frustumCulled=False)
            self._pos_attrs.append(pos)
            self._nrm_attrs.append(nrm)
            self._color_attrs.append(col)
            self._meshes.append(mesh)
        pts = np.concatenate([Vs[i] + self._offsets[i] for i in range(self.n_meshes)])
        aspect = self.width / self.height
        position, target = fit_camera(pts, fov=40.0, aspect=aspect)
        scale = float(np.linalg.norm(position - target))
        # A hemisphere light riding on the camera: it turns with the orbit controls. (Directional,
        # point and spot lights make pythreejs 2.4.2 log "Error setting state: t.on is not a
        # function" in JupyterLab 4 -- their shadow models -- so they are not used.)
        light = three.HemisphereLight(color="#ffffff", groundColor="#404040", intensity=0.8,
                                      position=tuple(float(x) for x in np.array([-0.4, 0.8, 0.0]) * scale))
        self.camera = three.PerspectiveCamera(position=tuple(float(x) for x in position), fov=40.0, aspect=aspect,
                                              near=scale * 1e-3, far=scale * 100.0, children=[light])
        self._home = (tuple(float(x) for x in position), tuple(float(x) for x in target))
        self.scene = three.Scene(children=[*self._meshes, self.camera, three.AmbientLight(color="white", intensity=0.35)],
                                 background=background)
        self.controls = three.OrbitControls(controlling=self.camera, target=tuple(float(x) for x in target))
        self.renderer = three.Renderer(camera=self.camera, scene=self.scene, controls=[self.controls],
                                       width=self.width, height=self.height, antialias=True)
        parts = []
        if self.titles is not None:
            cell = f"{self.width / self.n_meshes:.0f}px"
            parts.append(W.HBox([W.HTML(f"<div style='text-align:center'><b>{t}</b></div>",
                                        layout=W.Layout(width=cell)) for t in self.titles]))
        parts.append(self.renderer)
        self._caption = W.HTML(self._caption_html())
        parts.append(self._caption)
        self.widget = W.VBox(parts)
        self.widget.add_class("meshvae-viewer")  # a stable hook for styling and browser tests

    def reset_camera(self):
        """Put the camera back where it started (threejs mode; no-op otherwise)."""
        if self.mode == "threejs":
            position, target = self._home
            self.camera.position = position
            self.controls.target = target
            self.controls.exec_three_obj_method("update")

    # -- updates -------------------------------------------------------------------------------
    def update(self, V, index: int | None = None):
        """Show new vertex positions (same connectivity), updating buffers in place.

        Parameters
        ----------
        V : (n_vertices, 3), (n_meshes, n_vertices, 3) float or list of (n_vertices, 3)
            New positions for every mesh; or, with ``index``, for mesh ``index`` only.
        index : int, optional
            Which mesh ``V`` replaces.
        """
        t0 = time.perf_counter()
        if index is not None:
            if not 0 <= index < self.n_meshes:
                raise ValueError(f"index {index} out of range for {self.n_meshes} meshes")
            Vs = as_mesh_stack(V, n_meshes=1, n_vertices=self.n_vertices)
            which = [index]
        else:
            Vs = as_mesh_stack(V, n_meshes=self.n_meshes, n_vertices=self.n_vertices)
            which = list(range(self.n_meshes))
        P = Vs.astype(np.float32)
        N = np.asarray(vertex_normals(Vs, self.F), dtype=np.float32)
        self.set_buffers(P, N, which)
        self.n_updates += 1
        self.last_update_ms = 1e3 * (time.perf_counter() - t0)

    def set_buffers(self, P, N, which=None):
        """Hand positions ``P`` and normals ``N`` ((len(which), n_vertices, 3) float32) of the meshes
        ``which`` (default all) to the view as they are: the last stage of :meth:`update`, which
        computes the normals first."""
        which = list(range(self.n_meshes)) if which is None else list(which)
        for j, i in enumerate(which):
            self.positions[i] = np.ascontiguousarray(P[j], dtype=np.float32)
            self.normals[i] = np.ascontiguousarray(N[j], dtype=np.float32)
        if self.mode == "threejs":
            for i in which:
                self._pos_attrs[i].array = self.positions[i]
                self._nrm_attrs[i].array = self.normals[i]
        else:
            self._image.update(meshes=[p.astype(np.float64) for p in self.positions])

    # -- static copies ---------------------------------------------------------------------------
    def figure(self, **render_kw):
        """The current state as a matplotlib figure (to save what the view shows).

        Parameters
        ----------
        **render_kw
            Passed to :func:`~meshvae_lib.viewing.render.render_mesh_grid` (``view``, ``size``,
            ``dpi``, ``ncols``...).

        Returns
        -------
        fig : MeshFigure
        """
        from .render import render_mesh_grid

        render_kw.setdefault("ncols", self.n_meshes)
        return render_mesh_grid([p.astype(np.float64) for p in self.positions], self.F, titles=self.titles,
                                colors=self._colors, colorbar=self.mapping, legend=self.legend, **render_kw)

    def snapshot_png(self, size: float | None = None, dpi: int | None = None) -> bytes:
        """A small PNG of the current state: ``bytes``; ``size`` inches per panel at ``dpi`` dots per
        inch (default the viewer's ``snapshot_size`` and ``snapshot_dpi``)."""
        from .render import figure_to_png

        return figure_to_png(self.figure(size=self.snapshot_size if size is None else size,
                                         dpi=self.snapshot_dpi if dpi is None else dpi))

    # -- display -------------------------------------------------------------------------------
    def __repr__(self) -> str:
        return f"MeshViewer({self.n_meshes} mesh{'es' if self.n_meshes != 1 else ''} x {self.n_vertices} vertices, mode={self.mode!r})"

    def _repr_mimebundle_(self, include=None, exclude=None):
        if self.widget is not None:
            data = self.widget._repr_mimebundle_()
            data["text/plain"] = repr(self)
            if self.mode == "threejs" and self.snapshot:
                data["image/png"] = self.snapshot_png()
            return data
        return {"image/png": self._image.png, "text/plain": repr(self)}

    def _ipython_display_(self):
        if self.widget is not None:
            from IPython.display import display

            display(self._repr_mimebundle_(), raw=True)
        else:
            self._image._ipython_display_()
