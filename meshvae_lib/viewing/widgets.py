"""ipywidgets controls around a :class:`~meshvae_lib.viewing.viewer.MeshViewer`.

- :class:`FramePlayer`: play / step through a mesh sequence (one or several side by side).
- :class:`~meshvae_lib.viewing.explorer.LatentExplorer` (its own module): a slider per latent
  dimension, a 2D pad, reset and random buttons.
- :class:`InterpolationSlider`: a slider ``t`` in [0, 1] between two meshes (linear blend of
  coordinates, or any ``interpolate(t)`` callable such as latent or RIMD interpolation).

Every control is usable from code as well (``player.frame = 3``, ``explorer.set_z(z)``,
``slider.t = 0.5``), which is what the unit tests and the benchmark do; the sliders follow.
"""

from __future__ import annotations


import numpy as np

from meshvae_lib.defaults import STATIC_DPI, STATIC_PANEL_INCHES, STATIC_STRIP_FRAMES

from .viewer import MeshViewer, as_mesh_stack

__all__ = ["FramePlayer", "InterpolationSlider"]



class _Displayable:
    """Shared display plumbing: ``widget`` is what Jupyter shows; text repr stays short."""

    widget = None
    viewer: MeshViewer

    def _repr_mimebundle_(self, include=None, exclude=None):
        if self.widget is None:
            return self.viewer._repr_mimebundle_()
        data = self.widget._repr_mimebundle_()
        data["text/plain"] = repr(self)
        if self.viewer.mode == "threejs" and self.viewer.snapshot:
            data["image/png"] = self.static_png()
        return data

    def static_png(self) -> bytes:
        """What a page without a widget front end shows (PNG ``bytes``): the view's current state,
        unless the widget says more in a picture (a player's strip, an explorer's grid)."""
        return self.viewer.snapshot_png()

    def _ipython_display_(self):
        from IPython.display import display

        if self.viewer.mode == "static":
            self.viewer._ipython_display_()
            if self.widget is not None:
                display(self.widget)
            return
        display(self._repr_mimebundle_(), raw=True)


