"""Choosing how to show meshes, and the matplotlib fallback when pythreejs cannot display.

Three display modes:

``"threejs"``
    A pythreejs WebGL view (needs a widget front end: JupyterLab, Notebook 7, VS Code).
``"image"``
    A matplotlib rendering shown in an ``ipywidgets.Image`` and re-rendered on every update (needs
    a widget front end, not WebGL).
``"static"``
    A matplotlib PNG displayed as a plain output, updated in place through a display handle
    (works everywhere: nbconvert, CI, course HTML, a terminal IPython).

:func:`resolve_mode` chooses: an explicit argument wins, then the environment variable
``MESHVAE_VIEWER`` (e.g. ``MESHVAE_VIEWER=static`` when rendering the course to HTML), then
detection: inside a Jupyter kernel with pythreejs importable -> ``"threejs"``; with ipywidgets only
-> ``"image"``; outside a kernel (a script, a terminal) -> ``"static"``.
"""

from __future__ import annotations

import logging
import os

import numpy as np

from .render import DEFAULT_VIEW, figure_to_png, render_mesh_grid

__all__ = ["MODES", "ENV_VAR", "in_kernel", "resolve_mode", "ImageView"]

log = logging.getLogger(__name__)

MODES = ("threejs", "image", "static")
ENV_VAR = "MESHVAE_VIEWER"


def in_kernel() -> bool:
    """True inside a Jupyter (ipykernel) kernel, where a widget front end may be listening."""
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    ip = get_ipython()
    return ip is not None and getattr(ip, "kernel", None) is not None


def _importable(name: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(name) is not None


def resolve_mode(mode: str | None = "auto") -> str:
    """The display mode to use.

    Parameters
    ----------
    mode : {"auto", "threejs", "image", "static"} or None
        ``"auto"``/None: ``$MESHVAE_VIEWER`` if set, else detected (see the module docstring).

    Returns
    -------
    mode : {"threejs", "image", "static"}

    Raises
    ------
    ValueError
        For an unknown mode (argument or environment variable).
    ImportError
        When the requested mode's package (pythreejs or ipywidgets) is not installed.
    """
    source = "argument"
    if mode in (None, "auto"):
        env = os.environ.get(ENV_VAR, "").strip().lower()
        if env and env != "auto":
            mode, source = env, f"${ENV_VAR}"
        else:
            if not in_kernel():
                chosen = "static"
            elif _importable("pythreejs") and _importable("ipywidgets"):
                chosen = "threejs"
            elif _importable("ipywidgets"):
                chosen = "image"
            else:
                chosen = "static"
            log.debug("viewer mode detected: %s", chosen)
            return chosen
    if mode not in MODES:
        raise ValueError(f"viewer mode must be one of {('auto',) + MODES}, got {mode!r} (from {source})")
    needs = {"threejs": ("pythreejs", "ipywidgets"), "image": ("ipywidgets",), "static": ()}[mode]
    for pkg in needs:
        if not _importable(pkg):
            raise ImportError(f"viewer mode {mode!r} needs {pkg}, which is not installed; use mode='static'")
    return mode


class ImageView:
    """A matplotlib view of several meshes of one connectivity, re-rendered on update.

    Parameters
    ----------
    meshes : list of k arrays (n_vertices, 3) float64
    F : (n_faces, 3) int
    colors : list of k entries (None, a colour, or (n_vertices, 3) float), or None
    titles : list of k str, optional
    colorbar : ColorMapping, optional
    legend : list of (name, colour), optional
    mode : {"image", "static"}
        ``"image"``: :attr:`widget` is an ``ipywidgets.Image`` whose PNG is replaced on update.
        ``"static"``: displaying the view shows a PNG; updates replace it through a display handle.
    view : (elev, azim) degrees
    size : float
        Panel size in inches.
    dpi : int

    Attributes
    ----------
    png : bytes
        The current rendering.
    n_renders : int
        How many times it has rendered.
    """

    def __init__(self, meshes, F, colors=None, titles=None, colorbar=None, legend=None, mode="image",
                 view=DEFAULT_VIEW, size: float = 2.6, dpi: int = 80, up: str = "y"):
        if mode not in ("image", "static"):
            raise ValueError(f"ImageView mode must be 'image' or 'static', got {mode!r}")
        self.mode = mode
        self.F = np.asarray(F)
        self.meshes = [np.asarray(V, dtype=np.float64) for V in meshes]
        self.colors = list(colors) if colors is not None else [None] * len(self.meshes)
        self.titles = titles
        self.colorbar = colorbar
        self.legend = legend
        self.view, self.size, self.dpi, self.up = view, size, dpi, up
        self.n_renders = 0
        self._handle = None
        self.widget = None
        self.png = self.render()
        if mode == "image":
            import ipywidgets as W

            self.widget = W.Image(value=self.png, format="png")

    def figure(self):
        """The current meshes as a :class:`matplotlib.figure.Figure`."""
        return render_mesh_grid(self.meshes, self.F, titles=self.titles, ncols=max(len(self.meshes), 1),
                                colors=self.colors, colorbar=self.colorbar, legend=self.legend,
                                view=self.view, size=self.size, dpi=self.dpi, up=self.up)

    def render(self) -> bytes:
        """Render the current state to PNG bytes (stored in :attr:`png`)."""
        self.png = figure_to_png(self.figure())
        self.n_renders += 1
        return self.png

    def update(self, meshes=None, colors=None, colorbar=None, legend=None):
        """Replace meshes and/or colours and re-render.

        Parameters
        ----------
        meshes : list of k arrays (n_vertices, 3), optional
        colors : list of k colour entries, optional
        colorbar : ColorMapping, optional
        legend : list of (name, colour), optional
        """
        if meshes is not None:
            self.meshes = [np.asarray(V, dtype=np.float64) for V in meshes]
        if colors is not None:
            self.colors = list(colors)
        if colorbar is not None:
            self.colorbar = colorbar
        if legend is not None:
            self.legend = legend
        self.render()
        if self.widget is not None:
            self.widget.value = self.png
        elif self._handle is not None:
            self._handle.update(self._bundle(), raw=True)

    def _bundle(self) -> dict:
        return {"image/png": self.png, "text/plain": f"<{len(self.meshes)} mesh rendering(s)>"}

    def _ipython_display_(self):
        if self.widget is not None:
            from IPython.display import display

            display(self.widget)
            return
        from IPython.display import display

        self._handle = display(self._bundle(), raw=True, display_id=True)

    def _repr_png_(self):
        return self.png
