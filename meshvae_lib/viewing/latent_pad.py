"""A clickable 2D pad that sets two latent values at once (the first level of Fig. 8, continuously)."""

from __future__ import annotations

import numpy as np

__all__ = ["LatentPad"]


class LatentPad:
    """A clickable square that sets two values at once, plus the two sliders it is linked to.

    In "threejs" mode the pad is a small pythreejs view of a grid on a plane; a ``Picker`` reports
    where the user clicks (or, with ``event="mousemove"``, where the pointer hovers), which sets the
    two sliders; moving a slider moves the marker. Elsewhere only the sliders are shown.

    Parameters
    ----------
    x_slider, y_slider : ipywidgets.FloatSlider
        Their ``min``/``max`` define the pad's range.
    size : int
        Pixels.
    event : str
        DOM event the picker listens to: ``"click"`` (default) or ``"mousemove"``.
    use_three : bool
    """

    def __init__(self, x_slider, y_slider, size: int = 160, event: str = "click", use_three: bool = True):
        import ipywidgets as W

        self.x_slider, self.y_slider = x_slider, y_slider
        self.picker = None
        self.marker = None
        parts = []
        if use_three:
            import pythreejs as three

            plane = three.Mesh(geometry=three.PlaneGeometry(width=2.0, height=2.0),
                               material=three.MeshBasicMaterial(color="#f2f4f8", side="DoubleSide"))
            lines = []
            for t in np.linspace(-1.0, 1.0, 9):
                lines += [[t, -1.0, 0.001], [t, 1.0, 0.001], [-1.0, t, 0.001], [1.0, t, 0.001]]
            grid = three.LineSegments(
                geometry=three.BufferGeometry(attributes={"position": three.BufferAttribute(
                    array=np.array(lines, dtype=np.float32), normalized=False)}),
                material=three.LineBasicMaterial(color="#b8bfcc"))
            axes = three.LineSegments(
                geometry=three.BufferGeometry(attributes={"position": three.BufferAttribute(
                    array=np.array([[-1, 0, 0.002], [1, 0, 0.002], [0, -1, 0.002], [0, 1, 0.002]], dtype=np.float32),
                    normalized=False)}),
                material=three.LineBasicMaterial(color="#6b7385"))
            self.marker = three.Mesh(geometry=three.CircleGeometry(radius=0.07, segments=24),
                                     material=three.MeshBasicMaterial(color="#d62728"), position=self._marker_xy())
            camera = three.OrthographicCamera(left=-1.05, right=1.05, top=1.05, bottom=-1.05, near=0.1, far=10.0,
                                              position=(0.0, 0.0, 5.0))
            scene = three.Scene(children=[plane, grid, axes, self.marker, camera], background="#ffffff")
            self.picker = three.Picker(controlling=plane, event=event)
            self.picker.observe(self._on_pick, names="point")
            self.renderer = three.Renderer(camera=camera, scene=scene, controls=[self.picker], width=size,
                                           height=size, antialias=True)
            parts.append(self.renderer)
        x_slider.observe(self._on_slider, names="value")
        y_slider.observe(self._on_slider, names="value")
        self.widget = W.HBox([*parts, W.VBox([W.HTML("<b>2D pad</b>"), x_slider, y_slider])])
        self.widget.add_class("meshvae-latent-pad")

    @staticmethod
    def _to_unit(s) -> float:
        span = s.max - s.min
        return 0.0 if span <= 0 else 2.0 * (s.value - s.min) / span - 1.0

    def _marker_xy(self):
        return (self._to_unit(self.x_slider), self._to_unit(self.y_slider), 0.003)

    def _on_slider(self, change):
        if self.marker is not None:
            self.marker.position = self._marker_xy()

    def pick(self, u: float, v: float):
        """Act as if the pad was clicked at unit coordinates ``(u, v)`` in [-1, 1]^2."""
        u, v = float(np.clip(u, -1.0, 1.0)), float(np.clip(v, -1.0, 1.0))
        xs, ys = self.x_slider, self.y_slider
        xv = xs.min + 0.5 * (u + 1.0) * (xs.max - xs.min)
        yv = ys.min + 0.5 * (v + 1.0) * (ys.max - ys.min)
        self.on_pick(xv, yv)

    def on_pick(self, xv: float, yv: float):
        """Set both sliders (overridden by :class:`LatentExplorer` to decode once for both)."""
        self.x_slider.value, self.y_slider.value = xv, yv

    def _on_pick(self, change):
        p = change["new"]
        if p is None:
            return
        self.pick(p[0], p[1])