# -- frame player ------------------------------------------------------------------------------
class FramePlayer(_Displayable):
    """Play a mesh sequence.

    Parameters
    ----------
    frames : (n_frames, n_vertices, 3) float, or a list of such arrays (same n_frames)
        One sequence, or several shown side by side (e.g. ground truth and two methods).
    F : (n_faces, 3) int
    fps : float
        Playback speed of the Play button.
    titles : list of str, optional
        One per sequence.
    loop : bool
        Whether playback repeats.
    frame_values : (n_frames, n_vertices) or (n_frames, n_sequences, n_vertices) float, optional
        A scalar per vertex and frame (e.g. each method's error over time), coloured on one range
        for the whole sequence (``vmin``/``vmax`` default to its minimum and maximum), with a
        colour bar; ``cmap`` and ``value_label`` as for :class:`MeshViewer`.
    static_size : float
        Inches per panel of :meth:`static_png`, the strip a page without widgets shows (default
        ``defaults.STATIC_PANEL_INCHES``).
    **viewer_kw
        Passed to :class:`MeshViewer` (``colors``, ``values``, ``width``, ``mode``, ...).

    Attributes
    ----------
    viewer : MeshViewer
    play : ipywidgets.Play
    slider : ipywidgets.IntSlider
        Linked to ``play`` in the browser (``jslink``); the kernel follows ``slider.value``.
    n_frames : int
    """

    def __init__(self, frames, F, fps: float = 10.0, titles=None, loop: bool = True, frame_values=None,
                 static_size: float = STATIC_PANEL_INCHES, **viewer_kw):
        import ipywidgets as W

        if not static_size > 0:
            raise ValueError(f"static_size must be positive, got {static_size}")
        self.static_size = float(static_size)
        seqs = frames if isinstance(frames, (list, tuple)) else [frames]
        stacks = []
        for i, s in enumerate(seqs):
            a = np.asarray(s, dtype=np.float64)
            if a.ndim != 3 or a.shape[2] != 3 or a.shape[0] == 0:
                raise ValueError(f"frames[{i}] must have shape (n_frames, n_vertices, 3), got {a.shape}")
            stacks.append(a)
        if len({a.shape for a in stacks}) != 1:
            raise ValueError(f"all sequences must have one shape, got {[a.shape for a in stacks]}")
        if not fps > 0:
            raise ValueError(f"fps must be positive, got {fps}")
        self._frames = np.stack(stacks, axis=1)  # (n_frames, n_sequences, n_vertices, 3)
        self.n_frames = self._frames.shape[0]
        self._frame_values = None
        if frame_values is not None:
            T, k, n = self._frames.shape[:3]
            fv = np.asarray(frame_values, dtype=np.float64)
            if fv.shape == (T, n):
                fv = np.broadcast_to(fv[:, None, :], (T, k, n))
            if fv.shape != (T, k, n):
                raise ValueError(f"frame_values must have shape ({T}, {n}) or ({T}, {k}, {n}), got {fv.shape}")
            finite = fv[np.isfinite(fv)]
            self._value_kw = dict(
                cmap=viewer_kw.pop("cmap", "viridis"),
                vmin=viewer_kw.pop("vmin", float(finite.min()) if finite.size else 0.0),
                vmax=viewer_kw.pop("vmax", float(finite.max()) if finite.size else 1.0),
                value_label=viewer_kw.pop("value_label", ""),
            )
            self._frame_values = fv
            viewer_kw["values"] = fv[0]
            viewer_kw.update(self._value_kw)
        self.viewer = MeshViewer(list(self._frames[0]), F, titles=titles, **viewer_kw)
        self.play = W.Play(value=0, min=0, max=self.n_frames - 1, step=1, interval=int(round(1000 / fps)),
                           repeat=loop, description="play")
        self.slider = W.IntSlider(value=0, min=0, max=self.n_frames - 1, step=1, description="frame",
                                  continuous_update=True)
        W.jslink((self.play, "value"), (self.slider, "value"))
        self.slider.observe(self._on_frame, names="value")
        self.widget = W.VBox([self.viewer.widget, W.HBox([self.play, self.slider])]) if self.viewer.widget is not None \
            else W.HBox([self.play, self.slider])
        self.widget.add_class("meshvae-frame-player")

    def _on_frame(self, change):
        k = int(change["new"])
        self.viewer.update(list(self._frames[k]))
        if self._frame_values is not None:
            self.viewer.set_colors(values=self._frame_values[k], **self._value_kw)

    @property
    def frame(self) -> int:
        """The frame shown; setting it moves the slider and updates the view."""
        return int(self.slider.value)

    @frame.setter
    def frame(self, k: int):
        k = int(k)
        if not 0 <= k < self.n_frames:
            raise ValueError(f"frame {k} out of range 0..{self.n_frames - 1}")
        self.slider.value = k

    def step(self, k: int = 1) -> int:
        """Advance by ``k`` frames (wrapping around); returns the new frame index."""
        self.frame = (self.frame + int(k)) % self.n_frames
        return self.frame

    def static_png(self) -> bytes:
        """A strip of ``STATIC_STRIP_FRAMES`` evenly spaced frames (first and last included), one row
        per sequence, shaded: what a static page shows of the player (PNG ``bytes``)."""
        from .render import figure_to_png, render_mesh_grid

        idx = self._static_frames()
        n_seq = self._frames.shape[1]
        names = self.viewer.titles or [""] * n_seq
        meshes = [self._frames[i, s] for s in range(n_seq) for i in idx]
        titles = [f"{names[s]} frame {i}".strip() for s in range(n_seq) for i in idx]
        return figure_to_png(render_mesh_grid(meshes, self.viewer.F, titles=titles, ncols=len(idx),
                                              size=self.static_size, dpi=STATIC_DPI))

    def _static_frames(self) -> np.ndarray:
        """The strip's frame indices: ``STATIC_STRIP_FRAMES`` evenly spaced, first and last included."""
        return np.unique(np.linspace(0, self.n_frames - 1, min(self.n_frames, STATIC_STRIP_FRAMES)).round().astype(int))

    def __repr__(self) -> str:
        return f"FramePlayer({self.n_frames} frames, {self.viewer.n_meshes} sequence(s), mode={self.viewer.mode!r})"


