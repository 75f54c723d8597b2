"""ipywidgets controls around a :class:`~meshvae_lib.viewing.viewer.MeshViewer`.

- :class:`FramePlayer`: play / step through a mesh sequence (one or several side by side).
- :class:`LatentExplorer`: a slider per chosen latent dimension, a clickable 2D pad for two of
  them, reset and seeded random buttons; every change decodes and updates the view in place.
- :class:`InterpolationSlider`: a slider ``t`` in [0, 1] between two meshes (linear blend of
  coordinates, or any ``interpolate(t)`` callable such as latent or RIMD interpolation).

Every control is usable from code as well (``player.frame = 3``, ``explorer.set_z(z)``,
``slider.t = 0.5``), which is what the unit tests and the benchmark do; the sliders follow.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from meshvae_lib.defaults import LIVE_UPDATE_MAX_MS
from .viewer import MeshViewer, as_mesh_stack

__all__ = ["FramePlayer", "LatentPad", "LatentExplorer", "InterpolationSlider"]

log = logging.getLogger(__name__)


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
            data["image/png"] = self.viewer.snapshot_png()
        return data

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
                 **viewer_kw):
        import ipywidgets as W

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

    def __repr__(self) -> str:
        return f"FramePlayer({self.n_frames} frames, {self.viewer.n_meshes} sequence(s), mode={self.viewer.mode!r})"


# -- 2D pad ------------------------------------------------------------------------------------
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


# -- latent explorer ---------------------------------------------------------------------------
def _as_decoder(decode):
    """A callable z (latent_dim,) float64 -> meshes, from a callable or a model with decode_latent."""
    if callable(decode):
        return decode
    if hasattr(decode, "decode_latent"):
        return decode.decode_latent
    raise ValueError(f"decode must be a callable or have a decode_latent method, got {type(decode).__name__}")


class LatentExplorer(_Displayable):
    """Move through a latent space with sliders and watch the decoded mesh change.

    Parameters
    ----------
    decode : callable or model
        ``decode(z)`` with ``z : (latent_dim,) float64`` returning ``(n_vertices, 3)`` (or
        ``(1, n_vertices, 3)``, or ``(k, n_vertices, 3)`` to show k meshes side by side); an object
        with a ``decode_latent`` method (e.g. :class:`~meshvae_lib.model.meshvae_model.MeshVAEModel`) works too.
    latent_dim : int
    F : (n_faces, 3) int
    dims : sequence of int, optional
        Latent dimensions that get a slider (default the first ``min(latent_dim, 6)``).
    z0 : (latent_dim,) float, optional
        Starting point and what "reset" returns to (default zeros, the prior mean).
    value_range : (float, float) or (len(dims), 2) float
        Slider range, shared or one row per slider (default (-3, 3): three prior standard
        deviations).
    step : float
        Slider step.
    pad_dims : (int, int) or None
        Two latent dimensions driven by the 2D pad (default the first two of ``dims``; None: no pad).
    pad_event : {"click", "mousemove"}
    seed : int
        Seed of the "random" button's generator (successive clicks give a reproducible sequence).
    random_scale : float or (len(dims),) float
        Standard deviation of the random draws (clipped to the slider ranges).
    random_mean : (latent_dim,) float, optional
        Centre of the random draws (default zeros, the prior mean).
    reference : (n_vertices, 3) float, optional
        A fixed mesh shown to the left of the decoded one(s), for comparison.
    color_by : {None, "displacement"}
        ``"displacement"`` colours each vertex by its distance to the mesh decoded at ``z0`` (with a
        colour bar), showing which parts the moved dimensions control.
    continuous_update : bool or "auto"
        Decode while a slider is dragged (True) or on release (False). ``"auto"`` (default) starts
        continuous and switches to on-release when the median of the last three updates exceeds
        :data:`~meshvae_lib.defaults.LIVE_UPDATE_MAX_MS`, so a slow model does not build a
        backlog of stale slider positions.
    titles : list of str, optional
    **viewer_kw
        Passed to :class:`MeshViewer` (``width``, ``height``, ``mode``, ...).

    Attributes
    ----------
    viewer : MeshViewer
    sliders : dict int -> ipywidgets.FloatSlider
    pad : LatentPad or None
    n_decodes : int
    last_update_ms : float
        Wall time of the last decode + normals + buffer update, in milliseconds.
    """

    def __init__(self, decode, latent_dim: int, F, dims=None, z0=None, value_range=(-3.0, 3.0),
                 step: float = 0.05, pad_dims="auto", pad_event: str = "click", seed: int = 0,
                 random_scale=1.0, random_mean=None, reference=None, color_by=None, continuous_update="auto",
                 titles=None, **viewer_kw):
        import ipywidgets as W

        self._decode = _as_decoder(decode)
        latent_dim = int(latent_dim)
        if latent_dim < 1:
            raise ValueError(f"latent_dim must be >= 1, got {latent_dim}")
        self.latent_dim = latent_dim
        dims = list(range(min(latent_dim, 6))) if dims is None else [int(d) for d in dims]
        if not dims or len(set(dims)) != len(dims) or min(dims) < 0 or max(dims) >= latent_dim:
            raise ValueError(f"dims must be distinct indices in 0..{latent_dim - 1}, got {dims}")
        self.dims = dims
        vr = np.asarray(value_range, dtype=np.float64)
        if vr.shape == (2,):
            vr = np.tile(vr, (len(dims), 1))
        if vr.shape != (len(dims), 2) or not np.all(vr[:, 1] > vr[:, 0]):
            raise ValueError(f"value_range must be (low, high) or {len(dims)} rows of (low, high) with "
                             f"low < high, got {np.asarray(value_range).tolist()}")
        self.ranges = {d: (float(a), float(b)) for d, (a, b) in zip(dims, vr)}
        z0 = np.zeros(latent_dim) if z0 is None else np.asarray(z0, dtype=np.float64).copy()
        if z0.shape != (latent_dim,):
            raise ValueError(f"z0 must have shape ({latent_dim},), got {z0.shape}")
        self.z0 = z0
        self._z = z0.copy()
        if color_by not in (None, "displacement"):
            raise ValueError(f"color_by must be None or 'displacement', got {color_by!r}")
        self.color_by = color_by
        self.seed = seed
        self._rng = np.random.default_rng(seed)
        rs = np.asarray(random_scale, dtype=np.float64)
        if rs.shape not in ((), (len(dims),)) or np.any(rs < 0):
            raise ValueError(f"random_scale must be >= 0, a number or {len(dims)} numbers, got {rs.tolist()}")
        self.random_scale = np.broadcast_to(rs, (len(dims),)).copy()
        rm = np.zeros(latent_dim) if random_mean is None else np.asarray(random_mean, dtype=np.float64)
        if rm.shape != (latent_dim,):
            raise ValueError(f"random_mean must have shape ({latent_dim},), got {rm.shape}")
        self.random_mean = rm.copy()
        self.n_decodes = 0
        self.last_update_ms = float("nan")
        self._suspended = False
        if continuous_update not in (True, False, "auto"):
            raise ValueError(f"continuous_update must be True, False or 'auto', got {continuous_update!r}")
        self._auto_live = continuous_update == "auto"
        self._recent_ms: list[float] = []

        meshes = self._decode_meshes(self._z)
        self._base = meshes.copy()
        self._reference = None
        if reference is not None:
            ref = as_mesh_stack(reference, n_meshes=1, n_vertices=meshes.shape[1])
            self._reference = ref
            meshes = np.concatenate([ref, meshes])
        if color_by == "displacement":
            viewer_kw.setdefault("values", np.zeros(meshes.shape[:2]))
            viewer_kw.setdefault("cmap", "YlOrRd")
            viewer_kw.setdefault("value_label", "displacement")
        self.viewer = MeshViewer(meshes, F, titles=titles, **viewer_kw)

        self.sliders = {}
        for d in dims:
            lo, hi = self.ranges[d]
            s = W.FloatSlider(value=float(np.clip(self._z[d], lo, hi)), min=lo, max=hi, step=step,
                              description=f"z[{d}]", continuous_update=bool(continuous_update),
                              readout_format=".2f")
            s.observe(lambda change, d=d: self._on_slider(d, change), names="value")
            self.sliders[d] = s
        self.reset_button = W.Button(description="reset", icon="undo", tooltip="back to z0")
        self.random_button = W.Button(description="random", icon="random", tooltip=f"random draw (seed {seed})")
        self.reset_button.on_click(lambda _: self.reset())
        self.random_button.on_click(lambda _: self.randomize())
        self.status = W.HTML("")

        if pad_dims == "auto":
            pad_dims = tuple(dims[:2]) if len(dims) >= 2 else None
        self.pad = None
        self.pad_dims = None
        if pad_dims is not None:
            a, b = (int(x) for x in pad_dims)
            if a == b or a not in self.sliders or b not in self.sliders:
                raise ValueError(f"pad_dims must be two different entries of dims {dims}, got {pad_dims}")
            self.pad_dims = (a, b)
            self.pad = LatentPad(self.sliders[a], self.sliders[b], event=pad_event,
                                 use_three=self.viewer.mode == "threejs")
            self.pad.on_pick = self._on_pad
        others = [self.sliders[d] for d in dims if self.pad_dims is None or d not in self.pad_dims]
        controls = [W.HBox([self.reset_button, self.random_button, self.status])]
        if self.pad is not None:
            controls.append(self.pad.widget)
        controls += others
        panel = W.VBox(controls)
        self.widget = W.VBox([self.viewer.widget, panel]) if self.viewer.widget is not None else panel
        self.widget.add_class("meshvae-latent-explorer")
        for d, s in self.sliders.items():
            s.add_class(f"meshvae-z{d}")
        self._refresh_status()

    @classmethod
    def from_encodings(cls, decode, Z, F, n_dims: int = 6, spread: float = 3.0, **kw) -> "LatentExplorer":
        """An explorer fitted to where the data actually lies in latent space.

        A VAE often leaves many latent dimensions unused (their posterior collapses onto the
        prior), and a slider on such a dimension changes nothing. This picks the ``n_dims``
        dimensions along which the encoded training meshes vary most, starts at their mean, gives
        every slider the range mean +- ``spread`` standard deviations of the data, and draws
        "random" points from the data's per-dimension normal.

        Parameters
        ----------
        decode : callable or model
            As for :class:`LatentExplorer`.
        Z : (n_meshes, latent_dim) float
            Latent means of the training meshes (e.g. ``model.encode_meshes(collection)``).
        F : (n_faces, 3) int
        n_dims : int
            How many sliders.
        spread : float
            Slider half-range in data standard deviations.
        **kw
            Other :class:`LatentExplorer` arguments (``pad_dims``, ``seed``, ``color_by``, ...).

        Returns
        -------
        LatentExplorer
            ``dims`` sorted by decreasing data variance.
        """
        Z = np.asarray(Z, dtype=np.float64)
        if Z.ndim != 2 or Z.shape[0] < 2:
            raise ValueError(f"Z must have shape (n_meshes >= 2, latent_dim), got {Z.shape}")
        n_dims = int(n_dims)
        if not 1 <= n_dims <= Z.shape[1]:
            raise ValueError(f"n_dims must be in 1..{Z.shape[1]}, got {n_dims}")
        mean, std = Z.mean(axis=0), Z.std(axis=0)
        dims = [int(d) for d in np.argsort(-std, kind="stable")[:n_dims]]
        half = spread * np.maximum(std[dims], 1e-6)
        ranges = np.stack([mean[dims] - half, mean[dims] + half], axis=1)
        kw.setdefault("z0", mean)
        kw.setdefault("random_mean", mean)
        kw.setdefault("random_scale", std[dims])
        kw.setdefault("step", float(np.min(half)) / 50.0)
        return cls(decode, Z.shape[1], F, dims=dims, value_range=ranges, **kw)

    # -- decoding ------------------------------------------------------------------------------
    def _decode_meshes(self, z) -> np.ndarray:
        out = self._decode(np.array(z, dtype=np.float64))
        if hasattr(out, "detach"):  # a torch tensor
            out = out.detach().cpu().numpy()
        out = np.asarray(out, dtype=np.float64)
        shape = out.shape
        if out.ndim == 2:
            out = out[None]
        if out.ndim != 3 or out.shape[2] != 3:
            raise ValueError(f"decode(z) must return (n_vertices, 3) or (k, n_vertices, 3), got {shape}")
        self.n_decodes += 1
        return out

    def _show(self):
        """Decode the current z and update the view (the slider callback, end to end)."""
        t0 = time.perf_counter()
        meshes = self._decode_meshes(self._z)
        if meshes.shape != self._base.shape:
            raise ValueError(f"decode returned {meshes.shape}, earlier {self._base.shape}")
        if self._reference is not None:
            meshes = np.concatenate([self._reference, meshes])
        self.viewer.update(meshes)
        if self.color_by == "displacement":
            disp = np.linalg.norm(meshes[-len(self._base):] - self._base, axis=-1)
            if self._reference is not None:
                disp = np.concatenate([np.zeros((1, disp.shape[1])), disp])
            self.viewer.set_colors(values=disp, cmap="YlOrRd", vmin=0.0,
                                   vmax=max(float(disp.max()), 1e-12), value_label="displacement")
        self.last_update_ms = 1e3 * (time.perf_counter() - t0)
        self._adapt_live_updates()
        self._refresh_status()

    @property
    def live(self) -> bool:
        """Whether the sliders decode while dragged (``continuous_update``)."""
        return bool(next(iter(self.sliders.values())).continuous_update)

    def _adapt_live_updates(self):
        if not self._auto_live:
            return
        self._recent_ms = (self._recent_ms + [self.last_update_ms])[-3:]
        if len(self._recent_ms) == 3 and self.live and float(np.median(self._recent_ms)) > LIVE_UPDATE_MAX_MS:
            for s in self.sliders.values():
                s.continuous_update = False
            log.info("decoding takes %.0f ms per update; sliders now decode on release",
                     float(np.median(self._recent_ms)))

    def _refresh_status(self):
        if hasattr(self, "status"):
            ms = "" if np.isnan(self.last_update_ms) else f" &middot; {self.last_update_ms:.0f} ms"
            if not self.live:
                ms += " &middot; updates on release"
            self.status.value = f"<span style='font-size:12px'>|z| = {np.linalg.norm(self._z):.2f}{ms}</span>"

    def _on_slider(self, d: int, change):
        if self._suspended:
            return
        self._z[d] = float(change["new"])
        self._show()

    def _set_sliders(self, values: dict):
        """Move several sliders without decoding once per slider."""
        self._suspended = True
        try:
            for d, v in values.items():
                self.sliders[d].value = float(np.clip(v, *self.ranges[d]))
        finally:
            self._suspended = False

    # -- public controls -----------------------------------------------------------------------
    @property
    def z(self) -> np.ndarray:
        """Current latent vector, ``(latent_dim,) float64`` (a copy)."""
        return self._z.copy()

    def set_z(self, z):
        """Jump to ``z : (latent_dim,) float``; sliders follow (clipped to their range); one decode."""
        z = np.asarray(z, dtype=np.float64)
        if z.shape != (self.latent_dim,):
            raise ValueError(f"z must have shape ({self.latent_dim},), got {z.shape}")
        self._z = z.copy()
        self._set_sliders({d: z[d] for d in self.dims})
        self._show()

    def reset(self):
        """Back to ``z0``."""
        self.set_z(self.z0)

    def randomize(self) -> np.ndarray:
        """Draw the slider dimensions from N(random_mean, random_scale^2) (seeded, clipped to the
        slider ranges); the other dimensions keep their value."""
        z = self._z.copy()
        draw = self.random_mean[self.dims] + self._rng.standard_normal(len(self.dims)) * self.random_scale
        lo = np.array([self.ranges[d][0] for d in self.dims])
        hi = np.array([self.ranges[d][1] for d in self.dims])
        z[self.dims] = np.clip(draw, lo, hi)
        self.set_z(z)
        return self.z

    def _on_pad(self, xv: float, yv: float):
        a, b = self.pad_dims
        z = self._z.copy()
        z[a], z[b] = xv, yv
        self.set_z(z)

    @property
    def meshes(self) -> np.ndarray:
        """What the view shows now, ``(n_meshes, n_vertices, 3) float32``."""
        return np.stack(self.viewer.positions)

    def __repr__(self) -> str:
        return (f"LatentExplorer(latent_dim={self.latent_dim}, dims={self.dims}, pad_dims={self.pad_dims}, "
                f"mode={self.viewer.mode!r})")


# -- interpolation -----------------------------------------------------------------------------
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
    **viewer_kw
        Passed to :class:`MeshViewer`.
    """

    def __init__(self, V_a, V_b, F, interpolate=None, show_ends: bool = True, step: float = 0.02,
                 continuous_update: bool = True, **viewer_kw):
        import ipywidgets as W

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

    def __repr__(self) -> str:
        return f"InterpolationSlider({self.viewer.n_vertices} vertices, mode={self.viewer.mode!r})"
