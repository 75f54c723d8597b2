"""The latent explorer: a slider per latent dimension, a 2D pad for two of them, reset and seeded
random buttons; every change decodes and updates the 3D view in place (paper Sec. 5.5, Fig. 8).

Usable from code as well (``explorer.set_z(z)``, ``explorer.randomize()``); the sliders follow.
"""

from __future__ import annotations

import logging
import time

import numpy as np

from meshvae_lib.defaults import (EXPLORATION_RANGE, EXPLORER_MIN_DISPLACEMENT, LIVE_UPDATE_MAX_MS, STATIC_DPI,
                                  STATIC_GRID_DIMS, STATIC_PANEL_INCHES)
from meshvae_lib.tolerances import MIN_LATENT_SPREAD
from meshvae_lib.validation import check_choice, check_count
from .latent_pad import LatentPad
from .viewer import MeshViewer, as_mesh_stack
from .widgets import _Displayable

__all__ = ["LatentExplorer"]

log = logging.getLogger(__name__)


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
        Slider range, shared or one row per slider (default ``defaults.EXPLORATION_RANGE``,
        (-2, 2): the paper's browsing range, Fig. 8).
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
    static_size : float
        Inches per panel of :meth:`static_png`, the picture a page without widgets shows
        (default ``defaults.STATIC_PANEL_INCHES``).
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

    def __init__(self, decode, latent_dim: int, F, dims=None, z0=None, value_range=EXPLORATION_RANGE,
                 step: float = 0.05, pad_dims="auto", pad_event: str = "click", seed: int = 0,
                 random_scale=1.0, random_mean=None, reference=None, color_by=None, continuous_update="auto",
                 titles=None, static_size: float = STATIC_PANEL_INCHES, **viewer_kw):
        self._decode = _as_decoder(decode)
        if not static_size > 0:
            raise ValueError(f"static_size must be positive, got {static_size}")
        self.static_size = float(static_size)
        self.latent_dim = check_count(latent_dim, "latent_dim", minimum=1)
        self.dims = self._checked_dims(dims)
        self.ranges = self._checked_ranges(value_range)
        z0 = np.zeros(self.latent_dim) if z0 is None else np.asarray(z0, dtype=np.float64).copy()
        if z0.shape != (self.latent_dim,):
            raise ValueError(f"z0 must have shape ({self.latent_dim},), got {z0.shape}")
        self.z0 = z0
        self._z = z0.copy()
        self.color_by = check_choice(color_by, (None, "displacement"), "color_by")
        self.seed = seed
        self._rng = np.random.default_rng(seed)
        self.random_scale, self.random_mean = self._checked_random(random_scale, random_mean)
        self.n_decodes = 0
        self.last_update_ms = float("nan")
        self._suspended = False
        self._auto_live = check_choice(continuous_update, (True, False, "auto"), "continuous_update") == "auto"
        self._recent_ms: list[float] = []
        self.viewer = self._make_viewer(F, reference, titles, viewer_kw)
        self._make_controls(step, continuous_update, pad_dims, pad_event)
        self._refresh_status()

    # -- construction --------------------------------------------------------------------------
    def _checked_dims(self, dims) -> list[int]:
        dims = list(range(min(self.latent_dim, 6))) if dims is None else [int(d) for d in dims]
        if not dims or len(set(dims)) != len(dims) or min(dims) < 0 or max(dims) >= self.latent_dim:
            raise ValueError(f"dims must be distinct indices in 0..{self.latent_dim - 1}, got {dims}")
        return dims

    def _checked_ranges(self, value_range) -> dict:
        vr = np.asarray(value_range, dtype=np.float64)
        if vr.shape == (2,):
            vr = np.tile(vr, (len(self.dims), 1))
        if vr.shape != (len(self.dims), 2) or not np.all(vr[:, 1] > vr[:, 0]):
            raise ValueError(f"value_range must be (low, high) or {len(self.dims)} rows of (low, high) with "
                             f"low < high, got {np.asarray(value_range).tolist()}")
        return {d: (float(a), float(b)) for d, (a, b) in zip(self.dims, vr)}

    def _checked_random(self, random_scale, random_mean) -> tuple[np.ndarray, np.ndarray]:
        rs = np.asarray(random_scale, dtype=np.float64)
        if rs.shape not in ((), (len(self.dims),)) or np.any(rs < 0):
            raise ValueError(f"random_scale must be >= 0, a number or {len(self.dims)} numbers, got {rs.tolist()}")
        rm = np.zeros(self.latent_dim) if random_mean is None else np.asarray(random_mean, dtype=np.float64)
        if rm.shape != (self.latent_dim,):
            raise ValueError(f"random_mean must have shape ({self.latent_dim},), got {rm.shape}")
        return np.broadcast_to(rs, (len(self.dims),)).copy(), rm.copy()

    def _make_viewer(self, F, reference, titles, viewer_kw) -> MeshViewer:
        """Decode z0 and show it (after ``reference``), with the displacement colours when asked."""
        meshes = self._decode_meshes(self._z)
        self._base = meshes.copy()
        #: the least top of the displacement colour scale: a fraction of the mesh's diagonal (at the
        #: start every displacement is 0, and a zero-width scale says nothing)
        self._displacement_floor = max(
            EXPLORER_MIN_DISPLACEMENT * float(np.linalg.norm(np.ptp(self._base.reshape(-1, 3), axis=0))), 1e-300)
        self._reference = None
        if reference is not None:
            ref = as_mesh_stack(reference, n_meshes=1, n_vertices=meshes.shape[1])
            self._reference = ref
            meshes = np.concatenate([ref, meshes])
        if self.color_by == "displacement":
            viewer_kw.setdefault("values", np.zeros(meshes.shape[:2]))
            viewer_kw.setdefault("cmap", "YlOrRd")
            viewer_kw.setdefault("vmin", 0.0)
            viewer_kw.setdefault("vmax", self._displacement_floor)
            viewer_kw.setdefault("value_label", "displacement")
        return MeshViewer(meshes, F, titles=titles, **viewer_kw)

    def _make_controls(self, step, continuous_update, pad_dims, pad_event) -> None:
        """The sliders, the reset and random buttons, the status line and the pad; ``self.widget``."""
        import ipywidgets as W

        self.sliders = {}
        for d in self.dims:
            lo, hi = self.ranges[d]
            s = W.FloatSlider(value=float(np.clip(self._z[d], lo, hi)), min=lo, max=hi, step=step,
                              description=f"z[{d}]", continuous_update=bool(continuous_update),
                              readout_format=".2f")
            s.observe(lambda change, d=d: self._on_slider(d, change), names="value")
            self.sliders[d] = s
        self.reset_button = W.Button(description="reset", icon="undo", tooltip="back to z0")
        self.random_button = W.Button(description="random", icon="random", tooltip=f"random draw (seed {self.seed})")
        self.reset_button.on_click(lambda _: self.reset())
        self.random_button.on_click(lambda _: self.randomize())
        self.status = W.HTML("")
        self._make_pad(pad_dims, pad_event)
        others = [self.sliders[d] for d in self.dims if self.pad_dims is None or d not in self.pad_dims]
        controls = [W.HBox([self.reset_button, self.random_button, self.status])]
        if self.pad is not None:
            controls.append(self.pad.widget)
        controls += others
        panel = W.VBox(controls)
        self.widget = W.VBox([self.viewer.widget, panel]) if self.viewer.widget is not None else panel
        self.widget.add_class("meshvae-latent-explorer")
        for d, s in self.sliders.items():
            s.add_class(f"meshvae-z{d}")

    def _make_pad(self, pad_dims, pad_event) -> None:
        if pad_dims == "auto":
            pad_dims = tuple(self.dims[:2]) if len(self.dims) >= 2 else None
        self.pad = None
        self.pad_dims = None
        if pad_dims is not None:
            a, b = (int(x) for x in pad_dims)
            if a == b or a not in self.sliders or b not in self.sliders:
                raise ValueError(f"pad_dims must be two different entries of dims {self.dims}, got {pad_dims}")
            self.pad_dims = (a, b)
            self.pad = LatentPad(self.sliders[a], self.sliders[b], event=pad_event,
                                 use_three=self.viewer.mode == "threejs")
            self.pad.on_pick = self._on_pad

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
        half = spread * np.maximum(std[dims], MIN_LATENT_SPREAD)
        ranges = np.stack([mean[dims] - half, mean[dims] + half], axis=1)
        kw.setdefault("z0", mean)
        kw.setdefault("random_mean", mean)
        kw.setdefault("random_scale", std[dims])
        kw.setdefault("step", float(np.min(half)) / 50.0)
        return cls(decode, Z.shape[1], F, dims=dims, value_range=ranges, **kw)

    def static_png(self) -> bytes:
        """What a static page shows of the explorer (PNG ``bytes``): for each of the first
        ``STATIC_GRID_DIMS`` dimensions a row of three meshes, that dimension at the low end of its
        slider, at the start ``z0`` and at the high end (the others at ``z0``)."""
        from .render import figure_to_png, render_mesh_grid

        meshes, titles, count = [], [], self.n_decodes
        for d in self.dims[:STATIC_GRID_DIMS]:
            for v in (self.ranges[d][0], self.z0[d], self.ranges[d][1]):
                z = self.z0.copy()
                z[d] = v
                meshes.append(self._decode_meshes(z)[0])
                titles.append(f"z[{d}] = {v:+.1f}")
        self.n_decodes = count                      # a picture, not a slider move
        return figure_to_png(render_mesh_grid(meshes, self.viewer.F, titles=titles, ncols=3,
                                              size=self.static_size, dpi=STATIC_DPI))

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
                                   vmax=max(float(disp.max()), self._displacement_floor), value_label="displacement")
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
