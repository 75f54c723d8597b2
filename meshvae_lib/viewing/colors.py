"""Per-vertex colours: continuous values with a colour bar, reconstruction errors, categorical labels.

All functions return float32 RGB in [0, 1], ready for :func:`~meshvae_lib.viewing.buffers.color_buffer`
and for matplotlib. Only ``matplotlib.colors`` / ``matplotlib.colormaps`` are used (no pyplot).
"""

from __future__ import annotations

import html
from dataclasses import dataclass

import numpy as np

from meshvae_lib.validation import check_vertices

__all__ = [
    "ColorMapping",
    "scalar_colors",
    "error_colors",
    "label_colors",
    "colorbar_html",
    "legend_html",
    "DEFAULT_MESH_COLOR",
]

#: colour of a mesh shown without per-vertex values (a light blue-grey that shades well).
DEFAULT_MESH_COLOR = "#b7c3d6"
#: colour map for reconstruction errors: light for small errors, dark red for large ones.
ERROR_CMAP = "YlOrRd"


def _cmap(name):
    import matplotlib

    try:
        return matplotlib.colormaps[name] if isinstance(name, str) else name
    except KeyError:
        raise ValueError(f"unknown matplotlib colour map {name!r}") from None


@dataclass(frozen=True)
class ColorMapping:
    """How values became colours: the colour map, its range, and what the values are.

    Attributes
    ----------
    cmap : str
        matplotlib colour map name.
    vmin, vmax : float
        Values mapped to the two ends of the colour map (values outside are clipped).
    label : str
        What the values mean (shown next to the colour bar), e.g. ``"error (% of diagonal)"``.
    extend : str
        ``"neither"``, ``"min"``, ``"max"`` or ``"both"``: which ends clipped values past them (a colour
        bar draws a triangle there, as matplotlib's ``extend``).
    """

    cmap: str
    vmin: float
    vmax: float
    label: str = ""
    extend: str = "neither"

    def __call__(self, values) -> np.ndarray:
        """Map values ``(...,)`` float to RGB ``(..., 3) float32``; NaN maps to mid grey."""
        v = np.asarray(values, dtype=np.float64)
        span = self.vmax - self.vmin
        t = (v - self.vmin) / span if span > 0 else np.full_like(v, 0.5)
        nan = ~np.isfinite(t)
        t = np.clip(np.where(nan, 0.0, t), 0.0, 1.0)
        rgb = _cmap(self.cmap)(t)[..., :3]
        rgb[nan] = 0.5
        return rgb.astype(np.float32)

    def stops(self, n: int = 11) -> list[str]:
        """``n`` evenly spaced colours of the map, as ``#rrggbb`` strings (low to high)."""
        from matplotlib.colors import to_hex

        rgb = _cmap(self.cmap)(np.linspace(0.0, 1.0, n))
        return [to_hex(c[:3]) for c in rgb]


def scalar_colors(values, cmap: str = "viridis", vmin=None, vmax=None, label: str = "", show_clipped: bool = False):
    """Colour vertices by a scalar per vertex.

    Parameters
    ----------
    values : (n_vertices,) float or (n_meshes, n_vertices) float
        One value per vertex; several meshes share one range, so their colours compare.
    cmap : str
        matplotlib colour map name.
    vmin, vmax : float, optional
        Range mapped onto the colour map; default the finite minimum and maximum of ``values``.
    label : str
        Caption for the colour bar.
    show_clipped : bool
        If True, the mapping's ``extend`` names the ends that some finite value lies past (its colour
        bar then shows that those values were clipped); default ``"neither"``.

    Returns
    -------
    colors : (n_vertices, 3) or (n_meshes, n_vertices, 3) float32 in [0, 1]
    mapping : ColorMapping
        The range actually used (for :func:`colorbar_html` and the renderers' colour bars).
    """
    v = np.asarray(values, dtype=np.float64)
    if v.ndim not in (1, 2) or v.size == 0:
        raise ValueError(f"values must have shape (n_vertices,) or (n_meshes, n_vertices), got {v.shape}")
    finite = v[np.isfinite(v)]
    lo = float(finite.min()) if vmin is None and finite.size else (0.0 if vmin is None else float(vmin))
    hi = float(finite.max()) if vmax is None and finite.size else (1.0 if vmax is None else float(vmax))
    if hi < lo:
        raise ValueError(f"vmax ({hi}) must not be below vmin ({lo})")
    _cmap(cmap)
    low, high = show_clipped and bool((finite < lo).any()), show_clipped and bool((finite > hi).any())
    extend = {(False, False): "neither", (True, False): "min", (False, True): "max", (True, True): "both"}[low, high]
    mapping = ColorMapping(cmap=cmap if isinstance(cmap, str) else cmap.name, vmin=lo, vmax=hi, label=label,
                           extend=extend)
    return mapping(v), mapping