class InterpolationSlider(_Displayable):
    """A slider ``t`` in [0, 1] between two meshes.

    Parameters
    ----------
    V_a, V_b : (n_vertices, 3) float
        The two ends.
    F : (n_faces, 3) int
    interpolate : callable, optional
        ``interpolate(t) -> (n_vertices, 3)`` (e.g. decode of a latent blend, or an RIMD blend);
        default the linear blend ``(1 - t) V_a + t V_b``.
    show_ends : bool
        Show ``V_a`` and ``V_b`` left and right of the interpolated mesh.
    step : float
    continuous_update : bool
    static_size : float
        Inches per panel of :meth:`static_png`, the strip a page without widgets shows (default
        ``defaults.STATIC_PANEL_INCHES``).
    **viewer_kw
        Passed to :class:`MeshViewer`.
    """

    def __init__(self, V_a, V_b, F, interpolate=None, show_ends: bool = True, step: float = 0.02,
                 continuous_update: bool = True, static_size: float = STATIC_PANEL_INCHES, **viewer_kw):
        import ipywidgets as W

        if not static_size > 0:
            raise ValueError(f"static_size must be positive, got {static_size}")
        self.static_size = float(static_size)
        A = as_mesh_stack(V_a, n_meshes=1)[0]
        B = as_mesh_stack(V_b, n_meshes=1, n_vertices=len(A))[0]
        self._A, self._B = A, B
        if interpolate is not None and not callable(interpolate):
            raise ValueError(f"interpolate must be callable, got {type(interpolate).__name__}")
        self._interpolate = interpolate
        self.show_ends = show_ends
        mid = self.mesh_at(0.0)
        meshes = [A, mid, B] if show_ends else [mid]
        viewer_kw.setdefault("titles", ["A", "t = 0.00", "B"] if show_ends else None)
        self.viewer = MeshViewer(meshes, F, **viewer_kw)
        self.slider = W.FloatSlider(value=0.0, min=0.0, max=1.0, step=step, description="t",
                                    continuous_update=continuous_update, readout_format=".2f")
        self.slider.observe(self._on_t, names="value")
        self.widget = W.VBox([self.viewer.widget, self.slider]) if self.viewer.widget is not None else self.slider
        self.widget.add_class("meshvae-interpolation")

    def mesh_at(self, t: float) -> np.ndarray:
        """The interpolated mesh at ``t``: ``(n_vertices, 3) float64``."""
        if self._interpolate is None:
            return (1.0 - t) * self._A + t * self._B
        return as_mesh_stack(self._interpolate(float(t)), n_meshes=1, n_vertices=len(self._A))[0]

    def _on_t(self, change):
        V = self.mesh_at(float(change["new"]))
        self.viewer.update(V, index=1 if self.show_ends else 0)

    @property
    def t(self) -> float:
        return float(self.slider.value)

    @t.setter
    def t(self, value: float):
        if not 0.0 <= value <= 1.0:
            raise ValueError(f"t must be in [0, 1], got {value}")
        self.slider.value = float(value)

    def static_png(self) -> bytes:
        """A strip of ``STATIC_STRIP_FRAMES`` meshes along the path, ``t`` evenly spaced from 0 to 1
        (the ends included): what a static page shows of the slider (PNG ``bytes``)."""
        from .render import figure_to_png, render_mesh_grid

        ts = np.linspace(0.0, 1.0, STATIC_STRIP_FRAMES)
        return figure_to_png(render_mesh_grid([self.mesh_at(t) for t in ts], self.viewer.F,
                                              titles=[f"t = {t:.1f}" for t in ts], ncols=len(ts),
                                              size=self.static_size, dpi=STATIC_DPI))

    def __repr__(self) -> str:
        return f"InterpolationSlider({self.viewer.n_vertices} vertices, mode={self.viewer.mode!r})"