def error_colors(V_pred, V_true, vmax=None, scale: float = 1.0, cmap: str = ERROR_CMAP, label: str = "error",
                 show_clipped: bool = False):
    """Colour vertices by their distance to the ground truth.

    Parameters
    ----------
    V_pred : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        Reconstructed or generated meshes.
    V_true : (n_vertices, 3) or (n_meshes, n_vertices, 3) float
        Ground truth, broadcast against ``V_pred`` (one truth for several methods works).
    vmax : float, optional
        Error mapped to the darkest colour (after ``scale``); default the largest error, so set it
        explicitly to compare figures made separately.
    scale : float
        Multiplies the distances (e.g. ``100 / bounding_box_diagonal`` for percent of diagonal).
    cmap : str
    label : str
    show_clipped : bool
        Mark the distances past ``vmax`` on the colour bar (``mapping.extend == "max"``); see
        :func:`scalar_colors`.

    Returns
    -------
    colors : (n_vertices, 3) or (n_meshes, n_vertices, 3) float32
    mapping : ColorMapping
        ``vmin`` is 0.
    errors : (n_vertices,) or (n_meshes, n_vertices) float64
        ``scale * |V_pred - V_true|`` per vertex.
    """
    P, T = check_vertices(V_pred, "V_pred"), check_vertices(V_true, "V_true")
    try:
        diff = P - T
    except ValueError:
        raise ValueError(f"V_pred {P.shape} and V_true {T.shape} do not broadcast") from None
    errors = scale * np.linalg.norm(diff, axis=-1)
    colors, mapping = scalar_colors(errors, cmap=cmap, vmin=0.0, vmax=vmax, label=label, show_clipped=show_clipped)
    return colors, mapping, errors


def _palette(n: int, palette: str):
    cm = _cmap(palette)
    size = getattr(cm, "N", 256)
    if size <= 20 and n <= size:  # a qualitative map: take its colours in order
        return np.asarray([cm(i)[:3] for i in range(n)])
    import colorsys

    hues = (np.arange(n) * 0.618033988749895) % 1.0  # golden-ratio spacing keeps neighbours apart
    return np.asarray([colorsys.hsv_to_rgb(h, 0.65, 0.9) for h in hues])


def label_colors(labels, names=None, palette: str = "tab10"):
    """Colour vertices (or meshes) by a categorical label.

    Parameters
    ----------
    labels : (n,) int or str
        One label per vertex (e.g. a body-part segmentation) or per mesh (e.g. a pose class).
    names : dict or sequence, optional
        Display name of each label value (default ``str(value)``).
    palette : str
        A qualitative matplotlib map; more labels than it has colours get evenly spread hues.

    Returns
    -------
    colors : (n, 3) float32
        Equal labels get equal colours, different labels different colours.
    legend : list of (name, "#rrggbb")
        One entry per distinct label, in sorted label order.
    """
    from matplotlib.colors import to_hex

    lab = np.asarray(labels)
    if lab.ndim != 1 or lab.size == 0:
        raise ValueError(f"labels must have shape (n,) with n > 0, got {lab.shape}")
    values, inverse = np.unique(lab, return_inverse=True)
    pal = _palette(len(values), palette)
    colors = pal[inverse.reshape(-1)].astype(np.float32)
    if names is None:
        names = {}
    elif not isinstance(names, dict):
        names = dict(zip(values.tolist(), list(names)))
    legend = [(str(names.get(v, v)), to_hex(pal[i])) for i, v in enumerate(values.tolist())]
    return colors, legend


def _fmt(x: float) -> str:
    return f"{x:.3g}"


def colorbar_html(mapping: ColorMapping, width: int = 240, n_stops: int = 11) -> str:
    """A horizontal colour bar as a small HTML snippet (a CSS gradient; no image, no JavaScript).

    Parameters
    ----------
    mapping : ColorMapping
    width : int
        Width in pixels.
    n_stops : int
        Gradient stops sampled from the colour map.

    Returns
    -------
    html : str
        Shows ``vmin``, the midpoint and ``vmax`` (3 significant digits) under the gradient and
        ``mapping.label`` beside it.
    """
    stops = ", ".join(mapping.stops(n_stops))
    mid = 0.5 * (mapping.vmin + mapping.vmax)
    lab = html.escape(mapping.label)
    return (
        f'<div class="meshvae-colorbar" style="display:flex;align-items:center;gap:8px;font-size:12px">'
        f'<div style="width:{int(width)}px">'
        f'<div style="height:12px;border:1px solid #888;background:linear-gradient(to right, {stops})"></div>'
        f'<div style="display:flex;justify-content:space-between">'
        f"<span>{_fmt(mapping.vmin)}</span><span>{_fmt(mid)}</span><span>{_fmt(mapping.vmax)}</span>"
        f"</div></div><span>{lab}</span></div>"
    )


def legend_html(legend) -> str:
    """Swatches for categorical colours, from :func:`label_colors`'s ``legend``.

    Parameters
    ----------
    legend : list of (name, "#rrggbb")

    Returns
    -------
    html : str
    """
    items = "".join(
        f'<span style="display:inline-flex;align-items:center;gap:4px;margin-right:10px">'
        f'<span style="width:12px;height:12px;background:{html.escape(c)};border:1px solid #666"></span>'
        f"{html.escape(str(n))}</span>"
        for n, c in legend
    )
    return f'<div class="meshvae-legend" style="font-size:12px">{items}</div>'
